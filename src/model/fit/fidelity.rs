//! How close a bank sounds to a recording: the bank re-synthesised through the engine at the
//! recording's position and compared with it spectrogram to spectrogram.
//!
//! The score is the log-spectral distance over time: the RMS difference in dB between the two
//! spectrograms, over the time-frequency cells where either stands above the recording's noise
//! floor and within 60 dB of the recording's loudest cell (the range a listener hears of one
//! strike; below it the comparison would weigh window leakage and inaudible detail). Phases are
//! ignored (the engine starts every mode in sine phase; a microphone hears each with its own),
//! the level is not: a bank that reproduces the recording's spectrum and decays but not its
//! level scores the level difference.

use std::sync::Arc;

use super::analyse::Analysis;
use super::stft::{hann, Spectrogram};
use crate::dsp::ExciterKind;
use crate::engine::{Controls, PositionMap, PreparedBank};
use crate::model::Bank;
use crate::render::{render, Note, RenderSettings};

/// Length of the comparison's frames in seconds (rounded to a power of two of samples): about
/// the ear's time resolution for tones.
const FRAME_S: f64 = 0.04;

/// Cells within this many dB of the noise floor count as silent in both spectrograms.
const FLOOR_ABOVE_NOISE_DB: f64 = 6.0;

/// Cells more than this many dB below the recording's loudest count as silent too.
pub const DYNAMIC_RANGE_DB: f64 = 60.0;

/// Quietest level the engine renders, in dBFS: far below any recording's noise.
const TRUNCATION_DB: f32 = -140.0;

/// Key struck for re-synthesis; with key tracking off any key plays the bank as authored.
const KEY: u8 = 60;

/// The comparison of a recording with the bank's re-synthesis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fidelity {
    /// Log-spectral distance in dB: RMS over the cells above the noise floor and within
    /// [`DYNAMIC_RANGE_DB`] of the recording's loudest.
    pub lsd_db: f64,
    /// Energy of the re-synthesis over the recording's, in dB.
    pub level_db: f64,
}

/// `bank` struck at position `position` with a unit impulse and rendered mono through the
/// engine for `len` samples at `sample_rate_hz`, in the bank's own units: the engine's loudness
/// normalisation is undone, so a mode of gain `a` starts at amplitude `a`.
pub fn resynthesize(bank: &Bank, position: usize, sample_rate_hz: u32, len: usize) -> Vec<f32> {
    let prepared = Arc::new(PreparedBank::new(bank));
    let mut controls = Controls::for_bank(bank);
    controls.exciter = ExciterKind::Impulse;
    controls.width = 0.0;
    controls.key_tracking = 0.0;
    controls.position_variation = 0.0;
    controls.truncation_db = TRUNCATION_DB;
    let coords: Vec<Vec<f64>> = bank.positions.iter().map(|p| p.coords.clone()).collect();
    if let Some(at) = PositionMap::new(&coords).coords().get(position) {
        controls.strike_x = at[0] as f32;
        controls.strike_y = at[1] as f32;
    }
    let settings = RenderSettings {
        sample_rate_hz,
        controls,
        max_seconds: len as f64 / sample_rate_hz as f64,
        ..RenderSettings::default()
    };
    let note = Note {
        key: KEY,
        velocity: 1.0,
        time_s: 0.0,
        duration_s: None,
    };
    let rendered = render(&prepared, &[note], &settings, |_| {});
    // With width 0 both channels carry the sum of the modes.
    let scale = 1.0 / prepared.normalization;
    let mut out: Vec<f32> = rendered.left.iter().map(|v| v * scale).collect();
    out.resize(len, 0.0);
    out
}

/// Compares the recording analysed in `a` with `bank` struck at `position`, over the sound of
/// the recording and the bins between `min_hz` and `max_hz`.
pub fn fidelity(bank: &Bank, position: usize, a: &Analysis, min_hz: f64, max_hz: f64) -> Fidelity {
    let rate = a.sample_rate_hz;
    let synth: Vec<f64> = resynthesize(bank, position, rate as u32, a.signal.len())
        .into_iter()
        .map(f64::from)
        .collect();
    let len = ((FRAME_S * rate).log2().round().exp2() as usize).min(a.signal.len());
    let sum_sq: f64 = hann(len).iter().map(|w| w * w).sum();
    let rec = Spectrogram::new(&a.signal, rate, len, len / 2, 1);
    let syn = Spectrogram::new(&synth, rate, len, len / 2, 1);
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
        level_db: 10.0 * (energy(&synth) / energy(&a.signal).max(1e-300)).log10(),
    }
}
