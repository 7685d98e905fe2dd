//! Scenes: objects placed in space, sounded by timed events, heard from a listener's place.
//! Levels against the laws the docs give (1/r, an impact's loudness proportional to its speed),
//! arrival times against the speed of sound, the spherical head's interaural delay, and the
//! scene file's errors.

use std::fs;
use std::path::Path;
use std::process::Command;

use modal_resonator::scene::format::MAX_OBJECTS;
use modal_resonator::scene::listener::SPEED_OF_SOUND_M_PER_S;
use modal_resonator::scene::{render_scene, scene_schema_json, SceneSource};

const RATE: u32 = 48_000;

/// A scene of `objects` (JSON objects) and `events`, heard in `output` from the origin facing -z.
fn scene_json(objects: &str, events: &str, output: &str) -> String {
    format!(
        r#"{{"format": "modal-scene", "version": 1, "name": "test",
            "objects": [{objects}], "events": [{events}],
            "listener": {{"position": [0, 0, 0], "forward": [0, 0, -1], "output": "{output}"}}}}"#
    )
}

/// Scene text read and checked, its banks factory banks (or files beside the tests).
fn source_of(text: &str, origin: &str) -> SceneSource {
    SceneSource::from_str(text, origin, Path::new(env!("CARGO_MANIFEST_DIR")))
        .unwrap_or_else(|e| panic!("{e}"))
}

/// Renders scene text whose banks are factory banks.
fn render(text: &str) -> (Vec<f32>, Vec<f32>) {
    let source = source_of(text, "test");
    let r = render_scene(&source, RATE, 60.0, |_| {});
    assert!(!r.cut_short);
    (r.left, r.right)
}

fn rms(x: &[f32]) -> f64 {
    (x.iter().map(|&v| (v as f64).powi(2)).sum::<f64>() / x.len().max(1) as f64).sqrt()
}

fn db(ratio: f64) -> f64 {
    20.0 * ratio.log10()
}

/// First sample above `threshold` times the peak.
fn onset(x: &[f32], threshold: f32) -> usize {
    let peak = x.iter().fold(0.0f32, |a, v| a.max(v.abs()));
    x.iter().position(|v| v.abs() > threshold * peak).unwrap()
}

const BAR: &str = "steel-free-free-bar";

#[test]
fn a_source_twice_as_far_is_6_db_quieter() {
    let at = |z: f64| {
        let objects = format!(r#"{{"name": "o", "bank": "{BAR}", "position": [0, 0, {z}]}}"#);
        let events = r#"{"time_s": 0, "object": "o", "impact": {"speed_m_per_s": 1}}"#;
        render(&scene_json(&objects, events, "stereo"))
    };
    let (near, _) = at(-2.0);
    let (far, _) = at(-4.0);
    // The air's absorption over 2 m more takes a little of the highs too (0.2 dB at 8 kHz).
    let fall = db(rms(&near) / rms(&far));
    assert!(
        (fall - 6.02).abs() < 0.5,
        "twice as far: {fall:.2} dB quieter"
    );
    // And 2 m more of travel: 5.8 ms later.
    let late = onset(&far, 1e-3) as f64 - onset(&near, 1e-3) as f64;
    let expected = 2.0 / SPEED_OF_SOUND_M_PER_S * RATE as f64;
    assert!(
        (late - expected).abs() <= 2.0,
        "{late} samples later, expected {expected:.1}"
    );
}

#[test]
fn an_impact_twice_as_fast_is_6_db_louder() {
    // One object, struck at 2 m/s and, once that has died away, at 1 m/s.
    let objects = r#"{"name": "o", "bank": "acrylic-plate", "position": [0, 0, -1]}"#;
    let events = r#"{"time_s": 0, "object": "o", "impact": {"speed_m_per_s": 2}},
                    {"time_s": 2, "object": "o", "impact": {"speed_m_per_s": 1}}"#;
    let (left, _) = render(&scene_json(objects, events, "stereo"));
    let second = 2 * RATE as usize;
    let peak = |x: &[f32]| x.iter().fold(0.0f32, |a, v| a.max(v.abs())) as f64;
    let (fast, slow) = (&left[..RATE as usize], &left[second..]);
    // What is left of the first when the second comes.
    assert!(peak(&left[second - 480..second]) < 1e-3 * peak(fast));
    let louder = db(peak(fast) / peak(slow));
    assert!(
        (louder - 6.02).abs() < 1.0,
        "twice as fast: {louder:.2} dB louder"
    );
}

#[test]
fn stereo_places_a_source_by_its_azimuth() {
    let events = r#"{"time_s": 0, "object": "o", "impact": {"speed_m_per_s": 1}}"#;
    let at = |x: f64, z: f64| {
        let objects = format!(r#"{{"name": "o", "bank": "{BAR}", "position": [{x}, 0, {z}]}}"#);
        let (l, r) = render(&scene_json(&objects, events, "stereo"));
        db(rms(&l) / rms(&r))
    };
    assert!(at(-2.0, 0.0) > 60.0, "hard left");
    assert!(at(2.0, 0.0) < -60.0, "hard right");
    assert!(at(0.0, -2.0).abs() < 0.01, "ahead");
    // 45° to the left: the pan is halfway to the left, sin(3 pi / 8) over cos(3 pi / 8), 7.7 dB.
    let half = at(-1.0, -1.0);
    assert!((half - 7.66).abs() < 0.05, "45° left: {half:.2} dB");
}

#[test]
fn binaurally_a_source_at_the_left_reaches_the_left_ear_first() {
    // A plate of many modes struck by an impulse: broadband, so the correlation has one peak.
    let objects = r#"{"name": "o", "bank": "acrylic-plate", "position": [-2, 0, 0],
        "set": {"exciter": "impulse"}}"#;
    let events = r#"{"time_s": 0, "object": "o", "impact": {"speed_m_per_s": 1}}"#;
    let (l, r) = render(&scene_json(objects, events, "binaural"));
    // The lag of the right ear: the peak of the cross-correlation over the first 10 ms, of the
    // second differences (the highs: at low frequencies the head shadow's phase adds to the
    // delay, as on a real head, 3a/c against 2a/c at the side; Kuhn 1977).
    let n = (0.01 * RATE as f64) as usize;
    let start = onset(&l, 1e-3).saturating_sub(64);
    let highs = |x: &[f32]| -> Vec<f64> {
        x.windows(3)
            .map(|w| w[2] as f64 - 2.0 * w[1] as f64 + w[0] as f64)
            .collect()
    };
    let (hl, hr) = (
        highs(&l[start..start + n + 2]),
        highs(&r[start..start + n + 2]),
    );
    let lag = (0..96)
        .max_by(|&a, &b| {
            let c = |k: usize| (0..n - k).map(|i| hl[i] * hr[i + k]).sum::<f64>();
            c(a).total_cmp(&c(b))
        })
        .unwrap();
    let lag_ms = 1e3 * lag as f64 / RATE as f64;
    assert!(
        (0.6..=0.7).contains(&lag_ms),
        "right ear {lag_ms:.3} ms later"
    );
    // The head shadows the far ear's highs: 2 (+6 dB) at the near ear, 0.28 (-11 dB) at the far
    // one, at 180° from it.
    let level = |x: &[f64]| x.iter().map(|v| v * v).sum::<f64>().sqrt();
    let shadow_db = db(level(&hl) / level(&hr));
    assert!(
        (12.0..20.0).contains(&shadow_db),
        "highs {shadow_db:.1} dB louder at the near ear"
    );
}

#[test]
fn contacts_sound_and_objects_can_be_both_struck_and_scraped() {
    let objects = r#"{"name": "o", "bank": "acrylic-plate", "position": [0, 0, -1]}"#;
    let contact = r#"{"time_s": 0.5, "object": "o",
        "contact": {"duration_s": 1, "speed_m_per_s": [0.3, 1.0], "force": [0.5, 0.5]}}"#;
    let (scraped, _) = render(&scene_json(objects, contact, "stereo"));
    let during = &scraped[RATE as usize..(1.4 * RATE as f64) as usize];
    let before = &scraped[..(0.49 * RATE as f64) as usize];
    assert!(
        rms(before) == 0.0 && rms(during) > 1e-4,
        "scrape: {}",
        rms(during)
    );
    let both =
        format!(r#"{contact}, {{"time_s": 0, "object": "o", "impact": {{"speed_m_per_s": 1}}}}"#);
    let (both, _) = render(&scene_json(objects, &both, "stereo"));
    assert!(
        rms(&both[..RATE as usize / 4]) > 1e-3,
        "the strike sounds too"
    );
    // Past the strike's ring the contact alone sounds, as it did alone.
    let k = RATE as usize;
    let diff: Vec<f32> = both[k..k + 4800]
        .iter()
        .zip(&scraped[k..])
        .map(|(a, b)| a - b)
        .collect();
    assert!(rms(&diff) < 0.05 * rms(&scraped[k..k + 4800]));
}

#[test]
fn a_scene_renders_the_same_twice() {
    let objects = format!(
        r#"{{"name": "a", "bank": "{BAR}", "position": [-1, 0, -2]}},
           {{"name": "b", "bank": "acrylic-plate", "position": [2, 1, -1], "scale": 1.5}}"#
    );
    let events: Vec<String> = (0..20)
        .map(|i| {
            format!(
                r#"{{"time_s": {}, "object": "{}", "impact": {{"speed_m_per_s": {}}}}}"#,
                0.05 * i as f64,
                if i % 3 == 0 { "a" } else { "b" },
                0.5 + 0.1 * i as f64
            )
        })
        .collect();
    let text = scene_json(&objects, &events.join(","), "binaural");
    assert_eq!(render(&text), render(&text));
}

/// The problems of scene text, one per line.
fn problems(text: &str) -> String {
    match SceneSource::from_str(text, "scene.json", Path::new(env!("CARGO_MANIFEST_DIR"))) {
        Ok(_) => String::new(),
        Err(e) => e.to_string(),
    }
}

#[test]
fn broken_scenes_are_errors_naming_the_place() {
    let ok_object = format!(r#"{{"name": "o", "bank": "{BAR}", "position": [0, 0, -1]}}"#);
    let impact = r#"{"time_s": 0, "object": "o", "impact": {"speed_m_per_s": 1}}"#;
    assert_eq!(problems(&scene_json(&ok_object, impact, "stereo")), "");
    let cases = [
        (
            scene_json(
                r#"{"name": "o", "bank": "no-such-bank", "position": [0, 0, 1]}"#,
                "",
                "stereo",
            ),
            "scene.json: objects[0].bank: no factory bank named \"no-such-bank\"",
        ),
        (
            scene_json(
                r#"{"name": "o", "bank": "x", "position": [0, 0, 1], "mass": 2}"#,
                "",
                "stereo",
            ),
            "unknown field `mass`",
        ),
        (
            scene_json(
                &ok_object,
                r#"{"time_s": 0, "object": "p", "impact": {"speed_m_per_s": 1}}"#,
                "stereo",
            ),
            "scene.json: events[0].object: no object is named \"p\"",
        ),
        (
            scene_json(
                &ok_object,
                r#"{"time_s": 0, "object": "o", "impact": {"speed_m_per_s": -3}}"#,
                "stereo",
            ),
            "events[0].impact.speed_m_per_s: expected over 0 up to 1000 m/s, found -3",
        ),
        (
            scene_json(&ok_object, r#"{"time_s": 0, "object": "o"}"#, "stereo"),
            "events[0]: expected exactly one of \"impact\" and \"contact\", found neither",
        ),
        (
            scene_json(&format!(r#"{ok_object}, {ok_object}"#), "", "stereo"),
            "objects[1].name: \"o\" names another object too",
        ),
        (
            scene_json(
                r#"{"name": "o", "bank": "x", "position": [0, 0, 1e400]}"#,
                "",
                "stereo",
            ),
            "number out of range",
        ),
        (
            scene_json(
                r#"{"name": "o", "bank": "x", "position": [0, 0, 1e9]}"#,
                "",
                "stereo",
            ),
            "objects[0].position[2]: expected metres within 100000 of the origin, found 1000000000",
        ),
        (
            scene_json(
                &format!(r#"{{"name": "o", "bank": "{BAR}", "position": [0, 0, 1], "scale": 9}}"#),
                "",
                "stereo",
            ),
            "objects[0].scale: expected 0.25 to 4, found 9",
        ),
        (
            scene_json(
                &format!(
                    r#"{{"name": "o", "bank": "{BAR}", "position": [0, 0, 1], "set": {{"material": "cheese"}}}}"#
                ),
                "",
                "stereo",
            ),
            "objects[0].set.material:",
        ),
        (
            scene_json(&ok_object, "", "surround"),
            "unknown variant `surround`, expected `stereo` or `binaural`",
        ),
        (
            r#"{"format": "modal-bank", "version": 1}"#.to_string(),
            "scene.json: format: expected \"modal-scene\", found \"modal-bank\"",
        ),
    ];
    for (text, expected) in &cases {
        let got = problems(text);
        assert!(got.contains(expected), "expected {expected:?} in {got:?}");
    }
    // Too many objects: refused with the limit, before any bank is looked for.
    let many: Vec<String> = (0..=MAX_OBJECTS)
        .map(|i| format!(r#"{{"name": "o{i}", "bank": "nowhere", "position": [0, 0, 1]}}"#))
        .collect();
    let got = problems(&scene_json(&many.join(","), "", "stereo"));
    assert!(
        got.contains(&format!(
            "objects: {} objects, at most {MAX_OBJECTS}",
            MAX_OBJECTS + 1
        )),
        "{got}"
    );
}

/// The committed schema is the one the types generate. To regenerate it after changing the
/// types: `UPDATE_SCHEMA=1 cargo test --test scene`.
#[test]
fn committed_scene_schema_matches_the_types() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/modal-scene.schema.json");
    let generated = scene_schema_json();
    if std::env::var_os("UPDATE_SCHEMA").is_some() {
        fs::write(&path, &generated).expect("write presets/modal-scene.schema.json");
    }
    let committed = fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} is out of date; regenerate it with `UPDATE_SCHEMA=1 cargo test --test scene`",
        path.display()
    );
}

#[test]
fn the_command_line_renders_a_scene_and_writes_nothing_on_a_bad_one() {
    let dir = tempfile::tempdir().unwrap();
    let bin = env!("CARGO_BIN_EXE_modal-resonator");
    // Every scene in presets/scenes renders, its bank files found beside it.
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/scenes");
    let mut rendered = 0;
    for entry in fs::read_dir(&scenes).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "json") {
            continue;
        }
        let out = dir.path().join("out.wav");
        let run = Command::new(bin)
            .args(["scene", path.to_str().unwrap(), "-o", out.to_str().unwrap()])
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&run.stdout);
        assert!(
            run.status.success(),
            "{}: {}",
            path.display(),
            String::from_utf8_lossy(&run.stderr)
        );
        let impacts: usize = stdout
            .split(", ")
            .find_map(|part| {
                part.strip_suffix(" impacts")
                    .or(part.strip_suffix(" impact"))
            })
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("no impact count in {stdout}"));
        assert!(impacts > 0, "{}: {stdout}", path.display());
        let reader = hound::WavReader::open(&out).unwrap();
        assert!(reader.duration() > RATE / 2, "{}", path.display());
        rendered += 1;
    }
    assert!(rendered >= 1);
    // A scene naming a bank file that is not there: an error, and no file.
    let bad = dir.path().join("bad.json");
    fs::write(
        &bad,
        scene_json(
            r#"{"name": "o", "bank": "banks/gone.json", "position": [0, 0, 1]}"#,
            "",
            "stereo",
        ),
    )
    .unwrap();
    let out = dir.path().join("bad.wav");
    let run = Command::new(bin)
        .args(["scene", bad.to_str().unwrap(), "-o", out.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success());
    assert!(
        stderr.contains("objects[0].bank: no bank file") && stderr.contains("gone.json"),
        "{stderr}"
    );
    assert!(!out.exists());
    // The schema.
    let run = Command::new(bin)
        .args(["schema", "--scene"])
        .output()
        .unwrap();
    assert_eq!(String::from_utf8_lossy(&run.stdout), scene_schema_json());
}

/// A steel ball dropped from `height_m` (its bottom over the floor's top) onto a fixed spruce
/// floor that sounds, and what it played.
fn dropped(height_m: f64, seconds: f64) -> (SceneSource, String) {
    let text = format!(
        r#"{{"format": "modal-scene", "version": 1,
            "objects": [
              {{"name": "floor", "bank": "spruce-panel", "position": [0, -0.05, -1],
                "body": {{"collider": {{"cuboid": {{"half_extents_m": [1, 0.05, 1]}}}}}}}},
              {{"name": "ball", "position": [0, {}, -1],
                "body": {{"dynamic": true, "collider": {{"ball": {{"radius_m": 0.02}}}},
                         "density_kg_per_m3": 7800, "restitution": 0.5}}}}],
            "physics": {{"duration_s": {seconds}, "step_s": 0.004}},
            "listener": {{"position": [0, 0.5, 0]}}}}"#,
        height_m + 0.02
    );
    let source = source_of(&text, "drop");
    (source, text)
}

#[test]
fn a_dropped_ball_strikes_when_and_as_hard_as_it_falls() {
    let (low, _) = dropped(1.0, 2.0);
    let first = &low.events()[0];
    let expected_s = (2.0 * 1.0 / 9.81f64).sqrt();
    assert!(
        (first.time_s - expected_s).abs() <= 0.004,
        "first strike at {} s, a fall of 1 m takes {expected_s:.4} s",
        first.time_s
    );
    let speed = first.impact.unwrap().speed_m_per_s;
    assert!(
        (speed / (2.0 * 9.81f64).sqrt() - 1.0).abs() < 0.02,
        "{speed} m/s"
    );
    // The ball bounces, lower each time, and comes to rest: no strike once it lies still.
    let times: Vec<f64> = low.events().iter().map(|e| e.time_s).collect();
    assert!(
        times.len() >= 3 && times.windows(2).all(|w| w[1] > w[0]),
        "{times:?}"
    );
    let (resting, _) = dropped(0.2, 4.0);
    let last = resting.events().last().unwrap().time_s;
    assert!(
        last < 2.0,
        "still striking at {last} s: {:?}",
        resting.events()
    );
    // Four times the height: twice as fast, 6 dB louder (the first strike alone).
    let (high, _) = dropped(4.0, 1.0);
    let ratio = high.events()[0].impact.unwrap().speed_m_per_s / speed;
    assert!((ratio - 2.0).abs() < 0.05, "speed ratio {ratio}");
    let first_strike_level = |s: &SceneSource| {
        let r = render_scene(s, RATE, 60.0, |_| {});
        let t = s.events()[0].time_s;
        let from = (t * RATE as f64) as usize;
        let second = s
            .events()
            .get(1)
            .map_or(r.left.len(), |e| (e.time_s * RATE as f64) as usize);
        rms(&r.left[from..second.min(from + RATE as usize / 4)])
    };
    let louder = db(first_strike_level(&high) / first_strike_level(&low));
    assert!(
        (louder - 6.02).abs() < 1.0,
        "from 4 m: {louder:.2} dB louder"
    );
}

#[test]
fn bodies_placed_wrongly_are_errors() {
    let floor = r#"{"name": "floor", "bank": "spruce-panel", "position": [0, 0, -1],
        "body": {"collider": {"cuboid": {"half_extents_m": [1, 0.05, 1]}}}}"#;
    let cases = [
        (
            format!(r#"{floor}, {{"name": "box", "position": [0, 0.02, -1],
                "body": {{"dynamic": true, "collider": {{"cuboid": {{"half_extents_m": [0.1, 0.1, 0.1]}}}}}}}}"#),
            "objects[1].position: \"box\" overlaps \"floor\" (objects[0]) by",
        ),
        (
            format!(r#"{floor}, {{"name": "box", "position": [0, 0.5, 0],
                "body": {{"collider": {{"ball": {{"radius_m": 0.6}}}}}}}}"#),
            "listener.position: inside \"box\" (objects[1])",
        ),
        (
            format!(r#"{floor}, {{"name": "box", "position": [0, 0.5, -1],
                "body": {{"dynamic": true, "mass_kg": -2, "collider": {{"ball": {{"radius_m": 0.1}}}}}}}}"#),
            "objects[1].body.mass_kg: expected over 0 up to 1e9 kg, found -2",
        ),
        (
            format!(r#"{floor}, {{"name": "box", "position": [0, 0.5, -1],
                "body": {{"collider": {{"ball": {{"radius_m": 0}}}}}}}}"#),
            "objects[1].body.collider.ball.radius_m: expected metres over 0",
        ),
        (
            format!(r#"{floor}, {{"name": "die", "bank": "rosewood-claves", "position": [0, 0.5, -1],
                "body": {{"dynamic": true, "collider": {{"ball": {{"radius_m": 0.1}}}}}}}}"#),
            "objects[1].bank: a dynamic body cannot sound yet",
        ),
        (
            format!(r#"{floor}, {{"name": "bar", "bank": "rosewood-claves", "position": [0, 0.5, -1],
                "set": {{"velocity_sensitivity": "1"}}}}"#),
            "objects[1].set.velocity_sensitivity: set by the scene: an impact's loudness is",
        ),
        (
            format!(r#"{floor}, {{"name": "ghost", "position": [0, 0.5, -1]}}"#),
            "objects[1]: expected a \"bank\" (it sounds), a \"body\" (it moves or is struck) or both",
        ),
    ];
    for (objects, expected) in &cases {
        let text = format!(
            r#"{{"format": "modal-scene", "version": 1, "objects": [{objects}],
                "physics": {{"duration_s": 1}}, "listener": {{"position": [0, 1, 0]}}}}"#
        );
        let got = problems(&text);
        assert!(got.contains(expected), "expected {expected:?} in {got:?}");
    }
    // Too many steps.
    let text = format!(
        r#"{{"format": "modal-scene", "version": 1, "objects": [{floor}],
            "physics": {{"duration_s": 3000, "step_s": 0.0001}}}}"#
    );
    assert!(problems(&text).contains("physics.step_s: 3000 s in steps of 0.0001 s is over"));
}

#[test]
fn a_box_resting_on_the_floor_never_strikes() {
    // A box set down on the floor (touching it) and a ball dropped beside it: the ball strikes,
    // the box, resting, does not chatter.
    let text = r#"{"format": "modal-scene", "version": 1,
        "objects": [
          {"name": "floor", "bank": "spruce-panel", "position": [0, -0.05, -1],
           "body": {"collider": {"cuboid": {"half_extents_m": [1, 0.05, 1]}}}},
          {"name": "box", "position": [0.3, 0.1, -1],
           "body": {"dynamic": true, "collider": {"cuboid": {"half_extents_m": [0.1, 0.1, 0.1]}}}},
          {"name": "ball", "position": [-0.3, 0.5, -1],
           "body": {"dynamic": true, "collider": {"ball": {"radius_m": 0.02}}, "restitution": 0.2}}],
        "physics": {"duration_s": 3},
        "listener": {"position": [0, 1, 0]}}"#;
    let source = source_of(text, "rest");
    let times: Vec<f64> = source.events().iter().map(|e| e.time_s).collect();
    // The ball's bounces, from 0.5 m, all within the first second; nothing after.
    assert!(!times.is_empty() && times[0] > 0.25, "{times:?}");
    assert!(
        times.iter().all(|&t| t < 1.2),
        "strikes after the ball has settled: {times:?}"
    );
}

#[test]
fn a_simulated_scene_renders_the_same_twice() {
    let (a, _) = dropped(0.5, 2.0);
    let (b, _) = dropped(0.5, 2.0);
    assert_eq!(a.events(), b.events());
    let (ra, rb) = (
        render_scene(&a, RATE, 60.0, |_| {}),
        render_scene(&b, RATE, 60.0, |_| {}),
    );
    assert_eq!(ra, rb);
}

#[test]
fn hail_falls_at_its_rate_on_what_lies_under_it() {
    use modal_resonator::scene::format::DropKind;
    use modal_resonator::scene::physics::terminal_speed_m_per_s;
    // The drag equation for hail, Atlas et al. for rain.
    let hail = terminal_speed_m_per_s(DropKind::Hail, 0.01);
    let rain = terminal_speed_m_per_s(DropKind::Rain, 0.002);
    assert!(
        (hail - 12.8).abs() < 0.1 && (rain - 6.55).abs() < 0.05,
        "{hail} {rain}"
    );
    // A 1 m square plate under a 2 m by 2 m rectangle: a quarter of the drops strike it.
    let scene = |seed: u32| {
        format!(
            r#"{{"format": "modal-scene", "version": 1,
                "objects": [{{"name": "plate", "bank": "steel-plate", "position": [0, 0, -2],
                  "body": {{"collider": {{"cuboid": {{"half_extents_m": [0.5, 0.005, 0.5]}}}}}}}}],
                "emitters": [{{"kind": "hail", "centre": [0, 5, -2], "half_extents_m": [1, 1],
                  "rate_per_s": 400, "start_s": 1, "duration_s": 2, "seed": {seed}}}],
                "listener": {{"position": [0, 1, 0]}}}}"#
        )
    };
    let source = |seed| source_of(&scene(seed), "hail");
    let a = source(1);
    let n = a.events().len() as f64;
    // 800 drops, a quarter on the plate: 200, sd about 13.
    assert!((n - 200.0).abs() < 50.0, "{n} strikes");
    let (fastest, slowest) = (
        terminal_speed_m_per_s(DropKind::Hail, 0.020),
        terminal_speed_m_per_s(DropKind::Hail, 0.005),
    );
    for e in a.events() {
        let impact = e.impact.unwrap();
        let s = impact.speed_m_per_s;
        assert!(s >= slowest * 0.999 && s <= fastest * 1.001, "{s} m/s");
        // From 4.995 m up, at that speed; let go between 1 and 3 s.
        let fall_s = 4.995 / s;
        assert!(e.time_s >= 1.0 + fall_s - 1e-3 && e.time_s <= 3.0 + fall_s + 1e-3);
        // The largest stones play loudest: the gain is the mass, the cube of the diameter.
        assert!(
            impact.gain_db <= 0.0 && impact.gain_db >= -36.2,
            "{}",
            impact.gain_db
        );
    }
    assert_eq!(
        a.events(),
        source(1).events(),
        "the same seed, the same hail"
    );
    assert_ne!(a.events(), source(2).events());
    // Diameters given largest first are an error.
    let bad = scene(1).replace(r#""seed": 1"#, r#""seed": 1, "diameter_mm": [20, 5]"#);
    let got = problems(&bad);
    assert!(
        got.contains("emitters[0].diameter_mm: expected the smallest then the largest, 1 to 150 mm, found [20, 5]"),
        "{got}"
    );
}

#[test]
fn a_render_is_cut_with_a_fade_or_ends_a_tail_after_its_last_sound() {
    let objects = format!(r#"{{"name": "o", "bank": "{BAR}", "position": [0, 0, -1]}}"#);
    let events = r#"{"time_s": 0.1, "object": "o", "impact": {"speed_m_per_s": 1}}"#;
    let source = source_of(&scene_json(&objects, events, "stereo"), "t");
    // Cut at 0.5 s while the bar rings: exactly that long, faded to nothing over 10 ms.
    let cut = render_scene(&source, RATE, 0.5, |_| {});
    assert!(cut.cut_short && cut.left.len() == RATE as usize / 2);
    let n = cut.left.len();
    assert!(cut.left[n - 1].abs() < 1e-6 && rms(&cut.left[n - 960..n - 480]) > 1e-4);
    // Whole: it ends 0.1 s after its last sound, and streams to a sink what it makes in memory.
    let whole = render_scene(&source, RATE, 60.0, |_| {});
    let last = whole.left.iter().rposition(|&v| v != 0.0).unwrap();
    assert_eq!(whole.left.len(), last + 1 + (0.1 * RATE as f64) as usize);
    let mut streamed = Vec::new();
    let summary = modal_resonator::scene::render_scene_to(
        &source,
        RATE,
        60.0,
        |_| {},
        |l, _| {
            streamed.extend_from_slice(l);
            Ok::<(), ()>(())
        },
    )
    .unwrap();
    assert_eq!(streamed, whole.left);
    assert_eq!(summary.len, whole.left.len());
}
