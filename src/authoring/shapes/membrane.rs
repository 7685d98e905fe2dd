//! The ideal circular membrane fixed at its rim (a drum head without air loading).
//!
//! `f_mn = j_mn c / (2 pi a)`, `c = sqrt(T / sigma)` with tension `T` per unit length and areal
//! density `sigma = rho h`; `j_mn` is the n-th zero of `J_m` (Fletcher & Rossing ch. 3, Kinsler &
//! Frey ch. 4): ratios 1 : 1.594 : 2.136 : 2.296 : 2.653 : 2.918 ... Mode shapes
//! `J_m(j_mn r / a) cos(m theta)` and, for `m > 0`, a `sin(m theta)` twin at the same frequency.
//!
//! Positions are `(x, y)` in fractions of the radius from the centre; the sine twins are added
//! only when some position needs them (see `disc.rs`). The air that loads a real drum head lowers and spreads its low modes (timpani are
//! tuned that way); it is not modelled.

use super::bessel::{bessel_j_upto, bessel_zeros_below};
use super::disc::DiscPoints;
use super::objects::{Dimension, ObjectKind};
use super::positions::{plane_coords, position};
use super::shape::{mm, Object, DRUM_STICK_MS};
use super::{check_thin, ModeLimits, Shape, ShapeError, ShapedMode};
use crate::authoring::materials::{self, Material};
use crate::bank::Position;
use serde_json::{json, Map, Value};
use std::f64::consts::{SQRT_2, TAU};

/// First zero of `J_0`, which sets the fundamental.
const J_0_1: f64 = 2.404_825_557_695_773;

/// First argument bound of the search for Bessel zeros, grown by half until enough are found.
const FIRST_ZERO_SEARCH_BOUND: f64 = 16.0;

/// Where a drum or a disc is usually struck: two thirds of the way out.
pub(super) const DISC_STRIKE: [f64; 2] = [0.67, 0.0];

/// `circular-membrane` on the command line.
pub static CIRCULAR_MEMBRANE: ObjectKind = ObjectKind {
    name: "circular-membrane",
    about: "drum head fixed at its rim: Bessel-zero partials",
    dimensions: &[
        (Dimension::Radius, "m", 0.165),
        (Dimension::Thickness, "m", 0.25e-3),
        (Dimension::Tension, "N/m", 1400.0),
    ],
    options: &[],
    default_material: &materials::MYLAR,
    build: |spec| {
        Shape::CircularMembrane(CircularMembrane {
            radius_m: spec.value(Dimension::Radius),
            thickness_m: spec.value(Dimension::Thickness),
            tension_n_per_m: spec.value(Dimension::Tension),
        })
    },
};

/// A circular membrane under uniform tension, fixed at its rim: a drum head. Positions:
/// `(x, y)` in fractions of the radius from the centre.
#[derive(Debug, Clone, PartialEq)]
pub struct CircularMembrane {
    /// Radius in m.
    pub radius_m: f64,
    /// Thickness of the film in m (with the density, gives the areal density).
    pub thickness_m: f64,
    /// Tension per unit length of rim in N/m.
    pub tension_n_per_m: f64,
}

impl CircularMembrane {
    /// Areal density `sigma = rho h` in kg/m^2.
    pub fn areal_density_kg_per_m2(&self, material: &Material) -> f64 {
        material.density_kg_m3 * self.thickness_m
    }

    /// Transverse wave speed `c = sqrt(T / sigma)` in m/s.
    pub fn wave_speed_m_per_s(&self, material: &Material) -> f64 {
        (self.tension_n_per_m / self.areal_density_kg_per_m2(material)).sqrt()
    }

    /// Frequency in Hz of the mode with Bessel zero `j`.
    pub fn freq_hz_of_zero(&self, material: &Material, j: f64) -> f64 {
        j * self.wave_speed_m_per_s(material) / (TAU * self.radius_m)
    }

    /// Fundamental (the (0, 1) mode) in Hz.
    pub fn fundamental_hz(&self, material: &Material) -> f64 {
        self.freq_hz_of_zero(material, J_0_1)
    }

    /// The membrane with its tension changed so that the fundamental is `root_hz`
    /// (`f ~ sqrt(T)`), as a drummer tunes a head.
    pub fn tuned_to(&self, material: &Material, root_hz: f64) -> Self {
        let ratio = root_hz / self.fundamental_hz(material);
        Self {
            tension_n_per_m: self.tension_n_per_m * ratio * ratio,
            ..self.clone()
        }
    }

    /// The lowest modes within the limits, shapes (unit mean square over the disc) at `coords`.
    pub(super) fn shaped_modes(
        &self,
        material: &Material,
        coords: &[[f64; 2]],
        limits: &ModeLimits,
    ) -> Vec<ShapedMode> {
        let points = DiscPoints::new(coords);

        // Bessel argument of the frequency limit. Every zero below the current bound is found,
        // so once there are enough of them the lowest ones are the lowest of all.
        let zero_limit =
            limits.max_freq_hz * TAU * self.radius_m / self.wave_speed_m_per_s(material);
        let mut bound = FIRST_ZERO_SEARCH_BOUND.min(zero_limit);
        let zeros = loop {
            let mut zeros: Vec<(usize, f64)> = Vec::new();
            let mut count = 0;
            // j_m1 > m: orders at or above the bound have no zero below it.
            for m in 0..bound.ceil() as usize {
                for j in bessel_zeros_below(m, bound) {
                    zeros.push((m, j));
                    count += points.modes_per_root(m);
                }
            }
            if count >= limits.max_modes || bound >= zero_limit {
                break zeros;
            }
            bound = (bound * 1.5).min(zero_limit);
        };

        let mut modes = Vec::new();
        for (m, j) in zeros {
            let freq_hz = self.freq_hz_of_zero(material, j);
            // Mean square of J_m(j r) cos(m theta) over the disc: J_(m+1)(j)^2 for m = 0,
            // J_(m+1)(j)^2 / 2 otherwise, from the Lommel integral
            // int_0^1 J_m(j r)^2 r dr = J_(m+1)(j)^2 / 2 at a zero j of J_m.
            let j_next = bessel_j_upto(m + 1, j)[m + 1].abs();
            let norm = if m == 0 { j_next } else { j_next / SQRT_2 };
            points.push_modes(&mut modes, freq_hz, m, |r| {
                bessel_j_upto(m, j * r)[m] / norm
            });
        }
        modes
    }
}

impl Object for CircularMembrane {
    fn display_kind(&self) -> &'static str {
        "circular membrane"
    }

    fn validate(&self) -> Result<(), ShapeError> {
        super::check_positive("radius_m", self.radius_m)?;
        super::check_positive("thickness_m", self.thickness_m)?;
        super::check_positive("tension_n_per_m", self.tension_n_per_m)
    }

    fn check_proportions(&self) -> Result<(), ShapeError> {
        check_thin(
            "thickness_m",
            self.thickness_m,
            2.0 * self.radius_m,
            "diameter",
        )
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
        Ok(self.shaped_modes(material, &plane_coords(positions, true)?, limits))
    }

    fn default_positions(&self) -> Vec<Position> {
        vec![
            position("centre", &[0.0, 0.0]),
            position("half radius", &[0.5, 0.0]),
            position("two-thirds radius", &DISC_STRIKE),
            position("near rim", &[0.9, 0.0]),
        ]
    }

    fn typical_strike(&self) -> Vec<f64> {
        DISC_STRIKE.to_vec()
    }

    fn default_hardness_ms(&self, _material: &Material) -> f64 {
        DRUM_STICK_MS
    }

    fn dimensions_m(&self) -> Vec<(&'static str, f64)> {
        vec![("radius", self.radius_m), ("thickness", self.thickness_m)]
    }

    fn parameters(&self, _material: &Material) -> Map<String, Value> {
        let mut map = Map::new();
        map.insert("tension_n_per_m".into(), json!(self.tension_n_per_m));
        map
    }

    fn size(&self) -> String {
        format!(
            "{} mm radius, {:.2} mm film at {:.0} N/m",
            mm(self.radius_m),
            self.thickness_m * 1e3,
            self.tension_n_per_m
        )
    }
}
