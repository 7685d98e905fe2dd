//! The analytic objects by name, with the dimensions each takes and typical values for those not
//! given: what `modal-resonator shape` offers and an editor can list. Each kind of object declares
//! its [`ObjectKind`] in its own file; [`ObjectSpec::shape`] turns a name and named dimensions
//! into a [`Shape`].

use super::{PlateEdge, Shape, ShapeError, OBJECTS};
use crate::authoring::materials::Material;

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

/// An option other than a dimension that only some objects take.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ObjectOption {
    /// The frequencies of a tuned bar's first modes ([`ObjectSpec::tuning`]).
    Tuning,
    /// How a circular plate's rim is held ([`ObjectSpec::edge`]).
    Edge,
}

impl ObjectOption {
    /// Lowercase name, as on the command line (`--tuning`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Tuning => "tuning",
            Self::Edge => "edge",
        }
    }
}

/// An object `modal-resonator shape` can build: each kind of object declares its own, in its
/// file, and registers it in `mod.rs`.
#[derive(Debug)]
pub struct ObjectKind {
    /// Name on the command line and in bank sources ([`Shape::kind`]).
    pub name: &'static str,
    /// What it is, in a few words.
    pub about: &'static str,
    /// The dimensions it takes, each with its unit and a typical value used when not given.
    pub dimensions: &'static [(Dimension, &'static str, f64)],
    /// The options other than dimensions it takes.
    pub options: &'static [ObjectOption],
    /// The material it is made of when none is given.
    pub default_material: &'static Material,
    /// The object from a spec whose dimensions and options it takes (given or typical); the
    /// values are checked afterwards.
    pub build: fn(&ObjectSpec) -> Shape,
}

/// Two entries are the same object when they have the same name.
impl PartialEq for ObjectKind {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

impl ObjectKind {
    /// The object called `name` (any case).
    pub fn by_name(name: &str) -> Option<&'static ObjectKind> {
        OBJECTS
            .iter()
            .find(|object| object.name.eq_ignore_ascii_case(name.trim()))
            .copied()
    }

    /// Every object's name.
    pub fn names() -> Vec<&'static str> {
        OBJECTS.iter().map(|object| object.name).collect()
    }

    /// Whether the object takes `option`.
    pub fn takes_option(&self, option: ObjectOption) -> bool {
        self.options.contains(&option)
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
    pub fn value(&self, dimension: Dimension) -> f64 {
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
        let given = [
            (ObjectOption::Tuning, self.tuning.is_some()),
            (ObjectOption::Edge, self.edge.is_some()),
        ];
        for (option, is_given) in given {
            if is_given && !self.object.takes_option(option) {
                return Err(not_taken(option, name));
            }
        }
        let shape = (self.object.build)(self);
        shape.validate()?;
        Ok(shape)
    }
}

/// The error for an option the object does not take, naming those that do.
fn not_taken(option: ObjectOption, object: &str) -> ShapeError {
    let takers: Vec<&str> = OBJECTS
        .iter()
        .filter(|kind| kind.takes_option(option))
        .map(|kind| kind.name)
        .collect();
    ShapeError::BadParameter {
        name: option.name(),
        value: f64::NAN,
        reason: format!("only {} takes it, not {object}", takers.join(" or ")),
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
        // An option only another object takes names that object.
        let spec = ObjectSpec {
            tuning: Some(vec![1.0, 4.0]),
            ..ObjectSpec::typical(bar)
        };
        assert_eq!(
            spec.shape().unwrap_err().to_string(),
            "tuning = NaN: only tuned-bar takes it, not free-free-bar"
        );
    }
}
