//! Reading a scene from text and the checks its types do not make: the version, the limits,
//! names that must be unique or must exist, and values in range, each problem with its JSON
//! path.

use std::collections::{HashMap, HashSet};

use super::format::*;
use crate::bank::validate::Problem;

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
    check_objects(scene, &mut add);
    check_events(scene, &mut add);
    check_physics(scene, &mut add);
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
    check_listener(scene, &mut add);
    problems
}

/// The objects: names unique, a bank or a body, the bodies, places and scales.
fn check_objects(scene: &SceneFile, add: &mut impl FnMut(String, String)) {
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
            check_body(body, &at("body"), add);
            if body.dynamic && o.bank.is_some() {
                add(
                    at("bank"),
                    "a dynamic body cannot sound yet (it would be heard where it started); \
                     give the bank to the fixed bodies it strikes"
                        .into(),
                );
            }
        }
        check_point(&o.position, &at("position"), add);
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
}

/// The events: times, objects that exist and sound, one impact or contact each, their speeds
/// and forces, and the contacts' total length.
fn check_events(scene: &SceneFile, add: &mut impl FnMut(String, String)) {
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
                    add,
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
                    check_speed(*s, true, &at(&format!("contact.speed_m_per_s[{k}]")), add);
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
}

/// The physics: its duration, step and gravity.
fn check_physics(scene: &SceneFile, add: &mut impl FnMut(String, String)) {
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
}

/// The listener: a place, and a direction with a horizontal part.
fn check_listener(scene: &SceneFile, add: &mut impl FnMut(String, String)) {
    let l = &scene.listener;
    check_point(&l.position, "listener.position", add);
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
