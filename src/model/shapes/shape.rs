//! The [`Shape`] enum: one variant per object family, dispatching to the family's module.

use super::positions::{line_coords, plane_coords, position};
use super::{
    bell, check_positive, finish_modes, Bar, CircularMembrane, ModeLimits, RectangularPlate,
    ShapeError, StretchedString, TunedBar, TunedBell, TUNED_BELL_PARTIALS,
};
use crate::model::materials::{Material, MaterialClass};
use crate::model::{Mode, Position};
use serde_json::{json, Map, Value};

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
    /// An undercut bar with tuned overtones (marimba, vibraphone). Positions: fraction of the
    /// length.
    TunedBar(TunedBar),
    /// A drum head. Positions: `(x, y)` in fractions of the radius from the centre.
    CircularMembrane(CircularMembrane),
    /// A simply supported plate. Positions: `(x, y)` in fractions of the sides from a corner.
    RectangularPlate(RectangularPlate),
    /// A tuned church bell. Positions: along the profile, 0 at the crown, 1 at the lip.
    Bell(TunedBell),
}

/// Mallet contact time for strings, in ms: felt piano hammers stay on the string for roughly
/// 1-4 ms from treble to bass (Fletcher & Rossing ch. 12).
const STRING_HAMMER_MS: f64 = 1.5;

/// Mallet contact time for drum heads, in ms: a felt or wooden stick on a yielding head.
const DRUM_STICK_MS: f64 = 1.5;

/// Mallet contact time for a solid object of each material class, in ms: a hard mallet on metal
/// or glass makes a contact of a few tenths of a millisecond; the yarn and rubber mallets used on
/// wooden bars, and soft plastics, make longer, duller contacts.
fn solid_contact_ms(class: MaterialClass) -> f64 {
    match class {
        MaterialClass::Metal => 0.3,
        MaterialClass::GlassCeramic => 0.25,
        MaterialClass::Wood => 1.0,
        MaterialClass::Polymer => 0.6,
    }
}

impl Shape {
    /// Identifier of the kind of object, as used in bank sources and on the command line.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::IdealString(_) => "ideal-string",
            Self::StiffString(_) => "stiff-string",
            Self::FreeFreeBar(_) => "free-free-bar",
            Self::TunedBar(_) => "tuned-bar",
            Self::CircularMembrane(_) => "circular-membrane",
            Self::RectangularPlate(_) => "rectangular-plate",
            Self::Bell(_) => "bell",
        }
    }

    /// Name of the kind of object for people.
    pub fn display_kind(&self) -> &'static str {
        match self {
            Self::IdealString(_) => "ideal string",
            Self::StiffString(_) => "stiff string",
            Self::FreeFreeBar(_) => "free-free bar",
            Self::TunedBar(_) => "tuned bar",
            Self::CircularMembrane(_) => "circular membrane",
            Self::RectangularPlate(_) => "rectangular plate",
            Self::Bell(_) => "tuned bell",
        }
    }

    /// Number of coordinates of a strike position on this object.
    pub fn num_coords(&self) -> usize {
        match self {
            Self::CircularMembrane(_) | Self::RectangularPlate(_) => 2,
            _ => 1,
        }
    }

    /// `Ok` when every dimension and parameter is in range.
    pub fn validate(&self) -> Result<(), ShapeError> {
        match self {
            Self::IdealString(s) | Self::StiffString(s) => s.validate(),
            Self::FreeFreeBar(bar) => bar.validate(),
            Self::TunedBar(bar) => bar.validate(),
            Self::CircularMembrane(membrane) => membrane.validate(),
            Self::RectangularPlate(plate) => plate.validate(),
            Self::Bell(bell) => bell.validate(),
        }
    }

    /// The pitch the object is named by, in Hz: its lowest mode, except for a bell, whose
    /// strike note is the prime (an octave above the hum).
    pub fn root_hz(&self, material: &Material) -> f64 {
        match self {
            Self::IdealString(s) => s.mode_freq_hz(material, false, 1),
            Self::StiffString(s) => s.mode_freq_hz(material, true, 1),
            Self::FreeFreeBar(bar) => bar.fundamental_hz(material),
            Self::TunedBar(tuned) => tuned.bar.fundamental_hz(material),
            Self::CircularMembrane(membrane) => membrane.fundamental_hz(material),
            Self::RectangularPlate(plate) => plate.fundamental_hz(material),
            Self::Bell(bell) => bell.prime_hz(material),
        }
    }

    /// The same object tuned to `root_hz` the way such an object is tuned: strings and drum
    /// heads by their tension, bars by their length, plates by their sides (thickness kept),
    /// bells by their size.
    pub fn tuned_to(&self, material: &Material, root_hz: f64) -> Result<Self, ShapeError> {
        self.validate()?;
        check_positive("root_hz", root_hz)?;
        Ok(match self {
            Self::IdealString(s) => Self::IdealString(s.tuned_to(material, false, root_hz)?),
            Self::StiffString(s) => Self::StiffString(s.tuned_to(material, true, root_hz)?),
            Self::FreeFreeBar(bar) => Self::FreeFreeBar(bar.tuned_to(material, root_hz)),
            Self::TunedBar(tuned) => Self::TunedBar(TunedBar {
                bar: tuned.bar.tuned_to(material, root_hz),
                tuned_ratios: tuned.tuned_ratios.clone(),
            }),
            Self::CircularMembrane(membrane) => {
                Self::CircularMembrane(membrane.tuned_to(material, root_hz))
            }
            Self::RectangularPlate(plate) => {
                Self::RectangularPlate(plate.tuned_to(material, root_hz))
            }
            Self::Bell(bell) => Self::Bell(bell.tuned_to(material, root_hz)),
        })
    }

    /// Named strike positions that show the object off, ordered from one side of it to the
    /// other so that sweeping the strike position moves across the object.
    pub fn default_positions(&self) -> Vec<Position> {
        match self {
            Self::IdealString(_) | Self::StiffString(_) => vec![
                position("near the end", &[0.04]),
                position("one eighth", &[0.125]),
                position("one fifth", &[0.2]),
                position("middle", &[0.5]),
            ],
            Self::FreeFreeBar(_) | Self::TunedBar(_) => vec![
                position("end", &[0.0]),
                position("quarter", &[0.25]),
                position("near centre", &[0.4]),
                position("centre", &[0.5]),
            ],
            Self::CircularMembrane(_) => vec![
                position("centre", &[0.0, 0.0]),
                position("half radius", &[0.5, 0.0]),
                position("two-thirds radius", &[0.67, 0.0]),
                position("near rim", &[0.9, 0.0]),
            ],
            Self::RectangularPlate(_) => vec![
                position("centre", &[0.5, 0.5]),
                position("off-centre", &[0.38, 0.42]),
                position("near edge", &[0.5, 0.1]),
                position("near corner", &[0.1, 0.12]),
            ],
            Self::Bell(_) => vec![
                position("shoulder", &[0.2]),
                position("waist", &[0.55]),
                position("sound bow", &[bell::SOUND_BOW]),
                position("lip", &[1.0]),
            ],
        }
    }

    /// Where a player usually strikes the object, in position coordinates: a piano hammer at
    /// an eighth of the string, a bar near its centre, a drum two thirds of the way out, a plate
    /// off-centre, a bell on its sound bow.
    pub fn typical_strike(&self) -> Vec<f64> {
        match self {
            Self::IdealString(_) | Self::StiffString(_) => vec![0.125],
            Self::FreeFreeBar(_) | Self::TunedBar(_) => vec![0.4],
            Self::CircularMembrane(_) => vec![0.67, 0.0],
            Self::RectangularPlate(_) => vec![0.38, 0.42],
            Self::Bell(_) => vec![bell::SOUND_BOW],
        }
    }

    /// Mallet contact time in ms that suits the object.
    pub fn default_hardness_ms(&self, material: &Material) -> f64 {
        match self {
            Self::IdealString(_) | Self::StiffString(_) => STRING_HAMMER_MS,
            Self::CircularMembrane(_) => DRUM_STICK_MS,
            _ => solid_contact_ms(material.class),
        }
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
        let shaped = match self {
            Self::IdealString(s) => {
                s.shaped_modes(material, false, &line_coords(positions)?, limits)
            }
            Self::StiffString(s) => {
                s.shaped_modes(material, true, &line_coords(positions)?, limits)
            }
            Self::FreeFreeBar(bar) => bar.shaped_modes(material, &line_coords(positions)?, limits),
            Self::TunedBar(bar) => bar.shaped_modes(material, &line_coords(positions)?, limits),
            Self::CircularMembrane(membrane) => {
                membrane.shaped_modes(material, &plane_coords(positions, true)?, limits)
            }
            Self::RectangularPlate(plate) => {
                plate.shaped_modes(material, &plane_coords(positions, false)?, limits)
            }
            Self::Bell(bell) => bell.shaped_modes(material, &line_coords(positions)?, limits),
        };
        finish_modes(shaped, material, limits)
    }

    /// Dimensions in metres, by name.
    pub fn dimensions_m(&self) -> Map<String, Value> {
        let pairs: Vec<(&str, f64)> = match self {
            Self::IdealString(s) | Self::StiffString(s) => {
                vec![("length", s.length_m), ("diameter", s.diameter_m)]
            }
            Self::FreeFreeBar(bar) | Self::TunedBar(TunedBar { bar, .. }) => vec![
                ("length", bar.length_m),
                ("width", bar.width_m),
                ("thickness", bar.thickness_m),
            ],
            Self::CircularMembrane(membrane) => vec![
                ("radius", membrane.radius_m),
                ("thickness", membrane.thickness_m),
            ],
            Self::RectangularPlate(plate) => vec![
                ("length_x", plate.length_x_m),
                ("length_y", plate.length_y_m),
                ("thickness", plate.thickness_m),
            ],
            Self::Bell(bell) => vec![
                ("diameter", bell.diameter_m),
                ("thickness", bell.thickness_m),
            ],
        };
        pairs
            .into_iter()
            .map(|(name, value)| (name.to_string(), json!(value)))
            .collect()
    }

    /// Parameters other than dimensions (tension, tuning), by name with their unit.
    pub fn parameters(&self, material: &Material) -> Map<String, Value> {
        let mut map = Map::new();
        match self {
            Self::IdealString(s) => {
                map.insert("tension_n".into(), json!(s.tension_n));
            }
            Self::StiffString(s) => {
                map.insert("tension_n".into(), json!(s.tension_n));
                map.insert("inharmonicity".into(), json!(s.inharmonicity(material)));
            }
            Self::TunedBar(tuned) => {
                map.insert("tuned_ratios".into(), json!(tuned.tuned_ratios));
            }
            Self::CircularMembrane(membrane) => {
                map.insert("tension_n_per_m".into(), json!(membrane.tension_n_per_m));
            }
            Self::Bell(_) => {
                let ratios: Vec<f64> = TUNED_BELL_PARTIALS.iter().map(|p| p.ratio).collect();
                map.insert("partial_ratios".into(), json!(ratios));
            }
            Self::FreeFreeBar(_) | Self::RectangularPlate(_) => {}
        }
        map
    }

    /// One line saying what the object is, e.g. "Free-free bar of steel, 199.4 x 25 x 8 mm,
    /// fundamental 1046.5 Hz."
    pub fn summary(&self, material: &Material) -> String {
        let mm = |m: f64| format!("{:.1}", m * 1e3);
        let size = match self {
            Self::IdealString(s) | Self::StiffString(s) => format!(
                "{} mm long, {} mm wire at {:.0} N",
                mm(s.length_m),
                mm(s.diameter_m),
                s.tension_n
            ),
            Self::FreeFreeBar(bar) | Self::TunedBar(TunedBar { bar, .. }) => format!(
                "{} x {} x {} mm",
                mm(bar.length_m),
                mm(bar.width_m),
                mm(bar.thickness_m)
            ),
            Self::CircularMembrane(m) => format!(
                "{} mm radius, {:.2} mm film at {:.0} N/m",
                mm(m.radius_m),
                m.thickness_m * 1e3,
                m.tension_n_per_m
            ),
            Self::RectangularPlate(p) => format!(
                "{} x {} x {} mm",
                mm(p.length_x_m),
                mm(p.length_y_m),
                mm(p.thickness_m)
            ),
            Self::Bell(b) => format!(
                "{} mm across, sound bow {} mm thick",
                mm(b.diameter_m),
                mm(b.thickness_m)
            ),
        };
        let kind = self.display_kind();
        let mut kind_upper = kind[..1].to_uppercase();
        kind_upper.push_str(&kind[1..]);
        format!(
            "{kind_upper} of {}, {size}, {} {:.1} Hz.",
            material.display_name.to_lowercase(),
            if matches!(self, Self::Bell(_)) {
                "prime"
            } else {
                "fundamental"
            },
            self.root_hz(material)
        )
    }
}
