//! Unit tests of the factory library: completeness, coverage of objects and materials,
//! defaults, lookup and round trips.

use super::*;
use crate::model::materials;
use crate::model::shapes::OBJECTS;
use crate::model::summary::note_name;
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
