//! How a [`Shape`] is struck and described: named strike positions, the usual strike point and
//! mallet, its dimensions and parameters by name, and a one-line summary.

use super::positions::position;
use super::{bell, bowl, CircularPlate, PlateEdge, Shape, TunedBar, TUNED_BELL_PARTIALS};
use crate::authoring::materials::{Material, MaterialClass};
use crate::bank::Position;
use serde_json::{json, Map, Value};

/// Mallet contact time for strings, in ms: felt piano hammers stay on the string for roughly
/// 1-4 ms from treble to bass (Fletcher & Rossing ch. 12).
const STRING_HAMMER_MS: f64 = 1.5;

/// Mallet contact time for drum heads, in ms: a felt or wooden stick on a yielding head.
const DRUM_STICK_MS: f64 = 1.5;

/// Mallet contact time for a solid object of each material class, in ms: a hard mallet on metal
/// or glass makes a contact of a few tenths of a millisecond; the yarn and rubber mallets used on
/// wooden bars, and soft plastics, make longer, duller contacts.
pub(crate) fn solid_contact_ms(class: MaterialClass) -> f64 {
    match class {
        MaterialClass::Metal => 0.3,
        MaterialClass::GlassCeramic => 0.25,
        MaterialClass::Wood => 1.0,
        MaterialClass::Polymer => 0.6,
    }
}

impl Shape {
    /// Name of the kind of object for people.
    pub fn display_kind(&self) -> &'static str {
        match self {
            Self::IdealString(_) => "ideal string",
            Self::StiffString(_) => "stiff string",
            Self::FreeFreeBar(_) => "free-free bar",
            Self::ClampedFreeBar(_) => "clamped-free bar",
            Self::TunedBar(_) => "tuned bar",
            Self::CircularMembrane(_) => "circular membrane",
            Self::RectangularMembrane(_) => "rectangular membrane",
            Self::RectangularPlate(_) => "rectangular plate",
            Self::CircularPlate(CircularPlate {
                edge: PlateEdge::Free,
                ..
            }) => "free circular plate",
            Self::CircularPlate(CircularPlate {
                edge: PlateEdge::Clamped,
                ..
            }) => "clamped circular plate",
            Self::Bell(_) => "tuned bell",
            Self::Bowl(_) => "bowl",
        }
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
            Self::ClampedFreeBar(_) => vec![
                position("middle", &[0.5]),
                position("three quarters", &[0.75]),
                position("near the tip", &[0.9]),
                position("tip", &[1.0]),
            ],
            Self::CircularMembrane(_) => vec![
                position("centre", &[0.0, 0.0]),
                position("half radius", &[0.5, 0.0]),
                position("two-thirds radius", &[0.67, 0.0]),
                position("near rim", &[0.9, 0.0]),
            ],
            Self::CircularPlate(_) => vec![
                position("centre", &[0.0, 0.0]),
                position("third radius", &[0.33, 0.0]),
                position("two-thirds radius", &[0.67, 0.0]),
                position("near rim", &[0.9, 0.0]),
            ],
            Self::RectangularPlate(_) | Self::RectangularMembrane(_) => vec![
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
            Self::Bowl(_) => vec![
                position("low on the wall", &[0.4]),
                position("middle of the wall", &[0.65]),
                position("below the rim", &[0.85]),
                position("rim", &[bowl::RIM]),
            ],
        }
    }

    /// Where a player usually strikes the object, in position coordinates: a piano hammer at
    /// an eighth of the string, a bar near its centre, a tine at its tip, a drum or a disc two
    /// thirds of the way out, a plate off-centre, a bell on its sound bow.
    pub fn typical_strike(&self) -> Vec<f64> {
        match self {
            Self::IdealString(_) | Self::StiffString(_) => vec![0.125],
            Self::FreeFreeBar(_) | Self::TunedBar(_) => vec![0.4],
            Self::ClampedFreeBar(_) => vec![1.0],
            Self::CircularMembrane(_) | Self::CircularPlate(_) => vec![0.67, 0.0],
            Self::RectangularPlate(_) | Self::RectangularMembrane(_) => vec![0.38, 0.42],
            Self::Bell(_) => vec![bell::SOUND_BOW],
            Self::Bowl(_) => vec![bowl::RIM],
        }
    }

    /// Mallet contact time in ms that suits the object.
    pub fn default_hardness_ms(&self, material: &Material) -> f64 {
        match self {
            Self::IdealString(_) | Self::StiffString(_) => STRING_HAMMER_MS,
            Self::CircularMembrane(_) | Self::RectangularMembrane(_) => DRUM_STICK_MS,
            _ => solid_contact_ms(material.class),
        }
    }

    /// Dimensions in metres, by name.
    pub fn dimensions_m(&self) -> Map<String, Value> {
        let pairs: Vec<(&str, f64)> = match self {
            Self::IdealString(s) | Self::StiffString(s) => {
                vec![("length", s.length_m), ("diameter", s.diameter_m)]
            }
            Self::FreeFreeBar(bar)
            | Self::ClampedFreeBar(bar)
            | Self::TunedBar(TunedBar { bar, .. }) => vec![
                ("length", bar.length_m),
                ("width", bar.width_m),
                ("thickness", bar.thickness_m),
            ],
            Self::CircularMembrane(membrane) => vec![
                ("radius", membrane.radius_m),
                ("thickness", membrane.thickness_m),
            ],
            Self::RectangularMembrane(membrane) => vec![
                ("length_x", membrane.length_x_m),
                ("length_y", membrane.length_y_m),
                ("thickness", membrane.thickness_m),
            ],
            Self::RectangularPlate(plate) => vec![
                ("length_x", plate.length_x_m),
                ("length_y", plate.length_y_m),
                ("thickness", plate.thickness_m),
            ],
            Self::CircularPlate(plate) => {
                vec![("radius", plate.radius_m), ("thickness", plate.thickness_m)]
            }
            Self::Bell(bell) => vec![
                ("diameter", bell.diameter_m),
                ("thickness", bell.thickness_m),
            ],
            Self::Bowl(bowl) => vec![
                ("diameter", bowl.diameter_m),
                ("thickness", bowl.thickness_m),
            ],
        };
        pairs
            .into_iter()
            .map(|(name, value)| (name.to_string(), json!(value)))
            .collect()
    }

    /// Parameters other than dimensions (tension, tuning, edge), by name with their unit.
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
            Self::RectangularMembrane(membrane) => {
                map.insert("tension_n_per_m".into(), json!(membrane.tension_n_per_m));
            }
            Self::CircularPlate(plate) => {
                map.insert("edge".into(), json!(plate.edge.name()));
            }
            Self::Bell(_) => {
                let ratios: Vec<f64> = TUNED_BELL_PARTIALS.iter().map(|p| p.ratio).collect();
                map.insert("partial_ratios".into(), json!(ratios));
            }
            Self::Bowl(_) => {
                map.insert("doublet_split".into(), json!(bowl::DOUBLET_SPLIT));
                map.insert("strike_angle_rad".into(), json!(bowl::STRIKE_ANGLE_RAD));
            }
            Self::FreeFreeBar(_) | Self::ClampedFreeBar(_) | Self::RectangularPlate(_) => {}
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
            Self::FreeFreeBar(bar)
            | Self::ClampedFreeBar(bar)
            | Self::TunedBar(TunedBar { bar, .. }) => format!(
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
            Self::RectangularMembrane(m) => format!(
                "{} x {} mm, {:.2} mm film at {:.0} N/m",
                mm(m.length_x_m),
                mm(m.length_y_m),
                m.thickness_m * 1e3,
                m.tension_n_per_m
            ),
            Self::RectangularPlate(p) => format!(
                "{} x {} x {} mm",
                mm(p.length_x_m),
                mm(p.length_y_m),
                mm(p.thickness_m)
            ),
            Self::CircularPlate(p) => format!(
                "{} mm radius, {} mm thick",
                mm(p.radius_m),
                mm(p.thickness_m)
            ),
            Self::Bell(b) => format!(
                "{} mm across, sound bow {} mm thick",
                mm(b.diameter_m),
                mm(b.thickness_m)
            ),
            Self::Bowl(b) => format!(
                "{} mm across the rim, wall {} mm thick",
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
