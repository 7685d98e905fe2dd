//! Engine behaviour: timing, polyphony, truncation, loudness, smoothness and robustness.

mod common;

use common::*;
use modal_resonator::bank::{Bank, BankDefaults, Mode};
use modal_resonator::engine::{
    Controls, Engine, Note, NoteEvent, NoteExpression, PreparedBank, VoiceModulation,
    CONTROL_PERIOD, MAX_POLYPHONY, TARGET_PEAK,
};
use modal_resonator::units::{db_to_gain, gain_to_db, midi_key_to_hz, t60_to_decay};
use std::sync::Arc;

const RATE: f32 = 48_000.0;

#[test]
fn block_size_does_not_change_the_output() {
    let bank = dense_bank(300, 110.0);
    let events = [
        on(5, 45, 1.0),
        on(1003, 52, 0.6),
        NoteEvent::off(3000, 45),
        on(7777, 45, 0.3),
    ];
    let reference = render(&mut engine(&bank, RATE), &events, 0.5, 4096);
    for block in [1, 17, 64, 333] {
        let got = render(&mut engine(&bank, RATE), &events, 0.5, block);
        assert!(got == reference, "block {block} differs from block 4096");
    }
}

#[test]
fn reset_reproduces_the_output_exactly() {
    let bank = dense_bank(200, 220.0);
    let controls = Controls {
        position_variation: 0.3,
        exciter: modal_resonator::dsp::ExciterKind::Noise,
        ..Controls::default()
    };
    let mut e = engine(&bank, RATE);
    e.set_controls(&controls);
    let events = [on(0, 57, 0.9), on(2400, 60, 0.7)];
    let first = render(&mut e, &events, 0.3, 256);
    e.reset();
    let second = render(&mut e, &events, 0.3, 256);
    assert!(first == second, "output after reset differs");
    assert!(peak(&first.0) > 0.01);
}

#[test]
fn notes_start_on_their_exact_sample() {
    let bank = simple_bank(&[(440.0, 3.0, 1.0)]);
    for block in [1, 64, 1000] {
        for &t in &[0u32, 1, 63, 64, 999, 1234] {
            let (l, _) = render(&mut engine(&bank, RATE), &[on(t, 69, 1.0)], 0.05, block);
            let first = l.iter().position(|&v| v != 0.0).unwrap();
            // The mode starts at zero phase: silent on the strike sample, sounding from the next.
            assert_eq!(first, t as usize + 1, "block {block}, note at {t}");
        }
    }
}

#[test]
fn a_strike_peaks_near_minus_6_dbfs_at_every_rate() {
    for bank in [
        simple_bank(&[(440.0, 2.0, 1.0)]),
        simple_bank(&[(220.0, 2.0, 0.001), (661.0, 5.0, 0.002)]),
        dense_bank(1000, 110.0),
        dense_bank(12, 1000.0),
    ] {
        let root_key =
            modal_resonator::units::hz_to_midi_key(bank.effective_root_hz()).round() as u8;
        let mut peaks = Vec::new();
        for rate in [44_100.0, 48_000.0, 96_000.0, 192_000.0] {
            let mut e = engine(&bank, rate);
            let (l, r) = render(&mut e, &[on(0, root_key, 1.0)], 0.5, 512);
            peaks.push(gain_to_db(peak(&l).max(peak(&r))));
        }
        let (lo, hi) = peaks
            .iter()
            .fold((f32::MAX, f32::MIN), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        assert!(
            hi - lo <= 0.5,
            "{} modes: peaks {peaks:?} dBFS differ by more than 0.5 dB",
            bank.modes.len()
        );
        assert!(
            (peaks[1] - gain_to_db(TARGET_PEAK)).abs() <= 1.0,
            "{} modes: peak {} dBFS at 48 kHz, expected about -6",
            bank.modes.len(),
            peaks[1]
        );
    }
}

/// The lowest mode frequency a bank may hold still keeps a strike's level: a mode at 1 Hz that
/// never decays has peaked by the time the bank's level is measured, and a long render stays
/// within 1 dB of -6 dBFS; a slower one is refused.
#[test]
fn the_lowest_mode_a_bank_may_hold_keeps_the_strike_level() {
    use modal_resonator::bank::validate::validate_bank;
    let mut bank = simple_bank(&[(1.0, 0.0, 1.0), (220.0, 2.0, 0.3)]);
    bank.root_hz = Some(220.0);
    let problems = validate_bank(&bank);
    assert!(problems.is_empty(), "a mode at 1 Hz is valid: {problems:?}");
    let mut e = engine(&bank, RATE);
    let (l, r) = render(&mut e, &[on(0, 57, 1.0)], 3.0, 512);
    let peak_db = gain_to_db(peak(&l).max(peak(&r)));
    assert!(
        (peak_db - gain_to_db(TARGET_PEAK)).abs() <= 1.0,
        "peak {peak_db} dBFS over 3 s, expected about -6"
    );
    bank.modes[0].freq_hz = 0.001;
    let problems: Vec<String> = validate_bank(&bank).iter().map(|p| p.to_string()).collect();
    assert!(
        problems.len() == 1
            && problems[0].contains("modes[0].freq_hz")
            && problems[0].contains("from 1 to"),
        "{problems:?}"
    );
}

#[test]
fn a_default_strike_peaks_near_minus_6_dbfs_wherever_the_bank_strikes_and_however_late() {
    let peak_db = |bank: &Bank, key: u8, seconds: f64| {
        let mut e = engine(bank, RATE);
        let (l, r) = render(&mut e, &[on(0, key, 1.0)], seconds, 4096);
        gain_to_db(peak(&l).max(peak(&r)))
    };
    let target = gain_to_db(TARGET_PEAK);
    // Struck by default at its second position, where the mode is a million times louder
    // than at the first.
    let mut bank = Bank::new("two ends", two_ends());
    bank.modes = vec![Mode {
        freq_hz: 440.0,
        decay_per_s: 3.0,
        gains: vec![1e-6, 1.0],
    }];
    bank.root_hz = Some(440.0);
    bank.defaults = Some(BankDefaults {
        strike_position: Some(1.0),
        ..BankDefaults::default()
    });
    let got = peak_db(&bank, 69, 1.0);
    assert!(
        (got - target).abs() <= 1.0,
        "{got} dBFS at the default position"
    );
    // Two modes 0.01 Hz apart, opposite in sign: they cancel at the strike and drift into
    // phase over the next 40 s, while they barely decay.
    let mut bank = simple_bank(&[(1000.0, 0.01, 1.0), (1000.01, 0.01, -1.0)]);
    bank.root_hz = Some(1000.0);
    let got = peak_db(&bank, 83, 60.0);
    assert!(
        (got - target).abs() <= 1.0,
        "{got} dBFS for modes drifting into phase"
    );
}

#[test]
fn truncation_ends_modes_at_the_threshold_and_frees_the_voice() {
    let decay = t60_to_decay(0.5);
    let bank = simple_bank(&[(440.0, decay as f64, 1.0)]);
    for truncation_db in [-60.0f32, -96.0, -120.0] {
        let mut e = engine(&bank, RATE);
        let mut c = e.controls().clone();
        c.truncation_db = truncation_db;
        c.width = 0.0;
        c.exciter = modal_resonator::dsp::ExciterKind::Impulse;
        e.set_controls(&c);
        // An impulse leaves the mode at its (normalised) gain.
        let amplitude = e.bank().gains[0] as f64;
        let (l, _) = render(&mut e, &[on(0, 69, 1.0)], 2.0, 512);
        assert!(e.is_silent(), "voice not freed at {truncation_db} dB");
        assert_eq!(e.stats().voices, 0);
        let last = l.iter().rposition(|&v| v != 0.0).unwrap();
        // Analytic cut-off (seed 000 eq. 5.14): amplitude a exp(-d t) reaches the threshold at
        // t = ln(a / tau) / d; the engine checks once per control period.
        let tau = db_to_gain(truncation_db) as f64;
        let cut = ((amplitude / tau).ln() / decay * RATE as f64) as usize;
        assert!(
            last + 1 >= cut && last <= cut + CONTROL_PERIOD + 1,
            "{truncation_db} dB: output ends at sample {last}, analytic cut-off {cut}"
        );
        // What was dropped is below the threshold.
        let mut reference = engine(&bank, RATE);
        let mut c2 = c.clone();
        c2.truncation_db = -140.0;
        reference.set_controls(&c2);
        let (full, _) = render(&mut reference, &[on(0, 69, 1.0)], 2.0, 512);
        let dropped = peak(&full[last + 1..]);
        assert!(
            dropped <= tau as f32,
            "{truncation_db} dB: dropped tail peaks at {dropped}, threshold {tau}"
        );
    }
}

#[test]
fn restriking_a_ringing_key_adds_without_a_click() {
    let bank = dense_bank(50, 220.0);
    let mut e = engine(&bank, RATE);
    let t2 = 12_000;
    let (l, _) = render(&mut e, &[on(0, 57, 1.0), on(t2, 57, 1.0)], 0.6, 256);
    assert_eq!(e.stats().voices, 1, "the same key re-uses its voice");
    let before = max_step(&l[..t2 as usize]);
    let around = max_step(&l[t2 as usize - 10..t2 as usize + 10]);
    assert!(
        around <= before,
        "re-strike step {around} exceeds the first strike's largest step {before}"
    );
    // The new strike adds to the old: the level just after it differs from a lone strike's.
    let (lone, _) = render(&mut engine(&bank, RATE), &[on(0, 57, 1.0)], 0.1, 256);
    let after = &l[t2 as usize..t2 as usize + 2_000];
    assert!(
        after
            .iter()
            .zip(&lone[..2_000])
            .any(|(a, b)| (a - b).abs() > 1e-3),
        "re-strike reset the voice"
    );
}

#[test]
fn a_large_bank_gets_the_voices_its_polyphony_needs_and_a_small_one_every_voice() {
    let voices = |modes: usize, polyphony: usize| {
        let mut e = Engine::new(Arc::new(PreparedBank::new(&dense_bank(modes, 55.0))));
        e.reserve_voices(polyphony);
        e.prepare(RATE, 512);
        e
    };
    assert_eq!(voices(200, 2).voice_capacity(), MAX_POLYPHONY);
    assert_eq!(voices(20_000, 64).voice_capacity(), MAX_POLYPHONY);
    let mut e = voices(20_000, 2);
    let capacity = e.voice_capacity();
    assert!((2..MAX_POLYPHONY / 4).contains(&capacity), "{capacity}");
    // The polyphony control asks for more than was reserved: the voices there play.
    let mut c = e.controls().clone();
    c.polyphony = MAX_POLYPHONY;
    e.set_controls(&c);
    let chord: Vec<NoteEvent> = (0..MAX_POLYPHONY as u8)
        .map(|k| on(0, 30 + k, 1.0))
        .collect();
    render(&mut e, &chord, 0.003, 256);
    assert_eq!(e.stats().voices, capacity);
    // Reserving more reallocates.
    e.reserve_voices(MAX_POLYPHONY);
    assert_eq!(e.voice_capacity(), MAX_POLYPHONY);
    render(&mut e, &chord, 0.003, 256);
    assert_eq!(e.stats().voices, MAX_POLYPHONY);
}

#[test]
fn voices_are_stolen_quietest_first_with_a_fade() {
    let bank = dense_bank(40, 220.0);
    let with_polyphony = |polyphony: usize, events: &[NoteEvent]| {
        let mut e = engine(&bank, RATE);
        let mut c = e.controls().clone();
        c.polyphony = polyphony;
        e.set_controls(&c);
        let out = render(&mut e, events, 0.2, 128);
        (out, e)
    };
    // The first note is soft, the second loud: the third steals the first.
    let steal_at = 4_000;
    let events = [on(0, 50, 0.2), on(2_000, 55, 1.0), on(steal_at, 60, 1.0)];
    let ((l, _), e) = with_polyphony(2, &events);
    assert_eq!(e.stats().voices, 2);
    let mut keys: Vec<u8> = e.sounding_keys().collect();
    keys.sort();
    assert_eq!(
        keys,
        [55, 60],
        "the soft first note is the quietest and must be the one stolen"
    );
    // Voices add independently: what the stolen voice played is the difference from a render
    // without it.
    let ((others, _), _) = with_polyphony(2, &events[1..]);
    let stolen: Vec<f32> = l.iter().zip(&others).map(|(a, b)| a - b).collect();
    let s = steal_at as usize;
    let fade = (0.005 * RATE) as usize;
    assert!(
        peak(&stolen[s - 480..s]) > 1e-3,
        "the soft note was sounding before the steal"
    );
    assert!(
        peak(&stolen[s + fade + 1..]) < 1e-6,
        "the stolen voice is gone after its fade"
    );
    let own = max_step(&stolen[100..s]);
    let at_steal = max_step(&stolen[s - 2..s + fade + 2]);
    assert!(
        at_steal <= own,
        "stolen voice steps {at_steal} while fading, more than its own {own}: a click"
    );
}

/// Renders `bank` struck at t = 0, changing controls to `to` at 0.1 s; returns the output and
/// the same render with `to` from the start.
fn sweep(bank: &modal_resonator::bank::Bank, to: &Controls) -> (Vec<f32>, Vec<f32>) {
    let mut e = engine(bank, RATE);
    let mut l = vec![0.0; 24_000];
    let mut r = vec![0.0; 24_000];
    let switch = 4_800;
    e.process(&[on(0, 57, 1.0)], None, &mut l[..switch], &mut r[..switch]);
    e.set_controls(to);
    e.process(&[], None, &mut l[switch..], &mut r[switch..]);
    let mut steady = engine(bank, RATE);
    steady.set_controls(to);
    let (sl, _) = render(&mut steady, &[on(0, 57, 1.0)], 0.5, 512);
    (l, sl)
}

#[test]
fn parameter_changes_while_ringing_do_not_click() {
    let bank = dense_bank(60, 220.0);
    let base = Controls::for_bank(&bank);
    let mut bend = base.clone();
    bend.pitch_bend_semitones = 2.0;
    let mut size = base.clone();
    size.size_ratio = 0.5;
    let mut q = base.clone();
    q.material_q = Some(30.0);
    let mut tilt = base.clone();
    tilt.damping_tilt = 1.5;
    let mut gain = base.clone();
    gain.output_gain_db = -30.0;
    let mut width = base.clone();
    width.width = 1.0;
    for (name, to) in [
        ("bend", bend),
        ("size", size),
        ("q", q),
        ("tilt", tilt),
        ("gain", gain),
        ("width", width),
    ] {
        let (l, steady) = sweep(&bank, &to);
        // The signal's own largest step: before the change, or at the new setting.
        let own = max_step(&l[100..4_800]).max(max_step(&steady[100..]));
        let during = max_step(&l[4_790..6_000]);
        assert!(
            during <= own,
            "{name}: step {during} during the change exceeds the signal's own {own}"
        );
    }
    // A 2-semitone bend in 10 ms lands on the new pitch.
    let bent = Controls {
        pitch_bend_semitones: 2.0,
        ..Controls::default()
    };
    let (l, _) = sweep(&simple_bank(&[(220.0, 1.0, 1.0)]), &bent);
    let got = pitch_hz(&l[4_800 + 480..], RATE as f64, 150.0, 400.0);
    let want = 220.0 * 2f64.powf(2.0 / 12.0);
    assert!(
        (got / want - 1.0).abs() < 0.002,
        "after the bend: {got} Hz, want {want}"
    );
}

#[test]
fn key_tracking_size_and_tuning_set_the_pitch() {
    let bank = simple_bank(&[(220.0, 1.0, 1.0)]);
    let cases: [(u8, f32, f32, f32, f64); 5] = [
        (57, 1.0, 1.0, 0.0, 220.0),
        (69, 1.0, 1.0, 0.0, 440.0),
        (69, 0.0, 1.0, 0.0, 220.0),
        (57, 1.0, 2.0, 0.0, 110.0),
        (57, 1.0, 1.0, 50.0, 220.0 * 2f64.powf(0.5 / 12.0)),
    ];
    for (key, tracking, size, cents, want) in cases {
        let mut e = engine(&bank, RATE);
        let mut c = e.controls().clone();
        c.key_tracking = tracking;
        c.size_ratio = size;
        c.fine_tune_cents = cents;
        e.set_controls(&c);
        let (l, _) = render(&mut e, &[on(0, key, 1.0)], 0.4, 512);
        let got = pitch_hz(&l[100..], RATE as f64, 60.0, 900.0);
        assert!(
            (got / want - 1.0).abs() < 0.001,
            "key {key}, tracking {tracking}, size {size}: {got} Hz, want {want}"
        );
    }
    assert!((midi_key_to_hz(57.0) - 220.0).abs() < 1e-9);
}

#[test]
fn the_key_nearest_an_off_grid_root_plays_the_bank_as_authored() {
    // 452 Hz is A4 + 47 cents: A4 plays it at 452 Hz, the other keys relative to it.
    let mut bank = simple_bank(&[(452.0, 1.0, 1.0)]);
    bank.root_hz = Some(452.0);
    for (key, want) in [
        (69, 452.0),
        (81, 904.0),
        (64, 452.0 * 2f64.powf(-5.0 / 12.0)),
    ] {
        let mut e = engine(&bank, RATE);
        let (l, _) = render(&mut e, &[on(0, key, 1.0)], 0.5, 512);
        let got = spectral_peak_hz(&l, RATE as f64, want * 0.9, want * 1.1);
        let cents = 1200.0 * (got / want).log2();
        assert!(
            cents.abs() < 1.0,
            "key {key}: {got} Hz, {cents:.2} cents off {want}"
        );
    }
}

#[test]
fn modes_above_the_limit_are_not_played() {
    // 30 kHz is above 0.45 fs at 48 kHz but fine at 96 kHz.
    let bank = simple_bank(&[(1_000.0, 5.0, 1.0), (30_000.0, 5.0, 1.0)]);
    let mut e = engine(&bank, 48_000.0);
    render(&mut e, &[on(0, 83, 1.0)], 0.01, 64);
    assert_eq!(e.stats().live_modes, 1);
    let mut e = engine(&bank, 96_000.0);
    let mut c = e.controls().clone();
    c.key_tracking = 0.0;
    e.set_controls(&c);
    render(&mut e, &[on(0, 83, 1.0)], 0.01, 64);
    assert_eq!(e.stats().live_modes, 2);
}

/// Two modes, 300 Hz sounding only at position a (x = 0), 1.7 kHz only at b (x = 1).
fn a_mode_per_position() -> modal_resonator::bank::Bank {
    let mut bank = simple_bank(&[(300.0, 2.0, 1.0), (1_700.0, 2.0, 0.0)]);
    bank.positions.push(modal_resonator::bank::Position {
        name: "b".into(),
        coords: vec![1.0],
    });
    bank.modes[0].gains.push(0.0);
    bank.modes[1].gains.push(1.0);
    bank
}

#[test]
fn strike_position_selects_the_gain_column() {
    let bank = a_mode_per_position();
    for (x, want_live) in [(0.0f32, 1usize), (1.0, 1), (0.5, 2)] {
        let mut e = engine(&bank, RATE);
        let mut c = e.controls().clone();
        c.strike_x = x;
        e.set_controls(&c);
        render(&mut e, &[on(0, 60, 1.0)], 0.05, 64);
        assert_eq!(e.stats().live_modes, want_live, "strike at {x}");
    }
}

#[test]
fn a_strike_starts_exactly_the_modes_its_point_reaches() {
    // 21 modes (not a whole number of eights), struck at a point that reaches three: one in
    // each eight, the last in the short one at the end.
    let reached = [2usize, 9, 20];
    let modes: Vec<_> = (0..21)
        .map(|m| {
            (
                200.0 + 50.0 * m as f64,
                2.0,
                reached.contains(&m) as u8 as f64,
            )
        })
        .collect();
    let mut e = engine(&simple_bank(&modes), RATE);
    // Looked at while the mallet still plays: a mode started with no gain has not been retired.
    render(&mut e, &[on(0, 60, 1.0)], 0.0005, 64);
    let mut sounding = Vec::new();
    e.visit_mode_energies(|m, _| sounding.push(m));
    sounding.sort_unstable();
    assert_eq!(sounding, reached);
}

#[test]
fn a_restrike_that_starts_new_modes_plays_them_at_the_voice_pitch() {
    // Struck at a, then at b on the same ringing key (the voice's tuning unchanged): the
    // second strike starts the 1.7 kHz mode alone, and the output is the sum of the two
    // strikes played on their own.
    let bank = a_mode_per_position();
    for pruning in [false, true] {
        let played = |at_a: bool, at_b: bool| {
            let mut e = engine(&bank, RATE);
            let mut c = e.controls().clone();
            c.exciter = modal_resonator::dsp::ExciterKind::Impulse;
            c.position_variation = 0.0;
            c.pruning = pruning;
            c.strike_x = 0.0;
            e.set_controls(&c);
            let strike = |on_: bool| if on_ { vec![on(0, 60, 1.0)] } else { vec![] };
            let (mut l, _) = render(&mut e, &strike(at_a), 0.05, 64);
            c.strike_x = 1.0;
            e.set_controls(&c);
            let (second, _) = render(&mut e, &strike(at_b), 0.1, 64);
            l.extend(second);
            l
        };
        let (both, a, b) = (played(true, true), played(true, false), played(false, true));
        assert!(
            peak(&b) > 0.01,
            "pruning {pruning}: the 1.7 kHz mode sounds"
        );
        let error = both
            .iter()
            .zip(a.iter().zip(&b))
            .map(|(x, (y, z))| (x - y - z).abs())
            .fold(0.0f32, f32::max);
        assert!(
            error <= 1e-5 * peak(&both),
            "pruning {pruning}: off by {error} (peak {})",
            peak(&both)
        );
    }
}

#[test]
fn velocity_sets_force_and_hardness() {
    let bank = dense_bank(200, 100.0);
    let level = |velocity: f32| {
        let (l, _) = render(&mut engine(&bank, RATE), &[on(0, 43, velocity)], 0.2, 256);
        l
    };
    let (soft, loud) = (level(0.3), level(1.0));
    assert!(
        peak(&soft) < 0.5 * peak(&loud),
        "soft {} vs loud {}",
        peak(&soft),
        peak(&loud)
    );
    // Brightness: share of energy in sample-to-sample differences (a high-pass).
    let brightness = |x: &[f32]| {
        let e: f32 = x.iter().map(|v| v * v).sum();
        let d: f32 = x.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum();
        d / e
    };
    assert!(
        brightness(&loud) > brightness(&soft),
        "a harder strike must be brighter"
    );
}

#[test]
fn extreme_values_and_bad_input_never_break_the_sound() {
    let bank = dense_bank(500, 30.0);
    let mut e = engine(&bank, 44_100.0);
    let mut rng = 1u32;
    let mut next = || {
        rng ^= rng << 13;
        rng ^= rng >> 17;
        rng ^= rng << 5;
        rng as f32 / u32::MAX as f32
    };
    let specials = [
        f32::NAN,
        f32::INFINITY,
        -f32::INFINITY,
        0.0,
        -1e30,
        1e30,
        f32::MIN_POSITIVE,
    ];
    let mut input = vec![0.0f32; 256];
    let (mut l, mut r) = (vec![0.0; 256], vec![0.0; 256]);
    for block in 0..400 {
        let mut c = Controls::default();
        for spec in modal_resonator::engine::NUMERIC_CONTROLS {
            let v = if next() < 0.2 {
                specials[(next() * 6.99) as usize]
            } else {
                spec.min + next() * (spec.max - spec.min)
            };
            (spec.set)(&mut c, v);
        }
        c.material_q = Some(if next() < 0.5 { 1e-3 } else { 1e9 });
        e.set_controls(&c);
        for (i, x) in input.iter_mut().enumerate() {
            *x = if (block + i) % 97 == 0 {
                specials[i % 7]
            } else {
                (next() - 0.5) * 4.0
            };
        }
        let key = (next() * 127.0) as u8;
        let events = [
            on((next() * 255.0) as u32, key, next() * 1.5),
            NoteEvent::on(255, key, f32::NAN),
        ];
        e.process(&events, Some(&input), &mut l, &mut r);
        for (i, v) in l.iter().chain(&r).enumerate() {
            assert!(v.is_finite(), "block {block}: sample {i} is {v}");
        }
    }
}

#[test]
fn subnormal_input_and_long_tails_stay_clear_of_denormals() {
    let bank = simple_bank(&[(50.0, 0.5, 1.0), (3_000.0, 50.0, 0.5)]);
    let mut e = engine(&bank, RATE);
    let mut c = e.controls().clone();
    c.truncation_db = -140.0;
    e.set_controls(&c);
    // Subnormal input would put subnormal numbers into the resonators' state and output unless
    // the engine flushes them.
    let n = 4_800;
    let input: Vec<f32> = (0..n)
        .map(|i| if i % 3 == 0 { 1e-39 } else { -3e-40 })
        .collect();
    assert!(input.iter().all(|v| v.is_subnormal()));
    let (mut l, mut r) = (vec![0.0; n], vec![0.0; n]);
    e.process(&[], Some(&input), &mut l, &mut r);
    let (tl, tr) = render(&mut e, &[on(0, 43, 1.0)], 20.0, 512);
    let subnormal = l
        .iter()
        .chain(&r)
        .chain(&tl)
        .chain(&tr)
        .filter(|v| v.is_subnormal())
        .count();
    assert_eq!(subnormal, 0);
}

#[test]
fn width_zero_is_mono_and_width_spreads_modes() {
    let harmonics: Vec<(f64, f64, f64)> = (1..=24)
        .map(|n| (220.0 * n as f64, 2.0, 1.0 / n as f64))
        .collect();
    let bank = simple_bank(&harmonics);
    let stereo = |width: f32| {
        let mut e = engine(&bank, RATE);
        let mut c = e.controls().clone();
        c.width = width;
        e.set_controls(&c);
        render(&mut e, &[on(0, 57, 1.0)], 0.2, 256)
    };
    let (l, r) = stereo(0.0);
    assert!(l == r, "width 0 must be mono");
    let (l, r) = stereo(1.0);
    let side = l.iter().zip(&r).map(|(a, b)| (a - b).powi(2)).sum::<f32>();
    let mid = l.iter().zip(&r).map(|(a, b)| (a + b).powi(2)).sum::<f32>();
    assert!(
        side > 0.01 * mid,
        "full width should spread the modes: side/mid energy {}",
        side / mid
    );
    let (el, er) = (
        l.iter().map(|v| v * v).sum::<f32>(),
        r.iter().map(|v| v * v).sum::<f32>(),
    );
    assert!(
        (gain_to_db(el.sqrt()) - gain_to_db(er.sqrt())).abs() < 1.5,
        "image leans: L {el} R {er}"
    );
}

#[test]
fn position_variation_moves_each_strike() {
    // Each position excites one mode: where a strike lands shows in the balance of the two.
    let mut bank = simple_bank(&[(300.0, 2.0, 1.0), (1_100.0, 2.0, 0.0)]);
    bank.positions.push(modal_resonator::bank::Position {
        name: "b".into(),
        coords: vec![1.0],
    });
    bank.modes[0].gains.push(0.0);
    bank.modes[1].gains.push(1.0);
    // Key 57 plays the modes at their own frequencies.
    bank.root_hz = Some(midi_key_to_hz(57.0));
    let strikes = |variation: f32| {
        let mut e = engine(&bank, RATE);
        let mut c = e.controls().clone();
        c.strike_x = 0.5;
        c.position_variation = variation;
        c.release_damping = 1.0;
        e.set_controls(&c);
        // Separate strikes, each from silence and measured on its own.
        let events: Vec<NoteEvent> = (0..6u32)
            .flat_map(|i| {
                [
                    NoteEvent::AllSoundOff { time: i * 9_600 },
                    on(i * 9_600, 57, 1.0),
                ]
            })
            .collect();
        let (l, _) = render(&mut e, &events, 1.2, 512);
        (0..6)
            .map(|i| {
                let x = &l[i * 9_600..i * 9_600 + 4_800];
                let low = magnitude_at(x, RATE as f64, 300.0);
                let high = magnitude_at(x, RATE as f64, 1_100.0);
                high / (low + high)
            })
            .collect::<Vec<f64>>()
    };
    let spread = |b: &Vec<f64>| {
        b.iter().fold(0.0f64, |a, &v| a.max(v)) - b.iter().fold(1.0f64, |a, &v| a.min(v))
    };
    let (fixed, varied) = (strikes(0.0), strikes(0.5));
    assert!(
        spread(&fixed) < 0.01,
        "without variation every strike lands at the same place: {fixed:?}"
    );
    assert!(
        spread(&varied) > 0.2,
        "variation 0.5 should move strikes: {varied:?}"
    );
}

#[test]
fn decays_follow_pitch_at_constant_q() {
    let bank = simple_bank(&[(440.0, 4.0, 1.0)]);
    let decay_rate = |size: f32| {
        let mut e = engine(&bank, RATE);
        let mut c = e.controls().clone();
        c.size_ratio = size;
        e.set_controls(&c);
        let (l, _) = render(&mut e, &[on(0, 69, 1.0)], 1.0, 512);
        // Envelope slope from the peaks of two 50 ms windows 0.5 s apart.
        let a = peak(&l[2_400..4_800]) as f64;
        let b = peak(&l[26_400..28_800]) as f64;
        (a / b).ln() / 0.5
    };
    let (at_1, at_2) = (decay_rate(1.0), decay_rate(2.0));
    assert!(
        (at_1 / 4.0 - 1.0).abs() < 0.05,
        "decay {at_1} /s at size 1, authored 4"
    );
    assert!(
        (at_2 / 2.0 - 1.0).abs() < 0.05,
        "an object twice the size an octave down decays at half the rate: {at_2}"
    );
}

#[test]
fn strikes_between_2d_positions_blend_their_gains() {
    // Three corners of a plate, each exciting one mode only.
    let mut bank = simple_bank(&[(300.0, 2.0, 1.0), (700.0, 2.0, 0.0), (1_300.0, 2.0, 0.0)]);
    bank.positions = ["a", "b", "c"]
        .iter()
        .zip([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
        .map(|(n, c)| modal_resonator::bank::Position {
            name: n.to_string(),
            coords: c.to_vec(),
        })
        .collect();
    bank.modes[0].gains = vec![1.0, 0.0, 0.0];
    bank.modes[1].gains = vec![0.0, 1.0, 0.0];
    bank.modes[2].gains = vec![0.0, 0.0, 1.0];
    for ((x, y), live) in [
        ((0.0, 0.0), 1usize),
        ((1.0, 0.0), 1),
        ((0.5, 0.0), 2),
        ((0.3, 0.3), 3),
    ] {
        let mut e = engine(&bank, RATE);
        let mut c = e.controls().clone();
        c.strike_x = x;
        c.strike_y = y;
        e.set_controls(&c);
        render(&mut e, &[on(0, 60, 1.0)], 0.05, 64);
        assert_eq!(e.stats().live_modes, live, "strike at ({x}, {y})");
    }
}

#[test]
fn truncation_drops_less_than_the_threshold_in_all() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/steel-plate.json");
    let bank = modal_resonator::bank::load_bank_file(&path).unwrap();
    for truncation_db in [-60.0f32, -96.0] {
        let run = |db: f32| {
            let mut e = engine(&bank, RATE);
            let mut c = e.controls().clone();
            c.truncation_db = db;
            e.set_controls(&c);
            render(&mut e, &[on(0, 40, 1.0), on(24_000, 47, 0.7)], 6.0, 512).0
        };
        let (cut, full) = (run(truncation_db), run(-140.0));
        let dropped: Vec<f32> = cut.iter().zip(&full).map(|(a, b)| a - b).collect();
        let tau = db_to_gain(truncation_db);
        assert!(
            peak(&dropped) <= tau,
            "{} modes at {truncation_db} dB: what truncation dropped peaks at {} dBFS",
            bank.modes.len(),
            gain_to_db(peak(&dropped))
        );
    }
}

#[test]
fn audio_input_drives_the_modes() {
    let bank = simple_bank(&[(440.0, 5.0, 1.0), (1_320.0, 5.0, 1.0)]);
    let mut e = engine(&bank, RATE);
    let n = 9_600;
    // A click train at 10 Hz rings the object.
    let input: Vec<f32> = (0..n)
        .map(|i| if i % 4_800 == 0 { 0.5 } else { 0.0 })
        .collect();
    let (mut l, mut r) = (vec![0.0; n], vec![0.0; n]);
    e.process(&[], Some(&input), &mut l, &mut r);
    assert!(
        peak(&l) > 0.05,
        "input did not excite the modes: peak {}",
        peak(&l)
    );
    let got = pitch_hz(&l[10..4_000], RATE as f64, 300.0, 600.0);
    assert!((got / 440.0 - 1.0).abs() < 0.003, "input voice at {got} Hz");
    // Silence in, silence out once the ring has died.
    let silence = vec![0.0f32; 48_000];
    let (mut l, mut r) = (vec![0.0; 48_000], vec![0.0; 48_000]);
    for _ in 0..10 {
        e.process(&[], Some(&silence), &mut l, &mut r);
    }
    assert!(e.is_silent());
    assert_eq!(peak(&l), 0.0);
}

#[test]
fn all_sound_off_silences_at_once_and_all_notes_off_releases() {
    let bank = dense_bank(30, 220.0);
    let mut e = engine(&bank, RATE);
    let (l, _) = render(
        &mut e,
        &[
            on(0, 57, 1.0),
            on(0, 60, 1.0),
            NoteEvent::AllSoundOff { time: 1_000 },
        ],
        0.05,
        256,
    );
    assert!(peak(&l[..1_000]) > 0.01);
    assert_eq!(peak(&l[1_000..]), 0.0);
    assert!(e.is_silent());

    let mut e = engine(&bank, RATE);
    let mut c = e.controls().clone();
    c.release_damping = 1.0;
    e.set_controls(&c);
    let (l, _) = render(
        &mut e,
        &[on(0, 57, 1.0), NoteEvent::AllNotesOff { time: 1_000 }],
        1.0,
        256,
    );
    assert!(
        peak(&l[24_000..]) < 1e-3,
        "released notes should have damped"
    );
    assert!(e.is_silent());
}

#[test]
fn note_expressions_change_one_note_only() {
    // Two notes; the upper one is retuned up a whole tone and pressed, the lower is left alone.
    let bank = simple_bank(&[(220.0, 1.0, 1.0)]);
    let events = [
        on(0, 57, 1.0),
        on(0, 64, 1.0),
        NoteEvent::Expression {
            time: 4_800,
            note: Note::key(64),
            expression: modal_resonator::engine::NoteExpression::Tuning(2.0),
        },
    ];
    let alone = |key: u8, expression: Option<modal_resonator::engine::NoteExpression>| {
        let mut e = engine(&bank, RATE);
        let mut ev = vec![on(0, key, 1.0)];
        if let Some(x) = expression {
            ev.push(NoteEvent::Expression {
                time: 4_800,
                note: Note::key(key),
                expression: x,
            });
        }
        render(&mut e, &ev, 1.0, 256).0
    };
    let (both, _) = render(&mut engine(&bank, RATE), &events, 1.0, 256);
    let retuned = alone(
        64,
        Some(modal_resonator::engine::NoteExpression::Tuning(2.0)),
    );
    let low = alone(57, None);
    // Voices add: the pair equals the low note alone plus the retuned upper note alone.
    for (i, ((b, l), r)) in both.iter().zip(&low).zip(&retuned).enumerate() {
        assert!(
            (b - (l + r)).abs() < 1e-5,
            "sample {i}: the expression leaked to the other note"
        );
    }
    let want = midi_key_to_hz(66.0) * 220.0 / midi_key_to_hz(57.0);
    let got = pitch_hz(&retuned[9_600..], RATE as f64, 250.0, 450.0);
    assert!(
        (got / want - 1.0).abs() < 0.002,
        "retuned note at {got} Hz, want {want}"
    );
    // Pressure damps the note it is applied to.
    let pressed = alone(
        57,
        Some(modal_resonator::engine::NoteExpression::Pressure(1.0)),
    );
    assert!(
        peak(&pressed[24_000..]) < 0.2 * peak(&low[24_000..]),
        "pressure did not damp the note"
    );
}

#[test]
fn a_choke_silences_its_key_at_once_and_no_other() {
    let bank = dense_bank(30, 220.0);
    let events = [
        on(0, 57, 1.0),
        on(0, 60, 1.0),
        NoteEvent::Choke {
            time: 2_000,
            note: Note::key(57),
        },
    ];
    let (l, _) = render(&mut engine(&bank, RATE), &events, 0.2, 256);
    let (only_60, _) = render(&mut engine(&bank, RATE), &[on(0, 60, 1.0)], 0.2, 256);
    // After the choke only key 60 sounds, exactly as if it had been played alone.
    for (i, (a, b)) in l[2_000..].iter().zip(&only_60[2_000..]).enumerate() {
        assert!((a - b).abs() < 1e-6, "sample {}: {a} vs {b}", i + 2_000);
    }
}

/// A note with a channel and an id.
fn note(key: u8, channel: u8, id: i32) -> Note {
    Note {
        key,
        channel,
        id: Some(id),
    }
}

#[test]
fn ended_notes_are_reported_with_their_id_and_sample() {
    let bank = simple_bank(&[(440.0, 3.0, 1.0)]);
    let mut e = engine(&bank, RATE);
    let (mut l, mut r) = (vec![0.0; 512], vec![0.0; 512]);
    // A note restruck under a new id takes over the voice: the old id ends at the restrike.
    e.process(
        &[
            NoteEvent::On {
                time: 10,
                note: note(69, 0, 1),
                velocity: 1.0,
            },
            NoteEvent::On {
                time: 100,
                note: note(69, 0, 2),
                velocity: 1.0,
            },
            NoteEvent::Choke {
                time: 300,
                note: note(69, 0, 2),
            },
        ],
        None,
        &mut l,
        &mut r,
    );
    let ended: Vec<_> = e.take_ended_voices().collect();
    let want = [(100, note(69, 0, 1)), (300, note(69, 0, 2))];
    assert_eq!(
        ended.iter().map(|v| (v.time, v.note)).collect::<Vec<_>>(),
        want
    );
    assert!(e.take_ended_voices().next().is_none(), "reported twice");
    // A note that rings out ends when truncation frees it.
    e.process(&[NoteEvent::on(0, 60, 1.0)], None, &mut l, &mut r);
    let mut samples = 512;
    let mut ended = Vec::new();
    while ended.is_empty() && samples < 48_000 * 20 {
        e.process(&[], None, &mut l, &mut r);
        ended.extend(e.take_ended_voices());
        samples += 512;
    }
    assert_eq!(ended.len(), 1, "the ringing note never ended");
    assert_eq!(ended[0].note, Note::key(60));
    assert!(e.is_silent());
}

#[test]
fn the_same_key_on_two_channels_plays_two_voices_that_bend_apart() {
    let bank = sine_like_bank();
    let events = [
        NoteEvent::On {
            time: 0,
            note: Note {
                channel: 1,
                ..Note::key(69)
            },
            velocity: 1.0,
        },
        NoteEvent::On {
            time: 0,
            note: Note {
                channel: 2,
                ..Note::key(69)
            },
            velocity: 1.0,
        },
        NoteEvent::ChannelExpression {
            time: 0,
            channel: 2,
            expression: NoteExpression::Tuning(12.0),
        },
    ];
    let mut e = engine(&bank, RATE);
    let (l, _) = render(&mut e, &events, 0.3, 256);
    assert_eq!(e.stats().voices, 2);
    let x = &l[480..];
    let low = magnitude_at(x, RATE as f64, 440.0);
    let high = magnitude_at(x, RATE as f64, 880.0);
    assert!(
        high > 0.5 * low && low > 0.5 * high,
        "440 Hz: {low}, 880 Hz: {high}"
    );
    // Tuning sent with the note-on takes effect from its first sample: no glide from 440 Hz
    // leaves energy between the two.
    assert!(magnitude_at(x, RATE as f64, 660.0) < 0.01 * high);
}

/// One mode at 440 Hz, rooted at A4, ringing for seconds.
fn sine_like_bank() -> modal_resonator::bank::Bank {
    let mut bank = simple_bank(&[(440.0, 1.0, 1.0)]);
    bank.root_hz = Some(440.0);
    bank
}

#[test]
fn modulation_with_the_note_on_shapes_the_strike_and_stays_with_its_voice() {
    let bank = sine_like_bank();
    let on = |key: u8, id: i32| NoteEvent::On {
        time: 0,
        note: note(key, 0, id),
        velocity: 1.0,
    };
    // Fine tune +50 cents on note 1 alone, at the note-on's sample; note 2 follows the engine.
    let events = [
        on(69, 1),
        NoteEvent::Modulate {
            time: 0,
            id: 1,
            modulation: VoiceModulation::FineTuneCents(50.0),
        },
        on(57, 2),
        // Modulation of a note that does not exist changes nothing.
        NoteEvent::Modulate {
            time: 0,
            id: 99,
            modulation: VoiceModulation::FineTuneCents(-100.0),
        },
    ];
    let (l, _) = render(&mut engine(&bank, RATE), &events, 0.3, 64);
    let x = &l[64..];
    let up = 440.0 * 2f64.powf(0.5 / 12.0);
    assert!(magnitude_at(x, RATE as f64, 440.0) < 0.02 * magnitude_at(x, RATE as f64, up));
    assert!(magnitude_at(x, RATE as f64, 220.0) > 0.5 * magnitude_at(x, RATE as f64, up));

    // A softer mallet on one note (longer contact) makes that note quieter at the mode, and
    // NaN modulation is ignored.
    let hard = render(&mut engine(&bank, RATE), &[on(69, 1)], 0.1, 64).0;
    let soft_events = [
        on(69, 1),
        NoteEvent::Modulate {
            time: 0,
            id: 1,
            modulation: VoiceModulation::HardnessMs(20.0),
        },
        NoteEvent::Modulate {
            time: 0,
            id: 1,
            modulation: VoiceModulation::HardnessMs(f32::NAN),
        },
    ];
    let soft = render(&mut engine(&bank, RATE), &soft_events, 0.1, 64).0;
    assert!(
        peak(&soft) < 0.5 * peak(&hard),
        "soft {} against hard {}",
        peak(&soft),
        peak(&hard)
    );
}

#[test]
fn input_gain_changes_glide_instead_of_stepping() {
    // An impulse right after the input gain jumps 20 dB excites the modes with about the old
    // gain; one 0.2 s later with the new gain.
    let bank = sine_like_bank();
    let response = |delay: usize| {
        let mut e = engine(&bank, RATE);
        let (mut l, mut r) = (vec![0.0; 64], vec![0.0; 64]);
        let mut x = vec![0.0; 64];
        // Wake the input voice with a tiny signal at the old gain.
        x[0] = 1e-6;
        e.process(&[], Some(&x), &mut l, &mut r);
        let mut c = e.controls().clone();
        c.input_gain_db += 20.0;
        e.set_controls(&c);
        let mut out = Vec::new();
        for b in 0..(delay / 64 + 8) {
            let mut x = vec![0.0; 64];
            if b == delay / 64 {
                x[delay % 64] = 0.01;
            }
            e.process(&[], Some(&x), &mut l, &mut r);
            out.extend_from_slice(&l);
        }
        peak(&out[delay..])
    };
    let (early, late) = (response(3), response(9_600));
    let ratio = late / early;
    assert!(
        ratio > 8.0 && ratio < 10.5,
        "early {early}, late {late}: ratio {ratio}"
    );
}

#[test]
fn gains_at_a_strike_point_match_mode_by_mode() {
    let banks = modal_resonator::bank::factory::analytic_factory_banks();
    let mut blended = 0;
    for bank in banks.iter().filter(|b| b.positions.len() > 1) {
        let prepared = modal_resonator::engine::PreparedBank::new(bank);
        let mut all = vec![f32::NAN; prepared.num_modes()];
        for (x, y) in [
            (0.0, 0.0),
            (0.13, 0.71),
            (0.5, 0.5),
            (0.9, 0.35),
            (1.0, 1.0),
        ] {
            let w = prepared.positions.weights(x, y);
            blended += (w.count > 1) as usize;
            prepared.gains_at(&w, &mut all);
            for (m, &g) in all.iter().enumerate() {
                let one = prepared.gain_at(m, &w);
                assert!(
                    g == one,
                    "{}: mode {m} at ({x}, {y}): {g} in one pass, {one} alone",
                    bank.name
                );
            }
        }
    }
    assert!(blended > 0, "no strike point blends positions");
}
