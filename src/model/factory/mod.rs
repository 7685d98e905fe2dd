//! The factory banks: analytic objects at musical pitches (`presets/<slug>.json`, generated from
//! the tables in `bars.rs` and `surfaces.rs`) and banks fitted to recordings of real objects
//! (`presets/fitted/`, built in by `fitted.rs`) and banks made from meshes the project generates
//! (`presets/meshed/`, built in by `meshed.rs`). All of them are built into the program.
//!
//! The committed analytic preset files and the table in `presets/README.md` are generated here;
//! the test `factory_presets_are_up_to_date` (tests/factory_presets.rs) fails when they drift,
//! and `UPDATE_PRESETS=1 cargo test factory_presets` rewrites them.

mod bars;
mod compare;
pub mod fitted;
pub mod meshed;
mod surfaces;
mod table;

pub use compare::first_difference;
pub use table::factory_table_markdown;

use crate::model::materials::Material;
use crate::model::shapes::{design_bank, BankDesign, ModeLimits, Shape};
use crate::model::{parse_bank_str, Bank};
use crate::units::midi_key_to_hz;
use fitted::{FittedPreset, FITTED_PRESETS};
use meshed::{MeshedPreset, MESHED_PRESETS};
use std::path::{Path, PathBuf};

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

/// MIDI keys of the pitches the factory objects are tuned to.
mod key {
    pub const A1: u8 = 33;
    pub const C2: u8 = 36;
    pub const E2: u8 = 40;
    pub const F2: u8 = 41;
    pub const A2: u8 = 45;
    pub const A3: u8 = 57;
    pub const D3: u8 = 50;
    pub const F3: u8 = 53;
    pub const C4: u8 = 60;
    pub const G4: u8 = 67;
    pub const A4: u8 = 69;
    pub const C5: u8 = 72;
    pub const E5: u8 = 76;
    pub const F5: u8 = 77;
    pub const A5: u8 = 81;
    pub const C6: u8 = 84;
    pub const D6: u8 = 86;
    pub const G6: u8 = 91;
    pub const D7: u8 = 98;
}

/// One analytic factory bank before it is built.
struct FactoryObject {
    /// Display name, also the source of the slug.
    name: &'static str,
    /// What it is and how it sounds (the shape's summary is appended).
    description: &'static str,
    /// The object, with starting dimensions; [`Self::root_key`] retunes it.
    shape: Shape,
    /// What it is made of.
    material: &'static Material,
    /// MIDI key of the pitch the object is tuned to.
    root_key: u8,
    /// Departures from what the object's family gets by default.
    tweaks: Tweaks,
}

/// Settings a factory bank may change from its family's defaults.
#[derive(Debug, Clone, Copy)]
struct Tweaks {
    /// Mallet contact time in ms, instead of the family's.
    hardness_ms: Option<f64>,
    /// Name of the position struck by default, moved to the front, instead of the one nearest
    /// the family's usual strike point.
    strike_at: Option<&'static str>,
    /// A contact the bank is played with by default, instead of a strike.
    contact: Option<Contact>,
}

/// A contact a factory bank is played with: `defaults.exciter` and the contact's settings.
#[derive(Debug, Clone, Copy)]
struct Contact {
    /// `scrape`, `roll` or `rub`.
    exciter: &'static str,
    /// Roughness, 0 to 1.
    roughness: f64,
    /// Radius of a rolling object in mm (a roll only).
    rolling_radius_mm: Option<f64>,
    /// Speed in m/s.
    speed_m_per_s: f64,
    /// Force at full velocity, 0 to 1.
    force: f64,
}

impl Tweaks {
    /// The family's defaults throughout.
    const NONE: Tweaks = Tweaks {
        hardness_ms: None,
        strike_at: None,
        contact: None,
    };
}

/// Every analytic factory object, in display order.
fn factory_objects() -> Vec<FactoryObject> {
    let mut objects = bars::objects();
    objects.extend(surfaces::objects());
    objects
}

impl FactoryObject {
    fn build(&self) -> Bank {
        let design = BankDesign {
            name: self.name.to_string(),
            description: self.description.to_string(),
            shape: self.shape.clone(),
            material: self.material,
            positions: None,
            limits: ModeLimits::default(),
            root_hz: Some(midi_key_to_hz(f64::from(self.root_key))),
        };
        let (mut bank, _) =
            design_bank(&design).unwrap_or_else(|e| panic!("factory bank {:?}: {e}", self.name));
        let defaults = bank.defaults.get_or_insert_with(Default::default);
        if let Some(hardness_ms) = self.tweaks.hardness_ms {
            defaults.hardness_ms = Some(hardness_ms);
        }
        if let Some(c) = self.tweaks.contact {
            defaults.exciter = Some(c.exciter.to_string());
            defaults.roughness = Some(c.roughness);
            defaults.rolling_radius_mm = c.rolling_radius_mm;
            defaults.contact_speed_m_per_s = Some(c.speed_m_per_s);
            defaults.contact_force = Some(c.force);
        }
        if let Some(name) = self.tweaks.strike_at {
            strike_first(&mut bank, name)
                .unwrap_or_else(|| panic!("factory bank {:?}: no position {name:?}", self.name));
        }
        bank
    }
}

/// Moves the position called `name`, and its gain in every mode, to the front: a bank is struck
/// at its first position by default, and its loudness is set there. `None` if there is no such
/// position.
fn strike_first(bank: &mut Bank, name: &str) -> Option<()> {
    let k = bank.positions.iter().position(|p| p.name == name)?;
    let position = bank.positions.remove(k);
    bank.positions.insert(0, position);
    for mode in &mut bank.modes {
        let gain = mode.gains.remove(k);
        mode.gains.insert(0, gain);
    }
    Some(())
}

/// The analytic factory banks, in display order: the ones written to `presets/<slug>.json`.
pub fn analytic_factory_banks() -> Vec<Bank> {
    factory_objects().iter().map(FactoryObject::build).collect()
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
    if let Some(object) = factory_objects()
        .iter()
        .find(|object| slugify(object.name) == wanted)
    {
        return Some(object.build());
    }
    // Built-in files, fitted then meshed, as (bank, file stem).
    let files = FITTED_PRESETS
        .iter()
        .map(|preset| (preset.bank(), preset.stem()))
        .chain(
            MESHED_PRESETS
                .iter()
                .map(|preset| (preset.bank(), preset.stem())),
        );
    files
        .into_iter()
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
    crate::model::io::bank_to_json(bank)
}

/// Writes every analytic factory bank to `dir/<slug>.json`, creating `dir` if needed; returns
/// the paths. (The fitted banks are made from recordings, by `tests/fit_recordings.rs`.)
pub fn write_factory_presets(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    analytic_factory_banks()
        .iter()
        .map(|bank| {
            let path = dir.join(format!("{}.json", factory_slug(bank)));
            std::fs::write(&path, preset_json(bank))?;
            Ok(path)
        })
        .collect()
}

#[cfg(test)]
mod tests;
