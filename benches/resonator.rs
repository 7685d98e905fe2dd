//! Resonator throughput and engine real-time factor.
//!
//! Run with `cargo bench`. Every case renders a fixed amount of audio and prints a figure:
//! mode-samples per second for each kernel at several bank sizes (all kernels in the same run, so
//! ratios are side by side), then the real-time factor of 16 voices x 256 modes at 48 kHz in
//! 64-sample blocks through the whole engine, and of one voice held in contact (scrape, roll)
//! against one struck, on the same bank.

#[path = "../tests/common/mod.rs"]
mod common;

use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

use modal_resonator::dsp::coeffs::ModeCoeffs;
use modal_resonator::dsp::denormal::FlushDenormals;
use modal_resonator::dsp::{ExciterKind, Kernel, ResonatorBank, COLUMNS};
use modal_resonator::engine::{Engine, NoteEvent, PreparedBank};

const RATE_HZ: f64 = 48_000.0;
const BLOCK: usize = 64;
/// Mode-samples rendered per case by the vector kernels (the scalar oracle renders 1/8 of it).
const WORK: usize = 1 << 30;
/// Each case is timed this many times; the fastest counts (the machine is shared).
const REPEATS: usize = 3;

fn bank_of(num_modes: usize) -> ResonatorBank {
    let mut bank = ResonatorBank::new(num_modes);
    for m in 0..num_modes {
        let f = 50.0 + (m as f64 * 7.31) % 20_000.0;
        // T60 of about a minute: every mode stays live for the whole case.
        bank.activate(m, ModeCoeffs::from_freq_decay(RATE_HZ, f, 0.1), 0.0);
    }
    // Ring the modes up so the state is non-trivial.
    let mut acc = vec![[0.0f32; COLUMNS]; BLOCK];
    let mut x = vec![0.0f32; BLOCK];
    x[0] = 1.0;
    bank.set_gains_with(|m| 1.0 / (1.0 + m as f32));
    bank.process(Kernel::Scalar, Some(&x), &mut acc);
    bank
}

/// Mode-samples per second of `kernel` on `num_modes` modes; with `driven`, every sample has
/// input (as for audio driving the bank), else none (ringing between strikes).
fn mode_samples_per_s(kernel: Kernel, num_modes: usize, work: usize, driven: bool) -> f64 {
    // Small banks run for many minutes of audio and decay into subnormal numbers; the engine
    // flushes those to zero, and so does this.
    let _flush = FlushDenormals::new();
    let blocks = (work / (num_modes * BLOCK)).max(1);
    let input: Vec<f32> = (0..BLOCK).map(|n| ((n * 7) % 13) as f32 * 1e-3).collect();
    let mut best = f64::INFINITY;
    for _ in 0..REPEATS {
        let mut bank = bank_of(num_modes);
        let mut acc = vec![[0.0f32; COLUMNS]; BLOCK];
        let start = Instant::now();
        for _ in 0..blocks {
            acc.fill([0.0; COLUMNS]);
            bank.process(kernel, driven.then_some(&input[..]), &mut acc);
            black_box(&mut acc);
        }
        best = best.min(start.elapsed().as_secs_f64());
    }
    (blocks * BLOCK * num_modes) as f64 / best
}

/// Real-time factor of the engine; with `sweep`, the pitch bend moves every block so every voice
/// recomputes its coefficients on every control tick.
fn engine_realtime_factor(kernel: Kernel, sweep: bool, seconds: f64) -> (f64, usize) {
    let bank = common::bench_bank();
    let prepared = Arc::new(PreparedBank::new(&bank));
    let mut best = f64::INFINITY;
    let mut live = 0;
    for _ in 0..REPEATS {
        let mut engine = Engine::new(prepared.clone());
        engine.prepare(RATE_HZ as f32, BLOCK);
        engine.set_kernel(kernel);
        let mut controls = engine.controls().clone();
        controls.truncation_db = -140.0;
        engine.set_controls(&controls);
        // Keys 24..40 keep every mode below 0.45 fs.
        let notes: Vec<NoteEvent> = (0..16).map(|i| NoteEvent::on(0, 24 + i, 1.0)).collect();
        let (mut l, mut r) = (vec![0.0f32; BLOCK], vec![0.0f32; BLOCK]);
        engine.process(&notes, None, &mut l, &mut r);
        let blocks = (seconds * RATE_HZ) as usize / BLOCK;
        let start = Instant::now();
        for b in 0..blocks {
            if sweep {
                controls.pitch_bend_semitones = (b as f32 * 0.01).sin();
                engine.set_controls(&controls);
            }
            engine.process(&[], None, &mut l, &mut r);
            black_box((&mut l, &mut r));
        }
        best = best.min(start.elapsed().as_secs_f64());
        live = engine.stats().live_modes;
    }
    (seconds / best, live)
}

/// Real-time factor of one voice of the bench bank played by `kind` (a strike rings; a contact is
/// held throughout), with nothing truncated.
fn voice_realtime_factor(kind: ExciterKind, seconds: f64) -> f64 {
    let prepared = Arc::new(PreparedBank::new(&common::bench_bank()));
    let mut best = f64::INFINITY;
    for _ in 0..REPEATS {
        let mut engine = Engine::new(prepared.clone());
        engine.prepare(RATE_HZ as f32, BLOCK);
        let mut controls = engine.controls().clone();
        controls.truncation_db = -140.0;
        controls.exciter = kind;
        engine.set_controls(&controls);
        let (mut l, mut r) = (vec![0.0f32; BLOCK], vec![0.0f32; BLOCK]);
        engine.process(&[NoteEvent::on(0, 36, 1.0)], None, &mut l, &mut r);
        let blocks = (seconds * RATE_HZ) as usize / BLOCK;
        let start = Instant::now();
        for _ in 0..blocks {
            engine.process(&[], None, &mut l, &mut r);
            black_box((&mut l, &mut r));
        }
        best = best.min(start.elapsed().as_secs_f64());
    }
    seconds / best
}

fn main() {
    // `cargo test --benches` runs this with --bench absent; keep that quick.
    let quick = !std::env::args().any(|a| a == "--bench");
    let work = if quick { WORK >> 8 } else { WORK };
    // Seconds of audio per engine case.
    let engine_seconds = if quick { 0.2 } else { 10.0 };
    let kernels: Vec<Kernel> = Kernel::ALL
        .into_iter()
        .filter(|k| k.is_supported())
        .collect();
    print_kernels(&kernels, work);
    println!();
    print_driven(&kernels, work);
    println!();
    print_engine(&kernels, engine_seconds);
    println!();
    print_contacts(engine_seconds);
}

/// Mode-samples per second of each kernel at bank sizes from 16 to 16,384 modes, and the
/// speed-ups over the scalar kernel.
fn print_kernels(kernels: &[Kernel], work: usize) {
    println!(
        "Resonator kernels, mode-samples per second (one core, {BLOCK}-sample blocks, no input):"
    );
    print!("{:>8}", "modes");
    for k in kernels {
        print!("{:>14}", k.name());
    }
    println!("{:>12}{:>12}", "avx2/scalar", "best/scalar");
    for &n in &[16usize, 32, 48, 64, 256, 1024, 4096, 16384] {
        print!("{n:>8}");
        let mut figures = Vec::new();
        for &k in kernels {
            let w = if k == Kernel::Scalar { work / 8 } else { work };
            let v = mode_samples_per_s(k, n, w, false);
            figures.push((k, v));
            print!("{:>14.3e}", v);
        }
        let of = |k| figures.iter().find(|(kk, _)| *kk == k).map(|f| f.1);
        let scalar = of(Kernel::Scalar).unwrap();
        let best = figures.iter().map(|f| f.1).fold(0.0, f64::max);
        match of(Kernel::Avx2) {
            Some(a) => print!("{:>12.1}", a / scalar),
            None => print!("{:>12}", "-"),
        }
        println!("{:>12.1}", best / scalar);
    }
}

/// Each kernel driven by input on every sample against left to ring.
fn print_driven(kernels: &[Kernel], work: usize) {
    println!("Driven by input on every sample, 4096 modes (one operation more per mode group):");
    for &k in kernels {
        let w = if k == Kernel::Scalar { work / 8 } else { work };
        let (quiet, driven) = (
            mode_samples_per_s(k, 4096, w, false),
            mode_samples_per_s(k, 4096, w, true),
        );
        println!(
            "  {:<10} {:>12.3e} driven, {:>12.3e} without input ({:.2}x)",
            k.name(),
            driven,
            quiet,
            quiet / driven
        );
    }
}

/// The whole engine's real-time factor with each kernel, still and under a moving pitch bend.
fn print_engine(kernels: &[Kernel], engine_seconds: f64) {
    println!("Engine, 16 voices x 256 modes, 48 kHz, {BLOCK}-sample blocks:");
    for &k in kernels {
        let (rt, live) = engine_realtime_factor(k, false, engine_seconds);
        let (rt_sweep, _) = engine_realtime_factor(k, true, engine_seconds);
        println!(
            "  {:<10} real-time factor {:>8.1}x, with pitch bend moving every block {:>8.1}x  ({live} live modes)",
            k.name(),
            rt,
            rt_sweep
        );
    }
}

/// One voice held in each contact against one struck.
fn print_contacts(engine_seconds: f64) {
    println!(
        "One voice of the same bank ({} modes), struck and ringing against held in contact:",
        common::bench_bank().modes.len()
    );
    let struck = voice_realtime_factor(ExciterKind::Mallet, engine_seconds);
    // A rub computes its voice a sample at a time (the friction answers the modes' velocity).
    for kind in [ExciterKind::Scrape, ExciterKind::Roll, ExciterKind::Rub] {
        let held = voice_realtime_factor(kind, engine_seconds);
        println!(
            "  {:<8} real-time factor {:>8.1}x, struck {:>8.1}x: a contact voice costs {:.2}x a struck one",
            kind.name(),
            held,
            struck,
            struck / held
        );
    }
}
