//! An open bowl or glass: a thin round shell open at its rim (a singing bowl, a wine glass, a
//! cup), vibrating in its (m, 0) modes: the rim ovals into `m` waves around (m = 2, 3, ...) with
//! no nodal circle between base and rim.
//!
//! Frequencies: the inextensional bending of a thin ring, `f_m = (1 / 2 pi) sqrt(E / (12 rho))
//! (h / R^2) m (m^2 - 1) / sqrt(m^2 + 1)` (Hoppe 1871, in Rayleigh's *Theory of Sound* section
//! 233), with the rim radius for `R` and the wall thickness for `h`: partials at 1 : 2.83 : 5.42 :
//! 8.77. Measured singing bowls come close (1 : 2.76 : 5.12 : 8.10, Inacio, Henrique and Antunes,
//! *The dynamics of Tibetan singing bowls*, Acta Acustica 2006); a wine glass's stem and curved
//! wall lower the upper partials a little more. The absolute pitch is an estimate: use
//! `tuned_to`.
//!
//! Each (m, 0) mode is a pair at right angles around the rim; a real bowl is never perfectly
//! round, so the pair sits a little apart in frequency ([`DOUBLET_SPLIT`]) and beats, the slow
//! wah of a singing bowl. Struck or rubbed at an angle [`STRIKE_ANGLE_RAD`] from the pairs'
//! axes, both of a pair sound.
//!
//! Shapes along the wall: Rayleigh's inextensional modes of a hemispherical shell, radial
//! displacement `w(theta) = (m + cos theta) tan^m(theta / 2)`, theta from the base (0) to the rim
//! (pi / 2) (Rayleigh section 234): the higher the mode, the more it keeps to the rim. Positions
//! run along the wall, 0 at the base, 1 at the rim.

use super::objects::{Dimension, ObjectKind};
use super::positions::{line_coords, position};
use super::shape::{mm, Object};
use super::{check_thin, ModeLimits, Shape, ShapeError, ShapedMode};
use crate::authoring::materials::{self, Material};
use crate::bank::Position;
use serde_json::{json, Map, Value};
use std::f64::consts::{FRAC_PI_2, TAU};

/// Relative frequency gap between the two modes of a pair (0.2 %: about 1 Hz at 500 Hz, the
/// order measured on singing bowls and hand-blown glasses).
pub const DOUBLET_SPLIT: f64 = 0.002;

/// Angle around the rim, from the axes of the pairs, of every strike position, radians.
pub const STRIKE_ANGLE_RAD: f64 = 0.3;

/// Where a bowl is usually struck and rubbed: its rim.
pub const RIM: f64 = 1.0;

/// Highest number of waves around the rim.
const MAX_WAVES: u32 = 40;

/// `bowl` on the command line.
pub static BOWL: ObjectKind = ObjectKind {
    name: "bowl",
    about: "open bowl or glass rung at its rim: singing bowl, wine glass, cup",
    dimensions: &[
        (Dimension::Diameter, "m", 0.2),
        (Dimension::Thickness, "m", 0.004),
    ],
    options: &[],
    default_material: &materials::BRONZE,
    build: |spec| {
        Shape::Bowl(Bowl {
            diameter_m: spec.value(Dimension::Diameter),
            thickness_m: spec.value(Dimension::Thickness),
        })
    },
};

/// An open round shell: a bowl or a glass. Positions: along the wall, 0 at the base, 1 at the
/// rim.
#[derive(Debug, Clone, PartialEq)]
pub struct Bowl {
    /// Diameter of the rim in m.
    pub diameter_m: f64,
    /// Thickness of the wall in m.
    pub thickness_m: f64,
}

impl Bowl {
    /// Frequency of the mode with `m` waves around the rim, Hz (before the pair's split).
    fn ring_hz(&self, material: &Material, m: u32) -> f64 {
        ring_bending_hz(material, self.diameter_m, self.thickness_m, m)
    }

    /// The lowest mode, (2, 0), in Hz: the pitch a bowl sings at.
    pub fn fundamental_hz(&self, material: &Material) -> f64 {
        self.ring_hz(material, 2) * (1.0 - 0.5 * DOUBLET_SPLIT)
    }

    /// The bowl scaled in every dimension so that its fundamental is `root_hz`.
    pub fn tuned_to(&self, material: &Material, root_hz: f64) -> Self {
        let scale = self.fundamental_hz(material) / root_hz;
        Self {
            diameter_m: self.diameter_m * scale,
            thickness_m: self.thickness_m * scale,
        }
    }

    /// The pairs of (m, 0) modes within the limits, shapes at `coords` (along the wall).
    pub(super) fn shaped_modes(
        &self,
        material: &Material,
        coords: &[f64],
        limits: &ModeLimits,
    ) -> Vec<ShapedMode> {
        let mut modes = Vec::new();
        for m in 2..=MAX_WAVES {
            let hz = self.ring_hz(material, m);
            let norm = wall_rms(m);
            let around = f64::from(m) * STRIKE_ANGLE_RAD;
            for (detune, angular) in [(-0.5, around.cos()), (0.5, around.sin())] {
                let freq_hz = hz * (1.0 + detune * DOUBLET_SPLIT);
                if freq_hz >= limits.max_freq_hz || modes.len() >= limits.max_modes {
                    return modes;
                }
                modes.push(ShapedMode {
                    freq_hz,
                    // cos or sin of m phi has a mean square of 1/2 around the rim.
                    shape: coords
                        .iter()
                        .map(|&s| wall_shape(m, s) * angular * 2f64.sqrt() / norm)
                        .collect(),
                });
            }
        }
        modes
    }
}

impl Object for Bowl {
    fn display_kind(&self) -> &'static str {
        "bowl"
    }

    fn validate(&self) -> Result<(), ShapeError> {
        super::check_positive("diameter_m", self.diameter_m)?;
        super::check_positive("thickness_m", self.thickness_m)
    }

    fn check_proportions(&self) -> Result<(), ShapeError> {
        check_thin("thickness_m", self.thickness_m, self.diameter_m, "diameter")
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
            position("low on the wall", &[0.4]),
            position("middle of the wall", &[0.65]),
            position("below the rim", &[0.85]),
            position("rim", &[RIM]),
        ]
    }

    fn typical_strike(&self) -> Vec<f64> {
        vec![RIM]
    }

    fn dimensions_m(&self) -> Vec<(&'static str, f64)> {
        vec![
            ("diameter", self.diameter_m),
            ("thickness", self.thickness_m),
        ]
    }

    fn parameters(&self, _material: &Material) -> Map<String, Value> {
        let mut map = Map::new();
        map.insert("doublet_split".into(), json!(DOUBLET_SPLIT));
        map.insert("strike_angle_rad".into(), json!(STRIKE_ANGLE_RAD));
        map
    }

    fn size(&self) -> String {
        format!(
            "{} mm across the rim, wall {} mm thick",
            mm(self.diameter_m),
            mm(self.thickness_m)
        )
    }
}

/// The in-plane bending mode with `m` waves round a thin ring of `diameter_m` and
/// `thickness_m`, Hz: `(1 / 2 pi) sqrt(E / (12 rho)) (h / R^2) m (m^2 - 1) / sqrt(m^2 + 1)`
/// (Hoppe 1871).
pub fn ring_bending_hz(material: &Material, diameter_m: f64, thickness_m: f64, m: u32) -> f64 {
    let radius_m = 0.5 * diameter_m;
    let radius_of_gyration_m = thickness_m / 12f64.sqrt();
    let m = f64::from(m);
    radius_of_gyration_m * material.rod_wave_speed_m_per_s() / (TAU * radius_m * radius_m)
        * m
        * (m * m - 1.0)
        / (m * m + 1.0).sqrt()
}

/// Radial displacement of the mode with `m` waves at `s` along the wall (0 base, 1 rim), 1 at
/// the rim.
pub fn wall_shape(m: u32, s: f64) -> f64 {
    let theta = s.clamp(0.0, 1.0) * FRAC_PI_2;
    let m_f = f64::from(m);
    (m_f + theta.cos()) / m_f * (0.5 * theta).tan().powi(m as i32)
}

/// RMS of [`wall_shape`] over the shell's surface (a hemisphere: area element `sin theta`).
fn wall_rms(m: u32) -> f64 {
    const STEPS: usize = 400;
    let (mut sum, mut area) = (0.0, 0.0);
    for k in 0..STEPS {
        let s = (k as f64 + 0.5) / STEPS as f64;
        let weight = (s * FRAC_PI_2).sin();
        sum += weight * wall_shape(m, s).powi(2);
        area += weight;
    }
    (sum / area).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::authoring::materials::{BRONZE, GLASS};

    #[test]
    fn partials_follow_the_ring_and_come_in_beating_pairs() {
        let bowl = Bowl {
            diameter_m: 0.2,
            thickness_m: 0.004,
        };
        let modes = bowl.shaped_modes(&BRONZE, &[RIM], &ModeLimits::default());
        let f2 = modes[0].freq_hz;
        assert!((f2 / bowl.fundamental_hz(&BRONZE) - 1.0).abs() < 1e-12);
        // The pairs' lower modes at the ring's ratios.
        for (k, ratio) in [(1, 1.0), (2, 2.828), (3, 5.423), (4, 8.771)] {
            let f = modes[2 * (k - 1)].freq_hz;
            assert!((f / f2 / ratio - 1.0).abs() < 1e-3, "mode {k}: {}", f / f2);
            let pair = modes[2 * (k - 1) + 1].freq_hz / f;
            assert!((pair - 1.0 - DOUBLET_SPLIT).abs() < 1e-4);
        }
        // Tuned, the fundamental lands where asked.
        let tuned = bowl.tuned_to(&GLASS, 660.0);
        assert!((tuned.fundamental_hz(&GLASS) - 660.0).abs() < 1e-9);
    }

    #[test]
    fn higher_modes_keep_to_the_rim() {
        for m in 2..10 {
            assert!((wall_shape(m, 1.0) - 1.0).abs() < 1e-12);
            assert_eq!(wall_shape(m, 0.0), 0.0);
            // Half way up the wall, each mode moves less than the one below it.
            assert!(wall_shape(m + 1, 0.5) < wall_shape(m, 0.5));
        }
    }
}
