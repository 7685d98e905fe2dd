//! The percussion triangle: a round steel rod bent into a triangle, open at one corner, hung
//! from another and struck on a side.
//!
//! To first order, the bends leave the rod's flexural modes those of the same rod straight: a
//! free-free bar of the rod's whole length (Fletcher & Rossing, *The Physics of Musical
//! Instruments*, ch. 19, on the triangle). So `f_n = (b_n L)^2 / (2 pi L^2) k sqrt(E / rho)`
//! with the free-free roots `b_n L = 4.7300, 7.8532, 10.9956, ...` (`bar.rs`) and, for a round
//! rod of diameter `d`, the radius of gyration `k = d / 4`: partials at 1 : 2.756 : 5.404 :
//! 8.933, the mode shapes those of the free-free bar along the rod. Left out: the bends, which
//! make bending in the triangle's plane differ from bending out of it, so that each mode of the
//! straight rod becomes two at nearby frequencies; the rod's torsional modes; and the
//! suspension, taken to hold nothing.
//!
//! Positions are fractions of the rod's length from the free end at the open corner (0), up the
//! first side to the corner it hangs from (1/3), down the second to the closed lower corner
//! (2/3) and along the bottom side to the other free end (1).

use super::bar::{free_free_beta_l, free_free_shape};
use super::objects::{Dimension, ObjectKind};
use super::positions::{line_coords, position};
use super::shape::{mm, Object};
use super::{check_thin, ModeLimits, Shape, ShapeError, ShapedMode};
use crate::authoring::materials::{self, Material};
use crate::bank::Position;
use std::f64::consts::TAU;

/// Where a triangle is usually struck: on its bottom side, about a third of the way from the
/// closed corner (7 / 9 of the rod).
const BOTTOM_SIDE: f64 = 0.78;

/// `triangle` on the command line.
pub static TRIANGLE: ObjectKind = ObjectKind {
    name: "triangle",
    about: "steel rod bent into a triangle, as the free-free rod of its length: 1 : 2.756 : 5.404",
    dimensions: &[
        (Dimension::Length, "m", 0.54),
        (Dimension::Diameter, "m", 0.01),
    ],
    options: &[],
    default_material: &materials::STEEL,
    build: |spec| {
        Shape::Triangle(Triangle {
            length_m: spec.value(Dimension::Length),
            diameter_m: spec.value(Dimension::Diameter),
        })
    },
};

/// A round rod bent into a triangle of three equal sides. Positions: fraction of the rod's
/// length from the free end at the open corner.
#[derive(Debug, Clone, PartialEq)]
pub struct Triangle {
    /// Length of the rod, the three sides together, in m.
    pub length_m: f64,
    /// Diameter of the rod in m.
    pub diameter_m: f64,
}

impl Triangle {
    /// Frequency in Hz of the flexural mode with root `beta_l`:
    /// `(bL)^2 / (2 pi L^2) (d / 4) sqrt(E / rho)`.
    pub fn flexural_freq_hz(&self, material: &Material, beta_l: f64) -> f64 {
        let radius_of_gyration_m = self.diameter_m / 4.0;
        beta_l * beta_l / (TAU * self.length_m * self.length_m)
            * radius_of_gyration_m
            * material.rod_wave_speed_m_per_s()
    }

    /// Fundamental in Hz.
    pub fn fundamental_hz(&self, material: &Material) -> f64 {
        self.flexural_freq_hz(material, free_free_beta_l(1))
    }
}

impl Object for Triangle {
    fn display_kind(&self) -> &'static str {
        "triangle"
    }

    fn validate(&self) -> Result<(), ShapeError> {
        super::check_positive("length_m", self.length_m)?;
        super::check_positive("diameter_m", self.diameter_m)
    }

    /// The rod at most a fifth of a side thick: thicker, the corners are no longer short
    /// against the sides.
    fn check_proportions(&self) -> Result<(), ShapeError> {
        check_thin("diameter_m", self.diameter_m, self.length_m / 3.0, "side")
    }

    fn root_hz(&self, material: &Material) -> f64 {
        self.fundamental_hz(material)
    }

    /// Tuned by its size: the same rod, longer or shorter (`f ~ 1 / L^2`).
    fn tuned(&self, material: &Material, root_hz: f64) -> Result<Shape, ShapeError> {
        let scale = (self.fundamental_hz(material) / root_hz).sqrt();
        Ok(Shape::Triangle(Triangle {
            length_m: self.length_m * scale,
            ..self.clone()
        }))
    }

    fn modes_at(
        &self,
        material: &Material,
        positions: &[Position],
        limits: &ModeLimits,
    ) -> Result<Vec<ShapedMode>, ShapeError> {
        let coords = line_coords(positions)?;
        let mut modes = Vec::new();
        for n in 1..=limits.max_modes {
            let beta_l = free_free_beta_l(n);
            let freq_hz = self.flexural_freq_hz(material, beta_l);
            if freq_hz >= limits.max_freq_hz {
                break;
            }
            let shape = coords.iter().map(|&s| free_free_shape(beta_l, s)).collect();
            modes.push(ShapedMode { freq_hz, shape });
        }
        Ok(modes)
    }

    fn default_positions(&self) -> Vec<Position> {
        vec![
            position("open end", &[0.0]),
            position("middle of a side", &[0.17]),
            position("bottom side", &[BOTTOM_SIDE]),
            position("middle of the bottom", &[0.83]),
        ]
    }

    fn typical_strike(&self) -> Vec<f64> {
        vec![BOTTOM_SIDE]
    }

    fn dimensions_m(&self) -> Vec<(&'static str, f64)> {
        vec![("length", self.length_m), ("diameter", self.diameter_m)]
    }

    fn size(&self) -> String {
        format!(
            "{} mm of {} mm rod, sides of {} mm",
            mm(self.length_m),
            mm(self.diameter_m),
            mm(self.length_m / 3.0)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::authoring::shapes::{design_bank, BankDesign, ObjectKind, ObjectSpec};
    use crate::bank::validate::validate_bank;

    #[test]
    fn partials_are_the_free_free_rod_s() {
        // Steel, E = 200 GPa, rho = 7850 kg/m^3: sqrt(E / rho) = 5047.54 m/s; d / 4 = 2.5 mm;
        // (b1 L)^2 = 4.730041^2 = 22.37329 over 2 pi 0.54^2 = 1.832177 m^2: 12.21131 1/m^2.
        // f1 = 12.21131 * 0.0025 * 5047.54 = 154.093 Hz.
        let spec = ObjectSpec::typical(ObjectKind::by_name("triangle").unwrap());
        let shape = spec.shape().unwrap();
        let steel = &materials::STEEL;
        let modes = shape
            .modes(steel, &shape.default_positions(), &ModeLimits::default())
            .unwrap();
        let f1 = modes[0].freq_hz;
        assert!((f1 - 154.093).abs() < 0.01, "f1 = {f1}");
        assert_eq!(shape.root_hz(steel), f1);
        for (n, ratio) in [(2, 2.756), (3, 5.404), (4, 8.933)] {
            let got = modes[n - 1].freq_hz / f1;
            assert!(
                (got / ratio - 1.0).abs() < 1e-3,
                "mode {n}: {got} vs {ratio}"
            );
        }
        // Every mode up to 20 kHz, where b_n L reaches (2 n + 1) pi / 2 = 53.9: 16 modes.
        assert_eq!(modes.len(), 16);
        // Struck at the middle of the rod (a point of the second side) the antisymmetric
        // modes are silent.
        let middle = [position("middle", &[0.5])];
        let modes = shape.modes(steel, &middle, &ModeLimits::default()).unwrap();
        assert_eq!((modes[1].gains[0], modes[3].gains[0]), (0.0, 0.0));
    }

    #[test]
    fn tunes_by_length_and_refuses_a_rod_too_thick() {
        let triangle = ObjectKind::by_name("triangle").unwrap();
        let design = BankDesign {
            name: "Triangle".into(),
            description: String::new(),
            shape: ObjectSpec::typical(triangle).shape().unwrap(),
            material: &materials::STEEL,
            positions: None,
            limits: ModeLimits::default(),
            root_hz: Some(880.0),
        };
        let (bank, tuned) = design_bank(&design).unwrap();
        assert!(validate_bank(&bank).is_empty());
        assert!((bank.root_hz.unwrap() / 880.0 - 1.0).abs() < 1e-12);
        assert_eq!(bank.positions[0].name, "bottom side");
        assert_eq!(bank.source.as_ref().unwrap()["shape"], "triangle");
        // f ~ 1 / L^2: 880 Hz is sqrt(880 / 154.093) = 2.39 times shorter, 226.0 mm.
        let Shape::Triangle(rod) = tuned else {
            panic!("{tuned:?}")
        };
        assert!((rod.length_m - 0.54 / (880.0f64 / 154.093).sqrt()).abs() < 1e-5);
        assert!(
            bank.description
                .starts_with("Triangle of steel, 226.0 mm of 10.0 mm rod, sides of 75.3 mm"),
            "{}",
            bank.description
        );
        // A 20 mm rod bent into sides of 90 mm is a frame, not a rod.
        let thick = Triangle {
            length_m: 0.27,
            diameter_m: 0.02,
        };
        let side = [position("middle of a side", &[0.17])];
        let err = Shape::Triangle(thick)
            .modes(&materials::STEEL, &side, &ModeLimits::default())
            .unwrap_err();
        assert!(err.to_string().contains("a fifth of the side"), "{err}");
    }
}
