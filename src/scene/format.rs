//! The scene file: objects (a bank each, placed in space), the events that sound them, and the
//! listener. Versioned JSON; `modal-resonator schema --scene` prints its JSON Schema.
//!
//! Coordinates are metres in a right-handed frame with `y` up (rapier's and glTF's). Reading goes
//! text -> typed [`SceneFile`] (a syntax error, an unknown field or a wrong type stops here, with
//! its line and column) -> [`validate`], which collects every problem with its JSON path
//! (`events[3].object: ...`).

use std::collections::{BTreeMap, HashMap, HashSet};
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

/// Most problems reported at once.
const MAX_PROBLEMS: usize = 20;

/// Parses a scene from JSON text and checks it ([`validate`]); `origin` names the text in
/// messages.
pub fn parse_scene_str(text: &str, origin: &str) -> Result<SceneFile, SceneError> {
    let fail = |path: String, message: String| SceneError {
        origin: origin.to_string(),
        problems: vec![Problem { path, message }],
    };
    // The format first: a bank or another file given as a scene says so, not "unknown field".
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| fail(String::new(), e.to_string()))?;
    match value.get("format") {
        Some(serde_json::Value::String(f)) if f == SCENE_FORMAT => {}
        Some(found) => {
            return Err(fail(
                "format".into(),
                format!("expected \"{SCENE_FORMAT}\", found {found}"),
            ))
        }
        None => {
            return Err(fail(
                String::new(),
                format!("no \"format\": \"{SCENE_FORMAT}\""),
            ))
        }
    }
    let scene: SceneFile =
        serde_json::from_str(text).map_err(|e| fail(String::new(), e.to_string()))?;
    let problems = validate(&scene);
    if problems.is_empty() {
        Ok(scene)
    } else {
        Err(SceneError {
            origin: origin.to_string(),
            problems,
        })
    }
}

/// Every problem of `scene` that its types do not rule out, at most [`MAX_PROBLEMS`]: the
/// version, the limits, names that must be unique or must exist, and the listener's place.
pub fn validate(scene: &SceneFile) -> Vec<Problem> {
    let mut problems = Vec::new();
    let mut add = |path: String, message: String| {
        if problems.len() < MAX_PROBLEMS {
            problems.push(Problem { path, message });
        }
    };
    if scene.version != SCENE_VERSION {
        add(
            "version".into(),
            format!(
                "this build reads version {SCENE_VERSION}, found {}",
                scene.version
            ),
        );
    }
    if scene.objects.is_empty() {
        add("objects".into(), "expected at least one object".into());
    }
    if scene.objects.len() > MAX_OBJECTS {
        add(
            "objects".into(),
            format!(
                "{} objects, at most {MAX_OBJECTS} play in one scene",
                scene.objects.len()
            ),
        );
        return problems;
    }
    if scene.events.len() > MAX_EVENTS {
        add(
            "events".into(),
            format!("{} events, at most {MAX_EVENTS}", scene.events.len()),
        );
        return problems;
    }
    let mut names = HashSet::new();
    for (i, o) in scene.objects.iter().enumerate() {
        let at = |field: &str| format!("objects[{i}].{field}");
        if o.name.trim().is_empty() {
            add(at("name"), "expected a name".into());
        } else if !names.insert(o.name.as_str()) {
            add(
                at("name"),
                format!("\"{}\" names another object too", o.name),
            );
        }
        match &o.bank {
            Some(bank) if bank.trim().is_empty() => {
                add(
                    at("bank"),
                    "expected a factory bank's name or a bank file".into(),
                );
            }
            None if o.body.is_none() => add(
                format!("objects[{i}]"),
                "expected a \"bank\" (it sounds), a \"body\" (it moves or is struck) or both"
                    .into(),
            ),
            _ => {}
        }
        if let Some(body) = &o.body {
            check_body(body, &at("body"), &mut add);
            if body.dynamic && o.bank.is_some() {
                add(
                    at("bank"),
                    "a dynamic body cannot sound yet (it would be heard where it started); \
                     give the bank to the fixed bodies it strikes"
                        .into(),
                );
            }
        }
        check_point(&o.position, &at("position"), &mut add);
        if !(SCALE_RANGE.0..=SCALE_RANGE.1).contains(&o.scale) {
            add(
                at("scale"),
                format!(
                    "expected {} to {}, found {}",
                    SCALE_RANGE.0, SCALE_RANGE.1, o.scale
                ),
            );
        }
        if !(-60.0..=40.0).contains(&o.gain_db) {
            add(
                at("gain_db"),
                format!("expected -60 to 40 dB, found {}", o.gain_db),
            );
        }
    }
    let contact_s: f64 = scene
        .events
        .iter()
        .filter_map(|e| e.contact.map(|c| c.duration_s))
        .sum();
    if contact_s > MAX_CONTACT_S {
        add(
            "events".into(),
            format!("contacts last {contact_s:.0} s in all, at most {MAX_CONTACT_S} s in a scene"),
        );
    }
    // Whether each object has a bank, by name.
    let sounds: HashMap<&str, bool> = scene
        .objects
        .iter()
        .map(|o| (o.name.as_str(), o.bank.is_some()))
        .collect();
    for (i, e) in scene.events.iter().enumerate() {
        let at = |field: &str| format!("events[{i}].{field}");
        if !(0.0..=MAX_EVENT_TIME_S).contains(&e.time_s) {
            add(
                at("time_s"),
                format!("expected 0 to {MAX_EVENT_TIME_S} s, found {}", e.time_s),
            );
        }
        match sounds.get(e.object.as_str()) {
            None => add(at("object"), format!("no object is named \"{}\"", e.object)),
            Some(false) => add(
                at("object"),
                format!("\"{}\" has no bank: it cannot sound", e.object),
            ),
            Some(true) => {}
        }
        match (&e.impact, &e.contact) {
            (Some(impact), None) => {
                check_speed(
                    impact.speed_m_per_s,
                    false,
                    &at("impact.speed_m_per_s"),
                    &mut add,
                );
            }
            (None, Some(c)) => {
                if !(c.duration_s > 0.0 && c.duration_s <= MAX_EVENT_TIME_S) {
                    add(
                        at("contact.duration_s"),
                        format!(
                            "expected over 0 up to {MAX_EVENT_TIME_S} s, found {}",
                            c.duration_s
                        ),
                    );
                }
                for (k, s) in c.speed_m_per_s.iter().enumerate() {
                    check_speed(
                        *s,
                        true,
                        &at(&format!("contact.speed_m_per_s[{k}]")),
                        &mut add,
                    );
                }
                for (k, f) in c.force.iter().enumerate() {
                    if !(0.0..=1.0).contains(f) {
                        add(
                            at(&format!("contact.force[{k}]")),
                            format!("expected 0 to 1, found {f}"),
                        );
                    }
                }
            }
            (impact, _) => add(
                format!("events[{i}]"),
                format!(
                    "expected exactly one of \"impact\" and \"contact\", found {}",
                    if impact.is_some() { "both" } else { "neither" }
                ),
            ),
        }
    }
    if let Some(p) = &scene.physics {
        if !(p.duration_s > 0.0 && p.duration_s <= MAX_EVENT_TIME_S) {
            add(
                "physics.duration_s".into(),
                format!(
                    "expected over 0 up to {MAX_EVENT_TIME_S} s, found {}",
                    p.duration_s
                ),
            );
        }
        if !(1e-5..=0.1).contains(&p.step_s) {
            add(
                "physics.step_s".into(),
                format!("expected 0.00001 to 0.1 s, found {}", p.step_s),
            );
        } else if p.duration_s / p.step_s > MAX_STEPS {
            add(
                "physics.step_s".into(),
                format!(
                    "{} s in steps of {} s is over {MAX_STEPS} steps",
                    p.duration_s, p.step_s
                ),
            );
        }
        for (k, g) in p.gravity_m_per_s2.iter().enumerate() {
            if !g.is_finite() || g.abs() > 1000.0 {
                add(
                    format!("physics.gravity_m_per_s2[{k}]"),
                    format!("expected -1000 to 1000 m/s², found {g}"),
                );
            }
        }
    }
    for (i, e) in scene.emitters.iter().enumerate() {
        check_emitter(e, &format!("emitters[{i}]"), &mut add);
    }
    let drops: f64 = scene
        .emitters
        .iter()
        .map(|e| e.rate_per_s * e.duration_s)
        .sum();
    if drops > MAX_EVENTS as f64 {
        add(
            "emitters".into(),
            format!("{drops:.0} drops on average, at most {MAX_EVENTS} in a scene"),
        );
    }
    let l = &scene.listener;
    check_point(&l.position, "listener.position", &mut add);
    let f = l.forward;
    let horizontal = (f[0] * f[0] + f[2] * f[2]).sqrt();
    if !f.iter().all(|v| v.is_finite()) || horizontal < 1e-6 * (1.0 + f[1].abs()) {
        add(
            "listener.forward".into(),
            format!(
                "expected a direction with a horizontal part (the head is upright), found {f:?}"
            ),
        );
    }
    problems
}

/// Checks a point: finite, within [`MAX_COORDINATE_M`] of the origin.
fn check_point(p: &[f64; 3], path: &str, add: &mut impl FnMut(String, String)) {
    for (k, v) in p.iter().enumerate() {
        if !v.is_finite() || v.abs() > MAX_COORDINATE_M {
            add(
                format!("{path}[{k}]"),
                format!("expected metres within {MAX_COORDINATE_M} of the origin, found {v}"),
            );
        }
    }
}

/// Checks an emitter: its rectangle, rate, times and diameters.
fn check_emitter(e: &Emitter, path: &str, add: &mut impl FnMut(String, String)) {
    check_point(&e.centre, &format!("{path}.centre"), add);
    for (k, h) in e.half_extents_m.iter().enumerate() {
        if !(0.0..=MAX_COORDINATE_M).contains(h) {
            add(
                format!("{path}.half_extents_m[{k}]"),
                format!("expected 0 to {MAX_COORDINATE_M} m, found {h}"),
            );
        }
    }
    if !(e.rate_per_s > 0.0 && e.rate_per_s <= 1e5) {
        add(
            format!("{path}.rate_per_s"),
            format!(
                "expected over 0 up to 100000 a second, found {}",
                e.rate_per_s
            ),
        );
    }
    if !(0.0..=MAX_EVENT_TIME_S).contains(&e.start_s) {
        add(
            format!("{path}.start_s"),
            format!("expected 0 to {MAX_EVENT_TIME_S} s, found {}", e.start_s),
        );
    }
    if !(e.duration_s > 0.0 && e.duration_s <= MAX_EVENT_TIME_S) {
        add(
            format!("{path}.duration_s"),
            format!(
                "expected over 0 up to {MAX_EVENT_TIME_S} s, found {}",
                e.duration_s
            ),
        );
    }
    if let Some([lo, hi]) = e.diameter_mm {
        let (min, max) = e.kind.diameter_range_mm();
        if !((min..=max).contains(&lo) && (lo..=max).contains(&hi)) {
            add(
                format!("{path}.diameter_mm"),
                format!(
                    "expected the smallest then the largest, {min} to {max} mm, found [{lo}, {hi}]"
                ),
            );
        }
    }
}

/// Most physics steps a scene may take.
pub const MAX_STEPS: f64 = 2e6;

/// Checks a body: a shape of positive size, a positive mass or density, coefficients in range,
/// finite velocities.
fn check_body(b: &Body, path: &str, add: &mut impl FnMut(String, String)) {
    let size_ok = |v: f64| v > 0.0 && v <= MAX_COORDINATE_M;
    let sizes: Vec<(&str, f64)> = match b.collider {
        Collider::Ball { radius_m } => vec![("ball.radius_m", radius_m)],
        Collider::Cuboid { half_extents_m } => (0..3)
            .map(|k| {
                (
                    [
                        "cuboid.half_extents_m[0]",
                        "cuboid.half_extents_m[1]",
                        "cuboid.half_extents_m[2]",
                    ][k],
                    half_extents_m[k],
                )
            })
            .collect(),
        Collider::Cylinder {
            half_height_m,
            radius_m,
        } => vec![
            ("cylinder.half_height_m", half_height_m),
            ("cylinder.radius_m", radius_m),
        ],
    };
    for (name, v) in sizes {
        if !size_ok(v) {
            add(
                format!("{path}.collider.{name}"),
                format!("expected metres over 0 up to {MAX_COORDINATE_M}, found {v}"),
            );
        }
    }
    if let Some(m) = b.mass_kg {
        if !(m > 0.0 && m <= 1e9) {
            add(
                format!("{path}.mass_kg"),
                format!("expected over 0 up to 1e9 kg, found {m}"),
            );
        }
    }
    if !(b.density_kg_per_m3 > 0.0 && b.density_kg_per_m3 <= 1e5) {
        add(
            format!("{path}.density_kg_per_m3"),
            format!(
                "expected over 0 up to 100000 kg/m³, found {}",
                b.density_kg_per_m3
            ),
        );
    }
    if !(0.0..=1.0).contains(&b.restitution) {
        add(
            format!("{path}.restitution"),
            format!("expected 0 to 1, found {}", b.restitution),
        );
    }
    if !(0.0..=10.0).contains(&b.friction) {
        add(
            format!("{path}.friction"),
            format!("expected 0 to 10, found {}", b.friction),
        );
    }
    for (name, v) in [
        ("linear_velocity_m_per_s", b.linear_velocity_m_per_s),
        ("angular_velocity_rad_per_s", b.angular_velocity_rad_per_s),
    ] {
        for (k, x) in v.iter().enumerate() {
            if !x.is_finite() || x.abs() > MAX_SPEED_M_PER_S {
                add(
                    format!("{path}.{name}[{k}]"),
                    format!("expected -{MAX_SPEED_M_PER_S} to {MAX_SPEED_M_PER_S}, found {x}"),
                );
            }
        }
    }
}

/// Checks a speed: above 0 (or 0 too, for a contact), at most [`MAX_SPEED_M_PER_S`].
fn check_speed(s: f64, zero_ok: bool, path: &str, add: &mut impl FnMut(String, String)) {
    let low_ok = if zero_ok { s >= 0.0 } else { s > 0.0 };
    if !(low_ok && s <= MAX_SPEED_M_PER_S) {
        add(
            path.into(),
            format!(
                "expected {} up to {MAX_SPEED_M_PER_S} m/s, found {s}",
                if zero_ok { "0" } else { "over 0" }
            ),
        );
    }
}

/// The JSON Schema of [`SceneFile`], pretty-printed, with a final newline.
pub fn scene_schema_json() -> String {
    let schema = schemars::schema_for!(SceneFile);
    let mut json = serde_json::to_string_pretty(&schema).expect("a JSON Schema always serializes");
    json.push('\n');
    json
}
