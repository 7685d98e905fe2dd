//! Unit tests of the recipes: coverage of objects and materials, tweaks, and the files written.

use super::*;
use crate::authoring::materials;
use crate::authoring::shapes::ObjectKind;
use crate::bank::factory::{factory_bank, factory_slug, preset_json};
use std::collections::HashSet;

/// The materials the factory covers, by the representatives it uses.
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

/// The objects the analytic factory has banks of, by name: a new object may come before its
/// bank.
const LIBRARY_OBJECTS: [&str; 11] = [
    "ideal-string",
    "stiff-string",
    "free-free-bar",
    "clamped-free-bar",
    "tuned-bar",
    "circular-membrane",
    "rectangular-membrane",
    "rectangular-plate",
    "circular-plate",
    "bell",
    "bowl",
];

fn source_str<'a>(bank: &'a Bank, key: &str) -> &'a str {
    bank.source
        .as_ref()
        .and_then(|s| s.get(key))
        .and_then(|v| v.as_str())
        .unwrap_or("")
}

#[test]
fn analytic_banks_cover_every_object_and_material() {
    let banks = designed_factory_banks();
    for bank in &banks {
        assert_eq!(bank.license, "CC0-1.0", "{}", bank.name);
        assert_eq!(bank.author, "Modal Resonator", "{}", bank.name);
        assert_eq!(source_str(bank, "kind"), "analytic", "{}", bank.name);
    }
    let shapes: HashSet<&str> = banks.iter().map(|b| source_str(b, "shape")).collect();
    for name in LIBRARY_OBJECTS {
        assert!(shapes.contains(name), "no factory {name}");
        assert!(ObjectKind::by_name(name).is_some(), "no object {name}");
    }
    let used: HashSet<&str> = banks.iter().map(|b| source_str(b, "material")).collect();
    for name in LIBRARY_MATERIALS {
        assert!(used.contains(name), "no factory bank of {name}");
        assert!(materials::Material::by_name(name).is_some());
    }
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
fn writes_one_file_per_analytic_bank() {
    let dir = tempfile::tempdir().unwrap();
    let paths = write_factory_presets(dir.path()).unwrap();
    let banks = designed_factory_banks();
    assert_eq!(paths.len(), banks.len());
    for (path, bank) in paths.iter().zip(&banks) {
        assert_eq!(
            path.file_name().unwrap().to_str().unwrap(),
            format!("{}.json", factory_slug(bank))
        );
        assert_eq!(std::fs::read_to_string(path).unwrap(), preset_json(bank));
    }
}
