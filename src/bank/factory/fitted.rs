//! Factory banks fitted to recordings of real struck objects: the files in `presets/fitted/`,
//! built into the program so that the plugin and the command line have them too.
//!
//! `tests/fit_recordings.rs` makes these files with `modal-resonator fit` from recordings that
//! Debian packages ship, and writes into each its provenance, its licence (the recording's), its
//! root and its defaults; `tests/presets.rs` checks that every file loads and renders in tune.

use crate::bank::{parse_bank_str, Bank};

/// A fitted bank's file in `presets/fitted/` and its text.
pub struct FittedPreset {
    /// File name in `presets/fitted/`.
    pub file: &'static str,
    /// The file's JSON.
    pub json: &'static str,
}

/// Embeds `presets/fitted/<name>`.
macro_rules! fitted {
    ($file:literal) => {
        FittedPreset {
            file: $file,
            json: include_str!(concat!("../../../presets/fitted/", $file)),
        }
    };
}

/// The fitted banks, in display order.
pub const FITTED_PRESETS: [FittedPreset; 6] = [
    fitted!("tubular-bell.json"),
    fitted!("glockenspiel.json"),
    fitted!("marimba.json"),
    fitted!("celesta.json"),
    fitted!("hand-bell.json"),
    fitted!("cowbell.json"),
];

impl FittedPreset {
    /// The bank. The files are checked by the tests, so a broken one is a bug in the build.
    pub fn bank(&self) -> Bank {
        parse_bank_str(self.json, &format!("presets/fitted/{}", self.file))
            .unwrap_or_else(|e| panic!("a built-in fitted bank is invalid: {e}"))
    }

    /// The file name without `.json`, which also finds the bank by name.
    pub fn stem(&self) -> &'static str {
        self.file.trim_end_matches(".json")
    }
}
