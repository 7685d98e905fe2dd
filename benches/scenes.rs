//! Scenes: each factory scene in `presets/scenes/` with its physics and its audio timed apart,
//! and a large scene made here (1,000 objects of 214 to 300 modes each, over 200,000 modes in
//! all, each struck twice in 10 s), on one core.
//!
//! Run with `cargo bench --bench scenes` (the quickest of 3 runs of each). Without `--bench` (as
//! `cargo test --all-targets` runs it) it renders the first factory scene once.

use std::path::Path;
use std::time::Instant;

use modal_resonator::bank::factory::factory_bank;
use modal_resonator::scene::{render_scene, SceneSource};

const RATE: u32 = 48_000;

/// One row: the scene's name, its objects and impacts, then physics and audio apart.
fn row(name: &str, make: impl Fn() -> SceneSource, repeats: usize) {
    let mut best_physics = f64::INFINITY;
    let mut best_audio = f64::INFINITY;
    let mut row = None;
    for _ in 0..repeats {
        let source = make();
        let (steps, physics_s) = source.physics_cost();
        best_physics = best_physics.min(physics_s);
        let start = Instant::now();
        let r = render_scene(&source, RATE, 120.0, |_| {});
        best_audio = best_audio.min(start.elapsed().as_secs_f64());
        let simulated_s = source.file().physics.map_or(0.0, |p| p.duration_s);
        let used = !source.file().emitters.is_empty();
        let audio_s = r.left.len() as f64 / RATE as f64;
        row = Some((r.stats, steps, simulated_s, audio_s, used));
    }
    let (stats, steps, simulated_s, audio_s, physics_used) = row.expect("at least one run");
    let physics = if steps > 0 {
        format!(
            "{steps} steps ({simulated_s:.1} s) in {:.1} ms: {:.0}x real time",
            1e3 * best_physics,
            simulated_s / best_physics
        )
    } else if physics_used {
        format!("drops cast in {:.1} ms", 1e3 * best_physics)
    } else {
        "none".to_string()
    };
    println!(
        "{name:<28} {:>5} objects {:>6} impacts | physics: {physics} | audio: {audio_s:.1} s in \
         {:.3} s: {:.1}x real time",
        stats.objects,
        stats.impacts,
        best_audio,
        audio_s / best_audio
    );
}

/// A scene of `n` objects on a grid around the listener, every one struck twice.
fn large(n: usize) -> String {
    let banks = [
        "steel-plate",
        "spruce-panel",
        "acrylic-plate",
        "brass-disc-cymbal-like",
    ];
    let side = (n as f64).sqrt().ceil() as usize;
    let mut objects = Vec::new();
    let mut events = Vec::new();
    for i in 0..n {
        let (x, z) = (
            (i % side) as f64 - side as f64 / 2.0,
            (i / side) as f64 - side as f64 / 2.0,
        );
        objects.push(format!(
            r#"{{"name": "o{i}", "bank": "{}", "position": [{x}, 0, {z}], "scale": {}}}"#,
            banks[i % banks.len()],
            1.0 + 0.5 * ((i * 7919) % 100) as f64 / 100.0
        ));
        for k in 0..2 {
            let t = ((i * 2 + k) * 104_729 % 10_000) as f64 / 1000.0;
            events.push(format!(
                r#"{{"time_s": {t}, "object": "o{i}", "impact": {{"speed_m_per_s": {}}}}}"#,
                0.5 + ((i + k) % 10) as f64 / 5.0
            ));
        }
    }
    format!(
        r#"{{"format": "modal-scene", "version": 1, "objects": [{}], "events": [{}],
            "listener": {{"position": [0.5, 1.7, 0.5], "output": "binaural"}}}}"#,
        objects.join(","),
        events.join(",")
    )
}

fn main() {
    let full = std::env::args().any(|a| a == "--bench");
    let repeats = if full { 3 } else { 1 };
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/scenes");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .expect("presets/scenes")
        .map(|e| e.expect("a directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    files.sort();
    if !full {
        files.truncate(1);
    }
    for path in &files {
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        row(&name, || SceneSource::from_file(path).unwrap(), repeats);
    }
    if full {
        let text = large(1000);
        let make = || SceneSource::from_str(&text, "large", &dir).unwrap();
        let modes: usize = (0..1000)
            .map(|i| {
                let bank = [
                    "steel-plate",
                    "spruce-panel",
                    "acrylic-plate",
                    "brass-disc-cymbal-like",
                ][i % 4];
                factory_bank(bank).unwrap().modes.len()
            })
            .sum();
        println!("large scene: {modes} modes in all");
        row("large (1,000 objects)", make, 1);
    }
}
