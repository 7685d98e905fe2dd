//! The level of a strike played under the bank's root. Pitch scales a bank's frequencies and
//! decays together, so its impulse response only stretches in time and keeps its peak; a
//! mallet's contact lasts the same at every pitch, though, and is ever shorter against the
//! modes' periods as the note falls: played far enough below its root, a mallet strikes like an
//! impulse and excites every mode fully. A bank levelled for a mallet at its root (see
//! [`super::prepared::TARGET_PEAK`]) then peaks higher, the more so the more of its modes the
//! mallet leaves out at the root: a meshed bronze bell struck eight octaves down peaked 7.8 dB
//! over its root's level, clipping.
//!
//! The level is held to the root's with a gain per pitch below the root: the peak at a pitch
//! is taken between the root's peak and the impulse's, the two measured, in proportion to how
//! much more the mallet lets through there, `A(s) = sum |g_n| |P(f_n s T)|` over the modes at
//! the default strike point, with `P` the spectrum of the unit-area raised-cosine pulse of the
//! default contact time `T` (van den Doel's `1 - cos` force, seed 000 eq. 4.5). Above the root
//! a mallet lets less through and a note is quieter, as on a real instrument: no gain there.

use std::f64::consts::{LN_2, PI};

/// Steps of the table per octave under the root.
const STEPS_PER_OCTAVE: f64 = 12.0;

/// Octaves under the root the table covers: past them a strike is an impulse to every mode.
const OCTAVES: usize = 11;

/// Gain of a strike by how far under the root it is played.
#[derive(Debug, Clone, PartialEq)]
pub struct PitchLevel {
    /// Gain at the root and every [`STEPS_PER_OCTAVE`]th of an octave under it.
    gains: Vec<f32>,
}

impl Default for PitchLevel {
    /// The same level at every pitch.
    fn default() -> Self {
        Self { gains: vec![1.0] }
    }
}

impl PitchLevel {
    /// The table for modes at `freq_hz` with gains `gains` at the default strike point, struck
    /// by a mallet of `contact_s` whose strike at the root peaks at `root_peak` and whose
    /// impulse would peak at `impulse_peak` (both measured, same units).
    pub fn new(
        freq_hz: &[f64],
        gains: &[f32],
        contact_s: f64,
        root_peak: f32,
        impulse_peak: f32,
    ) -> Self {
        let passed = |s: f64| -> f64 {
            freq_hz
                .iter()
                .zip(gains)
                .map(|(f, g)| g.abs() as f64 * pulse_magnitude(f * s * contact_s))
                .sum()
        };
        let at_root = passed(1.0);
        let at_impulse: f64 = gains.iter().map(|g| g.abs() as f64).sum();
        let rise = (impulse_peak - root_peak) as f64;
        if !(rise > 0.0 && at_impulse > at_root && root_peak > 0.0) {
            return Self::default();
        }
        let steps = OCTAVES * STEPS_PER_OCTAVE as usize;
        let gains = (0..=steps)
            .map(|j| {
                let s = (-(j as f64) / STEPS_PER_OCTAVE * LN_2).exp();
                let share = (passed(s) - at_root) / (at_impulse - at_root);
                let peak = root_peak as f64 + rise * share.clamp(0.0, 1.0);
                (root_peak as f64 / peak).min(1.0) as f32
            })
            .collect();
        Self { gains }
    }

    /// Gain of a strike at natural log pitch `log_pitch` relative to the bank as authored.
    pub fn at(&self, log_pitch: f64) -> f32 {
        if log_pitch.is_nan() || log_pitch >= 0.0 {
            return 1.0;
        }
        let position = -log_pitch / LN_2 * STEPS_PER_OCTAVE;
        let last = self.gains.len() - 1;
        if position >= last as f64 {
            return self.gains[last];
        }
        let j = position as usize;
        let t = (position - j as f64) as f32;
        self.gains[j] + t * (self.gains[j + 1] - self.gains[j])
    }
}

/// `|P(x)|` of the unit-area raised-cosine pulse at `x` = frequency times contact time:
/// `|sinc(x) / (1 - x^2)|`, 1/2 at `x = 1` where both vanish.
fn pulse_magnitude(x: f64) -> f64 {
    let x = x.abs();
    if x < 1e-9 {
        1.0
    } else if (x - 1.0).abs() < 1e-9 {
        0.5
    } else {
        ((PI * x).sin() / (PI * x * (1.0 - x * x))).abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pulse_spectrum_is_that_of_the_raised_cosine() {
        // Numerically: the pulse (1 - cos(2 pi t / T)) / T on [0, T], T = 1, its spectrum at x.
        for x in [0.0, 0.3, 0.999, 1.0, 1.5, 2.0, 3.7] {
            let n = 20_000;
            let (mut re, mut im) = (0.0, 0.0);
            for k in 0..n {
                let t = (k as f64 + 0.5) / n as f64;
                let p = 1.0 - (2.0 * PI * t).cos();
                re += p * (2.0 * PI * x * t).cos() / n as f64;
                im -= p * (2.0 * PI * x * t).sin() / n as f64;
            }
            let exact = (re * re + im * im).sqrt();
            assert!((pulse_magnitude(x) - exact).abs() < 1e-4, "x {x}: {exact}");
        }
    }

    #[test]
    fn the_gain_falls_from_the_root_to_the_impulse_level() {
        // Modes at 1, 2 and 4 kHz under a 1 ms mallet: at the root it lets through a share of
        // each; far below, all of them.
        let level = PitchLevel::new(&[1000.0, 2000.0, 4000.0], &[1.0, 1.0, 1.0], 1e-3, 0.5, 0.8);
        assert_eq!(level.at(0.0), 1.0);
        assert_eq!(level.at(0.5), 1.0, "no gain above the root");
        let far = level.at(-11.0 * LN_2);
        assert!((far - 0.5 / 0.8).abs() < 1e-3, "{far}");
        let mut last = 1.0;
        for semitones in 1..132 {
            let g = level.at(-(semitones as f64) / 12.0 * LN_2);
            assert!(g <= last + 1e-6 && g >= far - 1e-6, "{semitones}: {g}");
            last = g;
        }
        // An impulse that peaks no higher leaves the level alone.
        let flat = PitchLevel::new(&[1000.0], &[1.0], 1e-3, 0.5, 0.5);
        assert_eq!(flat.at(-3.0), 1.0);
    }
}
