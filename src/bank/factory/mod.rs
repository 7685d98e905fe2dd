//! The factory banks, all of them files built into the program: analytic objects at musical
//! pitches (`presets/<slug>.json`, `analytic.rs`, designed by the recipes in
//! [`crate::authoring::factory_recipes`]), banks fitted to recordings of real objects
//! (`presets/fitted/`, `fitted.rs`) and banks made from meshes the project generates
//! (`presets/meshed/`, `meshed.rs`). The factory is data: it designs nothing at run time.
//!
//! The table in `presets/README.md` is generated here; the test `factory_presets_are_up_to_date`
//! (tests/factory_presets.rs) fails when it or an analytic file drifts from its recipe, and
//! `UPDATE_PRESETS=1 cargo test --test factory_presets` rewrites them.

pub mod analytic;
mod compare;
pub mod fitted;
pub mod meshed;
mod table;

pub use compare::first_difference;
pub use table::factory_table_markdown;

use crate::bank::{parse_bank_str, Bank};
use analytic::{AnalyticPreset, ANALYTIC_PRESETS};
use fitted::{FittedPreset, FITTED_PRESETS};
use meshed::{MeshedPreset, MESHED_PRESETS};

/// Name of the generated table of factory banks, next to the presets.
pub const FACTORY_TABLE_FILE: &str = "README.md";

/// Marks the start of the generated factory table in `presets/README.md`.
pub const FACTORY_TABLE_BEGIN: &str = "<!-- factory table: generated, do not edit -->\n";

/// Marks the end of the generated factory table in `presets/README.md`.
pub const FACTORY_TABLE_END: &str = "<!-- end of factory table -->\n";

/// `readme` with the text between the factory table markers replaced by `table`, or `None` when
/// the markers are missing.
pub fn splice_factory_table(readme: &str, table: &str) -> Option<String> {
    let start = readme.find(FACTORY_TABLE_BEGIN)? + FACTORY_TABLE_BEGIN.len();
    let end = start + readme[start..].find(FACTORY_TABLE_END)?;
    Some(format!("{}{}{}", &readme[..start], table, &readme[end..]))
}

/// The analytic factory banks, in display order (the files `presets/<slug>.json`).
pub fn analytic_factory_banks() -> Vec<Bank> {
    ANALYTIC_PRESETS.iter().map(AnalyticPreset::bank).collect()
}

/// The factory banks fitted to recordings, in display order (the files in `presets/fitted/`).
pub fn fitted_factory_banks() -> Vec<Bank> {
    FITTED_PRESETS.iter().map(FittedPreset::bank).collect()
}

/// The factory banks made from meshes, in display order (the files in `presets/meshed/`).
pub fn meshed_factory_banks() -> Vec<Bank> {
    MESHED_PRESETS.iter().map(MeshedPreset::bank).collect()
}

/// Every factory bank, in display order: the analytic ones, the fitted ones, then the meshed
/// ones.
pub fn factory_banks() -> Vec<Bank> {
    let mut banks = analytic_factory_banks();
    banks.extend(fitted_factory_banks());
    banks.extend(meshed_factory_banks());
    banks
}

/// The bank's name in lowercase with runs of anything but ASCII letters and digits turned into
/// single hyphens: "Piano-like stiff string" gives "piano-like-stiff-string". Used as the preset
/// file name and on the command line.
pub fn factory_slug(bank: &Bank) -> String {
    slugify(&bank.name)
}

fn slugify(name: &str) -> String {
    let mut slug = String::with_capacity(name.len());
    for c in name.chars() {
        if c.is_ascii_alphanumeric() {
            slug.push(c.to_ascii_lowercase());
        } else if !slug.is_empty() && !slug.ends_with('-') {
            slug.push('-');
        }
    }
    while slug.ends_with('-') {
        slug.pop();
    }
    slug
}

/// The factory bank played when a plugin's state holds none.
pub const DEFAULT_FACTORY_BANK: &str = "rosewood-marimba-bar";

/// The bank a plugin's state saved as `json` (the default factory bank when empty). Errors name
/// what is wrong.
pub fn bank_from_state(json: &str) -> Result<Bank, String> {
    if json.trim().is_empty() {
        return factory_bank(DEFAULT_FACTORY_BANK)
            .ok_or_else(|| format!("factory bank {DEFAULT_FACTORY_BANK} is missing"));
    }
    parse_bank_str(json, "saved bank").map_err(|e| e.to_string())
}

/// The factory bank with this name (any case) or slug; a fitted bank also by its file's name
/// ("celesta" for `presets/fitted/celesta.json`).
pub fn factory_bank(name_or_slug: &str) -> Option<Bank> {
    let wanted = slugify(name_or_slug);
    // Built-in files, analytic, fitted then meshed, as (bank, file stem).
    let analytic = ANALYTIC_PRESETS.iter().map(|p| (p.bank(), p.stem()));
    let fitted = FITTED_PRESETS.iter().map(|p| (p.bank(), p.stem()));
    let meshed = MESHED_PRESETS.iter().map(|p| (p.bank(), p.stem()));
    analytic
        .chain(fitted)
        .chain(meshed)
        .find_map(|(bank, stem)| (factory_slug(&bank) == wanted || stem == wanted).then_some(bank))
}

/// Where the factory bank's file is, relative to `presets/`: `<slug>.json` for an analytic bank,
/// `fitted/<file>` for a fitted one, `meshed/<file>` for one made from a mesh.
pub fn factory_file(bank: &Bank) -> String {
    if let Some(preset) = FITTED_PRESETS
        .iter()
        .find(|preset| preset.bank().name == bank.name)
    {
        return format!("fitted/{}", preset.file);
    }
    match MESHED_PRESETS
        .iter()
        .find(|preset| preset.bank().name == bank.name)
    {
        Some(preset) => format!("meshed/{}", preset.file),
        None => format!("{}.json", factory_slug(bank)),
    }
}

/// The text of a bank's preset file: pretty JSON and a trailing newline.
pub fn preset_json(bank: &Bank) -> String {
    crate::bank::io::bank_to_json(bank)
}

#[cfg(test)]
mod tests;
