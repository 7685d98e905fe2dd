//! Bars in flexure: the uniform free-free bar (glockenspiel) and tuned, undercut bars (marimba,
//! vibraphone, xylophone).
//!
//! Euler-Bernoulli beam with free ends (Fletcher & Rossing ch. 2, Blevins *Formulas for
//! Natural Frequency and Mode Shape* table 8-1): `cos(bL) cosh(bL) = 1`, roots
//! `bL = 4.7300, 7.8532, 10.9956, 14.1372, ...`, tending to `(2n + 1) pi / 2`, and
//! `f_n = (b_n L)^2 / (2 pi L^2) sqrt(E I / (rho A))` with `I / A = h^2 / 12` for a rectangular
//! section of thickness `h`: frequency ratios 1 : 2.756 : 5.404 : 8.933. Mode shapes
//! `cosh(bx) + cos(bx) - s (sinh(bx) + sin(bx))`, `s = (cosh bL - cos bL) / (sinh bL - sin bL)`,
//! which have unit mean square over the bar. Torsional and width-wise modes, shear and rotary
//! inertia (Timoshenko corrections, a few percent for the upper modes of thick bars) are left out.

use super::objects::{Dimension, ObjectKind, ObjectOption, ObjectSpec};
use super::positions::{line_coords, position};
use super::shape::{mm, Object};
use super::{ModeLimits, Shape, ShapeError, ShapedMode};
use crate::authoring::materials::{self, Material};
use crate::bank::Position;
use serde_json::{json, Map, Value};
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI, TAU};

/// Marimba tuning: the second mode two octaves above the first, the third three octaves and a
/// major third above (Fletcher & Rossing ch. 19; some makers leave the third near 9.2).
pub const MARIMBA_RATIOS: [f64; 3] = [1.0, 4.0, 10.0];

/// Vibraphone tuning: the second mode two octaves above the first (Fletcher & Rossing ch. 19).
pub const VIBRAPHONE_RATIOS: [f64; 2] = [1.0, 4.0];

/// Xylophone tuning: the second mode an octave and a fifth (a twelfth) above the first
/// (Fletcher & Rossing ch. 19).
pub const XYLOPHONE_RATIOS: [f64; 2] = [1.0, 3.0];

/// Named tunings of a tuned bar.
pub const BAR_TUNINGS: [(&str, &[f64]); 3] = [
    ("marimba", &MARIMBA_RATIOS),
    ("vibraphone", &VIBRAPHONE_RATIOS),
    ("xylophone", &XYLOPHONE_RATIOS),
];

/// Where a bar is usually struck: near its centre, off the antisymmetric modes' node.
const BAR_STRIKE: f64 = 0.4;

/// `free-free-bar` on the command line.
pub static FREE_FREE_BAR: ObjectKind = ObjectKind {
    name: "free-free-bar",
    about: "uniform bar free at both ends (glockenspiel): 1 : 2.756 : 5.404",
    dimensions: &[
        (Dimension::Length, "m", 0.3),
        (Dimension::Width, "m", 0.03),
        (Dimension::Thickness, "m", 0.01),
    ],
    options: &[],
    default_material: &materials::STEEL,
    build: |spec| Shape::FreeFreeBar(Bar::from_spec(spec)),
};

/// `tuned-bar` on the command line.
pub static TUNED_BAR: ObjectKind = ObjectKind {
    name: "tuned-bar",
    about: "undercut bar with tuned overtones (--tuning marimba, vibraphone, xylophone)",
    dimensions: &[
        (Dimension::Length, "m", 0.38),
        (Dimension::Width, "m", 0.06),
        (Dimension::Thickness, "m", 0.009),
    ],
    options: &[ObjectOption::Tuning],
    default_material: &materials::ROSEWOOD,
    build: |spec| {
        Shape::TunedBar(TunedBar {
            bar: Bar::from_spec(spec),
            tuned_ratios: spec
                .tuning
                .clone()
                .unwrap_or_else(|| MARIMBA_RATIOS.to_vec()),
        })
    },
};

/// A bar of rectangular section, free at both ends. Positions: one coordinate, fraction of the
/// length.
#[derive(Debug, Clone, PartialEq)]
pub struct Bar {
    /// Length in m.
    pub length_m: f64,
    /// Width in m (does not enter the flexural frequencies; kept for the description).
    pub width_m: f64,
    /// Thickness in the direction of vibration, in m.
    pub thickness_m: f64,
}

/// An undercut bar whose first modes are tuned to set ratios (marimba, vibraphone). Positions:
/// fraction of the length.
///
/// Only the frequencies are tuned: modes past the tuned ones continue the free-free progression
/// from the last tuned mode, `f_k = f_last (b_k / b_last)^2`, and every mode keeps the shape of the
/// corresponding free-free mode (the undercut moves the nodes a little towards the centre).
/// The fundamental is that of a uniform bar of the given length and thickness, so for a real
/// undercut bar `thickness_m` is the *equivalent* uniform thickness, thinner than the bar's ends.
#[derive(Debug, Clone, PartialEq)]
pub struct TunedBar {
    /// Outline of the bar.
    pub bar: Bar,
    /// Frequencies of the first modes over the first, starting with 1.0, ascending.
    pub tuned_ratios: Vec<f64>,
}

/// `b_n L` of free-free mode `n` (from 1): the n-th positive root of `cos(x) cosh(x) = 1` after
/// the rigid-body root at 0.
pub fn free_free_beta_l(n: usize) -> f64 {
    debug_assert!(n >= 1);
    // cos x = 1 / cosh x; 1 / cosh x < 0.02 past x = 4.6, so the root lies within pi/4 of
    // (2n + 1) pi / 2, where cos x changes sign.
    let centre = n as f64 * PI + FRAC_PI_2;
    let f = |x: f64| x.cos() - 1.0 / x.cosh();
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

/// Free-free mode shape with root `beta_l` at `x` (fraction of the length), unit mean square.
///
/// Written with `exp(b (x - L))` instead of `cosh`/`sinh` so that it stays exact for high modes,
/// where `cosh(bx) - s sinh(bx)` is a difference of two huge numbers.
pub fn free_free_shape(beta_l: f64, x: f64) -> f64 {
    let u = beta_l * x;
    let e_l = (-beta_l).exp();
    // sinh(bL) - sin(bL) and cosh(bL) - cos(bL), over exp(bL) / 2.
    let den = 1.0 - e_l * e_l - 2.0 * beta_l.sin() * e_l;
    let s = (1.0 + e_l * e_l - 2.0 * beta_l.cos() * e_l) / den;
    // cosh u - s sinh u = ((1 - s) e^u + (1 + s) e^-u) / 2, with
    // (1 - s) e^u / 2 = e^(u - bL) (cos bL - sin bL - e^-bL) / den.
    let growing = (u - beta_l).exp() * (beta_l.cos() - beta_l.sin() - e_l) / den;
    let decaying = 0.5 * (1.0 + s) * (-u).exp();
    u.cos() - s * u.sin() + growing + decaying
}

impl Bar {
    /// Frequency in Hz of the flexural mode with root `beta_l`:
    /// `(bL)^2 / (2 pi L^2) h sqrt(E / (12 rho))`.
    pub fn flexural_freq_hz(&self, material: &Material, beta_l: f64) -> f64 {
        let radius_of_gyration_m = self.thickness_m / 12f64.sqrt();
        beta_l * beta_l / (TAU * self.length_m * self.length_m)
            * radius_of_gyration_m
            * material.rod_wave_speed_m_per_s()
    }

    /// Fundamental in Hz.
    pub fn fundamental_hz(&self, material: &Material) -> f64 {
        self.flexural_freq_hz(material, free_free_beta_l(1))
    }

    /// The bar with its length changed so that the fundamental is `root_hz` (`f ~ 1 / L^2`).
    pub fn tuned_to(&self, material: &Material, root_hz: f64) -> Self {
        let scale = (self.fundamental_hz(material) / root_hz).sqrt();
        Self {
            length_m: self.length_m * scale,
            ..self.clone()
        }
    }

    /// The bar of `spec`'s dimensions.
    pub(super) fn from_spec(spec: &ObjectSpec) -> Self {
        Self {
            length_m: spec.value(Dimension::Length),
            width_m: spec.value(Dimension::Width),
            thickness_m: spec.value(Dimension::Thickness),
        }
    }

    /// Length, width and thickness, as a bank's source records them.
    pub(super) fn dimensions(&self) -> Vec<(&'static str, f64)> {
        vec![
            ("length", self.length_m),
            ("width", self.width_m),
            ("thickness", self.thickness_m),
        ]
    }

    /// "199.4 x 25.0 x 8.0 mm".
    pub(super) fn outline(&self) -> String {
        format!(
            "{} x {} x {} mm",
            mm(self.length_m),
            mm(self.width_m),
            mm(self.thickness_m)
        )
    }

    /// Free-free modes up to the limits, shapes at `coords` (fractions of the length).
    pub(super) fn shaped_modes(
        &self,
        material: &Material,
        coords: &[f64],
        limits: &ModeLimits,
    ) -> Vec<ShapedMode> {
        let mut modes = Vec::new();
        for n in 1..=limits.max_modes {
            let beta_l = free_free_beta_l(n);
            let freq_hz = self.flexural_freq_hz(material, beta_l);
            if freq_hz >= limits.max_freq_hz {
                break;
            }
            let shape = coords.iter().map(|&x| free_free_shape(beta_l, x)).collect();
            modes.push(ShapedMode { freq_hz, shape });
        }
        modes
    }
}

impl TunedBar {
    /// Frequency in Hz of mode `n` (from 1).
    pub fn mode_freq_hz(&self, material: &Material, n: usize) -> f64 {
        let f1 = self.bar.fundamental_hz(material);
        let tuned = self.tuned_ratios.len();
        if n <= tuned {
            f1 * self.tuned_ratios[n - 1]
        } else {
            let ratio = free_free_beta_l(n) / free_free_beta_l(tuned);
            f1 * self.tuned_ratios[tuned - 1] * ratio * ratio
        }
    }

    /// `Ok` when the ratios start with 1.0 and ascend.
    fn check_ratios(&self) -> Result<(), ShapeError> {
        let ratios = &self.tuned_ratios;
        let ascending = ratios.windows(2).all(|pair| pair[1] > pair[0]);
        if ratios.first() != Some(&1.0) || !ascending || ratios.iter().any(|r| !r.is_finite()) {
            return Err(ShapeError::BadParameter {
                name: "tuned_ratios",
                value: ratios.first().copied().unwrap_or(f64::NAN),
                reason: "must start with 1.0 and ascend".to_string(),
            });
        }
        Ok(())
    }

    /// Tuned modes up to the limits, free-free shapes at `coords` (fractions of the length).
    pub(super) fn shaped_modes(
        &self,
        material: &Material,
        coords: &[f64],
        limits: &ModeLimits,
    ) -> Vec<ShapedMode> {
        let mut modes = Vec::new();
        for n in 1..=limits.max_modes {
            let freq_hz = self.mode_freq_hz(material, n);
            if freq_hz >= limits.max_freq_hz {
                break;
            }
            let beta_l = free_free_beta_l(n);
            let shape = coords.iter().map(|&x| free_free_shape(beta_l, x)).collect();
            modes.push(ShapedMode { freq_hz, shape });
        }
        modes
    }
}

/// Positions along a bar free at both ends, from an end to the centre.
fn free_bar_positions() -> Vec<Position> {
    vec![
        position("end", &[0.0]),
        position("quarter", &[0.25]),
        position("near centre", &[0.4]),
        position("centre", &[0.5]),
    ]
}

impl Object for Bar {
    fn display_kind(&self) -> &'static str {
        "free-free bar"
    }

    fn validate(&self) -> Result<(), ShapeError> {
        super::check_positive("length_m", self.length_m)?;
        super::check_positive("width_m", self.width_m)?;
        super::check_positive("thickness_m", self.thickness_m)
    }

    /// `Ok` when the bar is slender enough for the theory: checked once it is tuned.
    fn check_proportions(&self) -> Result<(), ShapeError> {
        super::check_thin("thickness_m", self.thickness_m, self.length_m, "length")?;
        if self.width_m > self.length_m {
            return Err(ShapeError::BadParameter {
                name: "width_m",
                value: self.width_m,
                reason: format!(
                    "wider than the bar is long ({:.4} m): that is a plate",
                    self.length_m
                ),
            });
        }
        Ok(())
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
        free_bar_positions()
    }

    fn typical_strike(&self) -> Vec<f64> {
        vec![BAR_STRIKE]
    }

    fn dimensions_m(&self) -> Vec<(&'static str, f64)> {
        self.dimensions()
    }

    fn size(&self) -> String {
        self.outline()
    }
}

impl Object for TunedBar {
    fn display_kind(&self) -> &'static str {
        "tuned bar"
    }

    fn validate(&self) -> Result<(), ShapeError> {
        self.bar.validate()?;
        self.check_ratios()
    }

    fn check_proportions(&self) -> Result<(), ShapeError> {
        self.bar.check_proportions()
    }

    fn root_hz(&self, material: &Material) -> f64 {
        self.bar.fundamental_hz(material)
    }

    fn tuned(&self, material: &Material, root_hz: f64) -> Result<Shape, ShapeError> {
        Ok(TunedBar {
            bar: self.bar.tuned_to(material, root_hz),
            tuned_ratios: self.tuned_ratios.clone(),
        }
        .into())
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
        free_bar_positions()
    }

    fn typical_strike(&self) -> Vec<f64> {
        vec![BAR_STRIKE]
    }

    fn dimensions_m(&self) -> Vec<(&'static str, f64)> {
        self.bar.dimensions()
    }

    fn parameters(&self, _material: &Material) -> Map<String, Value> {
        let mut map = Map::new();
        map.insert("tuned_ratios".into(), json!(self.tuned_ratios));
        map
    }

    fn size(&self) -> String {
        self.bar.outline()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_match_tables() {
        // Blevins table 8-1 / Fletcher & Rossing ch. 2.
        let table = [
            4.730_040_7,
            7.853_204_6,
            10.995_607_8,
            14.137_165_5,
            17.278_759_6,
        ];
        for (n, want) in table.iter().enumerate() {
            let got = free_free_beta_l(n + 1);
            assert!((got - want).abs() < 1e-6, "mode {}: {got} vs {want}", n + 1);
        }
        for n in 6..60 {
            let asymptote = (2 * n + 1) as f64 * FRAC_PI_2;
            assert!((free_free_beta_l(n) - asymptote).abs() < 1e-6);
        }
    }

    /// Numerical mean square of a shape over [0, 1] (Simpson's rule).
    fn mean_square(beta_l: f64) -> f64 {
        let steps = 4000;
        let h = 1.0 / steps as f64;
        let sum: f64 = (0..=steps)
            .map(|i| {
                let w = if i == 0 || i == steps {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * free_free_shape(beta_l, i as f64 * h).powi(2)
            })
            .sum();
        sum * h / 3.0
    }

    #[test]
    fn shapes_have_unit_mean_square_and_free_ends() {
        for n in [1, 2, 3, 5, 10, 30, 80] {
            let beta_l = free_free_beta_l(n);
            let ms = mean_square(beta_l);
            assert!((ms - 1.0).abs() < 1e-6, "mode {n}: mean square {ms}");
            // |shape| is 2 at both free ends; odd modes symmetric, even antisymmetric.
            let left = free_free_shape(beta_l, 0.0);
            let right = free_free_shape(beta_l, 1.0);
            assert!((left.abs() - 2.0).abs() < 1e-9, "mode {n}: end {left}");
            let sign = if n % 2 == 1 { 1.0 } else { -1.0 };
            assert!(
                (right - sign * left).abs() < 1e-9,
                "mode {n}: {left} {right}"
            );
            assert!(free_free_shape(beta_l, 0.37).is_finite());
        }
        // The nodes of the fundamental lie 0.2242 of the length from the ends.
        let beta_1 = free_free_beta_l(1);
        assert!(free_free_shape(beta_1, 0.224_2).abs() < 2e-3);
        assert!(free_free_shape(free_free_beta_l(2), 0.5).abs() < 1e-12);
    }
}
