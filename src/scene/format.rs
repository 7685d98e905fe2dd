//! The scene file: objects (a bank each, placed in space), the events that sound them, and the
//! listener. Versioned JSON; `modal-resonator schema --scene` prints its JSON Schema.
//!
//! Coordinates are metres in a right-handed frame with `y` up (rapier's and glTF's). Reading goes
//! text -> typed [`SceneFile`] (a syntax error, an unknown field or a wrong type stops here, with
//! its line and column) -> [`validate`], which collects every problem with its JSON path
//! (`events[3].object: ...`).

use std::collections::BTreeMap;
use std::fmt;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use crate::bank::validate::Problem;

/// The `format` string of every scene file.
pub const SCENE_FORMAT: &str = "modal-scene";

/// The scene format's version this build reads and writes.
pub const SCENE_VERSION: u32 = 1;

/// Most objects in a scene: a limit on memory and time, far above what plays in real time.
pub const MAX_OBJECTS: usize = 10_000;

/// Most events in a scene.
pub const MAX_EVENTS: usize = 1_000_000;

/// Longest time all of a scene's contacts may last together, in seconds (each is followed
/// every 2 ms).
pub const MAX_CONTACT_S: f64 = 3600.0;

/// Latest time an event may be given at, in seconds (an hour).
pub const MAX_EVENT_TIME_S: f64 = 3600.0;

/// Fastest impact or contact speed, in m/s: far past anything struck that still rings.
pub const MAX_SPEED_M_PER_S: f64 = 1000.0;

/// Farthest any point of a scene lies from the origin, in metres.
pub const MAX_COORDINATE_M: f64 = 1e5;

/// Scale of an object, as the size ratio it plays at (the engine's range).
pub const SCALE_RANGE: (f64, f64) = (0.25, 4.0);

/// A scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Always "modal-scene".
    pub format: String,
    /// Format version, 1.
    pub version: u32,
    /// Name of the scene.
    #[serde(default)]
    pub name: String,
    /// What the scene is, for people.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub description: String,
    /// The sounding objects.
    pub objects: Vec<SceneObject>,
    /// What sounds them, in any order.
    #[serde(default)]
    pub events: Vec<SceneEvent>,
    /// Who hears them, and how.
    #[serde(default)]
    pub listener: Listener,
    /// The rigid-body simulation of the objects that have a `body`, whose impacts are events
    /// too; none without it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub physics: Option<Physics>,
    /// Hail or rain falling on the bodies.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub emitters: Vec<Emitter>,
}

/// Drops falling on the scene (seed 001's hail): from random points of a horizontal rectangle,
/// at random times (a Poisson process), each falls straight down at its terminal speed and
/// strikes the first body under it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Emitter {
    /// What falls.
    pub kind: DropKind,
    /// Centre of the rectangle the drops fall from, metres.
    pub centre: [f64; 3],
    /// Half the rectangle's size along x and z, metres.
    pub half_extents_m: [f64; 2],
    /// Drops a second, on average.
    pub rate_per_s: f64,
    /// When the first may fall, seconds (default 0).
    #[serde(default)]
    pub start_s: f64,
    /// How long they fall, seconds.
    pub duration_s: f64,
    /// Smallest and largest diameter, mm, drawn uniformly on a log scale (default 5 to 20 for
    /// hail, 0.5 to 4 for rain).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diameter_mm: Option<[f64; 2]>,
    /// Seed of the draws: the same seed, the same drops.
    #[serde(default = "one_u32")]
    pub seed: u32,
}

fn one_u32() -> u32 {
    1
}

/// What an emitter drops.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum DropKind {
    /// Hailstones: ice, 900 kg/m³.
    Hail,
    /// Raindrops: water, 1000 kg/m³.
    Rain,
}

impl DropKind {
    /// The diameters drawn when none are given, mm.
    pub fn default_diameter_mm(self) -> [f64; 2] {
        match self {
            DropKind::Hail => [5.0, 20.0],
            DropKind::Rain => [0.5, 4.0],
        }
    }

    /// The diameters a scene may give, mm.
    pub fn diameter_range_mm(self) -> (f64, f64) {
        match self {
            DropKind::Hail => (1.0, 150.0),
            DropKind::Rain => (0.1, 8.0),
        }
    }
}

/// How long and how finely the objects' bodies are simulated.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Physics {
    /// Seconds simulated from the start of the scene.
    pub duration_s: f64,
    /// Seconds per step (default 1/240): impacts are timed to a step.
    #[serde(default = "default_step_s")]
    pub step_s: f64,
    /// Gravity, m/s² (default `[0, -9.81, 0]`).
    #[serde(default = "default_gravity")]
    pub gravity_m_per_s2: [f64; 3],
}

fn default_step_s() -> f64 {
    1.0 / 240.0
}

fn default_gravity() -> [f64; 3] {
    [0.0, -9.81, 0.0]
}

/// An object's rigid body: its shape, and whether it moves.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// Whether it moves (falls, bounces); a fixed body does not (default false).
    #[serde(default)]
    pub dynamic: bool,
    /// Its shape, centred on its position.
    pub collider: Collider,
    /// Its mass, kg; from `density_kg_per_m3` and the shape's volume when not given.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Density, kg/m³, when no mass is given (default 1000).
    #[serde(default = "default_density")]
    pub density_kg_per_m3: f64,
    /// Coefficient of restitution, 0 to 1 (default 0.5): how much of the approach speed a
    /// bounce gives back.
    #[serde(default = "half")]
    pub restitution: f64,
    /// Coefficient of friction (default 0.5).
    #[serde(default = "half")]
    pub friction: f64,
    /// Initial velocity, m/s.
    #[serde(default)]
    pub linear_velocity_m_per_s: [f64; 3],
    /// Initial angular velocity, rad/s about each axis.
    #[serde(default)]
    pub angular_velocity_rad_per_s: [f64; 3],
}

fn default_density() -> f64 {
    1000.0
}

fn half() -> f64 {
    0.5
}

/// A body's shape.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Collider {
    /// A sphere.
    Ball {
        /// Radius, m.
        radius_m: f64,
    },
    /// A box.
    Cuboid {
        /// Half its size along x, y and z, m.
        half_extents_m: [f64; 3],
    },
    /// A cylinder along y.
    Cylinder {
        /// Half its height, m.
        half_height_m: f64,
        /// Radius, m.
        radius_m: f64,
    },
}

/// One sounding object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneObject {
    /// Its name, unique in the scene: events name the object they sound.
    pub name: String,
    /// Its bank: a factory bank's name, or a bank file (relative to the scene file). Without
    /// one the object is silent (a body other objects strike).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bank: Option<String>,
    /// Where it is, metres `[x, y, z]`.
    pub position: [f64; 3],
    /// How much larger than its bank it is: pitch falls as the scale grows, as with the size
    /// control (0.25 to 4).
    #[serde(default = "one")]
    pub scale: f64,
    /// Its level at 1 m for an impact at 1 m/s, in dB over the bank played at its default
    /// controls.
    #[serde(default)]
    pub gain_db: f64,
    /// Controls on top of the bank's defaults, by their names in `render --set`
    /// (e.g. `{"material": "wood", "hardness_ms": "0.5"}`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub set: BTreeMap<String, String>,
    /// Its rigid body, for the physics.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body: Option<Body>,
}

fn one() -> f64 {
    1.0
}

/// Something that sounds an object: an impact or a contact (exactly one of the two).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneEvent {
    /// When, in seconds from the start of the scene.
    pub time_s: f64,
    /// The object it sounds, by name.
    pub object: String,
    /// A strike.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub impact: Option<Impact>,
    /// A persistent contact.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact: Option<Contact>,
}

/// A strike, its loudness proportional to the relative normal speed (seed 004: the impulse).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Impact {
    /// Relative normal speed at the contact, m/s.
    pub speed_m_per_s: f64,
    /// Level of this impact over what its speed gives, dB, -120 to 40 (default 0): a lighter
    /// striker's impulse is smaller at the same speed.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub gain_db: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl Impact {
    /// Its strength: the speed, scaled by its gain.
    pub fn strength(&self) -> f64 {
        self.speed_m_per_s * 10f64.powf(self.gain_db / 20.0)
    }
}

/// A persistent contact (scrape, roll or rub: the object's exciter, chosen with its `set`), its
/// speed and force ramping from the first value to the second over its duration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Contact {
    /// How long it lasts, in seconds.
    pub duration_s: f64,
    /// Tangential speed at its start and end, m/s.
    pub speed_m_per_s: [f64; 2],
    /// Normal force at its start and end, 0 to 1.
    pub force: [f64; 2],
}

/// Who hears the scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Listener {
    /// Where the head's centre is, metres.
    #[serde(default)]
    pub position: [f64; 3],
    /// Where the nose points (need not be of unit length); the head is upright (`y` up).
    #[serde(default = "ahead")]
    pub forward: [f64; 3],
    /// How the scene reaches the two channels.
    #[serde(default)]
    pub output: Output,
}

fn ahead() -> [f64; 3] {
    [0.0, 0.0, -1.0]
}

impl Default for Listener {
    fn default() -> Self {
        Self {
            position: [0.0; 3],
            forward: ahead(),
            output: Output::default(),
        }
    }
}

/// How the scene reaches the two channels.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Output {
    /// Equal-power panning by azimuth, for loudspeakers.
    #[default]
    Stereo,
    /// A spherical head (Brown and Duda 1998): each ear's delay and head shadow, for headphones.
    Binaural,
}

/// Why a scene could not be read: every problem, each with its JSON path.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// The file, or whatever the text came from.
    pub origin: String,
    /// What is wrong: never empty.
    pub problems: Vec<Problem>,
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, p) in self.problems.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            if p.path.is_empty() {
                write!(f, "{}: {}", self.origin, p.message)?;
            } else {
                write!(f, "{}: {}: {}", self.origin, p.path, p.message)?;
            }
        }
        Ok(())
    }
}

impl std::error::Error for SceneError {}

/// The JSON Schema of [`SceneFile`], pretty-printed, with a final newline.
pub fn scene_schema_json() -> String {
    let schema = schemars::schema_for!(SceneFile);
    let mut json = serde_json::to_string_pretty(&schema).expect("a JSON Schema always serializes");
    json.push('\n');
    json
}
