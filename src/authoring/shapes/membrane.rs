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
use super::{ModeLimits, ShapeError, ShapedMode};
use crate::authoring::materials::Material;
use std::f64::consts::{SQRT_2, TAU};

/// First zero of `J_0`, which sets the fundamental.
const J_0_1: f64 = 2.404_825_557_695_773;

/// First argument bound of the search for Bessel zeros, grown by half until enough are found.
const FIRST_ZERO_SEARCH_BOUND: f64 = 16.0;

/// A circular membrane under uniform tension, fixed at its rim.
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

    pub(super) fn validate(&self) -> Result<(), ShapeError> {
        super::check_positive("radius_m", self.radius_m)?;
        super::check_positive("thickness_m", self.thickness_m)?;
        super::check_positive("tension_n_per_m", self.tension_n_per_m)
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
