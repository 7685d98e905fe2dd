//! How close a bank sounds to a recording: a strike of the bank at the recording's position,
//! re-synthesised (its modes alone with [`synthesize_strike`], or through the engine by the
//! caller), compared with the recording spectrogram to spectrogram.
//!
//! The score is the log-spectral distance over time: the RMS difference in dB between the two
//! spectrograms, over the time-frequency cells where either stands above the recording's noise
//! floor and within 60 dB of the recording's loudest cell (the range a listener hears of one
//! strike; below it the comparison would weigh window leakage and inaudible detail). Phases are
//! ignored (the engine starts every mode in sine phase; a microphone hears each with its own),
//! the level is not: a bank that reproduces the recording's spectrum and decays but not its
//! level scores the level difference.

use std::f64::consts::TAU;

use realfft::num_complex::Complex64;

use super::analysis::Analysis;
use super::stft::{hann, Spectrogram};
use crate::bank::format::{MAX_FREQ_RATIO, MIN_DECAY_PER_S};
use crate::bank::Bank;

/// Length of the comparison's frames in seconds (rounded to a power of two of samples): about
/// the ear's time resolution for tones.
const FRAME_S: f64 = 0.04;

/// Cells within this many dB of the noise floor count as silent in both spectrograms.
const FLOOR_ABOVE_NOISE_DB: f64 = 6.0;

/// Cells more than this many dB below the recording's loudest count as silent too.
pub const DYNAMIC_RANGE_DB: f64 = 60.0;

/// The comparison of a recording with the bank's re-synthesis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fidelity {
    /// Log-spectral distance in dB: RMS over the cells above the noise floor and within
    /// [`DYNAMIC_RANGE_DB`] of the recording's loudest.
    pub lsd_db: f64,
    /// Energy of the re-synthesis over the recording's, in dB.
    pub level_db: f64,
}

/// `bank` struck at position `position` with a unit impulse, `len` samples at
/// `sample_rate_hz`, in the bank's own units: `sum_m a_m exp(-d_m t) sin(2 pi f_m t)`. This is
/// the bank as data, as a fitted bank plays (`render::resynthesize` renders any bank through
/// the engine, with its default controls, and the tests hold the two together): modes at or
/// above [`MAX_FREQ_RATIO`] of the rate are left out, and no mode decays slower than
/// [`MIN_DECAY_PER_S`], as in the engine.
pub fn synthesize_strike(
    bank: &Bank,
    position: usize,
    sample_rate_hz: u32,
    len: usize,
) -> Vec<f64> {
    let rate = f64::from(sample_rate_hz);
    let mut out = vec![0.0; len];
    for mode in &bank.modes {
        let gain = mode.gains.get(position).copied().unwrap_or(0.0);
        if mode.freq_hz >= MAX_FREQ_RATIO * rate || gain == 0.0 {
            continue;
        }
        // The mode's phasor, turned by its pole each sample: its imaginary part is the mode.
        let decay_per_s = mode.decay_per_s.max(MIN_DECAY_PER_S);
        let pole = Complex64::from_polar((-decay_per_s / rate).exp(), TAU * mode.freq_hz / rate);
        let mut z = Complex64::new(gain, 0.0);
        for v in &mut out {
            *v += z.im;
            z *= pole;
        }
    }
    out
}

/// Compares the recording analysed in `a` with `synth`, a strike re-synthesised at the
/// recording's rate and length, over the bins between `min_hz` and `max_hz`.
pub fn fidelity(synth: &[f64], a: &Analysis, min_hz: f64, max_hz: f64) -> Fidelity {
    let rate = a.sample_rate_hz;
    let len = ((FRAME_S * rate).log2().round().exp2() as usize).min(a.signal.len());
    let sum_sq: f64 = hann(len).iter().map(|w| w * w).sum();
    let rec = Spectrogram::new(&a.signal, rate, len, len / 2, 1);
    let syn = Spectrogram::new(synth, rate, len, len / 2, 1);
    let bins = rec.bin_of(min_hz)..rec.bin_of(max_hz) + 1;
    let loudest = rec
        .power
        .iter()
        .flat_map(|frame| frame[bins.clone()].iter())
        .fold(0.0f64, |a, &p| a.max(p));
    let range_floor = loudest * 10f64.powf(-DYNAMIC_RANGE_DB / 10.0);
    let floors: Vec<f64> = bins
        .clone()
        .map(|b| {
            let noise = a.noise_density(b as f64 * rec.bin_hz) * sum_sq;
            (noise * 10f64.powf(FLOOR_ABOVE_NOISE_DB / 10.0)).max(range_floor)
        })
        .collect();
    let (mut total, mut cells) = (0.0, 0usize);
    for (r, s) in rec.power.iter().zip(&syn.power) {
        for (b, floor) in bins.clone().zip(&floors) {
            let (pr, ps) = (r[b].max(*floor), s[b].max(*floor));
            if pr > *floor || ps > *floor {
                total += (10.0 * (pr / ps).log10()).powi(2);
                cells += 1;
            }
        }
    }
    let energy = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>();
    Fidelity {
        lsd_db: if cells > 0 {
            (total / cells as f64).sqrt()
        } else {
            0.0
        },
        level_db: 10.0 * (energy(synth) / energy(&a.signal).max(1e-300)).log10(),
    }
}
