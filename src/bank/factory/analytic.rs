//! The analytic factory banks: the files `presets/<slug>.json`, built into the program.
//!
//! The recipes in [`crate::authoring::factory_recipes`] wrote them; `tests/factory_presets.rs`
//! checks that this list is the recipes' list, in their order, and that each file is what its
//! recipe designs.

use crate::bank::{parse_bank_str, Bank};

/// An analytic bank's file in `presets/` and its text.
pub struct AnalyticPreset {
    /// File name in `presets/`: the bank's slug and `.json`.
    pub file: &'static str,
    /// The file's JSON.
    pub json: &'static str,
}

/// Embeds `presets/<name>`.
macro_rules! analytic {
    ($file:literal) => {
        AnalyticPreset {
            file: $file,
            json: include_str!(concat!("../../../presets/", $file)),
        }
    };
}

/// The analytic banks, in display order.
pub const ANALYTIC_PRESETS: [AnalyticPreset; 28] = [
    analytic!("ideal-string.json"),
    analytic!("piano-like-stiff-string.json"),
    analytic!("steel-free-free-bar.json"),
    analytic!("rosewood-marimba-bar.json"),
    analytic!("aluminium-vibraphone-bar.json"),
    analytic!("rosewood-claves.json"),
    analytic!("spruce-xylophone-bar.json"),
    analytic!("glass-chime-bar.json"),
    analytic!("aluminium-chime-bar.json"),
    analytic!("kalimba-tine.json"),
    analytic!("steel-tuning-fork.json"),
    analytic!("steel-triangle.json"),
    analytic!("circular-membrane.json"),
    analytic!("steel-plate.json"),
    analytic!("glass-plate.json"),
    analytic!("rectangular-frame-drum.json"),
    analytic!("acrylic-plate.json"),
    analytic!("spruce-panel.json"),
    analytic!("scraped-steel-sheet.json"),
    analytic!("spruce-table-top-rolled-ball.json"),
    analytic!("rubbed-wine-glass.json"),
    analytic!("singing-bowl-circled-with-a-stick.json"),
    analytic!("brass-disc-cymbal-like.json"),
    analytic!("bronze-flat-gong.json"),
    analytic!("porcelain-saucer.json"),
    analytic!("bronze-bell.json"),
    analytic!("small-brass-bell.json"),
    analytic!("porcelain-bell.json"),
];

impl AnalyticPreset {
    /// The bank. The files are checked by the tests, so a broken one is a bug in the build.
    pub fn bank(&self) -> Bank {
        parse_bank_str(self.json, &format!("presets/{}", self.file))
            .unwrap_or_else(|e| panic!("a built-in analytic bank is invalid: {e}"))
    }

    /// The file name without `.json`: the bank's slug.
    pub fn stem(&self) -> &'static str {
        self.file.trim_end_matches(".json")
    }
}
