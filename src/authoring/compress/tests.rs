//! Unit tests of mode compression: merging within the limen, dropping by level, the result.

use super::*;
use crate::bank::Position;

fn bank(modes: &[(f64, f64, [f64; 2])]) -> Bank {
    let positions = ["edge", "centre"]
        .iter()
        .enumerate()
        .map(|(i, name)| Position {
            name: name.to_string(),
            coords: vec![i as f64],
        })
        .collect();
    let mut bank = Bank::new("test", positions);
    bank.modes = modes
        .iter()
        .map(|&(freq_hz, decay_per_s, gains)| Mode {
            freq_hz,
            decay_per_s,
            gains: gains.to_vec(),
        })
        .collect();
    bank
}

fn no_drop() -> CompressOptions {
    CompressOptions {
        limen_scale: 1.0,
        drop_below_db: None,
    }
}

#[test]
fn modes_within_the_limen_merge_and_sum_their_gains_per_position() {
    // At 2 kHz the limen is 5 Hz (seed 000 section 5.4.1): 2 Hz apart is one mode.
    let input = bank(&[
        (2000.0, 4.0, [0.5, -0.25]),
        (2002.0, 4.0, [0.25, 0.5]),
        (3000.0, 6.0, [0.1, 0.2]),
    ]);
    let (out, report) = compress_bank(&input, &no_drop()).unwrap();
    assert_eq!(out.modes.len(), 2, "{:?}", out.modes);
    let merged = &out.modes[0];
    assert_eq!(merged.gains, vec![0.75, 0.25], "gains summed per position");
    // Energy weights: the first has 0.3125 of summed squared gain, the second 0.3125 as well.
    assert!(
        (merged.freq_hz - 2001.0).abs() < 1e-9,
        "merged frequency {} vs 2001",
        merged.freq_hz
    );
    assert!((merged.decay_per_s - 4.0).abs() < 1e-12);
    assert_eq!(out.modes[1], input.modes[2]);
    assert_eq!(
        report,
        CompressReport {
            modes_before: 3,
            modes_after: 2,
            merged: 1,
            dropped: 0
        }
    );
    assert_eq!(
        report.to_string(),
        "3 modes -> 2 modes (merged 1, dropped 0)"
    );
}

#[test]
fn modes_outside_the_limen_stay_apart() {
    // 8 Hz apart at 2 kHz is beyond the 5 Hz limen; at 8 kHz the limen is 80 Hz, so 70 Hz
    // apart merges there.
    let input = bank(&[
        (2000.0, 4.0, [0.5, 0.5]),
        (2008.0, 4.0, [0.5, 0.5]),
        (8000.0, 9.0, [0.5, 0.5]),
        (8070.0, 9.0, [0.5, 0.5]),
    ]);
    let (out, report) = compress_bank(&input, &no_drop()).unwrap();
    let freqs: Vec<f64> = out.modes.iter().map(|m| m.freq_hz).collect();
    assert_eq!(freqs.len(), 3, "{freqs:?}");
    assert_eq!(&freqs[..2], &[2000.0, 2008.0]);
    assert!((freqs[2] - 8035.0).abs() < 1.0, "{freqs:?}");
    assert_eq!(report.merged, 1);
    // A smaller limen scale keeps even the close pair apart; scale 0 merges nothing.
    for scale in [0.5, 0.0] {
        let options = CompressOptions {
            limen_scale: scale,
            drop_below_db: None,
        };
        let (out, _) = compress_bank(&input, &options).unwrap();
        assert_eq!(out.modes.len(), 4, "limen scale {scale}");
    }
}

#[test]
fn a_dense_run_is_not_chained_into_one_mode() {
    // Modes every 3 Hz from 2 kHz: each is within the 5 Hz limen of the next, but a cluster
    // spans less than one limen, so 20 modes become several, not one.
    let modes: Vec<(f64, f64, [f64; 2])> = (0..20)
        .map(|i| (2000.0 + 3.0 * i as f64, 4.0, [0.1, 0.1]))
        .collect();
    let (out, _) = compress_bank(&bank(&modes), &no_drop()).unwrap();
    assert_eq!(
        out.modes.len(),
        10,
        "pairs 3 Hz apart merge, triples do not"
    );
    for pair in out.modes.windows(2) {
        let gap = pair[1].freq_hz - pair[0].freq_hz;
        assert!(gap > 5.0, "merged modes {gap} Hz apart");
    }
}

#[test]
fn the_stronger_mode_dominates_frequency_and_decay() {
    // A faint fast neighbour barely moves a strong slow mode: its energy weight is
    // (0.05^2 / 50) / (1 / 1) = 5e-5, so the decay moves by 5e-5 * 49 = 0.25%.
    let input = bank(&[(1000.0, 1.0, [1.0, 1.0]), (1001.5, 50.0, [0.05, 0.05])]);
    let (out, _) = compress_bank(&input, &no_drop()).unwrap();
    let m = &out.modes[0];
    assert_eq!(out.modes.len(), 1);
    assert!((m.freq_hz - 1000.0).abs() < 1e-3, "frequency {}", m.freq_hz);
    assert!(
        (m.decay_per_s - 1.0).abs() < 3e-3,
        "decay {}",
        m.decay_per_s
    );
}

#[test]
fn weak_modes_are_dropped_relative_to_the_strongest() {
    // Peak gains relative to the strongest: 0 dB, -40 dB, -79 dB, -81 dB (peak over either
    // position counts).
    let input = bank(&[
        (100.0, 1.0, [0.0, 2.0]),
        (300.0, 1.0, [0.02, 0.0]),
        (700.0, 1.0, [0.0, -2.0 * 10f64.powf(-79.0 / 20.0)]),
        (1100.0, 1.0, [2.0 * 10f64.powf(-81.0 / 20.0), 0.0]),
    ]);
    let (out, report) = compress_bank(&input, &CompressOptions::default()).unwrap();
    let freqs: Vec<f64> = out.modes.iter().map(|m| m.freq_hz).collect();
    assert_eq!(freqs, vec![100.0, 300.0, 700.0]);
    assert_eq!((report.merged, report.dropped), (0, 1));
    let strict = CompressOptions {
        limen_scale: 1.0,
        drop_below_db: Some(-30.0),
    };
    let (out, report) = compress_bank(&input, &strict).unwrap();
    assert_eq!(out.modes.len(), 1);
    assert_eq!(
        report.to_string(),
        "4 modes -> 1 modes (merged 0, dropped 3)"
    );
}

#[test]
fn result_validates_and_keeps_everything_but_the_modes() {
    let mut input = bank(&[
        (440.0, 2.0, [1.0, 0.5]),
        (440.5, 2.0, [0.5, 0.5]),
        (1320.0, 3.0, [0.3, 0.1]),
    ]);
    input.root_hz = Some(440.0);
    input.description = "A test bank.".into();
    let (out, _) = compress_bank(&input, &CompressOptions::default()).unwrap();
    assert!(validate_bank(&out).is_empty(), "{:?}", validate_bank(&out));
    assert_eq!(out.root_hz, input.root_hz);
    assert_eq!(out.positions, input.positions);
    assert_eq!(out.description, input.description);
    let compression = &out.source.as_ref().unwrap()["compression"];
    assert_eq!(compression["modes_before"], 3);
    assert_eq!(compression["drop_below_db"], -80.0);
    // Modes come out ascending, whatever the input order.
    let mut shuffled = input.clone();
    shuffled.modes.reverse();
    let (again, _) = compress_bank(&shuffled, &CompressOptions::default()).unwrap();
    assert_eq!(again.modes, out.modes);
}

#[test]
fn bad_options_are_refused() {
    let input = bank(&[(440.0, 2.0, [1.0, 0.5])]);
    for options in [
        CompressOptions {
            limen_scale: -1.0,
            drop_below_db: None,
        },
        CompressOptions {
            limen_scale: f64::NAN,
            drop_below_db: None,
        },
        // Would merge a whole bank into one mode.
        CompressOptions {
            limen_scale: 1e9,
            drop_below_db: None,
        },
        CompressOptions {
            limen_scale: 1.0,
            drop_below_db: Some(6.0),
        },
    ] {
        let err = compress_bank(&input, &options).unwrap_err();
        assert!(
            matches!(err, CompressError::BadOption { .. }),
            "{options:?}: {err}"
        );
    }
    // Summed gains beyond the format's range are reported, not saved.
    let huge = bank(&[(440.0, 2.0, [9e5, 0.0]), (440.2, 2.0, [9e5, 0.0])]);
    let err = compress_bank(&huge, &no_drop()).unwrap_err();
    assert!(err.to_string().contains("modes[0].gains[0]"), "{err}");
}
