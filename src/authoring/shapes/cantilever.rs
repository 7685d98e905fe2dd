//! The clamped-free bar (cantilever): a kalimba or music-box tine, a tuning-fork prong.
//!
//! Euler-Bernoulli beam clamped at one end and free at the other (Fletcher & Rossing ch. 2,
//! Blevins *Formulas for Natural Frequency and Mode Shape* table 8-1): `cos(bL) cosh(bL) = -1`,
//! roots `bL = 1.8751, 4.6941, 7.8548, 10.9955, ...`, tending to `(2n - 1) pi / 2`, and the same
//! frequency formula as the free-free bar, `f_n = (b_n L)^2 / (2 pi L^2) sqrt(E I / (rho A))`:
//! ratios 1 : 6.267 : 17.55 : 34.39. Mode shapes
//! `cosh(bx) - cos(bx) - s (sinh(bx) - sin(bx))`, `s = (cosh bL + cos bL) / (sinh bL + sin bL)`,
//! which have unit mean square over the bar, vanish with their slope at the clamp and reach
//! `|2|` at the free tip. A tine is tuned by its free length, as a kalimba's are by sliding them
//! over the bridge.
//!
//! Positions are fractions of the length from the clamp (0) to the free tip (1).

use super::objects::{Dimension, ObjectKind};
use super::positions::{line_coords, position};
use super::shape::Object;
use super::{Bar, ModeLimits, Shape, ShapeError, ShapedMode};
use crate::authoring::materials::{self, Material};
use crate::bank::Position;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// Where a tine is struck: its free tip.
const TIP: f64 = 1.0;

/// `clamped-free-bar` on the command line.
pub static CLAMPED_FREE_BAR: ObjectKind = ObjectKind {
    name: "clamped-free-bar",
    about: "bar clamped at one end (kalimba tine, tuning fork prong): 1 : 6.267 : 17.55",
    dimensions: &[
        (Dimension::Length, "m", 0.06),
        (Dimension::Width, "m", 0.004),
        (Dimension::Thickness, "m", 0.0012),
    ],
    options: &[],
    default_material: &materials::STEEL,
    build: |spec| Shape::ClampedFreeBar(Cantilever(Bar::from_spec(spec))),
};

/// A uniform bar clamped at one end (kalimba tine): its free length, width and thickness.
/// Positions: fraction of the length from the clamp.
#[derive(Debug, Clone, PartialEq)]
pub struct Cantilever(pub Bar);

/// `b_n L` of clamped-free mode `n` (from 1): the n-th positive root of `cos(x) cosh(x) = -1`.
pub fn clamped_free_beta_l(n: usize) -> f64 {
    debug_assert!(n >= 1);
    // cos x = -1 / cosh x, which is within 0.4 of 0 from x = 1.5 on: the root lies within pi/4 of
    // (2n - 1) pi / 2, where cos x changes sign.
    let centre = (n - 1) as f64 * PI + FRAC_PI_2;
    let f = |x: f64| x.cos() + 1.0 / x.cosh();
    let (mut a, mut b) = (centre - FRAC_PI_4, centre + FRAC_PI_4);
    let fa_negative = f(a) < 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (a + b);
        if mid <= a || mid >= b {
            break;
        }
        if (f(mid) < 0.0) == fa_negative {
            a = mid;
        } else {
            b = mid;
        }
    }
    0.5 * (a + b)
}

/// Clamped-free mode shape with root `beta_l` at `x` (fraction of the length from the clamp),
/// unit mean square.
///
/// Written with `exp(b (x - L))` instead of `cosh`/`sinh`, as for the free-free bar, so that it
/// stays exact for high modes.
pub fn clamped_free_shape(beta_l: f64, x: f64) -> f64 {
    let u = beta_l * x;
    let e_l = (-beta_l).exp();
    // sinh(bL) + sin(bL) and cosh(bL) + cos(bL), over exp(bL) / 2.
    let den = 1.0 - e_l * e_l + 2.0 * beta_l.sin() * e_l;
    let s = (1.0 + e_l * e_l + 2.0 * beta_l.cos() * e_l) / den;
    // cosh u - s sinh u = ((1 - s) e^u + (1 + s) e^-u) / 2, with
    // (1 - s) e^u / 2 = e^(u - bL) (sin bL - cos bL - e^-bL) / den.
    let growing = (u - beta_l).exp() * (beta_l.sin() - beta_l.cos() - e_l) / den;
    let decaying = 0.5 * (1.0 + s) * (-u).exp();
    growing + decaying - u.cos() + s * u.sin()
}

impl Cantilever {
    /// Fundamental in Hz.
    pub fn fundamental_hz(&self, material: &Material) -> f64 {
        self.0.flexural_freq_hz(material, clamped_free_beta_l(1))
    }

    /// The tine with its free length changed so that its fundamental is `root_hz`
    /// (`f ~ 1 / L^2`).
    pub fn tuned_to(&self, material: &Material, root_hz: f64) -> Self {
        let scale = (self.fundamental_hz(material) / root_hz).sqrt();
        Self(Bar {
            length_m: self.0.length_m * scale,
            ..self.0.clone()
        })
    }

    /// Clamped-free modes up to the limits, shapes at `coords` (fractions of the length from
    /// the clamp).
    pub(super) fn shaped_modes(
        &self,
        material: &Material,
        coords: &[f64],
        limits: &ModeLimits,
    ) -> Vec<ShapedMode> {
        let mut modes = Vec::new();
        for n in 1..=limits.max_modes {
            let beta_l = clamped_free_beta_l(n);
            let freq_hz = self.0.flexural_freq_hz(material, beta_l);
            if freq_hz >= limits.max_freq_hz {
                break;
            }
            let shape = coords
                .iter()
                .map(|&x| clamped_free_shape(beta_l, x))
                .collect();
            modes.push(ShapedMode { freq_hz, shape });
        }
        modes
    }
}

impl Object for Cantilever {
    fn display_kind(&self) -> &'static str {
        "clamped-free bar"
    }

    fn validate(&self) -> Result<(), ShapeError> {
        self.0.validate()
    }

    fn check_proportions(&self) -> Result<(), ShapeError> {
        self.0.check_proportions()
    }

    fn root_hz(&self, material: &Material) -> f64 {
        self.fundamental_hz(material)
    }

    fn tuned(&self, material: &Material, root_hz: f64) -> Result<Shape, ShapeError> {
        Ok(self.tuned_to(material, root_hz).into())
    }

    fn modes_at(
        &self,
        material: &Material,
        positions: &[Position],
        limits: &ModeLimits,
    ) -> Result<Vec<ShapedMode>, ShapeError> {
        Ok(self.shaped_modes(material, &line_coords(positions)?, limits))
    }

    fn default_positions(&self) -> Vec<Position> {
        vec![
            position("middle", &[0.5]),
            position("three quarters", &[0.75]),
            position("near the tip", &[0.9]),
            position("tip", &[TIP]),
        ]
    }

    fn typical_strike(&self) -> Vec<f64> {
        vec![TIP]
    }

    fn dimensions_m(&self) -> Vec<(&'static str, f64)> {
        self.0.dimensions()
    }

    fn size(&self) -> String {
        self.0.outline()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_match_tables() {
        // Blevins table 8-1 (clamped-free): 1.87510407, 4.69409113, 7.85475744, 10.99554073,
        // 14.13716839, then (2n - 1) pi / 2.
        let table = [
            1.875_104_07,
            4.694_091_13,
            7.854_757_44,
            10.995_540_73,
            14.137_168_39,
        ];
        for (n, want) in table.iter().enumerate() {
            let got = clamped_free_beta_l(n + 1);
            assert!((got - want).abs() < 1e-7, "mode {}: {got} vs {want}", n + 1);
        }
        for n in 6..60 {
            let asymptote = (2 * n - 1) as f64 * FRAC_PI_2;
            let got = clamped_free_beta_l(n);
            assert!((got - asymptote).abs() < 1e-6, "mode {n}: {got}");
        }
    }

    /// Numerical mean square of a shape over [0, 1] (Simpson's rule).
    fn mean_square(beta_l: f64) -> f64 {
        let steps = 4000;
        let h = 1.0 / steps as f64;
        let sum: f64 = (0..=steps)
            .map(|i| {
                let w = match i {
                    0 => 1.0,
                    i if i == steps => 1.0,
                    i if i % 2 == 1 => 4.0,
                    _ => 2.0,
                };
                w * clamped_free_shape(beta_l, i as f64 * h).powi(2)
            })
            .sum();
        sum * h / 3.0
    }

    #[test]
    fn shapes_have_unit_mean_square_a_clamp_and_a_free_tip() {
        for n in [1, 2, 3, 5, 10, 30, 80] {
            let beta_l = clamped_free_beta_l(n);
            let ms = mean_square(beta_l);
            assert!((ms - 1.0).abs() < 1e-6, "mode {n}: mean square {ms}");
            // No displacement and no slope at the clamp.
            let at_clamp = clamped_free_shape(beta_l, 0.0);
            let slope = (clamped_free_shape(beta_l, 1e-6) - at_clamp) / 1e-6;
            assert!(at_clamp.abs() < 1e-12, "mode {n}: {at_clamp} at the clamp");
            assert!(slope.abs() < 1e-3 * beta_l, "mode {n}: slope {slope}");
            // |2| at the tip, alternating in sign with the mode number.
            let tip = clamped_free_shape(beta_l, 1.0);
            let sign = if n % 2 == 1 { 1.0 } else { -1.0 };
            assert!((tip - 2.0 * sign).abs() < 1e-9, "mode {n}: tip {tip}");
        }
        // The second mode's node lies 0.7834 of the length from the clamp (Blevins table 8-1).
        let beta_2 = clamped_free_beta_l(2);
        assert!(clamped_free_shape(beta_2, 0.783_4).abs() < 2e-3);
    }
}
