//! The plugin's real-time factor through the CLAP path (the host-test harness loading the built
//! bundle), next to the engine's own figure, in one run: 16 voices of a 256-mode bank at 48 kHz
//! in 64-sample blocks.
//!
//! Needs the bundle: `cargo xtask bundle modal-resonator --release`.

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

use common::bench_bank;
use common::clap::{run, with_bank, Script, Send, INSTRUMENT};
use modal_resonator::bank::Bank;
use modal_resonator::engine::{Engine, NoteEvent, PreparedBank};
use modal_resonator::params::ModalParams;

const RATE_HZ: f32 = 48_000.0;
const BLOCK: usize = 64;
/// Keys 24 to 39: 16 voices, every mode below 0.45 fs.
const KEYS: std::ops::Range<u8> = 24..40;

/// Real-time factor of the engine alone, with the plugin's default controls.
fn engine_realtime_factor(bank: &Bank, seconds: f64) -> f64 {
    let mut engine = Engine::new(Arc::new(PreparedBank::new(bank)));
    engine.prepare(RATE_HZ, BLOCK);
    let mut controls = ModalParams::new(false).controls();
    controls.truncation_db = -140.0;
    engine.set_controls(&controls);
    let notes: Vec<NoteEvent> = KEYS.map(|key| NoteEvent::on(0, key, 1.0)).collect();
    let (mut l, mut r) = (vec![0.0f32; BLOCK], vec![0.0f32; BLOCK]);
    engine.process(&notes, None, &mut l, &mut r);
    let blocks = (seconds * RATE_HZ as f64) as usize / BLOCK;
    let start = Instant::now();
    for _ in 0..blocks {
        engine.process(&[], None, &mut l, &mut r);
        black_box((&mut l, &mut r));
    }
    (blocks * BLOCK) as f64 / RATE_HZ as f64 / start.elapsed().as_secs_f64()
}

/// Real-time factor of the plugin in a CLAP host: time spent in its process calls.
fn plugin_realtime_factor(bank: &Bank, seconds: f64) -> f64 {
    let first = run(&Script::new(INSTRUMENT, BLOCK));
    let state = with_bank(&first.state, bank);
    // Truncation at -140 dB (normalised 0) keeps every mode live, as for the engine.
    let mut events = vec![(0, Send::Param("trunc", 0.0))];
    events.extend(KEYS.map(|key| (0, Send::On(key as u16, 1.0))));
    let samples = (seconds * RATE_HZ as f64) as usize;
    let s = run(&Script {
        state: Some(&state),
        events: &events,
        blocks: &[BLOCK],
        ..Script::new(INSTRUMENT, samples)
    });
    samples as f64 / RATE_HZ as f64 / s.process_time.as_secs_f64()
}

fn main() {
    // `cargo test --benches` runs this without --bench: keep that quick.
    let quick = !std::env::args().any(|a| a == "--bench");
    let seconds = if quick { 0.2 } else { 10.0 };
    let bank = bench_bank();
    let repeats = if quick { 1 } else { 3 };
    let best = |f: &dyn Fn() -> f64| (0..repeats).map(|_| f()).fold(0.0, f64::max);
    let plugin = best(&|| plugin_realtime_factor(&bank, seconds));
    let engine = best(&|| engine_realtime_factor(&bank, seconds));
    println!("16 voices x 256 modes, 48 kHz, {BLOCK}-sample blocks, {seconds} s of audio, best of {repeats}:");
    println!("  plugin through CLAP (clack-host) real-time factor {plugin:>8.1}x");
    println!("  engine alone                     real-time factor {engine:>8.1}x");
    println!(
        "  plugin / engine                  {:>8.2}",
        plugin / engine
    );
}
