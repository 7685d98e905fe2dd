//! Strings under tension: the ideal string and the stiff (piano-like) string, pinned at both ends.
//!
//! Ideal string: `f_n = n f_0`, `f_0 = sqrt(T / mu) / (2 L)` (Fletcher & Rossing ch. 2).
//! Stiff string with hinged (pinned) ends: `f_n = n f_0 sqrt(1 + B n^2)`, inharmonicity
//! `B = pi^3 E d^4 / (64 T L^2)` for a solid round wire of diameter `d` (H. Fletcher, *Normal
//! vibration frequencies of a stiff piano string*, JASA 36, 1964; Fletcher & Rossing ch. 12),
//! without the correction for clamped ends. With pinned ends the mode shapes of both are exactly
//! `sin(n pi x / L)`.
//!
//! Excitation model: an ideal hammer, i.e. an impulse of velocity at the strike point
//! (seed 000 eqs. 3.10-3.11), so the displacement amplitude of mode n is
//! `sin(n pi x_p) / omega_n`, about `sin(n pi x_p) / n`: the spectrum of a struck string. A
//! plucked string would fall as `1/n^2` instead; the finite width and contact time of a real
//! hammer are left to the engine's mallet model.

use super::objects::{Dimension, ObjectKind, ObjectSpec};
use super::positions::{line_coords, position};
use super::shape::{mm, Object};
use super::{check_thin, ModeLimits, Shape, ShapeError, ShapedMode};
use crate::authoring::materials::{self, Material};
use crate::bank::Position;
use serde_json::{json, Map, Value};
use std::f64::consts::{PI, SQRT_2};

/// Mallet contact time for strings, in ms: felt piano hammers stay on the string for roughly
/// 1-4 ms from treble to bass (Fletcher & Rossing ch. 12).
const STRING_HAMMER_MS: f64 = 1.5;

/// Where a piano hammer strikes: an eighth of the string.
const HAMMER_STRIKE: f64 = 0.125;

/// Dimensions of a string: a plain steel piano wire at middle C by default.
const STRING_DIMENSIONS: &[(Dimension, &str, f64)] = &[
    (Dimension::Length, "m", 0.62),
    (Dimension::Diameter, "m", 1.0e-3),
    (Dimension::Tension, "N", 650.0),
];

/// `ideal-string` on the command line.
pub static IDEAL_STRING: ObjectKind = ObjectKind {
    name: "ideal-string",
    about: "string without stiffness: harmonic partials",
    dimensions: STRING_DIMENSIONS,
    options: &[],
    default_material: &materials::STEEL,
    build: |spec| Shape::IdealString(IdealString(StretchedString::from_spec(spec))),
};

/// `stiff-string` on the command line.
pub static STIFF_STRING: ObjectKind = ObjectKind {
    name: "stiff-string",
    about: "piano-like wire: partials stretched by stiffness",
    dimensions: STRING_DIMENSIONS,
    options: &[],
    default_material: &materials::STEEL,
    build: |spec| Shape::StiffString(StiffString(StretchedString::from_spec(spec))),
};

/// A string without stiffness: harmonic partials. Positions: one coordinate, fraction of the
/// length.
#[derive(Debug, Clone, PartialEq)]
pub struct IdealString(pub StretchedString);

/// A piano-like wire: partials stretched by stiffness. Positions as for the ideal string.
#[derive(Debug, Clone, PartialEq)]
pub struct StiffString(pub StretchedString);

/// A round solid wire stretched between two fixed points.
#[derive(Debug, Clone, PartialEq)]
pub struct StretchedString {
    /// Vibrating (speaking) length between the supports in m.
    pub length_m: f64,
    /// Diameter of the wire in m.
    pub diameter_m: f64,
    /// Tension in N.
    pub tension_n: f64,
}

impl StretchedString {
    /// Mass per unit length `mu = rho pi d^2 / 4` in kg/m.
    pub fn linear_density_kg_per_m(&self, material: &Material) -> f64 {
        material.density_kg_m3 * PI * self.diameter_m * self.diameter_m / 4.0
    }

    /// Fundamental of the same string without stiffness, `f_0 = sqrt(T / mu) / (2 L)`, in Hz.
    pub fn ideal_fundamental_hz(&self, material: &Material) -> f64 {
        (self.tension_n / self.linear_density_kg_per_m(material)).sqrt() / (2.0 * self.length_m)
    }

    /// Inharmonicity coefficient `B = pi^3 E d^4 / (64 T L^2)` (Fletcher 1964).
    pub fn inharmonicity(&self, material: &Material) -> f64 {
        PI.powi(3) * material.youngs_modulus_pa * self.diameter_m.powi(4)
            / (64.0 * self.tension_n * self.length_m * self.length_m)
    }

    /// Frequency of mode `n` (from 1) in Hz, with or without stiffness.
    pub fn mode_freq_hz(&self, material: &Material, stiff: bool, n: usize) -> f64 {
        let n = n as f64;
        let f0 = self.ideal_fundamental_hz(material);
        if stiff {
            n * f0 * (1.0 + self.inharmonicity(material) * n * n).sqrt()
        } else {
            n * f0
        }
    }

    /// The string retuned by its tension so that its lowest mode is `root_hz`.
    ///
    /// Ideal: `T = mu (2 L f)^2`. Stiff: `f_1^2 = f_0^2 (1 + B) = (T + K) / (4 L^2 mu)` with
    /// `K = B T` independent of the tension, so `T = 4 L^2 mu f_1^2 - K`.
    pub fn tuned_to(
        &self,
        material: &Material,
        stiff: bool,
        root_hz: f64,
    ) -> Result<Self, ShapeError> {
        let mu = self.linear_density_kg_per_m(material);
        let ideal_tension_n = mu * (2.0 * self.length_m * root_hz).powi(2);
        let stiffness_n = if stiff {
            self.inharmonicity(material) * self.tension_n
        } else {
            0.0
        };
        let tension_n = ideal_tension_n - stiffness_n;
        if tension_n <= 0.0 || !tension_n.is_finite() {
            return Err(ShapeError::CannotTune {
                reason: format!(
                    "a {:.2} mm wire this stiff sounds above {root_hz} Hz at any tension",
                    self.diameter_m * 1e3
                ),
            });
        }
        Ok(Self {
            tension_n,
            ..self.clone()
        })
    }

    /// The string of `spec`'s dimensions.
    fn from_spec(spec: &ObjectSpec) -> Self {
        Self {
            length_m: spec.value(Dimension::Length),
            diameter_m: spec.value(Dimension::Diameter),
            tension_n: spec.value(Dimension::Tension),
        }
    }

    fn validate(&self) -> Result<(), ShapeError> {
        super::check_positive("length_m", self.length_m)?;
        super::check_positive("diameter_m", self.diameter_m)?;
        super::check_positive("tension_n", self.tension_n)
    }

    /// Modes up to the limits, with shapes `sqrt(2) sin(n pi x)` (unit mean square) at `coords`
    /// (fractions of the length).
    fn shaped_modes(
        &self,
        material: &Material,
        stiff: bool,
        coords: &[f64],
        limits: &ModeLimits,
    ) -> Vec<ShapedMode> {
        let mut modes = Vec::new();
        for n in 1..=limits.max_modes {
            let freq_hz = self.mode_freq_hz(material, stiff, n);
            if freq_hz >= limits.max_freq_hz {
                break;
            }
            let shape = coords
                .iter()
                .map(|&x| SQRT_2 * (n as f64 * PI * x).sin())
                .collect();
            modes.push(ShapedMode { freq_hz, shape });
        }
        modes
    }
}

impl StretchedString {
    /// Positions along the string, from near an end to the middle.
    fn default_positions() -> Vec<Position> {
        vec![
            position("near the end", &[0.04]),
            position("one eighth", &[HAMMER_STRIKE]),
            position("one fifth", &[0.2]),
            position("middle", &[0.5]),
        ]
    }

    /// "620.0 mm long, 1.0 mm wire at 650 N".
    fn size(&self) -> String {
        format!(
            "{} mm long, {} mm wire at {:.0} N",
            mm(self.length_m),
            mm(self.diameter_m),
            self.tension_n
        )
    }

    /// The modes of the string, stiff or not, at `positions`.
    fn modes_at(
        &self,
        material: &Material,
        stiff: bool,
        positions: &[Position],
        limits: &ModeLimits,
    ) -> Result<Vec<ShapedMode>, ShapeError> {
        Ok(self.shaped_modes(material, stiff, &line_coords(positions)?, limits))
    }
}

impl Object for IdealString {
    fn display_kind(&self) -> &'static str {
        "ideal string"
    }

    fn validate(&self) -> Result<(), ShapeError> {
        self.0.validate()
    }

    fn check_proportions(&self) -> Result<(), ShapeError> {
        check_thin("diameter_m", self.0.diameter_m, self.0.length_m, "length")
    }

    fn root_hz(&self, material: &Material) -> f64 {
        self.0.mode_freq_hz(material, false, 1)
    }

    fn tuned(&self, material: &Material, root_hz: f64) -> Result<Shape, ShapeError> {
        Ok(IdealString(self.0.tuned_to(material, false, root_hz)?).into())
    }

    fn modes_at(
        &self,
        material: &Material,
        positions: &[Position],
        limits: &ModeLimits,
    ) -> Result<Vec<ShapedMode>, ShapeError> {
        self.0.modes_at(material, false, positions, limits)
    }

    fn default_positions(&self) -> Vec<Position> {
        StretchedString::default_positions()
    }

    fn typical_strike(&self) -> Vec<f64> {
        vec![HAMMER_STRIKE]
    }

    fn default_hardness_ms(&self, _material: &Material) -> f64 {
        STRING_HAMMER_MS
    }

    fn dimensions_m(&self) -> Vec<(&'static str, f64)> {
        vec![("length", self.0.length_m), ("diameter", self.0.diameter_m)]
    }

    fn parameters(&self, _material: &Material) -> Map<String, Value> {
        let mut map = Map::new();
        map.insert("tension_n".into(), json!(self.0.tension_n));
        map
    }

    fn size(&self) -> String {
        self.0.size()
    }
}

impl Object for StiffString {
    fn display_kind(&self) -> &'static str {
        "stiff string"
    }

    fn validate(&self) -> Result<(), ShapeError> {
        self.0.validate()
    }

    fn check_proportions(&self) -> Result<(), ShapeError> {
        check_thin("diameter_m", self.0.diameter_m, self.0.length_m, "length")
    }

    fn root_hz(&self, material: &Material) -> f64 {
        self.0.mode_freq_hz(material, true, 1)
    }

    fn tuned(&self, material: &Material, root_hz: f64) -> Result<Shape, ShapeError> {
        Ok(StiffString(self.0.tuned_to(material, true, root_hz)?).into())
    }

    fn modes_at(
        &self,
        material: &Material,
        positions: &[Position],
        limits: &ModeLimits,
    ) -> Result<Vec<ShapedMode>, ShapeError> {
        self.0.modes_at(material, true, positions, limits)
    }

    fn default_positions(&self) -> Vec<Position> {
        StretchedString::default_positions()
    }

    fn typical_strike(&self) -> Vec<f64> {
        vec![HAMMER_STRIKE]
    }

    fn default_hardness_ms(&self, _material: &Material) -> f64 {
        STRING_HAMMER_MS
    }

    fn dimensions_m(&self) -> Vec<(&'static str, f64)> {
        vec![("length", self.0.length_m), ("diameter", self.0.diameter_m)]
    }

    fn parameters(&self, material: &Material) -> Map<String, Value> {
        let mut map = Map::new();
        map.insert("tension_n".into(), json!(self.0.tension_n));
        map.insert(
            "inharmonicity".into(),
            json!(self.0.inharmonicity(material)),
        );
        map
    }

    fn size(&self) -> String {
        self.0.size()
    }
}
