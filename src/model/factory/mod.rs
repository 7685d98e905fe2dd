//! The factory banks: analytic objects at musical pitches (`presets/<slug>.json`, generated from
//! the tables in `bars.rs` and `surfaces.rs`) and banks fitted to recordings of real objects
//! (`presets/fitted/`, built in by `fitted.rs`). All of them are built into the program.
//!
//! The committed analytic preset files and the table in `presets/README.md` are generated here;
//! the test `factory_presets_are_up_to_date` (tests/factory_presets.rs) fails when they drift,
//! and `UPDATE_PRESETS=1 cargo test factory_presets` rewrites them.

mod bars;
mod compare;
pub mod fitted;
mod surfaces;

pub use compare::first_difference;

use crate::dsp::coeffs::midi_key_to_hz;
use crate::model::materials::Material;
use crate::model::shapes::{design_bank, BankDesign, ModeLimits, Shape};
use crate::model::summary::note_name;
use crate::model::Bank;
use fitted::{FittedPreset, FITTED_PRESETS};
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
}

impl Tweaks {
    /// The family's defaults throughout.
    const NONE: Tweaks = Tweaks {
        hardness_ms: None,
        strike_at: None,
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

/// Every factory bank, in display order: the analytic ones, then the fitted ones.
pub fn factory_banks() -> Vec<Bank> {
    let mut banks = analytic_factory_banks();
    banks.extend(fitted_factory_banks());
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
    FITTED_PRESETS.iter().find_map(|preset| {
        let bank = preset.bank();
        (factory_slug(&bank) == wanted || preset.stem() == wanted).then_some(bank)
    })
}

/// Where the factory bank's file is, relative to `presets/`: `<slug>.json` for an analytic bank,
/// `fitted/<file>` for a fitted one.
pub fn factory_file(bank: &Bank) -> String {
    let fitted = FITTED_PRESETS
        .iter()
        .find(|preset| preset.bank().name == bank.name);
    match fitted {
        Some(preset) => format!("fitted/{}", preset.file),
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

/// What a factory bank was made from, for the table: "free-free-bar, steel", or the recording.
fn made_from(bank: &Bank) -> String {
    let field = |key: &str| {
        bank.source
            .as_ref()
            .and_then(|s| s.get(key))
            .and_then(|v| v.as_str())
            .unwrap_or("")
            .to_string()
    };
    if field("kind") == "fitted" {
        let file = field("file");
        let file = file.rsplit('/').next().unwrap_or("");
        format!(
            "fitted to a recording: {} `{file}`",
            field("debian_package")
        )
    } else {
        format!("{}, {}", field("shape"), field("material"))
    }
}

/// The Markdown table of the factory banks, kept in `presets/README.md`.
pub fn factory_table_markdown(banks: &[Bank]) -> String {
    let mut text = String::from(
        "Generated from `src/model/factory/` by `UPDATE_PRESETS=1 cargo test factory_presets`; \
         do not edit by hand. Analytic banks (`source.kind = \"analytic\"`) have the closed-form \
         modes of the object (`src/model/shapes/`), decays from the material \
         (`src/model/materials.rs`) and gains `Psi_n(p) / omega_n` at each strike position \
         (seed 000 eq. 3.11); fitted banks (`source.kind = \"fitted\"`) were measured from a \
         recording by `modal-resonator fit`.\n\n\
         | Name | Slug (CLI) | File | Made from | Root | Modes | Licence |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for bank in banks {
        let root_hz = bank.effective_root_hz();
        text.push_str(&format!(
            "| {} | `{}` | `{}` | {} | {:.2} Hz ({}) | {} | {} |\n",
            bank.name,
            factory_slug(bank),
            factory_file(bank),
            made_from(bank),
            root_hz,
            note_name(root_hz),
            bank.modes.len(),
            bank.license,
        ));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::materials;
    use crate::model::shapes::OBJECTS;
    use crate::model::validate::validate_bank;
    use std::collections::HashSet;

    /// The list of materials, by the representatives the factory uses.
    const LIBRARY_MATERIALS: [&str; 8] = [
        "steel",
        "aluminium",
        "brass",
        "glass",
        "porcelain",
        "rosewood",
        "spruce",
        "acrylic",
    ];

    fn source_str<'a>(bank: &'a Bank, key: &str) -> &'a str {
        bank.source
            .as_ref()
            .and_then(|s| s.get(key))
            .and_then(|v| v.as_str())
            .unwrap_or("")
    }

    #[test]
    fn the_library_is_complete_and_distinct() {
        let banks = factory_banks();
        assert!(banks.len() >= 24, "{} factory banks", banks.len());
        let mut names = HashSet::new();
        let mut slugs = HashSet::new();
        for bank in &banks {
            let what = &bank.name;
            assert!(
                validate_bank(bank).is_empty(),
                "{what}: {:?}",
                validate_bank(bank)
            );
            assert!(
                names.insert(bank.name.to_lowercase()),
                "duplicate name {what}"
            );
            assert!(
                slugs.insert(factory_slug(bank)),
                "duplicate slug for {what}"
            );
            assert!(bank.description.len() > 40, "{what}: {}", bank.description);
            assert!(
                !bank.license.is_empty() && !bank.author.is_empty(),
                "{what}"
            );
            let defaults = bank
                .defaults
                .as_ref()
                .expect("every factory bank has defaults");
            assert!(defaults.hardness_ms.is_some(), "{what}");
            let root_hz = bank.root_hz.unwrap_or_else(|| panic!("{what}: no root_hz"));
            assert!(root_hz > 20.0 && root_hz < 5000.0, "{what}: {root_hz}");
            // The root is a mode of the bank (for a bell, the prime above the hum).
            assert!(
                bank.modes
                    .iter()
                    .any(|m| (m.freq_hz / root_hz - 1.0).abs() < 1e-12),
                "{what}: root {root_hz} Hz is not a mode"
            );
        }
        let fitted = fitted_factory_banks();
        assert_eq!(fitted.len(), FITTED_PRESETS.len());
        for bank in &fitted {
            assert_eq!(source_str(bank, "kind"), "fitted", "{}", bank.name);
            assert!(!source_str(bank, "recording").is_empty(), "{}", bank.name);
        }
    }

    #[test]
    fn analytic_banks_cover_every_object_and_material() {
        let banks = analytic_factory_banks();
        for bank in &banks {
            assert_eq!(bank.license, "CC0-1.0", "{}", bank.name);
            assert_eq!(bank.author, "Modal Resonator", "{}", bank.name);
            assert_eq!(source_str(bank, "kind"), "analytic", "{}", bank.name);
        }
        let shapes: HashSet<&str> = banks.iter().map(|b| source_str(b, "shape")).collect();
        for object in OBJECTS {
            assert!(shapes.contains(object.name), "no factory {}", object.name);
        }
        let used: HashSet<&str> = banks.iter().map(|b| source_str(b, "material")).collect();
        for name in LIBRARY_MATERIALS {
            assert!(used.contains(name), "no factory bank of {name}");
            assert!(materials::Material::by_name(name).is_some());
        }
    }

    #[test]
    fn analytic_banks_sit_on_equal_tempered_notes() {
        for bank in analytic_factory_banks() {
            let note = note_name(bank.root_hz.unwrap());
            assert!(!note.contains(" c"), "{}: {note}", bank.name);
        }
        assert_eq!(note_name(440.0), "A4");
        assert_eq!(note_name(261.625_565_300_598_6), "C4");
        assert_eq!(note_name(27.5), "A0");
        assert_eq!(note_name(446.0), "A4 +23 c");
    }

    #[test]
    fn tweaks_reach_the_defaults() {
        let gong = factory_bank("bronze-flat-gong").unwrap();
        assert_eq!(gong.defaults.as_ref().unwrap().hardness_ms, Some(3.0));
        // Struck near the centre by default: that position first, its gains moved with it.
        assert_eq!(gong.positions[0].name, "third radius");
        assert_eq!(gong.positions[1].name, "two-thirds radius");
        let mut unmoved = gong.clone();
        strike_first(&mut unmoved, "two-thirds radius").unwrap();
        for (a, b) in gong.modes.iter().zip(&unmoved.modes) {
            assert_eq!((a.gains[0], a.gains[1]), (b.gains[1], b.gains[0]));
        }
        assert!(strike_first(&mut unmoved, "no such position").is_none());
    }

    #[test]
    fn slugs_and_lookup() {
        assert_eq!(
            slugify("Piano-like stiff string"),
            "piano-like-stiff-string"
        );
        assert_eq!(slugify("  Steel  plate (2 mm)! "), "steel-plate-2-mm");
        for bank in factory_banks() {
            let slug = factory_slug(&bank);
            assert_eq!(factory_bank(&slug).as_ref(), Some(&bank));
            assert_eq!(
                factory_bank(&bank.name.to_uppercase()).as_ref(),
                Some(&bank)
            );
        }
        // Fitted banks also by their file's name.
        let celesta = factory_bank("celesta").unwrap();
        assert_eq!(factory_file(&celesta), "fitted/celesta.json");
        assert_eq!(
            factory_file(&factory_bank("steel-plate").unwrap()),
            "steel-plate.json"
        );
        assert_eq!(factory_bank("no such bank"), None);
    }

    #[test]
    fn presets_round_trip_through_json() {
        for bank in factory_banks() {
            let text = preset_json(&bank);
            assert!(text.ends_with("}\n"));
            let parsed: Bank = serde_json::from_str(&text).unwrap();
            assert_eq!(
                first_difference(&parsed, &bank, 1e-15),
                None,
                "{}",
                bank.name
            );
        }
        // A fitted bank written back is its file, byte for byte.
        for preset in &FITTED_PRESETS {
            assert_eq!(preset_json(&preset.bank()), preset.json, "{}", preset.file);
        }
    }

    #[test]
    fn writes_one_file_per_analytic_bank() {
        let dir = tempfile::tempdir().unwrap();
        let paths = write_factory_presets(dir.path()).unwrap();
        let banks = analytic_factory_banks();
        assert_eq!(paths.len(), banks.len());
        for (path, bank) in paths.iter().zip(&banks) {
            assert_eq!(
                path.file_name().unwrap().to_str().unwrap(),
                format!("{}.json", factory_slug(bank))
            );
            assert_eq!(std::fs::read_to_string(path).unwrap(), preset_json(bank));
        }
    }
}
