//! What the analysis of one recording holds ([`Analysis`]): the sound from its strike, its
//! noise floor and the modes found in it, which the stages of the fit read and refine.

use realfft::num_complex::Complex64;

use super::lsq::{add_modes, fit_amplitudes, Shape};
use super::noise::NoiseSpectrum;
use super::onset::Strike;
use super::track::Track;

/// One mode found in a recording.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Found {
    /// Frequency in Hz.
    pub freq_hz: f64,
    /// Decay rate in 1/s.
    pub decay_per_s: f64,
    /// Complex amplitude at the onset from the joint fit (`-i a` for `a sin(w t)`).
    pub amplitude: Complex64,
    /// Signed gain at the strike, as the bank holds it.
    pub gain: f64,
    /// The last tracking of the mode: frames used and how well they fit.
    pub track: Track,
}

/// What one recording holds.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// Position name of the recording.
    pub name: String,
    /// Sample rate in Hz.
    pub sample_rate_hz: f64,
    /// The sound from the onset to the end of the recording (at most the longest stretch
    /// analysed), as f64.
    pub signal: Vec<f64>,
    /// First sample of `signal` used by the fits.
    pub start: usize,
    /// Where the strike is in the recording.
    pub strike: Strike,
    /// Analysis window in samples.
    pub window_len: usize,
    /// Modes found, by frequency.
    pub modes: Vec<Found>,
    /// Warnings for the report.
    pub warnings: Vec<String>,
    /// Up to [`BEFORE_S`](super::analyse) of the recording before the onset.
    pub(super) before: Vec<f64>,
    /// Noise power per bin of the noise spectrogram.
    pub(super) noise: NoiseSpectrum,
    /// Bin width of the noise spectrogram in Hz.
    pub(super) bin_hz: f64,
    /// `sum(w)` and `sum(w^2)` of the analysis window.
    pub(super) window_sums: (f64, f64),
    /// Noise floor given by the user, as a linear amplitude.
    pub(super) floor_override: Option<f64>,
}

impl Analysis {
    /// Noise `|Z|^2` per unit `sum(w^2)` near `freq_hz` (see [`track`]).
    pub fn noise_density(&self, freq_hz: f64) -> f64 {
        let (sum, sum_sq) = self.window_sums;
        match self.floor_override {
            // A sinusoid of amplitude a gives |Z| = a sum(w) / 2.
            Some(a) => (0.5 * a * sum).powi(2) / sum_sq,
            None => {
                let bin =
                    ((freq_hz / self.bin_hz).round() as usize).min(self.noise.power.len() - 1);
                self.noise.power[bin] / sum_sq
            }
        }
    }

    /// Whether the user gave the noise floor.
    pub fn floor_given(&self) -> bool {
        self.floor_override.is_some()
    }

    /// Amplitude of a mode as strong as the noise in one analysis frame near `freq_hz`: the
    /// noise floor in the units of the bank's gains.
    pub fn floor_amplitude(&self, freq_hz: f64) -> f64 {
        let (sum, sum_sq) = self.window_sums;
        2.0 * (self.noise_density(freq_hz) * sum_sq).sqrt() / sum
    }

    /// The frequency and decay of each mode found.
    pub fn shapes(&self) -> Vec<Shape> {
        self.modes
            .iter()
            .map(|m| Shape {
                freq_hz: m.freq_hz,
                decay_per_s: m.decay_per_s,
            })
            .collect()
    }

    /// Joint amplitudes of `shapes` in this recording.
    pub fn amplitudes(&self, shapes: &[Shape]) -> Vec<Complex64> {
        fit_amplitudes(&self.signal, self.sample_rate_hz, self.start, shapes)
    }

    /// The signal less `shapes` with `amplitudes`.
    pub fn residual(&self, shapes: &[Shape], amplitudes: &[Complex64]) -> Vec<f64> {
        let mut model = vec![0.0; self.signal.len()];
        add_modes(&mut model, self.sample_rate_hz, shapes, amplitudes);
        self.signal.iter().zip(&model).map(|(x, m)| x - m).collect()
    }
}
