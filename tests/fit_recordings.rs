//! Fitting real recordings of struck objects from Debian packages (see
//! `tests/common/recordings.rs` for each file, its package and licence): the fitted bank's modes
//! re-synthesised stay within a bound of the recording and at its level, and so does the bank
//! kept in `presets/fitted/` played through the engine with its default controls.
//!
//! `UPDATE_PRESETS=1 cargo test --test fit_recordings` rewrites the banks in `presets/fitted/`.

mod common;

use std::path::PathBuf;

use common::recordings::{RealRecording, REAL_RECORDINGS};
use modal_resonator::authoring::fit::{compare, fit_bank, FitOptions};
use modal_resonator::bank::{load_bank_file, save_bank_file, Bank, BankDefaults};
use modal_resonator::render::resynthesize;
use serde_json::json;

/// Position name of the single strike in each recording.
const POSITION: &str = "strike";

/// Largest difference in dB between the re-synthesis's energy and the recording's. The fit
/// matches each partial's level frame by frame in dB, as the ear weighs it, so the loud onset,
/// where most of the energy is, counts no more than any stretch of the tail (the hand bell's
/// resynthesis has 4.6 dB less energy than its recording).
const MAX_LEVEL_DB: f64 = 5.0;

fn options(r: &RealRecording) -> FitOptions {
    FitOptions {
        name: format!("{} (fitted)", r.object),
        ..FitOptions::default()
    }
}

/// `bank` struck at `position` through the engine, with its default controls, for `compare`.
fn engine(bank: &Bank, position: usize, sample_rate_hz: u32, len: usize) -> Vec<f64> {
    resynthesize(bank, position, sample_rate_hz, len)
        .into_iter()
        .map(f64::from)
        .collect()
}

fn preset_path(r: &RealRecording) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("presets/fitted")
        .join(format!("{}.json", r.slug))
}

/// Mallet contact time in ms the fitted banks play with by default: the shortest, nearly an
/// impulse, since the recording's gains already hold the real mallet's spectrum.
const FITTED_HARDNESS_MS: f64 = 0.05;

/// The fitted bank with where it came from (licence, credit and package in its metadata), a
/// description, its root (the fitted mode nearest the note it is played as) and defaults.
fn with_provenance(mut bank: Bank, r: &RealRecording) -> Bank {
    bank.description = format!(
        "{} Fitted from one recorded strike by modal-resonator fit.",
        r.about
    );
    let root = bank
        .modes
        .iter()
        .map(|m| m.freq_hz)
        .min_by(|a, b| {
            (a - r.root_near_hz)
                .abs()
                .total_cmp(&(b - r.root_near_hz).abs())
        })
        .expect("a fitted bank has modes");
    bank.root_hz = Some(root);
    bank.defaults = Some(BankDefaults {
        hardness_ms: Some(FITTED_HARDNESS_MS),
        ..BankDefaults::default()
    });
    bank.author = format!("Fitted from a recording by {}", r.credit);
    bank.license = r.license.to_string();
    let source = bank.source.get_or_insert_with(Default::default);
    source.insert("recording".into(), json!(r.credit));
    source.insert("debian_package".into(), json!(r.package));
    source.insert("file".into(), json!(r.path));
    if r.path.ends_with(".pat") {
        source.insert("patch_sample".into(), json!(r.sample));
    }
    bank
}

/// Slowest decay a fitted mode of these recordings may have, per second: a T60 of about 70 s.
const MIN_FITTED_DECAY_PER_S: f64 = 0.1;

#[test]
fn real_recordings_fit_within_their_bounds() {
    let update = std::env::var_os("UPDATE_PRESETS").is_some();
    for r in REAL_RECORDINGS {
        let recording = r.load(POSITION);
        let fit = fit_bank(&[recording], &options(r)).unwrap_or_else(|e| panic!("{}: {e}", r.slug));
        let report = &fit.report.recordings[0];
        println!(
            "{} ({}, {}): {} modes of {} found, log-spectral distance {:.2} dB (bound {}), \
             level {:+.2} dB, SNR {:.1} dB, {} warnings",
            r.slug,
            r.package,
            r.license,
            fit.bank.modes.len(),
            fit.report.modes_found,
            report.lsd_db,
            r.max_lsd_db,
            report.level_db,
            report.snr_db,
            report.warnings.len()
        );
        assert!(
            report.lsd_db <= r.max_lsd_db,
            "{}: log-spectral distance {:.2} dB, bound {} dB\n{}",
            r.slug,
            report.lsd_db,
            r.max_lsd_db,
            fit.report
        );
        assert!(
            report.level_db.abs() <= MAX_LEVEL_DB,
            "{}: re-synthesis {:+.2} dB from the recording's level",
            r.slug,
            report.level_db
        );
        // Every mode dies away: none at the floor of decays, which would keep a voice ringing
        // for minutes.
        let slowest = fit
            .bank
            .modes
            .iter()
            .min_by(|a, b| a.decay_per_s.total_cmp(&b.decay_per_s))
            .unwrap();
        assert!(
            slowest.decay_per_s >= MIN_FITTED_DECAY_PER_S,
            "{}: a mode at {:.1} Hz decays at {} /s",
            r.slug,
            slowest.freq_hz,
            slowest.decay_per_s
        );
        if update {
            let path = preset_path(r);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            save_bank_file(&with_provenance(fit.bank, r), &path).unwrap();
        }
    }
}

#[test]
fn kept_banks_still_match_their_recordings() {
    for r in REAL_RECORDINGS {
        let path = preset_path(r);
        let bank = load_bank_file(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(bank.license, r.license, "{}", path.display());
        let scores = compare(&bank, &[r.load(POSITION)], &options(r), engine).unwrap();
        assert!(
            scores[0].lsd_db <= r.max_lsd_db && scores[0].level_db.abs() <= MAX_LEVEL_DB,
            "{}: log-spectral distance {:.2} dB (bound {}), level {:+.2} dB",
            path.display(),
            scores[0].lsd_db,
            r.max_lsd_db,
            scores[0].level_db
        );
    }
}
