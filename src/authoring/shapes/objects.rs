//! The analytic objects by name, with the dimensions each takes and typical values for those not
//! given: what `modal-resonator shape` offers and an editor can list. [`ObjectSpec::shape`] turns
//! a name and named dimensions into a [`Shape`].

use super::{
    Bar, Bowl, CircularMembrane, CircularPlate, PlateEdge, RectangularMembrane, RectangularPlate,
    Shape, ShapeError, StretchedString, TunedBar, TunedBell, MARIMBA_RATIOS, VIBRAPHONE_RATIOS,
    XYLOPHONE_RATIOS,
};
use crate::authoring::materials::{self, Material};

/// A dimension or parameter an object is given by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dimension {
    /// Length in m (the free length of a tine; the side along x of a rectangle).
    Length,
    /// Width in m (the side along y of a rectangle).
    Width,
    /// Thickness in m (of a bar in the direction it vibrates, of a plate, a film, a bell's
    /// sound bow).
    Thickness,
    /// Radius in m.
    Radius,
    /// Diameter in m (of a wire, of a bell's mouth, of a bowl's rim).
    Diameter,
    /// Tension: N for a string, N/m for a membrane.
    Tension,
}

impl Dimension {
    /// Every dimension, in the order they are listed.
    pub const ALL: [Dimension; 6] = [
        Dimension::Length,
        Dimension::Width,
        Dimension::Thickness,
        Dimension::Radius,
        Dimension::Diameter,
        Dimension::Tension,
    ];

    /// Lowercase name, as on the command line (`--length`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Length => "length",
            Self::Width => "width",
            Self::Thickness => "thickness",
            Self::Radius => "radius",
            Self::Diameter => "diameter",
            Self::Tension => "tension",
        }
    }
}

/// An object `modal-resonator shape` can build.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectKind {
    /// Name on the command line, the same as [`Shape::kind`].
    pub name: &'static str,
    /// What it is, in a few words.
    pub about: &'static str,
    /// The dimensions it takes, each with its unit and a typical value used when not given.
    pub dimensions: &'static [(Dimension, &'static str, f64)],
    /// The material it is made of when none is given.
    pub default_material: &'static Material,
}

/// Every object, in the order they are listed.
pub const OBJECTS: &[ObjectKind] = &[
    ObjectKind {
        name: "ideal-string",
        about: "string without stiffness: harmonic partials",
        dimensions: STRING_DIMENSIONS,
        default_material: &materials::STEEL,
    },
    ObjectKind {
        name: "stiff-string",
        about: "piano-like wire: partials stretched by stiffness",
        dimensions: STRING_DIMENSIONS,
        default_material: &materials::STEEL,
    },
    ObjectKind {
        name: "free-free-bar",
        about: "uniform bar free at both ends (glockenspiel): 1 : 2.756 : 5.404",
        dimensions: &[
            (Dimension::Length, "m", 0.3),
            (Dimension::Width, "m", 0.03),
            (Dimension::Thickness, "m", 0.01),
        ],
        default_material: &materials::STEEL,
    },
    ObjectKind {
        name: "clamped-free-bar",
        about: "bar clamped at one end (kalimba tine, tuning fork prong): 1 : 6.267 : 17.55",
        dimensions: &[
            (Dimension::Length, "m", 0.06),
            (Dimension::Width, "m", 0.004),
            (Dimension::Thickness, "m", 0.0012),
        ],
        default_material: &materials::STEEL,
    },
    ObjectKind {
        name: "tuned-bar",
        about: "undercut bar with tuned overtones (--tuning marimba, vibraphone, xylophone)",
        dimensions: &[
            (Dimension::Length, "m", 0.38),
            (Dimension::Width, "m", 0.06),
            (Dimension::Thickness, "m", 0.009),
        ],
        default_material: &materials::ROSEWOOD,
    },
    ObjectKind {
        name: "circular-membrane",
        about: "drum head fixed at its rim: Bessel-zero partials",
        dimensions: &[
            (Dimension::Radius, "m", 0.165),
            (Dimension::Thickness, "m", 0.25e-3),
            (Dimension::Tension, "N/m", 1400.0),
        ],
        default_material: &materials::MYLAR,
    },
    ObjectKind {
        name: "rectangular-membrane",
        about: "rectangular head fixed at its frame (seed 000 section 3.1)",
        dimensions: &[
            (Dimension::Length, "m", 0.4),
            (Dimension::Width, "m", 0.3),
            (Dimension::Thickness, "m", 0.2e-3),
            (Dimension::Tension, "N/m", 2000.0),
        ],
        default_material: &materials::MYLAR,
    },
    ObjectKind {
        name: "rectangular-plate",
        about: "thin plate with hinged edges: a dense metallic wash",
        dimensions: &[
            (Dimension::Length, "m", 0.4),
            (Dimension::Width, "m", 0.3),
            (Dimension::Thickness, "m", 0.002),
        ],
        default_material: &materials::STEEL,
    },
    ObjectKind {
        name: "circular-plate",
        about: "thin disc, free or clamped at its rim (--edge): gong, cymbal, saucer",
        dimensions: &[
            (Dimension::Radius, "m", 0.15),
            (Dimension::Thickness, "m", 0.002),
        ],
        default_material: &materials::BRASS,
    },
    ObjectKind {
        name: "bell",
        about: "tuned church bell: hum, prime, tierce, quint, nominal",
        dimensions: &[
            (Dimension::Diameter, "m", 0.6),
            (Dimension::Thickness, "m", 0.046),
        ],
        default_material: &materials::BRONZE,
    },
    ObjectKind {
        name: "bowl",
        about: "open bowl or glass rung at its rim: singing bowl, wine glass, cup",
        dimensions: &[
            (Dimension::Diameter, "m", 0.2),
            (Dimension::Thickness, "m", 0.004),
        ],
        default_material: &materials::BRONZE,
    },
];

/// Dimensions of a string: a plain steel piano wire at middle C by default.
const STRING_DIMENSIONS: &[(Dimension, &str, f64)] = &[
    (Dimension::Length, "m", 0.62),
    (Dimension::Diameter, "m", 1.0e-3),
    (Dimension::Tension, "N", 650.0),
];

/// Named tunings of a tuned bar.
pub const BAR_TUNINGS: [(&str, &[f64]); 3] = [
    ("marimba", &MARIMBA_RATIOS),
    ("vibraphone", &VIBRAPHONE_RATIOS),
    ("xylophone", &XYLOPHONE_RATIOS),
];

impl ObjectKind {
    /// The object called `name` (any case).
    pub fn by_name(name: &str) -> Option<&'static ObjectKind> {
        OBJECTS
            .iter()
            .find(|object| object.name.eq_ignore_ascii_case(name.trim()))
    }

    /// Every object's name.
    pub fn names() -> Vec<&'static str> {
        OBJECTS.iter().map(|object| object.name).collect()
    }

    /// Whether the object takes `dimension`.
    pub fn takes(&self, dimension: Dimension) -> bool {
        self.dimensions.iter().any(|(d, _, _)| *d == dimension)
    }

    /// The dimensions it takes with their typical values, e.g. "--length 0.3 m --width 0.03 m".
    pub fn usage(&self) -> String {
        let parts: Vec<String> = self
            .dimensions
            .iter()
            .map(|(d, unit, value)| format!("--{} {value} {unit}", d.name()))
            .collect();
        parts.join(" ")
    }
}

/// What to build: an object, its dimensions, and the options only some objects take.
#[derive(Debug, Clone, PartialEq)]
pub struct ObjectSpec {
    /// Which object.
    pub object: &'static ObjectKind,
    /// Dimensions given, in the units of [`ObjectKind::dimensions`]; the others take their
    /// typical values.
    pub dimensions: Vec<(Dimension, f64)>,
    /// Frequencies of a tuned bar's first modes over its first (starting with 1); only for
    /// `tuned-bar`, which is tuned as a marimba bar when not given.
    pub tuning: Option<Vec<f64>>,
    /// How a circular plate's rim is held; only for `circular-plate`, free when not given.
    pub edge: Option<PlateEdge>,
}

impl ObjectSpec {
    /// The object with every dimension at its typical value.
    pub fn typical(object: &'static ObjectKind) -> Self {
        Self {
            object,
            dimensions: Vec::new(),
            tuning: None,
            edge: None,
        }
    }

    /// The value of `dimension`: given, or typical.
    fn value(&self, dimension: Dimension) -> f64 {
        self.dimensions
            .iter()
            .rev()
            .find(|(d, _)| *d == dimension)
            .map(|(_, v)| *v)
            .or_else(|| {
                let typical = self
                    .object
                    .dimensions
                    .iter()
                    .find(|(d, _, _)| *d == dimension);
                typical.map(|(_, _, v)| *v)
            })
            .unwrap_or(f64::NAN)
    }

    /// The shape, with every dimension and option checked against what the object takes.
    pub fn shape(&self) -> Result<Shape, ShapeError> {
        let name = self.object.name;
        for &(dimension, value) in &self.dimensions {
            if !self.object.takes(dimension) {
                return Err(ShapeError::BadParameter {
                    name: dimension.name(),
                    value,
                    reason: format!("{name} does not take it; it takes {}", self.object.usage()),
                });
            }
        }
        if self.tuning.is_some() && name != "tuned-bar" {
            return Err(not_taken("tuning", name, "tuned-bar"));
        }
        if self.edge.is_some() && name != "circular-plate" {
            return Err(not_taken("edge", name, "circular-plate"));
        }
        let v = |dimension| self.value(dimension);
        let bar = || Bar {
            length_m: v(Dimension::Length),
            width_m: v(Dimension::Width),
            thickness_m: v(Dimension::Thickness),
        };
        let string = || StretchedString {
            length_m: v(Dimension::Length),
            diameter_m: v(Dimension::Diameter),
            tension_n: v(Dimension::Tension),
        };
        let shape = match name {
            "ideal-string" => Shape::IdealString(string()),
            "stiff-string" => Shape::StiffString(string()),
            "free-free-bar" => Shape::FreeFreeBar(bar()),
            "clamped-free-bar" => Shape::ClampedFreeBar(bar()),
            "tuned-bar" => Shape::TunedBar(TunedBar {
                bar: bar(),
                tuned_ratios: self
                    .tuning
                    .clone()
                    .unwrap_or_else(|| MARIMBA_RATIOS.to_vec()),
            }),
            "circular-membrane" => Shape::CircularMembrane(CircularMembrane {
                radius_m: v(Dimension::Radius),
                thickness_m: v(Dimension::Thickness),
                tension_n_per_m: v(Dimension::Tension),
            }),
            "rectangular-membrane" => Shape::RectangularMembrane(RectangularMembrane {
                length_x_m: v(Dimension::Length),
                length_y_m: v(Dimension::Width),
                thickness_m: v(Dimension::Thickness),
                tension_n_per_m: v(Dimension::Tension),
            }),
            "rectangular-plate" => Shape::RectangularPlate(RectangularPlate {
                length_x_m: v(Dimension::Length),
                length_y_m: v(Dimension::Width),
                thickness_m: v(Dimension::Thickness),
            }),
            "circular-plate" => Shape::CircularPlate(CircularPlate {
                radius_m: v(Dimension::Radius),
                thickness_m: v(Dimension::Thickness),
                edge: self.edge.unwrap_or(PlateEdge::Free),
            }),
            "bell" => Shape::Bell(TunedBell {
                diameter_m: v(Dimension::Diameter),
                thickness_m: v(Dimension::Thickness),
            }),
            "bowl" => Shape::Bowl(Bowl {
                diameter_m: v(Dimension::Diameter),
                thickness_m: v(Dimension::Thickness),
            }),
            _ => unreachable!("every object in OBJECTS has a shape"),
        };
        shape.validate()?;
        Ok(shape)
    }
}

/// The error for an option the object does not take.
fn not_taken(option: &'static str, object: &str, only: &str) -> ShapeError {
    ShapeError::BadParameter {
        name: option,
        value: f64::NAN,
        reason: format!("only {only} takes it, not {object}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dimensions_are_checked_against_the_object() {
        let bar = ObjectKind::by_name("free-free-bar").unwrap();
        let spec = ObjectSpec {
            dimensions: vec![(Dimension::Length, 0.2), (Dimension::Radius, 0.1)],
            ..ObjectSpec::typical(bar)
        };
        let err = spec.shape().unwrap_err().to_string();
        assert_eq!(
            err,
            "radius = 0.1: free-free-bar does not take it; it takes --length 0.3 m \
             --width 0.03 m --thickness 0.01 m"
        );
        let spec = ObjectSpec {
            dimensions: vec![(Dimension::Thickness, -1.0)],
            ..ObjectSpec::typical(bar)
        };
        assert!(spec.shape().is_err());
        let spec = ObjectSpec {
            edge: Some(PlateEdge::Clamped),
            ..ObjectSpec::typical(bar)
        };
        assert!(spec
            .shape()
            .unwrap_err()
            .to_string()
            .contains("circular-plate"));
        // Given dimensions replace the typical ones.
        let spec = ObjectSpec {
            dimensions: vec![(Dimension::Length, 0.2)],
            ..ObjectSpec::typical(bar)
        };
        match spec.shape().unwrap() {
            Shape::FreeFreeBar(b) => assert_eq!((b.length_m, b.width_m), (0.2, 0.03)),
            other => panic!("{other:?}"),
        }
    }
}
