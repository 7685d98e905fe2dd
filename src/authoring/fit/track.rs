//! Tracking one mode over time by complex demodulation, and fitting its frequency, decay and
//! initial amplitude by regression (seed 000 section 6.2.2, improved).
//!
//! Near a mode `a exp(-d t) sin(w1 t + phi)`, the windowed sum of the signal demodulated at `w0`,
//!
//! ```text
//! Z(t_j) = sum_k w[k] x[n_j + k] exp(-i w0 (n_j + k) / fs),   t_j the centre of frame j,
//! ```
//!
//! is `(a / 2) W exp((-d + i (w1 - w0)) t_j)` times a constant phase, where `W` depends on the
//! window, `d` and `w1 - w0` but not on `j`. So `ln |Z|` falls on a line of slope `-d` and the
//! unwrapped phase on a line of slope `w1 - w0`: a weighted regression of each gives the decay and
//! the frequency far below one bin, and the intercept of the first gives `a`. Frames are used
//! from the strike until the mode meets the noise floor.

use std::f64::consts::TAU;

use realfft::num_complex::Complex64;

use super::stft::hann;

/// The first frame must stand this many dB above the noise for a mode to be tracked at all.
const START_ABOVE_NOISE_DB: f64 = 10.0;

/// Frames are used while the mode stays this many dB above the noise.
const KEEP_ABOVE_NOISE_DB: f64 = 6.0;

/// Fewest frames a regression is made from.
pub const MIN_FRAMES: usize = 3;

/// Frames per window length: a hop of a quarter window.
const FRAMES_PER_WINDOW: usize = 4;

/// Demodulation passes: each re-centres the frequency on the last estimate, so the window's
/// response is flat around it.
const PASSES: usize = 3;

/// A mode followed through the frames.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Track {
    /// Frequency in Hz.
    pub freq_hz: f64,
    /// Decay rate of the amplitude in 1/s, at least 0.
    pub decay_per_s: f64,
    /// Amplitude extrapolated to the onset (`t = 0`), linear full scale.
    pub amplitude: f64,
    /// Frames the regression used.
    pub frames: usize,
    /// RMS distance in dB of the frames' levels from the fitted line.
    pub rms_error_db: f64,
    /// Level of the first frame above the noise, in dB.
    pub snr_db: f64,
}

/// Tracks the mode near `freq_hz` in `x` (time 0 at `x[0]`, the onset), with frames of `window_len`
/// samples starting at sample `start`. `noise_density` is the noise's mean `|Z|^2` per unit of
/// `sum(w^2)`, the same for any window: for white noise of variance `s^2` it is `s^2`.
///
/// Returns `None` when the mode never stands clearly above the noise or fades within too few
/// frames to fit.
pub fn track(
    x: &[f64],
    sample_rate_hz: f64,
    start: usize,
    freq_hz: f64,
    window_len: usize,
    noise_density: f64,
) -> Option<Track> {
    let window = hann(window_len);
    let sum_w: f64 = window.iter().sum();
    let noise_z = (noise_density * window.iter().map(|w| w * w).sum::<f64>()).sqrt();
    let hop = (window_len / FRAMES_PER_WINDOW).max(1);
    let mut freq = freq_hz;
    let mut fit = None;
    for _ in 0..PASSES {
        let frames = demodulate(x, sample_rate_hz, start, freq, &window, hop, noise_z);
        if frames.len() < MIN_FRAMES {
            return None;
        }
        let f = regress(&frames);
        freq += f.phase_slope / TAU;
        let converged = (f.phase_slope / TAU).abs() < 1e-6 * freq.max(1.0);
        fit = Some((f, frames));
        if converged {
            break;
        }
    }
    let (f, frames) = fit?;
    let decay = (-f.log_slope).max(0.0);
    // W: the window's response to the decaying envelope about the frame centre.
    let centre = 0.5 * (window_len - 1) as f64;
    let w_sum: f64 = window
        .iter()
        .enumerate()
        .map(|(k, w)| w * (-decay * (k as f64 - centre) / sample_rate_hz).exp())
        .sum();
    let amplitude = 2.0 * f.log_intercept.exp() / w_sum.max(1e-9 * sum_w);
    Some(Track {
        freq_hz: freq,
        decay_per_s: decay,
        amplitude,
        frames: frames.len(),
        rms_error_db: f.rms_residual * 20.0 / std::f64::consts::LN_10,
        snr_db: 20.0 * (frames[0].1.norm() / noise_z).log10(),
    })
}

/// `(t_j, Z_j)` for the frames from `start` while the mode stands above the noise.
fn demodulate(
    x: &[f64],
    sample_rate_hz: f64,
    start: usize,
    freq_hz: f64,
    window: &[f64],
    hop: usize,
    noise_z: f64,
) -> Vec<(f64, Complex64)> {
    let len = window.len();
    let omega = TAU * freq_hz / sample_rate_hz;
    let step = Complex64::from_polar(1.0, -omega);
    let start_level = noise_z * 10f64.powf(START_ABOVE_NOISE_DB / 20.0);
    let keep_level = noise_z * 10f64.powf(KEEP_ABOVE_NOISE_DB / 20.0);
    let mut frames = Vec::new();
    let mut n0 = start;
    while n0 + len <= x.len() {
        // The phasor restarts exactly at each frame, so rounding never accumulates past one.
        let mut phasor = Complex64::from_polar(1.0, -omega * n0 as f64);
        let mut z = Complex64::new(0.0, 0.0);
        for (w, v) in window.iter().zip(&x[n0..n0 + len]) {
            z += phasor * (w * v);
            phasor *= step;
        }
        let level = z.norm();
        let threshold = if frames.is_empty() {
            start_level
        } else {
            keep_level
        };
        if level < threshold {
            break;
        }
        let t = (n0 as f64 + 0.5 * (len - 1) as f64) / sample_rate_hz;
        frames.push((t, z));
        n0 += hop;
    }
    frames
}

/// Weighted regressions of a track's log-magnitude and unwrapped phase on time.
#[derive(Debug, Clone, Copy)]
struct Regression {
    /// Slope of `ln |Z|` in 1/s.
    log_slope: f64,
    /// `ln |Z|` at `t = 0`.
    log_intercept: f64,
    /// Slope of the phase in rad/s.
    phase_slope: f64,
    /// Weighted RMS residual of `ln |Z|`.
    rms_residual: f64,
}

/// Fits lines to `ln |Z_j|` and the unwrapped `arg Z_j`, each point weighted by `|Z_j|^2`: the
/// noise on a frame's log-level and phase is inversely proportional to its level.
fn regress(frames: &[(f64, Complex64)]) -> Regression {
    let mut phase = Vec::with_capacity(frames.len());
    let mut last = frames[0].1.arg();
    let mut unwrapped = last;
    for &(_, z) in frames {
        let a = z.arg();
        let mut delta = a - last;
        delta -= TAU * (delta / TAU).round();
        unwrapped += delta;
        last = a;
        phase.push(unwrapped);
    }
    let weights: Vec<f64> = frames.iter().map(|(_, z)| z.norm_sqr()).collect();
    let times: Vec<f64> = frames.iter().map(|(t, _)| *t).collect();
    let logs: Vec<f64> = frames.iter().map(|(_, z)| z.norm().ln()).collect();
    let (log_slope, log_intercept, rms_residual) = weighted_line(&times, &logs, &weights);
    let (phase_slope, _, _) = weighted_line(&times, &phase, &weights);
    Regression {
        log_slope,
        log_intercept,
        phase_slope,
        rms_residual,
    }
}

/// Weighted least-squares line `y = slope t + intercept`; returns the slope, the intercept and
/// the weighted RMS residual.
fn weighted_line(t: &[f64], y: &[f64], w: &[f64]) -> (f64, f64, f64) {
    let sw: f64 = w.iter().sum();
    let mean = |v: &[f64]| v.iter().zip(w).map(|(a, b)| a * b).sum::<f64>() / sw;
    let (tm, ym) = (mean(t), mean(y));
    let stt: f64 = t.iter().zip(w).map(|(a, b)| b * (a - tm).powi(2)).sum();
    let sty: f64 = t
        .iter()
        .zip(y)
        .zip(w)
        .map(|((a, c), b)| b * (a - tm) * (c - ym))
        .sum();
    let slope = if stt > 0.0 { sty / stt } else { 0.0 };
    let intercept = ym - slope * tm;
    let residual: f64 = t
        .iter()
        .zip(y)
        .zip(w)
        .map(|((a, c), b)| b * (c - intercept - slope * a).powi(2))
        .sum();
    (slope, intercept, (residual / sw).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_frequency_decay_and_amplitude_of_a_damped_sinusoid() {
        let rate = 48_000.0;
        for &(f, d, a, phi) in &[
            (440.0, 2.0, 0.5, 0.3),
            (1234.567, 15.0, 0.01, -2.0),
            (9876.5, 40.0, 0.2, 1.0),
        ] {
            let x: Vec<f64> = (0..96_000)
                .map(|n| {
                    let t = n as f64 / rate;
                    a * (-d * t).exp() * (TAU * f * t + phi).sin()
                })
                .collect();
            // Start a third of a bin away: the track finds the frequency itself.
            let guess = f + 0.3 * rate / 4096.0;
            let tr = track(&x, rate, 0, guess, 4096, 1e-14).unwrap();
            assert!(
                (tr.freq_hz / f - 1.0).abs() < 1e-6,
                "{f} Hz: found {}",
                tr.freq_hz
            );
            assert!(
                (tr.decay_per_s / d - 1.0).abs() < 1e-3,
                "{f} Hz: decay {} vs {d}",
                tr.decay_per_s
            );
            assert!(
                (tr.amplitude / a - 1.0).abs() < 1e-2,
                "{f} Hz: amplitude {} vs {a}",
                tr.amplitude
            );
        }
    }

    #[test]
    fn noise_alone_is_not_tracked() {
        let mut rng = crate::rng::Rng::new(5);
        let x: Vec<f64> = (0..48_000).map(|_| 1e-3 * rng.bipolar() as f64).collect();
        // Uniform noise in [-s, s] has variance s^2 / 3.
        let density = 1e-6 / 3.0;
        let found = (0..50)
            .filter(|i| track(&x, 48_000.0, 0, 300.0 + 97.0 * *i as f64, 2048, density).is_some())
            .count();
        assert_eq!(found, 0);
    }
}
