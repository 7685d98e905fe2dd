//! The engine's per-mode meters, read by the editor: energies follow the closed-form decay,
//! truncated modes drop out, and modes are numbered in the prepared bank's order.

mod common;

use common::*;
use modal_resonator::dsp::ExciterKind;
use modal_resonator::engine::{Engine, PreparedBank};
use modal_resonator::units::t60_to_decay;

const RATE: f32 = 48_000.0;

/// Summed energy of each mode over the voices, and how many voices each mode sounds in.
fn energies(e: &Engine) -> (Vec<f32>, Vec<usize>) {
    let n = e.bank().num_modes();
    let (mut energy, mut count) = (vec![0.0f32; n], vec![0usize; n]);
    e.visit_mode_energies(|m, en| {
        energy[m] += en;
        count[m] += 1;
    });
    (energy, count)
}

/// An engine with impulse strikes and no stereo spread, so a mode's state is its gain.
fn impulse_engine(bank: &modal_resonator::bank::Bank, truncation_db: f32) -> Engine {
    let mut e = engine(bank, RATE);
    let mut c = e.controls().clone();
    c.exciter = ExciterKind::Impulse;
    c.truncation_db = truncation_db;
    e.set_controls(&c);
    e
}

#[test]
fn mode_energy_follows_the_closed_form_decay() {
    let decay_per_s = t60_to_decay(1.5);
    let bank = simple_bank(&[(440.0, decay_per_s, 1.0)]);
    let mut e = impulse_engine(&bank, -140.0);
    render(&mut e, &[on(0, 69, 1.0)], 0.1, 256);
    let (first, _) = energies(&e);
    render(&mut e, &[], 0.2, 256);
    let (second, _) = energies(&e);
    // |z| = a exp(-d t), so the energy falls by exp(-2 d t) over t = 0.2 s.
    let expected = (-2.0 * decay_per_s * 0.2).exp() as f32;
    let ratio = second[0] / first[0];
    assert!(
        (ratio / expected - 1.0).abs() < 0.01,
        "energy ratio {ratio}, closed form {expected}"
    );
    // The amplitude is the strike's gain decayed over the first 0.1 s.
    let amplitude = e.bank().gains[0] as f64 * (-decay_per_s * 0.1).exp();
    let measured = (first[0] as f64).sqrt();
    assert!(
        (measured / amplitude - 1.0).abs() < 0.01,
        "amplitude {measured}, closed form {amplitude}"
    );
}

#[test]
fn truncated_modes_are_not_visited_and_voices_add_up() {
    // A fast mode dies long before the slow one.
    let fast = t60_to_decay(0.05);
    let slow = t60_to_decay(5.0);
    let bank = simple_bank(&[(300.0, fast, 1.0), (500.0, slow, 1.0)]);
    let mut e = impulse_engine(&bank, -80.0);
    render(&mut e, &[on(0, 60, 1.0), on(0, 67, 1.0)], 0.01, 64);
    let (energy, count) = energies(&e);
    assert_eq!(count, vec![2, 2], "both modes sound in both voices");
    let total: f32 = energy.iter().sum();
    let mut visited = 0.0;
    e.visit_mode_energies(|_, en| visited += en);
    assert_eq!(total, visited);

    render(&mut e, &[], 0.5, 64);
    let (energy, count) = energies(&e);
    assert_eq!(count[0], 0, "the fast mode is truncated: {energy:?}");
    assert_eq!(count[1], 2, "the slow mode still sounds in both voices");
    assert!(energy[1] > 0.0);
    assert_eq!(e.stats().live_modes, 2);
}

#[test]
fn modes_are_numbered_by_ascending_frequency() {
    let bank = simple_bank(&[(900.0, 2.0, 0.5), (100.0, 2.0, 1.0), (400.0, 2.0, 0.2)]);
    let order = PreparedBank::frequency_order(&bank);
    let prepared = PreparedBank::new(&bank);
    assert_eq!(order, vec![1, 2, 0]);
    for (m, &i) in order.iter().enumerate() {
        assert_eq!(
            prepared.freq_hz[m], bank.modes[i].freq_hz,
            "prepared mode {m} is bank mode {i}"
        );
    }
}
