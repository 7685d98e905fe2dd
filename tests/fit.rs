//! Fitting banks to recordings: a known bank rendered through the engine with noise at 40 dB SNR
//! is recovered within the tolerances, and bad input gets clear errors or warnings.

mod common;

use std::sync::Arc;

use modal_resonator::authoring::fit::{
    compare, fit_bank, synthesize_strike, FitError, FitOptions, Recording,
};
use modal_resonator::dsp::ExciterKind;
use modal_resonator::engine::{Controls, PreparedBank};

use modal_resonator::bank::{Bank, Mode, Position};
use modal_resonator::render::{render, resynthesize, Note, CUT_FADE_S};

const RATE: u32 = 48_000;

/// Seconds of sound rendered after the strike.
const SECONDS: f64 = 3.0;

/// Noise-only lead-in before the strike, in seconds.
const LEAD_IN_S: f64 = 0.1;

/// Signal-to-noise ratio of the synthetic recordings: noise RMS this many dB below the RMS of
/// the clean render over its `SECONDS`.
const SNR_DB: f64 = 40.0;

/// Tolerances from the issue.
const FREQ_TOLERANCE: f64 = 0.0005;
const DECAY_TOLERANCE: f64 = 0.10;
const GAIN_TOLERANCE_DB: f64 = 1.5;

/// Largest RMS distance, in dB, of a mode's measured levels from its fitted exponential allowed
/// for a clean exponential decay under 40 dB SNR noise (the modes of the ground truth reach
/// 0.25 dB).
const FIT_ERROR_DB: f64 = 0.5;

/// Modes of the ground truth: frequency in Hz, decay in 1/s, and gain in dB relative to the
/// strongest at the two positions (`None`: not excited there), with a sign.
#[allow(clippy::type_complexity)]
const TRUTH: [(f64, f64, [Option<f64>; 2]); 12] = [
    (196.0, 1.2, [Some(0.0), Some(-10.0)]),
    (523.7, 2.0, [Some(-6.0), Some(-3.0)]),
    // A close pair: 12 Hz apart (about two bins of the analysis window, five limens).
    (1000.0, 3.0, [Some(-12.0), Some(-20.0)]),
    (1012.0, 3.5, [Some(-15.0), Some(-9.0)]),
    (1571.3, 5.0, [Some(-20.0), Some(-30.0)]),
    (2250.8, 7.0, [Some(-25.0), None]),
    (3120.4, 9.0, [Some(-30.0), Some(-26.0)]),
    (4440.0, 12.0, [Some(-34.0), Some(-38.0)]),
    (5800.0, 16.0, [Some(-38.0), Some(-24.0)]),
    (7712.0, 20.0, [Some(-40.0), Some(-36.0)]),
    (9900.0, 25.0, [None, Some(-40.0)]),
    (12500.0, 30.0, [Some(-36.0), Some(-39.0)]),
];

/// Signs of the gains, mode by mode and position by position.
const SIGNS: [[f64; 2]; 12] = [
    [1.0, 1.0],
    [1.0, -1.0],
    [1.0, 1.0],
    [-1.0, 1.0],
    [1.0, -1.0],
    [1.0, 1.0],
    [-1.0, -1.0],
    [1.0, 1.0],
    [1.0, -1.0],
    [-1.0, 1.0],
    [1.0, 1.0],
    [1.0, -1.0],
];

/// Amplitude of the strongest mode in the recordings.
const STRONGEST: f64 = 0.4;

fn truth_bank() -> Bank {
    let positions = ["edge", "centre"]
        .iter()
        .enumerate()
        .map(|(k, name)| Position {
            name: name.to_string(),
            coords: vec![k as f64],
        })
        .collect();
    let mut bank = Bank::new("truth", positions);
    bank.modes = TRUTH
        .iter()
        .zip(SIGNS)
        .map(|(&(freq_hz, decay_per_s, gains_db), signs)| Mode {
            freq_hz,
            decay_per_s,
            gains: gains_db
                .iter()
                .zip(signs)
                .map(|(g, s)| g.map_or(0.0, |db| s * STRONGEST * 10f64.powf(db / 20.0)))
                .collect(),
        })
        .collect();
    bank
}

/// Gaussian white noise from a seeded xorshift generator (Box-Muller).
fn gaussian_noise(len: usize, seed: u64) -> Vec<f64> {
    let mut state = seed.max(1);
    let mut uniform = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    (0..len)
        .map(|_| {
            let (u, v) = (uniform(), uniform());
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        })
        .collect()
}

/// The bank struck at position `k` with an impulse and rendered through the engine, in the
/// bank's units (the loudness normalisation undone): written here, apart from the library's
/// `resynthesize`, so the test does not take the code under test as its reference.
fn clean_render(bank: &Bank, k: usize) -> Vec<f64> {
    clean_render_at(bank, k, RATE)
}

/// [`clean_render`] at `rate` Hz.
fn clean_render_at(bank: &Bank, k: usize, rate: u32) -> Vec<f64> {
    let prepared = Arc::new(PreparedBank::new(bank));
    let mut controls = Controls::for_bank(bank);
    controls.exciter = ExciterKind::Impulse;
    controls.width = 0.0;
    controls.key_tracking = 0.0;
    controls.truncation_db = -140.0;
    controls.strike_x = k as f32 / (bank.positions.len() - 1) as f32;
    let settings = modal_resonator::render::RenderSettings {
        sample_rate_hz: rate,
        controls,
        max_seconds: SECONDS,
        ..Default::default()
    };
    let note = Note::new(60, 1.0, 0.0, None);
    let out = render(&prepared, &[note], &settings, |_| {});
    let mut x: Vec<f64> = out
        .left
        .iter()
        .map(|v| (v / prepared.normalization) as f64)
        .collect();
    x.resize((SECONDS * rate as f64) as usize, 0.0);
    x
}

/// `bank` struck at `position` through the engine, with its default controls, for `compare`.
fn engine(bank: &Bank, position: usize, sample_rate_hz: u32, len: usize) -> Vec<f64> {
    resynthesize(bank, position, sample_rate_hz, len)
        .into_iter()
        .map(f64::from)
        .collect()
}

/// The recording of position `k`: a lead-in, the render, and noise `snr_db` below it.
fn noisy_recording(bank: &Bank, k: usize, snr_db: f64, seed: u64) -> Recording {
    noisy_recording_at(bank, k, snr_db, seed, RATE)
}

/// [`noisy_recording`] at `rate` Hz.
fn noisy_recording_at(bank: &Bank, k: usize, snr_db: f64, seed: u64, rate: u32) -> Recording {
    let clean = clean_render_at(bank, k, rate);
    let rms = (clean.iter().map(|v| v * v).sum::<f64>() / clean.len() as f64).sqrt();
    let sigma = rms * 10f64.powf(-snr_db / 20.0);
    let lead_in = (LEAD_IN_S * rate as f64) as usize;
    let noise = gaussian_noise(lead_in + clean.len(), seed);
    let samples = noise
        .iter()
        .enumerate()
        .map(|(n, z)| {
            let s = if n >= lead_in {
                clean[n - lead_in]
            } else {
                0.0
            };
            (s + sigma * z) as f32
        })
        .collect();
    Recording::new(bank.positions[k].name.clone(), samples, rate)
}

fn db(x: f64) -> f64 {
    20.0 * x.abs().log10()
}

#[test]
fn the_renderer_used_here_matches_the_resyntheses_of_the_renderer_and_the_fit() {
    let bank = truth_bank();
    for k in 0..2 {
        let ours = clean_render(&bank, k);
        let theirs = resynthesize(&bank, k, RATE, ours.len());
        let err = ours
            .iter()
            .zip(&theirs)
            .fold(0.0f64, |a, (x, y)| a.max((x - *y as f64).abs()));
        assert!(err < 1e-6, "position {k}: largest difference {err}");
        // The fit's score synthesises the modes itself, as the engine plays them.
        // Up to the fade a render cut at its length ends with.
        let model = synthesize_strike(&bank, k, RATE, ours.len());
        let faded = (CUT_FADE_S * RATE as f64).ceil() as usize;
        let peak = model.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let err = model
            .iter()
            .zip(&theirs)
            .take(model.len() - faded)
            .fold(0.0f64, |a, (x, y)| a.max((x - *y as f64).abs()));
        assert!(
            err < 1e-4 * peak,
            "position {k}: the fit's synthesis is {err} off the engine's (peak {peak})"
        );
        // The impulse response starts as the model says: y(1/fs) = sum a sin(2 pi f / fs).
        let expected: f64 = bank
            .modes
            .iter()
            .map(|m| {
                let t = 1.0 / RATE as f64;
                m.gains[k]
                    * (-m.decay_per_s * t).exp()
                    * (std::f64::consts::TAU * m.freq_hz * t).sin()
            })
            .sum();
        assert!(
            (ours[1] - expected).abs() < 1e-4 * expected.abs().max(1e-3),
            "position {k}: second sample {} vs model {expected}",
            ours[1]
        );
    }
}

#[test]
fn a_known_bank_is_recovered_from_noisy_renders() {
    let truth = truth_bank();
    let recordings: Vec<Recording> = (0..2)
        .map(|k| noisy_recording(&truth, k, SNR_DB, 17 + k as u64))
        .collect();
    let options = FitOptions {
        name: "recovered".into(),
        ..FitOptions::default()
    };
    let fit = fit_bank(&recordings, &options).unwrap();
    let found = &fit.bank.modes;
    let strongest_fit = found
        .iter()
        .flat_map(|m| m.gains.iter())
        .fold(0.0f64, |a, g| a.max(g.abs()));

    let (mut worst_freq, mut worst_decay, mut worst_gain) = (0.0f64, 0.0f64, 0.0f64);
    for (i, (truth_mode, &(_, _, gains_db))) in truth.modes.iter().zip(&TRUTH).enumerate() {
        // Every true mode is within 40 dB of the strongest, so every one must be found.
        let nearest = nearest(found, truth_mode.freq_hz);
        let freq_err = (nearest.freq_hz / truth_mode.freq_hz - 1.0).abs();
        worst_freq = worst_freq.max(freq_err);
        assert!(
            freq_err <= FREQ_TOLERANCE,
            "mode {i}: true {} Hz, nearest found {} Hz ({:.4}%)",
            truth_mode.freq_hz,
            nearest.freq_hz,
            100.0 * freq_err
        );
        let decay_err = (nearest.decay_per_s / truth_mode.decay_per_s - 1.0).abs();
        worst_decay = worst_decay.max(decay_err);
        assert!(
            decay_err <= DECAY_TOLERANCE,
            "mode {i} ({} Hz): true decay {} /s, found {} /s ({:.1}%)",
            truth_mode.freq_hz,
            truth_mode.decay_per_s,
            nearest.decay_per_s,
            100.0 * decay_err
        );
        for (k, expected_db) in gains_db.iter().enumerate() {
            let got = nearest.gains[k];
            match expected_db {
                Some(expected_db) => {
                    let got_db = db(got / strongest_fit);
                    worst_gain = worst_gain.max((got_db - expected_db).abs());
                    assert!(
                        (got_db - expected_db).abs() <= GAIN_TOLERANCE_DB,
                        "mode {i} ({} Hz) position {k}: gain {got_db:.2} dB, expected \
                         {expected_db:.2} dB relative to the strongest",
                        truth_mode.freq_hz
                    );
                }
                None => assert!(
                    got == 0.0 || db(got / strongest_fit) < -45.0,
                    "mode {i} ({} Hz) position {k}: not excited, found gain {got} ({:.1} dB)",
                    truth_mode.freq_hz,
                    db(got / strongest_fit)
                ),
            }
        }
    }
    // An impulse starts every mode in sine phase: the sign of each gain is recovered, so two
    // positions that move a mode opposite ways keep opposite signs.
    for (i, t) in truth.modes.iter().enumerate() {
        let m = nearest(found, t.freq_hz);
        for k in 0..2 {
            if t.gains[k] != 0.0 {
                assert_eq!(
                    m.gains[k].signum(),
                    t.gains[k].signum(),
                    "mode {i} ({} Hz) position {k}: gain {} for true gain {}",
                    t.freq_hz,
                    m.gains[k],
                    t.gains[k]
                );
            }
        }
    }
    // Nothing spurious that could be heard: every mode found is one of the true modes, or has
    // at least 60 dB less energy over the recording than the strongest mode found (the fit may
    // leave a steady mode some 70 dB under a strong one beside it).
    let recorded_s = recordings[0].samples.len() as f64 / RATE as f64;
    let energy = |m: &Mode| {
        let a = m.gains.iter().fold(0.0f64, |acc, g| acc.max(g.abs()));
        let d = m.decay_per_s.max(1e-9);
        a * a * -(-2.0 * d * recorded_s).exp_m1() / (2.0 * d)
    };
    let loudest = found.iter().map(energy).fold(0.0, f64::max);
    for (j, m) in found.iter().enumerate() {
        let matched = truth
            .modes
            .iter()
            .any(|t| (m.freq_hz / t.freq_hz - 1.0).abs() <= FREQ_TOLERANCE)
            || energy(m) < 1e-6 * loudest;
        assert!(
            matched,
            "found mode {j} at {} Hz (decay {} 1/s, gains {:?}) matches no true mode",
            m.freq_hz, m.decay_per_s, m.gains
        );
    }
    // Every true mode's decay was measured over several frames that lie close to an exponential.
    let true_mode = |f: f64| {
        truth
            .modes
            .iter()
            .any(|t| (f / t.freq_hz - 1.0).abs() <= FREQ_TOLERANCE)
    };
    for m in fit.report.modes.iter().filter(|m| true_mode(m.freq_hz)) {
        assert!(
            m.fit_frames >= 3 && m.fit_error_db < FIT_ERROR_DB && m.snr_db > 0.0,
            "{} Hz: {} frames, {:.2} dB from the exponential, {:.1} dB over the noise",
            m.freq_hz,
            m.fit_frames,
            m.fit_error_db,
            m.snr_db
        );
    }
    println!(
        "worst errors: frequency {:.5}%, decay {:.2}%, gain {:.2} dB",
        100.0 * worst_freq,
        100.0 * worst_decay,
        worst_gain
    );
    for r in &fit.report.recordings {
        println!(
            "{}: log-spectral distance {:.2} dB, level {:+.2} dB",
            r.name, r.lsd_db, r.level_db
        );
        assert!(r.warnings.is_empty(), "{}: {:?}", r.name, r.warnings);
        assert!(r.lsd_db < 3.0, "{}: distance {} dB", r.name, r.lsd_db);
        assert!(
            r.level_db.abs() < 0.5,
            "{}: level {} dB",
            r.name,
            r.level_db
        );
    }
}

#[test]
fn a_known_bank_is_recovered_at_any_common_sample_rate() {
    // Each mode clear of the top of the range fitted (0.45 fs), to the same tolerances.
    // The noise of the test above (another draw puts the 12.5 kHz decay 10.5 % off at 44.1 and
    // 48 kHz alike: that mode is near the noise).
    for rate in [22_050, 44_100, 96_000] {
        let mut truth = truth_bank();
        truth.modes.retain(|m| m.freq_hz < 0.4 * f64::from(rate));
        let recordings: Vec<Recording> = (0..2)
            .map(|k| noisy_recording_at(&truth, k, SNR_DB, 17 + k as u64, rate))
            .collect();
        let fit = fit_bank(&recordings, &FitOptions::default()).unwrap().bank;
        let strongest = fit
            .modes
            .iter()
            .flat_map(|m| m.gains.iter())
            .fold(0.0f64, |a, g| a.max(g.abs()));
        for (t, &(_, _, gains_db)) in truth.modes.iter().zip(&TRUTH) {
            let m = nearest(&fit.modes, t.freq_hz);
            assert!(
                (m.freq_hz / t.freq_hz - 1.0).abs() <= FREQ_TOLERANCE
                    && (m.decay_per_s / t.decay_per_s - 1.0).abs() <= DECAY_TOLERANCE,
                "{rate} Hz: true {} Hz, {} /s; found {} Hz, {} /s",
                t.freq_hz,
                t.decay_per_s,
                m.freq_hz,
                m.decay_per_s
            );
            for (k, expected_db) in gains_db.iter().enumerate() {
                if let Some(expected_db) = expected_db {
                    let gain_db = db(m.gains[k] / strongest);
                    assert!(
                        (gain_db - expected_db).abs() <= GAIN_TOLERANCE_DB,
                        "{rate} Hz: {} Hz at position {k}: {gain_db:.2} dB, expected \
                         {expected_db} dB",
                        t.freq_hz
                    );
                }
            }
        }
    }
}

#[test]
fn the_bank_is_the_same_on_any_number_of_threads() {
    let truth = truth_bank();
    let recordings = [noisy_recording(&truth, 0, SNR_DB, 5)];
    let on = |threads: usize| {
        let options = FitOptions {
            threads,
            ..FitOptions::default()
        };
        fit_bank(&recordings, &options).unwrap().bank
    };
    let one = on(1);
    assert!(one.modes.len() >= TRUTH.len(), "{} modes", one.modes.len());
    for threads in [2, 5] {
        assert_eq!(on(threads), one, "{threads} threads");
    }
}

#[test]
fn silence_is_an_error_naming_the_recording() {
    let silent = Recording::new("edge", vec![0.0; 48_000], RATE);
    let error = fit_bank(&[silent], &FitOptions::default()).unwrap_err();
    assert!(matches!(error, FitError::Silent { .. }), "{error:?}");
    let message = error.to_string();
    assert!(
        message.contains("edge") && message.contains("no strike"),
        "{message}"
    );

    // Steady noise has no strike either.
    let noise: Vec<f32> = gaussian_noise(48_000, 3)
        .iter()
        .map(|v| 0.01 * *v as f32)
        .collect();
    let error = fit_bank(
        &[Recording::new("edge", noise, RATE)],
        &FitOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(error, FitError::Silent { .. }), "{error:?}");
    assert!(error.to_string().contains("it is steady noise"), "{error}");
}

#[test]
fn a_recording_too_short_to_measure_is_an_error() {
    let bank = truth_bank();
    let mut recording = noisy_recording(&bank, 0, SNR_DB, 5);
    // The lead-in and 20 ms of the strike.
    recording
        .samples
        .truncate(((LEAD_IN_S + 0.02) * RATE as f64) as usize);
    let error = fit_bank(&[recording], &FitOptions::default()).unwrap_err();
    match &error {
        FitError::TooShort {
            found_s, needed_s, ..
        } => assert!(found_s < needed_s, "{error}"),
        other => panic!("expected TooShort, got {other:?}"),
    }
    assert!(error.to_string().contains("after the strike"), "{error}");
}

#[test]
fn a_recording_shorter_than_a_fit_needs_is_too_short_not_noise() {
    // 100 samples of a strike: a decaying tone, no lead-in.
    let samples: Vec<f32> = (0..100)
        .map(|n| {
            let t = n as f64 / RATE as f64;
            (0.5 * (-30.0 * t).exp() * (std::f64::consts::TAU * 440.0 * t).sin()) as f32
        })
        .collect();
    let error = fit_bank(
        &[Recording::new("hit", samples, RATE)],
        &FitOptions::default(),
    )
    .unwrap_err();
    assert!(matches!(error, FitError::TooShort { .. }), "{error}");
    assert!(!error.to_string().contains("noise"), "{error}");
}

#[test]
fn clipped_and_very_noisy_recordings_fit_with_warnings() {
    let bank = truth_bank();
    // Driven into a converter that clips at full scale: a little too hot clips the start of the
    // ring (a warning); four times too hot flattens much of it (an error).
    let hot = |gain: f32| {
        let mut clipped = noisy_recording(&bank, 0, SNR_DB, 7);
        for v in &mut clipped.samples {
            *v = (*v * gain / STRONGEST as f32).clamp(-1.0, 1.0);
        }
        clipped
    };
    let fit = fit_bank(&[hot(1.2)], &FitOptions::default()).unwrap();
    let warnings = &fit.report.recordings[0].warnings;
    assert!(
        warnings.iter().any(|w| w.starts_with("clipped")),
        "{warnings:?}"
    );
    assert!(fit.report.to_string().contains("warning: clipped"));
    let error = fit_bank(&[hot(4.0)], &FitOptions::default()).unwrap_err();
    assert!(matches!(error, FitError::Clipped { .. }), "{error:?}");
    let message = error.to_string();
    assert!(
        message.starts_with("edge: clipped:") && message.contains("more headroom"),
        "{message}"
    );

    // Noise 12 dB below the render's RMS: the strike's first millisecond stands about 26 dB
    // above it.
    let noisy = noisy_recording(&bank, 1, 12.0, 8);
    let fit = fit_bank(&[noisy], &FitOptions::default()).unwrap();
    let warnings = &fit.report.recordings[0].warnings;
    assert!(
        warnings.iter().any(|w| w.starts_with("very noisy")),
        "{warnings:?}"
    );
    // The strongest modes are still found.
    for f in [196.0, 523.7] {
        assert!(
            fit.bank
                .modes
                .iter()
                .any(|m| (m.freq_hz / f - 1.0).abs() < FREQ_TOLERANCE),
            "{f} Hz not found in the noisy recording"
        );
    }
}

#[test]
fn bad_names_and_options_are_errors() {
    let bank = truth_bank();
    let a = noisy_recording(&bank, 0, SNR_DB, 9);
    let error = fit_bank(&[a.clone(), a.clone()], &FitOptions::default()).unwrap_err();
    assert!(matches!(error, FitError::DuplicateName { .. }), "{error:?}");
    assert!(matches!(
        fit_bank(&[], &FitOptions::default()).unwrap_err(),
        FitError::NoRecordings
    ));
    for options in [
        FitOptions {
            max_modes: 0,
            ..FitOptions::default()
        },
        FitOptions {
            min_hz: 5_000.0,
            max_hz: 1_000.0,
            ..FitOptions::default()
        },
        FitOptions {
            noise_floor_db: Some(3.0),
            ..FitOptions::default()
        },
    ] {
        let error = fit_bank(std::slice::from_ref(&a), &options).unwrap_err();
        assert!(matches!(error, FitError::BadOption { .. }), "{error:?}");
    }
    let low = Recording::new("edge", a.samples.clone(), 4_000);
    let error = fit_bank(&[low], &FitOptions::default()).unwrap_err();
    assert!(error.to_string().contains("8000 Hz"), "{error}");
}

#[test]
fn the_mode_count_and_frequency_range_are_respected() {
    let bank = truth_bank();
    let recordings: Vec<Recording> = (0..2)
        .map(|k| noisy_recording(&bank, k, SNR_DB, 30 + k as u64))
        .collect();
    let options = FitOptions {
        max_modes: 4,
        min_hz: 300.0,
        max_hz: 6_000.0,
        ..FitOptions::default()
    };
    let fit = fit_bank(&recordings, &options).unwrap();
    assert_eq!(fit.bank.modes.len(), 4);
    assert!(fit
        .bank
        .modes
        .iter()
        .all(|m| (300.0..=6_000.0).contains(&m.freq_hz)));
    // The four with the most energy in range (seed 000 eq. 5.15, about a^2 / d here).
    for (m, expected) in fit.bank.modes.iter().zip([523.7, 1000.0, 1012.0, 1571.3]) {
        assert!(
            (m.freq_hz / expected - 1.0).abs() < FREQ_TOLERANCE,
            "kept {} Hz, expected {expected} Hz",
            m.freq_hz
        );
    }

    // A noise floor above the weak modes leaves them out.
    let options = FitOptions {
        noise_floor_db: Some(20.0 * (STRONGEST * 10f64.powf(-20.0 / 20.0)).log10()),
        ..FitOptions::default()
    };
    let fit = fit_bank(&recordings, &options).unwrap();
    let largest = fit
        .bank
        .modes
        .iter()
        .flat_map(|m| m.gains.iter())
        .fold(0.0f64, |a, g| a.max(g.abs()));
    for m in &fit.bank.modes {
        let strongest_db = db(m.gains.iter().fold(0.0f64, |a, g| a.max(g.abs())) / largest);
        assert!(
            strongest_db > -21.0,
            "{} Hz at {strongest_db:.1} dB kept",
            m.freq_hz
        );
    }
}

/// The bank of `modes` (frequency, decay, gains at the two ends), fitted from its noisy renders
/// at both ends.
fn fit_of(modes: &[(f64, f64, [f64; 2])], seed: u64) -> Bank {
    let mut bank = Bank::new("pair", common::two_ends());
    for &(freq_hz, decay_per_s, gains) in modes {
        bank.modes.push(Mode {
            freq_hz,
            decay_per_s,
            gains: gains.to_vec(),
        });
    }
    let recordings: Vec<Recording> = (0..2)
        .map(|k| noisy_recording(&bank, k, SNR_DB, seed + k as u64))
        .collect();
    fit_bank(&recordings, &FitOptions::default()).unwrap().bank
}

/// The mode of `modes` nearest `freq_hz`.
fn nearest(modes: &[Mode], freq_hz: f64) -> &Mode {
    modes
        .iter()
        .min_by(|a, b| {
            (a.freq_hz - freq_hz)
                .abs()
                .total_cmp(&(b.freq_hz - freq_hz).abs())
        })
        .expect("at least one mode")
}

/// The modes of `bank` within `within_hz` of `freq_hz`.
fn modes_near(bank: &Bank, freq_hz: f64, within_hz: f64) -> Vec<&Mode> {
    bank.modes
        .iter()
        .filter(|m| (m.freq_hz - freq_hz).abs() < within_hz)
        .collect()
}

#[test]
fn a_beating_pair_comes_out_as_two_modes() {
    // 1 Hz apart at 1 kHz, inside the 2.5 Hz limen (seed 000 section 5.4.1): alone, each is
    // one pitch, but together they beat once a second, which one mode cannot do.
    let fit = fit_of(
        &[
            (440.0, 2.0, [0.3, 0.2]),
            (1000.0, 3.0, [0.1, 0.05]),
            (1001.0, 3.0, [0.1, 0.05]),
        ],
        50,
    );
    let near = modes_near(&fit, 1000.5, 10.0);
    assert_eq!(near.len(), 2, "modes near 1 kHz: {:?}", fit.modes);
    for (m, want) in near.iter().zip([1000.0, 1001.0]) {
        assert!(
            (m.freq_hz - want).abs() < 0.1 && (m.decay_per_s / 3.0 - 1.0).abs() < 0.1,
            "{want} Hz, 3 /s: found {m:?}"
        );
    }
    // Anything else is faint: a trace of the strike's click or of the noise, 50 dB down.
    let strongest = fit
        .modes
        .iter()
        .map(|m| m.gains[0].abs())
        .fold(0.0, f64::max);
    let others: Vec<&Mode> = fit
        .modes
        .iter()
        .filter(|m| (m.freq_hz - 440.0).abs() > 0.1 && (m.freq_hz - 1000.5).abs() > 0.6)
        .collect();
    assert!(
        others
            .iter()
            .all(|m| m.gains.iter().all(|g| db(*g) < db(strongest) - 50.0)),
        "{others:?}"
    );
}

#[test]
fn a_fast_then_slow_decay_comes_out_as_two_modes() {
    // A partial that falls 35 dB in its first 0.2 s, then rings on 25 dB down: the sum of a
    // fast and a slow mode at nearly one frequency, as a bar's near-degenerate pair gives it.
    let (fast, slow) = ((2000.0, 40.0, [0.3, 0.2]), (2000.3, 1.5, [0.02, 0.015]));
    let fit = fit_of(&[(440.0, 2.0, [0.3, 0.2]), fast, slow], 70);
    let near = modes_near(&fit, 2000.0, 20.0);
    assert_eq!(near.len(), 2, "modes near 2 kHz: {:?}", fit.modes);
    let (quick, long) = if near[0].decay_per_s > near[1].decay_per_s {
        (near[0], near[1])
    } else {
        (near[1], near[0])
    };
    for (m, want) in [(quick, fast), (long, slow)] {
        assert!(
            (m.freq_hz - want.0).abs() < 0.5 && (m.decay_per_s / want.1 - 1.0).abs() < 0.1,
            "{} Hz, {} /s: found {m:?}",
            want.0,
            want.1
        );
    }
}

#[test]
fn the_fidelity_score_tells_a_wrong_bank_from_the_right_one() {
    // The recordings' own bank scores near 0 dB; the same bank 6 dB louder scores its level;
    // detuned, or decaying twice as fast, it scores far worse.
    let truth = truth_bank();
    let recordings: Vec<Recording> = (0..2)
        .map(|k| noisy_recording(&truth, k, SNR_DB, 90 + k as u64))
        .collect();
    let options = FitOptions::default();
    let score = |bank: &Bank| compare(bank, &recordings, &options, engine).unwrap();
    let altered = |change: &dyn Fn(&mut Mode)| {
        let mut bank = truth.clone();
        bank.modes.iter_mut().for_each(change);
        bank
    };
    let right = score(&truth);
    let louder = score(&altered(&|m| m.gains.iter_mut().for_each(|g| *g *= 2.0)));
    let detuned = score(&altered(&|m| m.freq_hz *= 1.03));
    let faster = score(&altered(&|m| m.decay_per_s *= 2.0));
    for k in 0..2 {
        let name = &recordings[k].name;
        println!(
            "{name}: right {:.2} dB ({:+.2} dB), 6 dB louder {:.2} dB ({:+.2} dB), detuned 3% \
             {:.2} dB, decaying twice as fast {:.2} dB ({:+.2} dB)",
            right[k].lsd_db,
            right[k].level_db,
            louder[k].lsd_db,
            louder[k].level_db,
            detuned[k].lsd_db,
            faster[k].lsd_db,
            faster[k].level_db
        );
        assert!(right[k].lsd_db < 2.0, "{name}: {:?}", right[k]);
        assert!(right[k].level_db.abs() < 0.3, "{name}: {:?}", right[k]);
        let gain_db = 20.0 * 2f64.log10();
        assert!(
            (louder[k].level_db - gain_db).abs() < 0.3,
            "{name}: 6 dB louder reads {:?}",
            louder[k]
        );
        assert!(
            louder[k].lsd_db > 4.5 && louder[k].lsd_db < gain_db + 0.5,
            "{name}: 6 dB louder reads {:?}",
            louder[k]
        );
        assert!(
            detuned[k].lsd_db > 10.0 && detuned[k].lsd_db > 4.0 * right[k].lsd_db,
            "{name}: detuned reads {:?}, the right bank {:?}",
            detuned[k],
            right[k]
        );
        assert!(
            faster[k].lsd_db > right[k].lsd_db + 3.0 && faster[k].level_db < -1.0,
            "{name}: decaying twice as fast reads {:?}, the right bank {:?}",
            faster[k],
            right[k]
        );
    }
}

#[test]
fn hum_before_the_strike_is_left_out_and_a_slow_mode_from_the_strike_is_kept() {
    // A mode at 700 Hz losing under 2% over the 3 s recorded, and 60 Hz mains hum through the
    // whole recording, lead-in included.
    let mut bank = Bank::new("hum", common::two_ends());
    for (freq_hz, decay_per_s, gain) in [(440.0, 2.0, 0.3), (700.0, 0.006f64, 0.05)] {
        bank.modes.push(Mode {
            freq_hz,
            decay_per_s: decay_per_s.max(0.01),
            gains: vec![gain, gain],
        });
    }
    let mut recording = noisy_recording(&bank, 0, SNR_DB, 90);
    for (n, v) in recording.samples.iter_mut().enumerate() {
        *v += (0.01 * (std::f64::consts::TAU * 60.0 * n as f64 / RATE as f64).sin()) as f32;
    }
    let fit = fit_bank(&[recording], &FitOptions::default()).unwrap();
    let freqs: Vec<f64> = fit.bank.modes.iter().map(|m| m.freq_hz).collect();
    assert!(
        modes_near(&fit.bank, 60.0, 2.0).is_empty(),
        "hum kept: {freqs:?}"
    );
    for f in [440.0, 700.0] {
        let near = modes_near(&fit.bank, f, 1.0);
        let strongest = near
            .iter()
            .max_by(|a, b| a.gains[0].abs().total_cmp(&b.gains[0].abs()))
            .unwrap_or_else(|| panic!("{f} Hz left out: {freqs:?}"));
        assert!((strongest.freq_hz - f).abs() < 0.05, "{f} Hz: {freqs:?}");
    }
    let warnings = &fit.report.recordings[0].warnings;
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("60.0 Hz left out as hum") && w.contains("before the strike")),
        "{warnings:?}"
    );
}

/// The most amplitude of a sinusoid at `freq_hz` in any Hann window of 4,096 samples (hop
/// 2,048) of `x` from sample `from` on.
fn most_amplitude_from(x: &[f64], from: usize, freq_hz: f64) -> f64 {
    let len = 4096;
    let w: Vec<f64> = (0..len)
        .map(|n| 0.5 - 0.5 * (std::f64::consts::TAU * n as f64 / len as f64).cos())
        .collect();
    let omega = std::f64::consts::TAU * freq_hz / RATE as f64;
    (from..x.len() - len)
        .step_by(len / 2)
        .map(|start| {
            let (mut re, mut im) = (0.0, 0.0);
            for (n, (v, w)) in x[start..start + len].iter().zip(&w).enumerate() {
                re += v * w * (omega * n as f64).cos();
                im -= v * w * (omega * n as f64).sin();
            }
            2.0 * (re * re + im * im).sqrt() / w.iter().sum::<f64>()
        })
        .fold(0.0, f64::max)
}

/// The factory bank `name` struck at `key` as `render` plays it (the left channel), its ring
/// decaying into -70 dBFS of noise over `seconds`, in 16 bits, and its fit.
fn noisy_factory_strike(name: &str, key: u8, seconds: f64) -> (Bank, Vec<f64>, Bank) {
    let bank = modal_resonator::bank::factory::factory_bank(name).unwrap();
    let len = (seconds * RATE as f64) as usize;
    let settings = modal_resonator::render::RenderSettings {
        sample_rate_hz: RATE,
        controls: Controls::for_bank(&bank),
        max_seconds: seconds,
        ..Default::default()
    };
    let played = render(
        &Arc::new(PreparedBank::new(&bank)),
        &[Note::new(key, 1.0, 0.2, None)],
        &settings,
        |_| {},
    );
    let sigma = 10f64.powf(-70.0 / 20.0);
    let noise = gaussian_noise(len, 77);
    let x: Vec<f64> = (0..len)
        .map(|n| {
            let v = played.left.get(n).copied().unwrap_or(0.0) as f64 + sigma * noise[n];
            (v * 32767.0).round().clamp(-32768.0, 32767.0) / 32767.0
        })
        .collect();
    let samples: Vec<f32> = x.iter().map(|&v| v as f32).collect();
    let fit = fit_bank(
        &[Recording::new("edge", samples, RATE)],
        &FitOptions::default(),
    )
    .unwrap();
    (bank, x, fit.bank)
}

#[test]
fn no_fitted_mode_rings_on_past_what_the_recording_shows() {
    // The steel bar an octave under its root: weak modes the fits cannot follow into the noise
    // must not be left at the decay floor, ringing for minutes where the recording shows
    // nothing.
    let (bank, x, fitted) = noisy_factory_strike("steel-free-free-bar", 72, 6.0);
    let tail = (0.75 * x.len() as f64) as usize;
    let t = tail as f64 / RATE as f64;
    for m in &fitted.modes {
        // At the start of the last quarter a mode stands at most 12 dB over the most the
        // recording holds at its frequency in that quarter (6 dB of the fit's margin, 6 of
        // frames that differ from the fit's).
        let level = m.gains[0].abs() * (-m.decay_per_s * t).exp();
        let shown = most_amplitude_from(&x, tail, m.freq_hz);
        assert!(
            level < 4.0 * shown,
            "{:.1} Hz decaying {:.3} /s (T60 {:.0} s) at {:.1} dBFS after {t:.1} s where the \
             recording shows {:.1} dBFS",
            m.freq_hz,
            m.decay_per_s,
            6.91 / m.decay_per_s,
            db(level),
            db(shown),
        );
    }
    // The bar's own fundamental, an octave under its root, is still there with its slow decay
    // (the bank's, played an octave down: half the rate).
    let root = 0.5 * bank.root_hz.unwrap();
    let fundamental = modes_near(&fitted, root, 1.0);
    let loudest = fundamental
        .iter()
        .max_by(|a, b| a.gains[0].abs().total_cmp(&b.gains[0].abs()))
        .unwrap_or_else(|| panic!("the fundamental {root} Hz left out"));
    let truth = 0.5 * bank.modes[0].decay_per_s;
    assert!(
        (loudest.decay_per_s / truth - 1.0).abs() < 0.1,
        "fundamental decays {} /s, played {truth} /s",
        loudest.decay_per_s
    );

    // The bronze bell at its root, 4 s: its slowest mode, the hum, decays at 0.44 /s; a weak
    // mode a few hertz beside it was kept at the floor (227.9 Hz at 0.01 /s, 42 dB under the
    // strongest), which the frames of the fit cannot part from the hum. No mode within 60 dB of
    // the strongest may be that slow.
    let (_, _, fitted) = noisy_factory_strike("bronze-bell", 69, 4.0);
    let strongest = fitted
        .modes
        .iter()
        .map(|m| m.gains[0].abs())
        .fold(0.0, f64::max);
    for m in &fitted.modes {
        assert!(
            m.decay_per_s > 0.05 || m.gains[0].abs() < 1e-3 * strongest,
            "{:.2} Hz decaying {:.3} /s at {:.1} dB of the strongest",
            m.freq_hz,
            m.decay_per_s,
            db(m.gains[0].abs() / strongest)
        );
    }
}

#[test]
fn a_tone_that_never_decays_is_hum_in_a_file_that_starts_at_the_strike() {
    // 2.5 s from the strike itself, nothing before it to hear the hum in: two modes, and 60 Hz
    // mains hum through the whole file, which cannot be a mode of a struck object (it would
    // ring for minutes).
    let len = 5 * RATE as usize / 2;
    let noise = gaussian_noise(len, 7);
    let samples: Vec<f32> = (0..len)
        .map(|n| {
            let t = n as f64 / RATE as f64;
            let ring = 0.3 * (-2.0 * t).exp() * (std::f64::consts::TAU * 440.0 * t).sin()
                + 0.1 * (-5.0 * t).exp() * (std::f64::consts::TAU * 1234.5 * t).sin();
            let hum = 0.01 * (std::f64::consts::TAU * 60.0 * t).sin();
            (ring + hum + 1e-4 * noise[n]) as f32
        })
        .collect();
    let recording = Recording::new("hum", samples, RATE);
    let fit = fit_bank(&[recording], &FitOptions::default()).unwrap();
    let freqs: Vec<f64> = fit.bank.modes.iter().map(|m| m.freq_hz).collect();
    assert!(
        modes_near(&fit.bank, 60.0, 2.0).is_empty(),
        "hum kept: {freqs:?}"
    );
    for f in [440.0, 1234.5] {
        assert!(
            modes_near(&fit.bank, f, 0.5)
                .iter()
                .any(|m| (m.freq_hz - f).abs() < 0.05),
            "{f} Hz: {freqs:?}"
        );
    }
    let warnings = &fit.report.recordings[0].warnings;
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("60.0 Hz left out as hum")),
        "{warnings:?}"
    );
}

#[test]
fn a_strike_cut_before_its_ring_dies_is_fitted() {
    // The recording stops 0.5 s after the strike, its slowest mode only 4 dB down: no quiet
    // stretch to take the noise from.
    let bank = truth_bank();
    let mut recording = noisy_recording(&bank, 0, SNR_DB, 110);
    let lead_in = (LEAD_IN_S * RATE as f64) as usize;
    recording.samples.drain(..lead_in);
    recording.samples.truncate(RATE as usize / 2);
    let fit = fit_bank(&[recording], &FitOptions::default()).unwrap();
    for t in bank.modes.iter().take(4) {
        let m = modes_near(&fit.bank, t.freq_hz, 2.0);
        assert_eq!(m.len(), 1, "{} Hz: {:?}", t.freq_hz, fit.bank.modes);
        assert!(
            (m[0].decay_per_s / t.decay_per_s - 1.0).abs() < 0.25,
            "{} Hz: decay {} /s, true {} /s",
            t.freq_hz,
            m[0].decay_per_s,
            t.decay_per_s
        );
    }
}

#[test]
fn a_strike_after_digital_silence_is_fitted_as_well_as_one_after_noise() {
    // Three modes struck 1 s into a 16-bit file whose lead-in is exact zeros: no noise is shown
    // anywhere, and the quietest millisecond blocks are not the lead-in's tenth of the file.
    const MODES: [(f64, f64, f64); 3] =
        [(440.0, 3.0, 0.4), (1234.5, 6.0, 0.2), (3333.0, 15.0, 0.1)];
    for lead_in_s in [0.1, 1.0] {
        let len = ((lead_in_s + 1.0) * RATE as f64) as usize;
        let lead_in = (lead_in_s * RATE as f64) as usize;
        let samples: Vec<f32> = (0..len)
            .map(|n| {
                let Some(k) = n.checked_sub(lead_in) else {
                    return 0.0;
                };
                let t = k as f64 / RATE as f64;
                let x: f64 = MODES
                    .iter()
                    .map(|&(f, d, a)| a * (-d * t).exp() * (std::f64::consts::TAU * f * t).sin())
                    .sum();
                ((x * 32767.0).round() / 32767.0) as f32
            })
            .collect();
        let fit = fit_bank(
            &[Recording::new("silent lead-in", samples, RATE)],
            &FitOptions::default(),
        )
        .unwrap();
        let strongest = fit
            .bank
            .modes
            .iter()
            .fold(0.0f64, |a, m| a.max(m.gains[0].abs()));
        for (f, d, a) in MODES {
            let m = modes_near(&fit.bank, f, 1.0);
            assert!(
                !m.is_empty(),
                "{lead_in_s} s: {f} Hz missing: {:?}",
                fit.bank.modes
            );
            let m = m[0];
            let gain_db = db(m.gains[0] / strongest) - db(a / MODES[0].2);
            assert!(
                (m.freq_hz / f - 1.0).abs() <= FREQ_TOLERANCE
                    && (m.decay_per_s / d - 1.0).abs() <= DECAY_TOLERANCE
                    && gain_db.abs() <= GAIN_TOLERANCE_DB,
                "{lead_in_s} s: {f} Hz, {d} /s: found {} Hz, {} /s, gain {gain_db:+.2} dB off",
                m.freq_hz,
                m.decay_per_s
            );
        }
        let warnings = &fit.report.recordings[0].warnings;
        assert!(
            !warnings.iter().any(|w| w.contains("noisy")),
            "{lead_in_s} s: {warnings:?}"
        );
    }
}
