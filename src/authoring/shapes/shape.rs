//! The shape family: [`Object`], what every kind of object with closed-form modes says about
//! itself, implemented in the kind's own file; [`Shape`], the value that holds one of them; and
//! `register_shapes!`, which turns the one-line registrations in `mod.rs` into the [`Shape`] enum
//! and the list of objects (`OBJECTS`).

use super::{finish_modes, ModeLimits, Shape, ShapeError, ShapedMode};
use crate::authoring::materials::{Material, MaterialClass};
use crate::bank::{Mode, Position};
use serde_json::{json, Map, Value};

/// Mallet contact time for drum heads, in ms: a felt or wooden stick on a yielding head.
pub(super) const DRUM_STICK_MS: f64 = 1.5;

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

/// Everything one kind of object says about itself, beyond its entry on the command line
/// ([`super::ObjectKind`]): implemented by the type that holds its parameters, in the kind's own file.
pub(crate) trait Object {
    /// Name of the kind of object for people, e.g. "free-free bar".
    fn display_kind(&self) -> &'static str;

    /// `Ok` when every dimension and parameter is in range.
    fn validate(&self) -> Result<(), ShapeError>;

    /// `Ok` when the object is thin or slender enough for the theory its modes come from.
    fn check_proportions(&self) -> Result<(), ShapeError>;

    /// The pitch the object is named by, in Hz.
    fn root_hz(&self, material: &Material) -> f64;

    /// What the pitch of [`Object::root_hz`] is called in a summary.
    fn root_name(&self) -> &'static str {
        "fundamental"
    }

    /// The same object tuned to `root_hz` the way such an object is tuned.
    fn tuned(&self, material: &Material, root_hz: f64) -> Result<Shape, ShapeError>;

    /// Its modes within `limits`, with their unit-mean-square shapes at `positions`, in any
    /// order; the positions are checked against the object.
    fn modes_at(
        &self,
        material: &Material,
        positions: &[Position],
        limits: &ModeLimits,
    ) -> Result<Vec<ShapedMode>, ShapeError>;

    /// Named strike positions that show the object off, ordered from one side of it to the
    /// other so that sweeping the strike position moves across the object.
    fn default_positions(&self) -> Vec<Position>;

    /// Where a player usually strikes the object, in position coordinates.
    fn typical_strike(&self) -> Vec<f64>;

    /// Mallet contact time in ms that suits the object.
    fn default_hardness_ms(&self, material: &Material) -> f64 {
        solid_contact_ms(material.class)
    }

    /// Dimensions in metres, by name, as a bank's source records them.
    fn dimensions_m(&self) -> Vec<(&'static str, f64)>;

    /// Parameters other than dimensions (tension, tuning, edge), by name with their unit, as a
    /// bank's source records them.
    fn parameters(&self, _material: &Material) -> Map<String, Value> {
        Map::new()
    }

    /// Its size in a few words for a summary, e.g. "199.4 x 25.0 x 8.0 mm".
    fn size(&self) -> String;
}

/// Millimetres to one decimal, for sizes.
pub(super) fn mm(m: f64) -> String {
    format!("{:.1}", m * 1e3)
}

/// Declares the shapes from one line each, `Variant(Parameters) => KIND`: the [`Shape`] enum,
/// whose variant holds the parameters (a type implementing [`Object`]); a `From` of the
/// parameters into it; the dispatch to the parameters and to the command line's entry `KIND`
/// (an [`super::ObjectKind`]); and `OBJECTS`, every entry in the order of the lines.
macro_rules! register_shapes {
    ($($variant:ident($params:ty) => $kind:path,)*) => {
        /// An object with closed-form modes, dimensions in metres: one variant for each kind of
        /// object, holding its parameters (see each parameter type for the object, its theory
        /// and its positions).
        #[derive(Debug, Clone, PartialEq)]
        pub enum Shape {
            $(
                #[doc = concat!("See [`", stringify!($params), "`].")]
                $variant($params),
            )*
        }

        impl Shape {
            /// The parameters of the object, which know everything about it.
            pub(crate) fn object(&self) -> &dyn $crate::authoring::shapes::shape::Object {
                match self {
                    $(Self::$variant(params) => params,)*
                }
            }

            /// The kind of object, as listed on the command line.
            pub fn object_kind(&self) -> &'static ObjectKind {
                match self {
                    $(Self::$variant(_) => &$kind,)*
                }
            }
        }

        $(
            impl From<$params> for Shape {
                fn from(params: $params) -> Self {
                    Self::$variant(params)
                }
            }
        )*

        /// Every object, in the order they are listed.
        pub static OBJECTS: &[&ObjectKind] = &[$(&$kind,)*];
    };
}
pub(super) use register_shapes;

impl Shape {
    /// Identifier of the kind of object, as used in bank sources and on the command line.
    pub fn kind(&self) -> &'static str {
        self.object_kind().name
    }

    /// Name of the kind of object for people.
    pub fn display_kind(&self) -> &'static str {
        self.object().display_kind()
    }

    /// Number of coordinates of a strike position on this object (as many as its typical
    /// strike has).
    pub fn num_coords(&self) -> usize {
        self.typical_strike().len()
    }

    /// `Ok` when every dimension and parameter is in range.
    pub fn validate(&self) -> Result<(), ShapeError> {
        self.object().validate()
    }

    /// `Ok` when the object is thin or slender enough for the theory its modes come from: a
    /// thickness (a string's diameter) at most a fifth of its length, diameter or shorter side,
    /// and a bar no wider than long. Checked on the object as tuned, whose size may differ.
    pub fn check_proportions(&self) -> Result<(), ShapeError> {
        self.object().check_proportions()
    }

    /// The pitch the object is named by, in Hz: its lowest mode, except for a bell, whose
    /// strike note is the prime (an octave above the hum).
    pub fn root_hz(&self, material: &Material) -> f64 {
        self.object().root_hz(material)
    }

    /// The same object tuned to `root_hz` the way such an object is tuned: strings and drum
    /// heads by their tension, bars and tines by their length, plates by their size (thickness
    /// kept), bells by their size.
    pub fn tuned_to(&self, material: &Material, root_hz: f64) -> Result<Self, ShapeError> {
        self.validate()?;
        super::check_positive("root_hz", root_hz)?;
        self.object().tuned(material, root_hz)
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
        let shaped = self.object().modes_at(material, positions, limits)?;
        finish_modes(shaped, material, limits)
    }

    /// Named strike positions that show the object off, ordered from one side of it to the
    /// other so that sweeping the strike position moves across the object.
    pub fn default_positions(&self) -> Vec<Position> {
        self.object().default_positions()
    }

    /// Where a player usually strikes the object, in position coordinates: a piano hammer at
    /// an eighth of the string, a bar near its centre, a tine at its tip, a drum or a disc two
    /// thirds of the way out, a plate off-centre, a bell on its sound bow.
    pub fn typical_strike(&self) -> Vec<f64> {
        self.object().typical_strike()
    }

    /// Mallet contact time in ms that suits the object.
    pub fn default_hardness_ms(&self, material: &Material) -> f64 {
        self.object().default_hardness_ms(material)
    }

    /// Dimensions in metres, by name.
    pub fn dimensions_m(&self) -> Map<String, Value> {
        self.object()
            .dimensions_m()
            .into_iter()
            .map(|(name, value)| (name.to_string(), json!(value)))
            .collect()
    }

    /// Parameters other than dimensions (tension, tuning, edge), by name with their unit.
    pub fn parameters(&self, material: &Material) -> Map<String, Value> {
        self.object().parameters(material)
    }

    /// One line saying what the object is, e.g. "Free-free bar of steel, 199.4 x 25.0 x 8.0 mm,
    /// fundamental 1046.5 Hz."
    pub fn summary(&self, material: &Material) -> String {
        let object = self.object();
        let kind = object.display_kind();
        let mut kind_upper = kind[..1].to_uppercase();
        kind_upper.push_str(&kind[1..]);
        format!(
            "{kind_upper} of {}, {}, {} {:.1} Hz.",
            material.display_name.to_lowercase(),
            object.size(),
            object.root_name(),
            object.root_hz(material)
        )
    }
}
