//! Poles and coefficients: every slot's pole (angle and decay per sample) is kept apart from the
//! fade it is going through, and the kernels' coefficients are computed from both, all at once
//! (seed 000 section 5.1: the phasor keeps amplitude and phase when its pole changes).

use super::{coeffs_batch, ResonatorBank, COLUMNS, GHOST, NONE};

impl ResonatorBank {
    /// Sets the coefficients of every live mode to those of the pole `pole_of(mode) = (theta,
    /// delta)` (angle in radians per sample, radius `exp(-delta)`; see
    /// [`ModeCoeffs::from_angle_radius`]), computed for all modes at once.
    ///
    /// Dormant modes take their new poles from now on, their state carried with the old ones up
    /// to now.
    pub fn set_poles_with(&mut self, mut pole_of: impl FnMut(usize) -> (f64, f64)) {
        let n = self.rows_active * COLUMNS;
        for slot in 0..n {
            let entry = self.mode_of_slot[slot];
            // A pole at (0, 0) gives coefficients (0, 0): empty slots stay silent.
            (self.theta[slot], self.delta[slot]) = if entry == NONE {
                (0.0, 0.0)
            } else {
                pole_of((entry & !GHOST) as usize)
            };
        }
        let now = self.clock;
        for d in &mut self.dormant[..self.num_dormant] {
            d.advance_to(now);
            let (theta, delta) = pole_of(d.mode as usize);
            d.set_pole(theta, delta);
        }
        self.refresh_coeffs();
    }

    /// Recomputes every slot's coefficients from its pole and fade, all at once.
    pub(super) fn refresh_coeffs(&mut self) {
        let n = self.rows_active * COLUMNS;
        for slot in 0..n {
            if self.theta[slot].is_nan() {
                (self.theta[slot], self.delta[slot]) = self.pole_of_slot(slot);
            }
            self.pole_delta[slot] = self.delta[slot] + self.fade_delta[slot];
        }
        coeffs_batch(
            &self.theta[..n],
            &self.pole_delta[..n],
            &mut self.q_re[..n],
            &mut self.q_im[..n],
        );
        self.coeffs_stale = false;
    }

    /// Recomputes one slot's coefficients from its pole and fade.
    pub(super) fn set_slot_coeffs(&mut self, slot: usize) {
        let (theta, delta) = self.pole_of_slot(slot);
        (self.theta[slot], self.delta[slot]) = (theta, delta);
        let (mut q_re, mut q_im) = ([0.0], [0.0]);
        coeffs_batch(
            &[theta],
            &[delta + self.fade_delta[slot]],
            &mut q_re,
            &mut q_im,
        );
        (self.q_re[slot], self.q_im[slot]) = (q_re[0], q_im[0]);
    }

    /// The pole `(theta, delta)` of a slot without its fade: as set, or read back from the
    /// coefficients the kernel runs (`p = 1 + q`).
    pub(super) fn pole_of_slot(&self, slot: usize) -> (f64, f64) {
        if !self.theta[slot].is_nan() {
            return (self.theta[slot], self.delta[slot]);
        }
        let (q_re, q_im) = (self.q_re[slot] as f64, self.q_im[slot] as f64);
        // |p|^2 = 1 + 2 q_re + q_re^2 + q_im^2, kept exact near 1.
        let delta = -0.5 * (2.0 * q_re + q_re * q_re + q_im * q_im).ln_1p();
        (q_im.atan2(1.0 + q_re), delta - self.fade_delta[slot])
    }
}
