//! A tuned (Simpson or "true-harmonic") church bell: published partial ratios, sized by a
//! ring estimate, with heuristic gains along the profile.
//!
//! A bell's shape is tuned by the founder, so its partials come from tables, not from a closed
//! form: hum 0.5, prime 1, tierce 1.2 (minor third), quint 1.5, nominal 2, and above the nominal
//! the deciem 2.5 (major third), undeciem 2.667 (fourth), superquint 3 (twelfth) and octave
//! nominal 4 (Fletcher & Rossing ch. 21, table of the partials of a tuned bell with their
//! Rossing-Perrin mode labels; W. Hibbert, *The Quantification of Strike Pitch and Pitch Shifts
//! in Church Bells*, PhD thesis, Open University 2008). The untuned (7, 1) and (8, 1) partials
//! are put at about 5.4 and 6.8, typical measured values.
//!
//! Absolute pitch: the hum, the (2, 0) mode, is an ovalling of the mouth much like the lowest
//! in-plane bending mode of a thin ring, `f_m = (1 / 2 pi) sqrt(E / (12 rho)) (h / R^2)
//! m (m^2 - 1) / sqrt(m^2 + 1)` with m = 2 (Hoppe 1871, in Rayleigh's *Theory of Sound* and
//! Blevins' tables), taking the mouth radius for `R` and the sound-bow thickness for `h`. This is
//! an estimate only (a real bell is not a ring; expect tens of percent): use `tuned_to`.
//!
//! Gains: the profile runs from the crown (0) to the lip (1), and each partial's shape along it
//! is a heuristic, `s * prod_c (s - s_c) / (1 - s_c)`: zero at the crown, one at the lip, with
//! a sign change at each of its nodal circles `s_c`. The (m, 1) modes have their nodal circle
//! in the upper part of the bell, lower as m grows; the "#" modes (prime, quint, deciem) have
//! theirs near the sound bow, and the quint's sits where the clapper strikes, which is why a
//! bell struck normally barely sounds its quint (Hibbert). The placements are estimates from
//! the published nodal patterns, not measurements.

use super::objects::{Dimension, ObjectKind};
use super::positions::{line_coords, position};
use super::shape::{mm, Object};
use super::{check_thin, ModeLimits, Shape, ShapeError, ShapedMode};
use crate::authoring::materials::{self, Material};
use crate::bank::Position;
use serde_json::{json, Map, Value};

/// One partial of the tuned bell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BellPartial {
    /// Traditional name of the partial.
    pub name: &'static str,
    /// Frequency over the prime.
    pub ratio: f64,
    /// Rossing-Perrin mode label (m, n): nodal meridian pairs and nodal circles; "#" marks a
    /// nodal circle near the sound bow.
    pub label: &'static str,
    /// Positions of the nodal circles along the profile, 0 at the crown, 1 at the lip.
    pub nodal_circles: &'static [f64],
}

/// The partials of a tuned church bell, ascending.
// One partial per line, so that the table reads as the published one.
#[rustfmt::skip]
pub const TUNED_BELL_PARTIALS: [BellPartial; 11] = [
    BellPartial { name: "hum", ratio: 0.5, label: "(2,0)", nodal_circles: &[] },
    BellPartial { name: "prime", ratio: 1.0, label: "(2,1#)", nodal_circles: &[0.75] },
    BellPartial { name: "tierce", ratio: 1.2, label: "(3,1)", nodal_circles: &[0.4] },
    BellPartial { name: "quint", ratio: 1.5, label: "(3,1#)", nodal_circles: &[0.9] },
    BellPartial { name: "nominal", ratio: 2.0, label: "(4,1)", nodal_circles: &[0.5] },
    BellPartial { name: "deciem", ratio: 2.5, label: "(4,1#)", nodal_circles: &[0.8] },
    BellPartial { name: "undeciem", ratio: 8.0 / 3.0, label: "(2,2)", nodal_circles: &[0.35, 0.8] },
    BellPartial { name: "superquint", ratio: 3.0, label: "(5,1)", nodal_circles: &[0.6] },
    BellPartial { name: "octave nominal", ratio: 4.0, label: "(6,1)", nodal_circles: &[0.65] },
    BellPartial { name: "(7,1)", ratio: 5.4, label: "(7,1)", nodal_circles: &[0.7] },
    BellPartial { name: "(8,1)", ratio: 6.8, label: "(8,1)", nodal_circles: &[0.75] },
];

/// Where the clapper strikes: the middle of the sound bow, on the quint's nodal circle.
pub const SOUND_BOW: f64 = 0.9;

/// `bell` on the command line.
pub static BELL: ObjectKind = ObjectKind {
    name: "bell",
    about: "tuned church bell: hum, prime, tierce, quint, nominal",
    dimensions: &[
        (Dimension::Diameter, "m", 0.6),
        (Dimension::Thickness, "m", 0.046),
    ],
    options: &[],
    default_material: &materials::BRONZE,
    build: |spec| {
        Shape::Bell(TunedBell {
            diameter_m: spec.value(Dimension::Diameter),
            thickness_m: spec.value(Dimension::Thickness),
        })
    },
};

/// A church bell of the classic Western profile. Positions: along the profile, 0 at the crown,
/// 1 at the lip.
#[derive(Debug, Clone, PartialEq)]
pub struct TunedBell {
    /// Diameter of the mouth in m.
    pub diameter_m: f64,
    /// Thickness of the sound bow in m (about 1/13 of the diameter in a classic profile).
    pub thickness_m: f64,
}

impl TunedBell {
    /// Hum frequency in Hz, from the thin-ring estimate: the ring's lowest bending mode.
    pub fn hum_hz(&self, material: &Material) -> f64 {
        super::bowl::ring_bending_hz(material, self.diameter_m, self.thickness_m, 2)
    }

    /// Prime (strike note of a tuned bell) in Hz.
    pub fn prime_hz(&self, material: &Material) -> f64 {
        2.0 * self.hum_hz(material)
    }

    /// The bell scaled in every dimension so that its prime is `root_hz` (`f ~ 1 / size`).
    pub fn tuned_to(&self, material: &Material, root_hz: f64) -> Self {
        let scale = self.prime_hz(material) / root_hz;
        Self {
            diameter_m: self.diameter_m * scale,
            thickness_m: self.thickness_m * scale,
        }
    }

    /// The partials within the limits, heuristic shapes at `coords` (along the profile).
    pub(super) fn shaped_modes(
        &self,
        material: &Material,
        coords: &[f64],
        limits: &ModeLimits,
    ) -> Vec<ShapedMode> {
        let prime_hz = self.prime_hz(material);
        TUNED_BELL_PARTIALS
            .iter()
            .take(limits.max_modes)
            .map(|partial| ShapedMode {
                freq_hz: prime_hz * partial.ratio,
                shape: coords.iter().map(|&s| profile_shape(partial, s)).collect(),
            })
            .filter(|mode| mode.freq_hz < limits.max_freq_hz)
            .collect()
    }
}

impl Object for TunedBell {
    fn display_kind(&self) -> &'static str {
        "tuned bell"
    }

    fn validate(&self) -> Result<(), ShapeError> {
        super::check_positive("diameter_m", self.diameter_m)?;
        super::check_positive("thickness_m", self.thickness_m)
    }

    fn check_proportions(&self) -> Result<(), ShapeError> {
        check_thin("thickness_m", self.thickness_m, self.diameter_m, "diameter")
    }

    /// The strike note, the prime (an octave above the hum).
    fn root_hz(&self, material: &Material) -> f64 {
        self.prime_hz(material)
    }

    fn root_name(&self) -> &'static str {
        "prime"
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
            position("shoulder", &[0.2]),
            position("waist", &[0.55]),
            position("sound bow", &[SOUND_BOW]),
            position("lip", &[1.0]),
        ]
    }

    fn typical_strike(&self) -> Vec<f64> {
        vec![SOUND_BOW]
    }

    fn dimensions_m(&self) -> Vec<(&'static str, f64)> {
        vec![
            ("diameter", self.diameter_m),
            ("thickness", self.thickness_m),
        ]
    }

    fn parameters(&self, _material: &Material) -> Map<String, Value> {
        let ratios: Vec<f64> = TUNED_BELL_PARTIALS.iter().map(|p| p.ratio).collect();
        let mut map = Map::new();
        map.insert("partial_ratios".into(), json!(ratios));
        map
    }

    fn size(&self) -> String {
        format!(
            "{} mm across, sound bow {} mm thick",
            mm(self.diameter_m),
            mm(self.thickness_m)
        )
    }
}

/// The heuristic shape of `partial` at profile position `s`.
pub fn profile_shape(partial: &BellPartial, s: f64) -> f64 {
    partial
        .nodal_circles
        .iter()
        .fold(s, |value, &circle| value * (s - circle) / (1.0 - circle))
}
