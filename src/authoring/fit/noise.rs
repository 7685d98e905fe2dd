//! The noise floor of a recording: the power a frame holds at each frequency when the object is
//! silent there.
//!
//! Each bin's power is low for a good share of the frames once the ring has died away: a low
//! percentile over the frames finds that level, and a median across neighbouring bins removes
//! narrow peaks of modes that ring through the whole recording. The median follows a smooth noise
//! colour (hum, hiss tilt) but not single modes.
//!
//! That holds only where the sound has died away before the file ends. Where it still falls over
//! the last frames (a recording cut at a sampler's loop start, a short click, a cymbal still
//! ringing), the quietest frames are the sound itself, and the noise is taken as the lowest the
//! recording does show.

use super::stft::Spectrogram;

/// Percentile of a bin's power over the frames taken as its noise level.
const NOISE_PERCENTILE: f64 = 0.2;

/// Ratio of the 20th percentile of an exponentially distributed power (a noise bin) to its mean,
/// `-ln(1 - 0.2)`: dividing by it turns the percentile into the mean noise power.
const PERCENTILE_TO_MEAN: f64 = 0.223_143_551_314_209_75;

/// Half-width of the median across frequency, in bins of the unpadded window: wide enough that a
/// mode's main lobe (4 bins) is a minority.
const MEDIAN_HALF_WIDTH_BINS: usize = 16;

/// The last quarter of the frames is compared with the quarter before it: where their power,
/// summed over a bin's neighbourhood, falls by more than this factor (3 dB), the sound is still
/// dying away when the recording ends.
const STILL_FALLING: f64 = 2.0;

/// A bin's estimate is the sound of its last frames, not noise shown before or after the sound,
/// when it is at least this share of their mean power (within 3 dB).
const TAIL_SHARE: f64 = 0.5;

/// Where the recording never shows its noise, the noise is taken at most this many dB under the
/// loudest bin of any frame: about 10 dB under the modes the fit leaves out as inaudible beside
/// the strongest (70 dB of energy), so that most modes that may stay can stand clear of it.
/// Lower, the level matching starts to give modes to the window's side lobes and the fit's
/// rounding.
const MAX_RANGE_DB: f64 = 80.0;

/// No noise is taken lower than this many dB under the loudest bin of any frame: a recording
/// whose quiet stretches are digital silence shows a floor of nothing, under which the level
/// matching would follow the window's side lobes and the sound's rounding.
const PRECISION_RANGE_DB: f64 = 120.0;

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
        let power: Vec<f64> = median_across(&per_bin, half)
            .into_iter()
            .map(|p| p.max(floor))
            .collect();
        let (falling, tail) = still_falling(spec, half);
        let tail = median_across(&tail, half);
        // Where the sound still falls at the end and the estimate is as loud as those last
        // frames, the quietest frames were sound, not noise: the recording never shows the
        // noise there, which lies somewhere below. (Where frames before the strike or after the
        // ring gave a lower estimate, it stands.) It is taken as the lowest noise the recording
        // shows at any frequency, but no lower than MAX_RANGE_DB under the loudest bin. (The
        // noise shown at the nearest frequency scores worse on the fitting benchmark, 2.93
        // against 2.85 dB: next to a sound still falling, the estimate is often still sound.)
        let unshown: Vec<bool> = (0..bins)
            .map(|b| falling[b] && power[b] >= TAIL_SHARE * tail[b])
            .collect();
        let loudest = spec
            .power
            .iter()
            .flat_map(|frame| frame.iter())
            .fold(0.0, |a: f64, b| a.max(*b));
        let lowest = (loudest * 10f64.powf(-MAX_RANGE_DB / 10.0)).max(floor);
        let shown = power
            .iter()
            .zip(&falling)
            .filter(|(_, f)| !**f)
            .map(|(p, _)| *p)
            .fold(f64::INFINITY, f64::min);
        let lowest = if shown.is_finite() {
            shown.max(lowest)
        } else {
            lowest
        };
        // Digital silence shows no noise at all: the floor is then the precision of the sound
        // itself, some way under its loudest bin.
        let precision = loudest * 10f64.powf(-PRECISION_RANGE_DB / 10.0);
        let power = power
            .iter()
            .zip(&unshown)
            .map(|(p, u)| if *u { p.min(lowest) } else { *p })
            .map(|p| p.max(precision))
            .collect();
        Self { power }
    }

    /// Noise power in the bin of `spec` nearest `freq_hz`.
    #[cfg(test)]
    pub fn at(&self, spec: &Spectrogram, freq_hz: f64) -> f64 {
        self.power[spec.bin_of(freq_hz)]
    }
}

/// The median of `values` over each one's neighbourhood of `half` on either side.
fn median_across(values: &[f64], half: usize) -> Vec<f64> {
    let n = values.len();
    let mut neighbourhood = Vec::with_capacity(2 * half + 1);
    (0..n)
        .map(|b| {
            neighbourhood.clear();
            neighbourhood.extend_from_slice(&values[b.saturating_sub(half)..(b + half + 1).min(n)]);
            let mid = neighbourhood.len() / 2;
            let (_, median, _) = neighbourhood.select_nth_unstable_by(mid, f64::total_cmp);
            *median
        })
        .collect()
}

/// For each bin of `spec`: whether the power around it (within `half` bins) still falls by
/// [`STILL_FALLING`] from the next-to-last quarter of the frames to the last, and the bin's
/// own mean power over that last quarter. With fewer than four frames, none falls.
fn still_falling(spec: &Spectrogram, half: usize) -> (Vec<bool>, Vec<f64>) {
    let bins = spec.num_bins();
    let frames = spec.power.len();
    if frames < 4 {
        return (vec![false; bins], vec![0.0; bins]);
    }
    let quarter = frames / 4;
    let sum_over = |range: std::ops::Range<usize>| -> Vec<f64> {
        let mut sum = vec![0.0; bins];
        for frame in &spec.power[range] {
            for (s, p) in sum.iter_mut().zip(frame) {
                *s += p;
            }
        }
        sum
    };
    let last = sum_over(frames - quarter..frames);
    let before = sum_over(frames - 2 * quarter..frames - quarter);
    // Sums over each bin's neighbourhood, summed directly: running sums would round away the
    // power of quiet bins beside loud ones.
    let around = |sum: &[f64], b: usize| -> f64 {
        sum[b.saturating_sub(half)..(b + half + 1).min(bins)]
            .iter()
            .sum()
    };
    let falling = (0..bins)
        .map(|b| around(&before, b) > STILL_FALLING * around(&last, b))
        .collect();
    let tail = last.iter().map(|s| s / quarter as f64).collect();
    (falling, tail)
}

#[cfg(test)]
mod tests {
    use super::super::stft::{hann, Spectrogram};
    use super::*;
    use crate::rng::Rng;

    /// Analysis window of the tests, in samples, at 48 kHz.
    const LEN: usize = 2048;

    /// The spectrogram of `x` (48 kHz) and the noise estimated from it.
    fn estimate(x: &[f64]) -> (Spectrogram, NoiseSpectrum) {
        let spec = Spectrogram::new(x, 48_000.0, LEN, LEN / 4, 2);
        let noise = NoiseSpectrum::estimate(&spec, hann(LEN).iter().sum());
        (spec, noise)
    }

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

    #[test]
    fn sound_still_dying_at_the_end_is_not_taken_for_noise() {
        let rate = 48_000.0;
        let sigma = 1e-3f64;
        let mut rng = Rng::new(11);
        // A dense band of modes (1-3 kHz, one every 5 Hz) still 25 dB over the noise when the
        // recording ends, as a wood block's or a cymbal's sound cut short; white noise under it.
        let tau = std::f64::consts::TAU;
        let phases: Vec<f64> = (0..400)
            .map(|_| std::f64::consts::PI * rng.bipolar() as f64)
            .collect();
        let x: Vec<f64> = (0..48_000)
            .map(|n| {
                let t = n as f64 / rate;
                let ring: f64 = phases
                    .iter()
                    .enumerate()
                    .map(|(k, p)| (tau * (1000.0 + 5.0 * k as f64) * t + p).sin())
                    .sum();
                sigma * 3f64.sqrt() * rng.bipolar() as f64 + 1e-2 * (-4.0 * t).exp() * ring
            })
            .collect();
        let (spec, noise) = estimate(&x);
        // White noise of variance s^2 gives E|X|^2 = s^2 sum(w^2) in every bin.
        let expected = sigma * sigma * hann(LEN).iter().map(|v| v * v).sum::<f64>();
        for f in [1500.0, 2000.0, 2500.0, 8000.0] {
            let ratio_db = 10.0 * (noise.at(&spec, f) / expected).log10();
            assert!(
                ratio_db.abs() < 3.0,
                "{f} Hz: noise estimate off by {ratio_db:.2} dB"
            );
        }
    }

    #[test]
    fn noise_heard_before_the_strike_stands_under_a_sound_still_dying() {
        let rate = 48_000.0;
        let tau = std::f64::consts::TAU;
        let mut rng = Rng::new(5);
        // Steady noise 40 dB louder between 1 and 3 kHz than elsewhere (a tone-dense hiss), heard
        // for 0.6 s before a strike that rings there to the end of the file.
        let hiss: Vec<(f64, f64)> = (0..400)
            .map(|k| {
                let phase = std::f64::consts::PI * rng.bipolar() as f64;
                (1002.5 + 5.0 * k as f64, phase)
            })
            .collect();
        let ring: Vec<(f64, f64)> = (0..400)
            .map(|k| {
                (
                    1000.0 + 5.0 * k as f64,
                    std::f64::consts::PI * rng.bipolar() as f64,
                )
            })
            .collect();
        let sum = |modes: &[(f64, f64)], t: f64| -> f64 {
            modes.iter().map(|(f, p)| (tau * f * t + p).sin()).sum()
        };
        let onset = 0.6;
        let noise_only: Vec<f64> = (0..76_800)
            .map(|n| {
                let t = n as f64 / rate;
                1e-6 * 3f64.sqrt() * rng.bipolar() as f64 + 1e-4 * sum(&hiss, t)
            })
            .collect();
        let x: Vec<f64> = noise_only
            .iter()
            .enumerate()
            .map(|(n, v)| {
                let t = n as f64 / rate - onset;
                v + if t >= 0.0 {
                    1e-2 * (-4.0 * t).exp() * sum(&ring, t)
                } else {
                    0.0
                }
            })
            .collect();
        let (_, heard) = estimate(&x);
        let (spec, truth) = estimate(&noise_only);
        // The percentile over the whole file lies further into the frames before the strike
        // than the same percentile of the noise alone: a few dB above it. Taking the noise from
        // the quieter frequencies around would put it 30 dB below.
        for f in [1500.0, 2000.0, 2500.0] {
            let ratio_db = 10.0 * (heard.at(&spec, f) / truth.at(&spec, f)).log10();
            assert!(
                (-3.0..6.0).contains(&ratio_db),
                "{f} Hz: noise estimate off by {ratio_db:.2} dB"
            );
        }
    }
}
