//! Unit tests of the factory library: completeness, lookup and round trips.

use super::*;
use crate::bank::summary::note_name;
use crate::bank::validate::validate_bank;
use std::collections::HashSet;

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
        assert_eq!(
            bank.source_text("kind").unwrap_or(""),
            "fitted",
            "{}",
            bank.name
        );
        assert!(
            !bank.source_text("recording").unwrap_or("").is_empty(),
            "{}",
            bank.name
        );
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
