//! The [`Shape`] enum: one variant per object family, dispatching to the family's module. How a
//! shape is struck and described is in `shape_describe.rs`.

use super::positions::{line_coords, plane_coords};
use super::{
    cantilever, finish_modes, Bar, Bowl, CircularMembrane, CircularPlate, ModeLimits,
    RectangularMembrane, RectangularPlate, ShapeError, StretchedString, TunedBar, TunedBell,
};
use crate::authoring::materials::Material;
use crate::bank::{Mode, Position};

/// An object with closed-form modes, dimensions in metres.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A string without stiffness: harmonic partials. Positions: one coordinate, fraction of
    /// the length.
    IdealString(StretchedString),
    /// A piano-like wire: partials stretched by stiffness. Positions as for the ideal string.
    StiffString(StretchedString),
    /// A uniform bar free at both ends (glockenspiel). Positions: fraction of the length.
    FreeFreeBar(Bar),
    /// A uniform bar clamped at one end (kalimba tine). Positions: fraction of the length from
    /// the clamp.
    ClampedFreeBar(Bar),
    /// An undercut bar with tuned overtones (marimba, vibraphone). Positions: fraction of the
    /// length.
    TunedBar(TunedBar),
    /// A drum head. Positions: `(x, y)` in fractions of the radius from the centre.
    CircularMembrane(CircularMembrane),
    /// A rectangular drum head, fixed at its frame. Positions: `(x, y)` in fractions of the
    /// sides from a corner.
    RectangularMembrane(RectangularMembrane),
    /// A simply supported plate. Positions: `(x, y)` in fractions of the sides from a corner.
    RectangularPlate(RectangularPlate),
    /// A circular plate, free or clamped at its rim. Positions: `(x, y)` in fractions of the
    /// radius from the centre.
    CircularPlate(CircularPlate),
    /// A tuned church bell. Positions: along the profile, 0 at the crown, 1 at the lip.
    Bell(TunedBell),
    /// An open bowl or glass. Positions: along the wall, 0 at the base, 1 at the rim.
    Bowl(Bowl),
}

impl Shape {
    /// Identifier of the kind of object, as used in bank sources and on the command line.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::IdealString(_) => "ideal-string",
            Self::StiffString(_) => "stiff-string",
            Self::FreeFreeBar(_) => "free-free-bar",
            Self::ClampedFreeBar(_) => "clamped-free-bar",
            Self::TunedBar(_) => "tuned-bar",
            Self::CircularMembrane(_) => "circular-membrane",
            Self::RectangularMembrane(_) => "rectangular-membrane",
            Self::RectangularPlate(_) => "rectangular-plate",
            Self::CircularPlate(_) => "circular-plate",
            Self::Bell(_) => "bell",
            Self::Bowl(_) => "bowl",
        }
    }

    /// Number of coordinates of a strike position on this object.
    pub fn num_coords(&self) -> usize {
        match self {
            Self::CircularMembrane(_)
            | Self::RectangularMembrane(_)
            | Self::RectangularPlate(_)
            | Self::CircularPlate(_) => 2,
            _ => 1,
        }
    }

    /// `Ok` when every dimension and parameter is in range.
    pub fn validate(&self) -> Result<(), ShapeError> {
        match self {
            Self::IdealString(s) | Self::StiffString(s) => s.validate(),
            Self::FreeFreeBar(bar) => bar.validate(),
            Self::ClampedFreeBar(bar) => cantilever::validate(bar),
            Self::TunedBar(bar) => bar.validate(),
            Self::CircularMembrane(membrane) => membrane.validate(),
            Self::RectangularMembrane(membrane) => membrane.validate(),
            Self::RectangularPlate(plate) => plate.validate(),
            Self::CircularPlate(plate) => plate.validate(),
            Self::Bell(bell) => bell.validate(),
            Self::Bowl(bowl) => bowl.validate(),
        }
    }

    /// `Ok` when the object is thin or slender enough for the theory its modes come from: a
    /// thickness (a string's diameter) at most a fifth of its length, diameter or shorter side,
    /// and a bar no wider than long. Checked on the object as tuned, whose size may differ.
    pub fn check_proportions(&self) -> Result<(), ShapeError> {
        use super::check_thin;
        match self {
            Self::IdealString(s) | Self::StiffString(s) => {
                check_thin("diameter_m", s.diameter_m, s.length_m, "length")
            }
            Self::FreeFreeBar(bar) | Self::ClampedFreeBar(bar) => bar.check_proportions(),
            Self::TunedBar(tuned) => tuned.bar.check_proportions(),
            Self::CircularMembrane(m) => {
                check_thin("thickness_m", m.thickness_m, 2.0 * m.radius_m, "diameter")
            }
            Self::RectangularMembrane(m) => check_thin(
                "thickness_m",
                m.thickness_m,
                m.length_x_m.min(m.length_y_m),
                "shorter side",
            ),
            Self::RectangularPlate(p) => check_thin(
                "thickness_m",
                p.thickness_m,
                p.length_x_m.min(p.length_y_m),
                "shorter side",
            ),
            Self::CircularPlate(p) => {
                check_thin("thickness_m", p.thickness_m, 2.0 * p.radius_m, "diameter")
            }
            Self::Bell(b) => check_thin("thickness_m", b.thickness_m, b.diameter_m, "diameter"),
            Self::Bowl(b) => check_thin("thickness_m", b.thickness_m, b.diameter_m, "diameter"),
        }
    }

    /// The pitch the object is named by, in Hz: its lowest mode, except for a bell, whose
    /// strike note is the prime (an octave above the hum).
    pub fn root_hz(&self, material: &Material) -> f64 {
        match self {
            Self::IdealString(s) => s.mode_freq_hz(material, false, 1),
            Self::StiffString(s) => s.mode_freq_hz(material, true, 1),
            Self::FreeFreeBar(bar) => bar.fundamental_hz(material),
            Self::ClampedFreeBar(bar) => cantilever::fundamental_hz(bar, material),
            Self::TunedBar(tuned) => tuned.bar.fundamental_hz(material),
            Self::CircularMembrane(membrane) => membrane.fundamental_hz(material),
            Self::RectangularMembrane(membrane) => membrane.fundamental_hz(material),
            Self::RectangularPlate(plate) => plate.fundamental_hz(material),
            Self::CircularPlate(plate) => plate.fundamental_hz(material),
            Self::Bell(bell) => bell.prime_hz(material),
            Self::Bowl(bowl) => bowl.fundamental_hz(material),
        }
    }

    /// The same object tuned to `root_hz` the way such an object is tuned: strings and drum
    /// heads by their tension, bars and tines by their length, plates by their size (thickness
    /// kept), bells by their size.
    pub fn tuned_to(&self, material: &Material, root_hz: f64) -> Result<Self, ShapeError> {
        self.validate()?;
        super::check_positive("root_hz", root_hz)?;
        Ok(match self {
            Self::IdealString(s) => Self::IdealString(s.tuned_to(material, false, root_hz)?),
            Self::StiffString(s) => Self::StiffString(s.tuned_to(material, true, root_hz)?),
            Self::FreeFreeBar(bar) => Self::FreeFreeBar(bar.tuned_to(material, root_hz)),
            Self::ClampedFreeBar(bar) => {
                Self::ClampedFreeBar(cantilever::tuned_to(bar, material, root_hz))
            }
            Self::TunedBar(tuned) => Self::TunedBar(TunedBar {
                bar: tuned.bar.tuned_to(material, root_hz),
                tuned_ratios: tuned.tuned_ratios.clone(),
            }),
            Self::CircularMembrane(membrane) => {
                Self::CircularMembrane(membrane.tuned_to(material, root_hz))
            }
            Self::RectangularMembrane(membrane) => {
                Self::RectangularMembrane(membrane.tuned_to(material, root_hz))
            }
            Self::RectangularPlate(plate) => {
                Self::RectangularPlate(plate.tuned_to(material, root_hz))
            }
            Self::CircularPlate(plate) => Self::CircularPlate(plate.tuned_to(material, root_hz)),
            Self::Bell(bell) => Self::Bell(bell.tuned_to(material, root_hz)),
            Self::Bowl(bowl) => Self::Bowl(bowl.tuned_to(material, root_hz)),
        })
    }

    /// The modes of the object made of `material`, with a gain for each of `positions`
    /// (seed 000 eq. 3.11), ascending in frequency.
    pub fn modes(
        &self,
        material: &Material,
        positions: &[Position],
        limits: &ModeLimits,
    ) -> Result<Vec<Mode>, ShapeError> {
        self.validate()?;
        self.check_proportions()?;
        let shaped = match self {
            Self::IdealString(s) => {
                s.shaped_modes(material, false, &line_coords(positions)?, limits)
            }
            Self::StiffString(s) => {
                s.shaped_modes(material, true, &line_coords(positions)?, limits)
            }
            Self::FreeFreeBar(bar) => bar.shaped_modes(material, &line_coords(positions)?, limits),
            Self::ClampedFreeBar(bar) => {
                cantilever::shaped_modes(bar, material, &line_coords(positions)?, limits)
            }
            Self::TunedBar(bar) => bar.shaped_modes(material, &line_coords(positions)?, limits),
            Self::CircularMembrane(membrane) => {
                membrane.shaped_modes(material, &plane_coords(positions, true)?, limits)
            }
            Self::RectangularMembrane(membrane) => {
                membrane.shaped_modes(material, &plane_coords(positions, false)?, limits)
            }
            Self::RectangularPlate(plate) => {
                plate.shaped_modes(material, &plane_coords(positions, false)?, limits)
            }
            Self::CircularPlate(plate) => {
                plate.shaped_modes(material, &plane_coords(positions, true)?, limits)
            }
            Self::Bell(bell) => bell.shaped_modes(material, &line_coords(positions)?, limits),
            Self::Bowl(bowl) => bowl.shaped_modes(material, &line_coords(positions)?, limits),
        };
        finish_modes(shaped, material, limits)
    }
}
