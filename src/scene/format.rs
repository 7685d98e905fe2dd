//! The scene file: objects (a bank each, placed in space), the events that sound them, and the
//! listener. Versioned JSON; `modal-resonator schema --scene` prints its JSON Schema.
//!
//! Coordinates are metres in a right-handed frame with `y` up (rapier's and glTF's). Reading goes
//! text -> typed [`SceneFile`] (a syntax error, an unknown field or a wrong type stops here, with
//! its line and column) -> [`validate`], which collects every problem with its JSON path
//! (`events[3].object: ...`).

use std::collections::{BTreeMap, HashSet};
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
}

/// One sounding object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SceneObject {
    /// Its name, unique in the scene: events name the object they sound.
    pub name: String,
    /// Its bank: a factory bank's name, or a bank file (relative to the scene file).
    pub bank: String,
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
        if o.bank.trim().is_empty() {
            add(
                at("bank"),
                "expected a factory bank's name or a bank file".into(),
            );
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
    for (i, e) in scene.events.iter().enumerate() {
        let at = |field: &str| format!("events[{i}].{field}");
        if !(0.0..=MAX_EVENT_TIME_S).contains(&e.time_s) {
            add(
                at("time_s"),
                format!("expected 0 to {MAX_EVENT_TIME_S} s, found {}", e.time_s),
            );
        }
        if !names.contains(e.object.as_str()) {
            add(at("object"), format!("no object is named \"{}\"", e.object));
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
