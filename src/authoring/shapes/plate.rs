//! The simply supported rectangular Kirchhoff plate.
//!
//! `f_mn = (pi / 2) sqrt(D / (rho h)) ((m / a)^2 + (n / b)^2)`, flexural rigidity
//! `D = E h^3 / (12 (1 - nu^2))`, mode shapes `sin(m pi x / a) sin(n pi y / b)` (Fletcher &
//! Rossing ch. 3, Leissa *Vibration of Plates* NASA SP-160 ch. 4). A square plate sounds
//! 1 : 2.5 : 2.5 : 4 : 5 : 5 : 6.5 ... Thin-plate theory: shear and rotary inertia are ignored,
//! which holds while the bending wavelength is long against the thickness.
//!
//! Positions are `(x / a, y / b)`, fractions of the sides from a corner.

use super::lattice::lowest_lattice_modes;
use super::objects::{Dimension, ObjectKind};
use super::positions::{plane_coords, rectangle_positions, RECTANGLE_STRIKE};
use super::shape::{mm, Object};
use super::{check_thin, ModeLimits, Shape, ShapeError, ShapedMode};
use crate::authoring::materials::{self, Material};
use crate::bank::Position;
use std::f64::consts::{FRAC_PI_2, PI};

/// Shapes are scaled by 2 so that their mean square over the plate is 1.
const UNIT_MEAN_SQUARE_SCALE: f64 = 2.0;

/// `rectangular-plate` on the command line.
pub static RECTANGULAR_PLATE: ObjectKind = ObjectKind {
    name: "rectangular-plate",
    about: "thin plate with hinged edges: a dense metallic wash",
    dimensions: &[
        (Dimension::Length, "m", 0.4),
        (Dimension::Width, "m", 0.3),
        (Dimension::Thickness, "m", 0.002),
    ],
    options: &[],
    default_material: &materials::STEEL,
    build: |spec| {
        Shape::RectangularPlate(RectangularPlate {
            length_x_m: spec.value(Dimension::Length),
            length_y_m: spec.value(Dimension::Width),
            thickness_m: spec.value(Dimension::Thickness),
        })
    },
};

/// A flat rectangular plate of uniform thickness, simply supported (hinged) on all four edges.
/// Positions: `(x, y)` in fractions of the sides from a corner.
#[derive(Debug, Clone, PartialEq)]
pub struct RectangularPlate {
    /// Side along x in m.
    pub length_x_m: f64,
    /// Side along y in m.
    pub length_y_m: f64,
    /// Thickness in m.
    pub thickness_m: f64,
}

impl RectangularPlate {
    /// `sqrt(D / (rho h))` in m^2/s, with `D = E h^3 / (12 (1 - nu^2))`.
    pub fn bending_constant_m2_per_s(&self, material: &Material) -> f64 {
        let h = self.thickness_m;
        let rigidity = material.youngs_modulus_pa * h.powi(3)
            / (12.0 * (1.0 - material.poisson_ratio * material.poisson_ratio));
        (rigidity / (material.density_kg_m3 * h)).sqrt()
    }

    /// Frequency in Hz of mode (m, n), both from 1.
    pub fn mode_freq_hz(&self, material: &Material, m: usize, n: usize) -> f64 {
        let kx = m as f64 / self.length_x_m;
        let ky = n as f64 / self.length_y_m;
        FRAC_PI_2 * self.bending_constant_m2_per_s(material) * (kx * kx + ky * ky)
    }

    /// Fundamental, the (1, 1) mode, in Hz.
    pub fn fundamental_hz(&self, material: &Material) -> f64 {
        self.mode_freq_hz(material, 1, 1)
    }

    /// The plate with both sides scaled (the thickness kept) so that the fundamental is
    /// `root_hz` (`f ~ 1 / side^2`).
    pub fn tuned_to(&self, material: &Material, root_hz: f64) -> Self {
        let scale = (self.fundamental_hz(material) / root_hz).sqrt();
        Self {
            length_x_m: self.length_x_m * scale,
            length_y_m: self.length_y_m * scale,
            ..self.clone()
        }
    }

    /// Approximate number of modes below `freq_hz`: the quarter ellipse
    /// `(m / a)^2 + (n / b)^2 < 2 f / (pi k)` holds `a b f / (2 k)` lattice points.
    fn approx_mode_count(&self, material: &Material, freq_hz: f64) -> f64 {
        self.length_x_m * self.length_y_m * freq_hz
            / (2.0 * self.bending_constant_m2_per_s(material))
    }

    /// The lowest modes within the limits, shapes (unit mean square) at `coords`.
    pub(super) fn shaped_modes(
        &self,
        material: &Material,
        coords: &[[f64; 2]],
        limits: &ModeLimits,
    ) -> Vec<ShapedMode> {
        // A first bound that holds a little over the wanted count.
        let per_hz = self.approx_mode_count(material, 1.0);
        let indices = lowest_lattice_modes(
            |m, n| self.mode_freq_hz(material, m, n),
            2.0 * limits.max_modes as f64 / per_hz,
            limits.max_freq_hz,
            limits.max_modes,
        );

        indices
            .into_iter()
            .map(|(m, n)| ShapedMode {
                freq_hz: self.mode_freq_hz(material, m, n),
                shape: coords
                    .iter()
                    .map(|&[x, y]| {
                        UNIT_MEAN_SQUARE_SCALE
                            * (m as f64 * PI * x).sin()
                            * (n as f64 * PI * y).sin()
                    })
                    .collect(),
            })
            .collect()
    }
}

impl Object for RectangularPlate {
    fn display_kind(&self) -> &'static str {
        "rectangular plate"
    }

    fn validate(&self) -> Result<(), ShapeError> {
        super::check_positive("length_x_m", self.length_x_m)?;
        super::check_positive("length_y_m", self.length_y_m)?;
        super::check_positive("thickness_m", self.thickness_m)
    }

    fn check_proportions(&self) -> Result<(), ShapeError> {
        let shorter_m = self.length_x_m.min(self.length_y_m);
        check_thin("thickness_m", self.thickness_m, shorter_m, "shorter side")
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
        Ok(self.shaped_modes(material, &plane_coords(positions, false)?, limits))
    }

    fn default_positions(&self) -> Vec<Position> {
        rectangle_positions()
    }

    fn typical_strike(&self) -> Vec<f64> {
        RECTANGLE_STRIKE.to_vec()
    }

    fn dimensions_m(&self) -> Vec<(&'static str, f64)> {
        vec![
            ("length_x", self.length_x_m),
            ("length_y", self.length_y_m),
            ("thickness", self.thickness_m),
        ]
    }

    fn size(&self) -> String {
        format!(
            "{} x {} x {} mm",
            mm(self.length_x_m),
            mm(self.length_y_m),
            mm(self.thickness_m)
        )
    }
}
