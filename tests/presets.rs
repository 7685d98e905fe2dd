//! Every committed preset loads, validates, round-trips, and renders non-silent and in tune.

mod common;

use std::path::PathBuf;

use common::*;
use modal_resonator::bank::io::{bank_to_json, load_bank_file, parse_bank_str};
use modal_resonator::bank::validate::validate_bank;
use modal_resonator::units::hz_to_midi_key;

/// The banks in `presets/` and in `presets/fitted/` (banks fitted to recordings).
fn preset_files() -> Vec<PathBuf> {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("presets");
    let mut files: Vec<PathBuf> = [dir.clone(), dir.join("fitted")]
        .iter()
        .flat_map(|d| std::fs::read_dir(d).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.extension().is_some_and(|e| e == "json")
                && !p.to_string_lossy().ends_with(".schema.json")
        })
        .collect();
    files.sort();
    files
}

#[test]
fn there_are_at_least_six_presets() {
    assert!(preset_files().len() >= 6, "{:?}", preset_files());
}

#[test]
fn every_preset_loads_validates_and_round_trips() {
    for path in preset_files() {
        let bank = load_bank_file(&path).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            validate_bank(&bank).is_empty(),
            "{}: {:?}",
            path.display(),
            validate_bank(&bank)
        );
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            bank_to_json(&bank),
            text,
            "{}: saving does not reproduce the file",
            path.display()
        );
        let again = parse_bank_str(&bank_to_json(&bank), "round trip").unwrap();
        assert_eq!(again, bank, "{}", path.display());
        assert!(
            !bank.description.is_empty() && !bank.license.is_empty(),
            "{}",
            path.display()
        );
    }
}

#[test]
fn every_preset_renders_in_tune() {
    let rate = 48_000.0;
    for path in preset_files() {
        let bank = load_bank_file(&path).unwrap();
        let root_hz = bank.effective_root_hz();
        let key = hz_to_midi_key(root_hz).round() as u8;
        // The key nearest the root plays the bank at its own pitch, on the grid or not.
        let mut e = engine(&bank, rate as f32);
        // A bank played by a contact is heard in tune by striking it.
        let mut c = e.controls().clone();
        if c.exciter.is_contact() {
            c.exciter = modal_resonator::dsp::ExciterKind::Mallet;
            e.set_controls(&c);
        }
        let (l, r) = render(&mut e, &[on(0, key, 1.0)], 1.0, 512);
        let level = peak(&l).max(peak(&r));
        assert!(level > 0.1, "{}: peak {level}", path.display());
        assert!(l.iter().chain(&r).all(|v| v.is_finite()));
        // The spectrum peaks at the root within +-3%: its largest value there is within 0.3%.
        let mono: Vec<f32> = l.iter().zip(&r).map(|(a, b)| a + b).take(24_000).collect();
        let (best_hz, best) = (0..=120)
            .map(|i| root_hz * (0.97 + 0.06 * i as f64 / 120.0))
            .map(|f| (f, magnitude_at(&mono, rate, f)))
            .fold((0.0, 0.0), |a, b| if b.1 > a.1 { b } else { a });
        assert!(
            (best_hz / root_hz - 1.0).abs() < 0.003,
            "{}: spectral peak near the root at {best_hz:.2} Hz, root {root_hz:.2} Hz",
            path.display()
        );
        let off = magnitude_at(&mono, rate, root_hz * 1.25);
        assert!(
            best > 4.0 * off,
            "{}: no clear partial at the root ({best} vs {off} a third above)",
            path.display()
        );
    }
}
