//! The fitting benchmark's score (`tests/common/fit_score.rs`) on recordings made from known
//! modes: the modes themselves score near 0 dB at any gain, and wrong frequencies or decays score
//! far worse.

mod common;

use common::fit_score::{score, synthesize, FittedMode, Score};
use modal_resonator::authoring::fit::Recording;

/// Sample rate of the test recordings.
const RATE_HZ: u32 = 44_100;
/// Length of the test recordings in seconds.
const SECONDS: f64 = 2.0;
/// Highest score, in dB, of the modes a recording was made from.
const EXACT_DB: f64 = 0.1;
/// Lowest score, in dB, of modes detuned by 3 % or whose tail is 10 dB off.
const WRONG_DB: f64 = 2.0;

/// Five inharmonic modes over 30 dB, ringing from 0.3 s to 2 s.
fn modes() -> Vec<FittedMode> {
    [
        (180.0, 1.5, 0.3),
        (440.0, 3.0, 0.5),
        (1210.0, 6.0, 0.3),
        (2630.0, 12.0, 0.2),
        (5000.0, 20.0, 0.05),
    ]
    .iter()
    .map(|&(freq_hz, decay_per_s, gain)| FittedMode {
        freq_hz,
        decay_per_s,
        gain,
    })
    .collect()
}

/// A recording of `modes` struck at its first sample.
fn recording(modes: &[FittedMode]) -> Recording {
    let len = (SECONDS * f64::from(RATE_HZ)) as usize;
    let samples = synthesize(modes, RATE_HZ, len)
        .iter()
        .map(|&v| v as f32)
        .collect();
    Recording::new("strike", samples, RATE_HZ)
}

/// `modes` with `change` applied to each.
fn changed(modes: &[FittedMode], change: impl Fn(&mut FittedMode)) -> Vec<FittedMode> {
    let mut out = modes.to_vec();
    out.iter_mut().for_each(change);
    out
}

fn show(what: &str, s: &Score) {
    println!(
        "{what}: all {:.3} dB, attack {:.3} dB, tail {:.3} dB, offset {:+.2} dB, {:.2} cents",
        s.all_db, s.attack_db, s.tail_db, s.offset_db, s.peak_cents
    );
}

#[test]
fn the_modes_a_recording_was_made_from_score_near_zero() {
    let m = modes();
    let s = score(&m, &recording(&m));
    show("exact", &s);
    for (part, db) in [
        ("all", s.all_db),
        ("attack", s.attack_db),
        ("tail", s.tail_db),
    ] {
        assert!(
            db < EXACT_DB,
            "{part}: {db:.3} dB, expected under {EXACT_DB} dB"
        );
    }
    assert!(s.offset_db.abs() < EXACT_DB, "offset {:.3} dB", s.offset_db);
    assert!(s.peak_cents < 1.0, "peak error {:.2} cents", s.peak_cents);
}

#[test]
fn a_gain_change_is_absorbed_by_the_offset() {
    let m = modes();
    let louder = changed(&m, |x| x.gain *= 4.0);
    let s = score(&louder, &recording(&m));
    show("12 dB louder", &s);
    assert!(s.all_db < EXACT_DB, "{:.3} dB", s.all_db);
    let expected_db = -20.0 * 4f64.log10();
    assert!(
        (s.offset_db - expected_db).abs() < EXACT_DB,
        "offset {:.3} dB, expected {expected_db:.3} dB",
        s.offset_db
    );
}

#[test]
fn detuned_modes_score_far_worse() {
    let m = modes();
    let detuned = changed(&m, |x| x.freq_hz *= 1.03);
    let s = score(&detuned, &recording(&m));
    show("detuned 3 %", &s);
    assert!(s.all_db > WRONG_DB, "{:.3} dB", s.all_db);
    // 3 % is 51 cents.
    assert!(
        (s.peak_cents - 51.2).abs() < 1.0,
        "{:.2} cents",
        s.peak_cents
    );
}

#[test]
fn a_tail_10_db_off_scores_far_worse() {
    let m = modes();
    // 10 dB quieter one second after the strike.
    let extra_decay_per_s = 10.0 / 20.0 * std::f64::consts::LN_10;
    let faster = changed(&m, |x| x.decay_per_s += extra_decay_per_s);
    let s = score(&faster, &recording(&m));
    show("tail 10 dB quieter at 1 s", &s);
    // The offset splits the difference between the attack and the tail.
    assert!(s.all_db > WRONG_DB, "{:.3} dB", s.all_db);
    assert!(s.tail_db > WRONG_DB, "tail {:.3} dB", s.tail_db);
}

#[test]
fn modes_missing_from_a_fit_leave_the_offset_at_the_modes_it_has() {
    let m = modes();
    // The strongest mode alone, at its level: the bands of the others are empty in the
    // re-synthesis, which must not pull the offset away from the band it matches.
    let s = score(&m[1..2], &recording(&m));
    show("one mode of five", &s);
    assert!(s.offset_db.abs() < 1.0, "offset {:.3} dB", s.offset_db);
    assert!(
        s.all_db.is_finite() && s.all_db > WRONG_DB,
        "{:.3} dB",
        s.all_db
    );
}
