//! The noise floor of a recording: the power a frame holds at each frequency when the object is
//! silent there.
//!
//! Each bin's power is low for a good share of the frames once the ring has died away: a low
//! percentile over the frames finds that level, and a median across neighbouring bins removes
//! narrow peaks of modes that ring through the whole recording. The median follows a smooth noise
//! colour (hum, hiss tilt) but not single modes.

use super::stft::Spectrogram;

/// Percentile of a bin's power over the frames taken as its noise level.
const NOISE_PERCENTILE: f64 = 0.2;

/// Ratio of the 20th percentile of an exponentially distributed power (a noise bin) to its mean,
/// `-ln(1 - 0.2)`: dividing by it turns the percentile into the mean noise power.
const PERCENTILE_TO_MEAN: f64 = 0.223_143_551_314_209_75;

/// Half-width of the median across frequency, in bins of the unpadded window: wide enough that a
/// mode's main lobe (4 bins) is a minority.
const MEDIAN_HALF_WIDTH_BINS: usize = 16;

/// Lowest noise power per bin relative to a full-scale sinusoid's (-150 dB): digital silence
/// still has a finite floor.
const MIN_RELATIVE_POWER: f64 = 1e-15;

/// Estimated mean noise power in each bin of a spectrogram's frames.
#[derive(Debug, Clone)]
pub struct NoiseSpectrum {
    /// Mean `|X|^2` of noise in each bin.
    pub power: Vec<f64>,
}

impl NoiseSpectrum {
    /// Estimates the noise in the frames of `spec` (which should span the whole recording,
    /// before the strike and after the ring as well as during it).
    pub fn estimate(spec: &Spectrogram, window_sum: f64) -> Self {
        let bins = spec.num_bins();
        let frames = spec.power.len();
        let floor = MIN_RELATIVE_POWER * (0.5 * window_sum).powi(2);
        if frames == 0 {
            return Self {
                power: vec![floor; bins],
            };
        }
        let rank = ((frames - 1) as f64 * NOISE_PERCENTILE).round() as usize;
        let mut column = vec![0.0; frames];
        let per_bin: Vec<f64> = (0..bins)
            .map(|b| {
                for (c, frame) in column.iter_mut().zip(&spec.power) {
                    *c = frame[b];
                }
                let (_, value, _) = column.select_nth_unstable_by(rank, f64::total_cmp);
                *value / PERCENTILE_TO_MEAN
            })
            .collect();
        let half = MEDIAN_HALF_WIDTH_BINS * spec.pad;
        let mut neighbourhood = Vec::with_capacity(2 * half + 1);
        let power = (0..bins)
            .map(|b| {
                neighbourhood.clear();
                neighbourhood
                    .extend_from_slice(&per_bin[b.saturating_sub(half)..(b + half + 1).min(bins)]);
                let mid = neighbourhood.len() / 2;
                let (_, median, _) = neighbourhood.select_nth_unstable_by(mid, f64::total_cmp);
                median.max(floor)
            })
            .collect();
        Self { power }
    }

    /// Noise power in the bin of `spec` nearest `freq_hz`.
    #[cfg(test)]
    pub fn at(&self, spec: &Spectrogram, freq_hz: f64) -> f64 {
        self.power[spec.bin_of(freq_hz)]
    }
}

#[cfg(test)]
mod tests {
    use super::super::stft::{hann, Spectrogram};
    use super::*;
    use crate::dsp::rng::Rng;

    #[test]
    fn white_noise_power_is_found_under_decaying_and_ringing_modes() {
        let rate = 48_000.0;
        let sigma = 1e-3f64;
        let mut rng = Rng::new(7);
        // Uniform noise of variance sigma^2; a strong mode that dies within the first second,
        // and a weak one ringing through the whole signal 10 dB above the noise in its bin.
        let x: Vec<f64> = (0..96_000)
            .map(|n| {
                let t = n as f64 / rate;
                let tau = std::f64::consts::TAU;
                sigma * 3f64.sqrt() * rng.bipolar() as f64
                    + 0.5 * (-10.0 * t).exp() * (tau * 1000.0 * t).sin()
                    + 2e-4 * (tau * 3000.0 * t).sin()
            })
            .collect();
        let len = 2048;
        let spec = Spectrogram::new(&x, rate, len, len / 4, 2);
        let w = hann(len);
        let noise = NoiseSpectrum::estimate(&spec, w.iter().sum());
        // White noise of variance s^2 gives E|X|^2 = s^2 sum(w^2) in every bin.
        let expected = sigma * sigma * w.iter().map(|v| v * v).sum::<f64>();
        for f in [200.0, 1000.0, 3000.0, 5000.0, 15000.0] {
            let ratio_db = 10.0 * (noise.at(&spec, f) / expected).log10();
            assert!(
                ratio_db.abs() < 1.5,
                "{f} Hz: noise estimate off by {ratio_db:.2} dB"
            );
        }
    }
}
