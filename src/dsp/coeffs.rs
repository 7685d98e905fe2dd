//! Coefficients of one mode's resonator, built from natural units.
//!
//! Each mode is a complex one-pole "phasor" resonator (DESIGN.md, Rendering):
//!
//! ```text
//! z[n] = p z[n-1] + g x[n],   p = R e^(i theta),   y[n] = Im z[n]
//! R = exp(-d / fs),  theta = 2 pi f / fs
//! ```
//!
//! For a unit impulse the output is `g R^n sin(n theta)`: the model's `a exp(-d t) sin(2 pi f t)`
//! sampled at `t = n / fs`, so the input gain `g` is the mode's amplitude `a` itself (seed 000
//! section 5.1, with the phasor instead of the two-pole reson). The phasor keeps amplitude and phase
//! when `p` changes mid-ring, so pitch bends and damping sweeps do not click.
//!
//! The recursion is computed as `z += q z + g x` with `q = p - 1`. Near `p = 1` (slow decays, low
//! frequencies) `q` keeps its full relative precision in `f32`, where `p` itself would round the
//! pole radius and angle to a coarse grid: with `p` in `f32` a 20 Hz mode at 192 kHz would be
//! mistuned by several percent; with `q` the error is below 1e-6.

use std::f64::consts::TAU;

use crate::bank::format::MAX_FREQ_RATIO;

/// The recursion coefficient `q = p - 1` of one mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeCoeffs {
    /// `R cos(theta) - 1`.
    pub q_re: f32,
    /// `R sin(theta)`.
    pub q_im: f32,
}

impl ModeCoeffs {
    /// Coefficients for a mode of `freq_hz` decaying at `decay_per_s` at `sample_rate_hz`.
    pub fn from_freq_decay(sample_rate_hz: f64, freq_hz: f64, decay_per_s: f64) -> Self {
        debug_assert!(sample_rate_hz > 0.0, "sample rate must be positive");
        debug_assert!(
            freq_hz >= 0.0 && freq_hz <= MAX_FREQ_RATIO * sample_rate_hz,
            "mode at {freq_hz} Hz is outside 0..{MAX_FREQ_RATIO} fs"
        );
        debug_assert!(decay_per_s >= 0.0, "decay must not be negative");
        Self::from_angle_radius(TAU * freq_hz / sample_rate_hz, decay_per_s / sample_rate_hz)
    }

    /// Coefficients for a pole at angle `theta` (radians per sample) and radius `exp(-delta)`.
    #[inline]
    pub fn from_angle_radius(theta: f64, delta: f64) -> Self {
        let em1 = (-delta).exp_m1(); // R - 1, exact near 0
        let (sin, cos) = theta.sin_cos();
        let sin_half = (0.5 * theta).sin();
        // R cos(theta) - 1 = (R - 1) cos(theta) - 2 sin^2(theta / 2), free of cancellation.
        let q_re = em1 * cos - 2.0 * sin_half * sin_half;
        let q_im = (1.0 + em1) * sin;
        Self {
            q_re: q_re as f32,
            q_im: q_im as f32,
        }
    }

    /// The output of this resonator for an impulse of height `gain` at sample 0, `n` samples
    /// later: `gain R^n sin(n theta)`. Computed in closed form, for tests.
    pub fn impulse_response(
        sample_rate_hz: f64,
        freq_hz: f64,
        decay_per_s: f64,
        gain: f64,
        n: usize,
    ) -> f64 {
        let t = n as f64 / sample_rate_hz;
        gain * (-decay_per_s * t).exp() * (TAU * freq_hz * t).sin()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn q_matches_pole_minus_one() {
        for &(theta, delta) in &[(0.001, 1e-6), (0.5, 1e-3), (2.8, 0.2)] {
            let c = ModeCoeffs::from_angle_radius(theta, delta);
            let r = (-delta).exp();
            let want_re = r * theta.cos() - 1.0;
            let want_im = r * theta.sin();
            assert!(
                (c.q_re as f64 - want_re).abs() <= 1e-6 * want_re.abs().max(1e-9),
                "{theta} {delta}"
            );
            assert!(
                (c.q_im as f64 - want_im).abs() <= 1e-6 * want_im.abs(),
                "{theta} {delta}"
            );
        }
    }
}
