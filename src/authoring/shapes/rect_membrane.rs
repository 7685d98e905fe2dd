//! The ideal rectangular membrane fixed at its edges: the object seed 000 section 3.1 works
//! through (after van den Doel and Pai).
//!
//! The wave operator `A = d^2/dx^2 + d^2/dy^2` (seed 000 eq. 3.2) with the membrane held at its
//! frame has eigenfunctions `Psi = sin(pi m x / Lx) sin(pi n y / Ly)` and eigenvalues
//! `omega_mn = pi sqrt((m / Lx)^2 + (n / Ly)^2)` (seed 000 section 3.1), so with wave speed
//! `c = sqrt(T / sigma)` (tension `T` per unit length, areal density `sigma = rho h`) the mode
//! frequencies are `f_mn = (c / 2) sqrt((m / Lx)^2 + (n / Ly)^2)` (also Fletcher & Rossing
//! ch. 3, Morse & Ingard ch. 5). A square membrane sounds 1 : 1.581 : 2 : 2.236 : 2.550 ...
//! (`sqrt((m^2 + n^2) / 2)`). Air loading and the stiffness of the film are left out.
//!
//! Positions are `(x / Lx, y / Ly)`, fractions of the sides from a corner.

use super::lattice::lowest_lattice_modes;
use super::objects::{Dimension, ObjectKind};
use super::positions::{plane_coords, rectangle_positions, RECTANGLE_STRIKE};
use super::shape::{mm, Object, DRUM_STICK_MS};
use super::{check_thin, ModeLimits, Shape, ShapeError, ShapedMode};
use crate::authoring::materials::{self, Material};
use crate::bank::Position;
use serde_json::{json, Map, Value};
use std::f64::consts::PI;

/// Shapes are scaled by 2 so that their mean square over the membrane is 1.
const UNIT_MEAN_SQUARE_SCALE: f64 = 2.0;

/// The first search bound over the fundamental: enough for a few dozen modes, widened as needed.
const FIRST_BOUND_OVER_FUNDAMENTAL: f64 = 8.0;

/// `rectangular-membrane` on the command line.
pub static RECTANGULAR_MEMBRANE: ObjectKind = ObjectKind {
    name: "rectangular-membrane",
    about: "rectangular head fixed at its frame (seed 000 section 3.1)",
    dimensions: &[
        (Dimension::Length, "m", 0.4),
        (Dimension::Width, "m", 0.3),
        (Dimension::Thickness, "m", 0.2e-3),
        (Dimension::Tension, "N/m", 2000.0),
    ],
    options: &[],
    default_material: &materials::MYLAR,
    build: |spec| {
        Shape::RectangularMembrane(RectangularMembrane {
            length_x_m: spec.value(Dimension::Length),
            length_y_m: spec.value(Dimension::Width),
            thickness_m: spec.value(Dimension::Thickness),
            tension_n_per_m: spec.value(Dimension::Tension),
        })
    },
};

/// A rectangular membrane under uniform tension, fixed along its four edges: a rectangular drum
/// head. Positions: `(x, y)` in fractions of the sides from a corner.
#[derive(Debug, Clone, PartialEq)]
pub struct RectangularMembrane {
    /// Side along x in m.
    pub length_x_m: f64,
    /// Side along y in m.
    pub length_y_m: f64,
    /// Thickness of the film in m (with the density, gives the areal density).
    pub thickness_m: f64,
    /// Tension per unit length of edge in N/m.
    pub tension_n_per_m: f64,
}

impl RectangularMembrane {
    /// Transverse wave speed `c = sqrt(T / (rho h))` in m/s.
    pub fn wave_speed_m_per_s(&self, material: &Material) -> f64 {
        (self.tension_n_per_m / (material.density_kg_m3 * self.thickness_m)).sqrt()
    }

    /// Frequency in Hz of mode (m, n), both from 1: `(c / 2) sqrt((m / Lx)^2 + (n / Ly)^2)`.
    pub fn mode_freq_hz(&self, material: &Material, m: usize, n: usize) -> f64 {
        let kx = m as f64 / self.length_x_m;
        let ky = n as f64 / self.length_y_m;
        0.5 * self.wave_speed_m_per_s(material) * (kx * kx + ky * ky).sqrt()
    }

    /// Fundamental, the (1, 1) mode, in Hz.
    pub fn fundamental_hz(&self, material: &Material) -> f64 {
        self.mode_freq_hz(material, 1, 1)
    }

    /// The membrane with its tension changed so that the fundamental is `root_hz`
    /// (`f ~ sqrt(T)`).
    pub fn tuned_to(&self, material: &Material, root_hz: f64) -> Self {
        let ratio = root_hz / self.fundamental_hz(material);
        Self {
            tension_n_per_m: self.tension_n_per_m * ratio * ratio,
            ..self.clone()
        }
    }

    /// The lowest modes within the limits, shapes (unit mean square) at `coords`.
    pub(super) fn shaped_modes(
        &self,
        material: &Material,
        coords: &[[f64; 2]],
        limits: &ModeLimits,
    ) -> Vec<ShapedMode> {
        let indices = lowest_lattice_modes(
            |m, n| self.mode_freq_hz(material, m, n),
            FIRST_BOUND_OVER_FUNDAMENTAL * self.fundamental_hz(material),
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

impl Object for RectangularMembrane {
    fn display_kind(&self) -> &'static str {
        "rectangular membrane"
    }

    fn validate(&self) -> Result<(), ShapeError> {
        super::check_positive("length_x_m", self.length_x_m)?;
        super::check_positive("length_y_m", self.length_y_m)?;
        super::check_positive("thickness_m", self.thickness_m)?;
        super::check_positive("tension_n_per_m", self.tension_n_per_m)
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

    fn default_hardness_ms(&self, _material: &Material) -> f64 {
        DRUM_STICK_MS
    }

    fn dimensions_m(&self) -> Vec<(&'static str, f64)> {
        vec![
            ("length_x", self.length_x_m),
            ("length_y", self.length_y_m),
            ("thickness", self.thickness_m),
        ]
    }

    fn parameters(&self, _material: &Material) -> Map<String, Value> {
        let mut map = Map::new();
        map.insert("tension_n_per_m".into(), json!(self.tension_n_per_m));
        map
    }

    fn size(&self) -> String {
        format!(
            "{} x {} mm, {:.2} mm film at {:.0} N/m",
            mm(self.length_x_m),
            mm(self.length_y_m),
            self.thickness_m * 1e3,
            self.tension_n_per_m
        )
    }
}
