//! Perceptual pruning on a busy scene: hail on a picnic (seed 001 section 6).
//!
//! Nine objects (four roof panes, three plates, a table and a can; two banks of over a thousand
//! modes, 3,300 modes in all) built from the analytic plate, struck by a random rain of impacts
//! whose energies follow a 1/E law, for ten seconds. Each object is one voice of one engine: the
//! scene is a bank whose strike positions are the objects (an object's modes have gain only in
//! its own column), played with key tracking off, one key per object.
//!
//! Printed in one run: mode-samples computed and wall time with pruning off and at a_v = 2.5, 5
//! and 10 dB; the share of live modes pruned; the pruning overhead (analyses and wakes, timed)
//! against the rest of the synthesis; and the level of the difference between each pruned render
//! and the unpruned one relative to the unpruned signal, per critical band.
//!
//! Run with `cargo bench --bench pruning`. Settings for experiments, from the environment:
//! `PRUNING_REPEATS` (timed renders per case, default 5, the cases taking turns; the fastest of
//! each counts), `PRUNING_OFFSETS=2.5,5,20` (other masking offsets; the targets are read at
//! 5 dB), `PRUNING_FRAME_MS` (another analysis frame) and `PRUNING_ONLY=5` (pruned renders only,
//! `PRUNING_REPEATS` of them, with every counter of the last, for profilers).

use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

use modal_resonator::dsp::ExciterKind;
use modal_resonator::engine::{Controls, Engine, NoteEvent, PreparedBank};
use modal_resonator::model::{Bank, Position};

#[path = "pruning/bands.rs"]
mod bands;
#[path = "pruning/scene.rs"]
mod scene;

use bands::{band_power, bark_to_hz, db};
use scene::{hail, object_modes, objects, scene_bank, Impact, ENERGY_RANGE, FIRST_KEY};

/// Sample rate of the renders.
pub const RATE_HZ: f64 = 48_000.0;
/// Longest block handed to the engine (blocks are also cut at every impact).
const BLOCK: usize = 256;
/// Timed renders per case; the fastest counts (the machine is shared).
const REPEATS: usize = 5;

/// Timed renders per case: `PRUNING_REPEATS`, else [`REPEATS`].
fn repeats() -> usize {
    std::env::var("PRUNING_REPEATS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(REPEATS)
}

/// What one render measured.
struct Run {
    /// Left output.
    left: Vec<f32>,
    /// Right output.
    right: Vec<f32>,
    /// Wall time of the render, seconds.
    wall_s: f64,
    /// Mode-samples the kernels computed (row padding included).
    mode_samples: u64,
    /// Time-average of dormant over live modes.
    pruned_share: f64,
    /// Pruning analyses run.
    analyses: u64,
    /// Modes those analyses and the strikes' decisions looked at.
    candidates: u64,
    /// Time in the analyses, seconds.
    analysis_s: f64,
    /// Time deciding strikes on dormant modes, seconds.
    wake_s: f64,
    /// Modes woken by strikes and input.
    woken: u64,
    /// Every pruning counter.
    stats: modal_resonator::engine::PruningStats,
}

/// The scene's controls: mallet strikes, no key tracking, a voice per object; pruning at
/// `masking_offset_db` when given.
fn controls(bank: &Bank, objects: usize, masking_offset_db: Option<f32>) -> Controls {
    let mut c = Controls::for_bank(bank);
    c.key_tracking = 0.0;
    c.velocity_sensitivity = 0.5;
    c.velocity_to_hardness = 0.0;
    c.exciter = ExciterKind::Mallet;
    c.hardness_ms = 0.3;
    c.polyphony = objects;
    if let Some(av) = masking_offset_db {
        c.pruning = true;
        c.masking_offset_db = av;
    }
    // `PRUNING_FRAME_MS=40` tries another analysis frame.
    if let Some(ms) = std::env::var("PRUNING_FRAME_MS")
        .ok()
        .and_then(|v| v.parse().ok())
    {
        c.analysis_frame_ms = ms;
    }
    c
}

/// Renders the scene; with `measure`, also gathers the share of modes pruned (outside timing
/// runs, since reading the meters costs time).
fn render(
    prepared: &Arc<PreparedBank>,
    impacts: &[Impact],
    seconds: f64,
    base: &Controls,
    measure: bool,
) -> Run {
    let num_objects = prepared.num_positions;
    let total = (seconds * RATE_HZ) as usize;
    let mut engine = Engine::new(prepared.clone());
    engine.prepare(RATE_HZ as f32, BLOCK);
    engine.set_profiling(true);
    let mut c = base.clone();
    engine.set_controls(&c);
    let (mut left, mut right) = (vec![0.0f32; total], vec![0.0f32; total]);
    // Touch the output before timing, as a host's buffers are: the first write to each fresh page
    // of a large allocation costs a page fault, which is not the engine's work.
    black_box(&mut left).fill(0.0);
    black_box(&mut right).fill(0.0);
    let (mut dormant, mut live) = (0.0f64, 0.0f64);
    let mut next = 0;
    let mut pos = 0;
    let start = Instant::now();
    while pos < total {
        let mut end = (pos + BLOCK).min(total);
        let mut events = [NoteEvent::AllNotesOff { time: 0 }; 1];
        let mut num_events = 0;
        if next < impacts.len() && impacts[next].0 == pos {
            let (_, object, velocity) = impacts[next];
            c.strike_x = object as f32 / (num_objects - 1) as f32;
            engine.set_controls(&c);
            events[0] = NoteEvent::on(0, FIRST_KEY + object as u8, velocity);
            num_events = 1;
            next += 1;
        }
        if next < impacts.len() {
            end = end.min(impacts[next].0.max(pos + 1));
        }
        engine.process(
            &events[..num_events],
            None,
            &mut left[pos..end],
            &mut right[pos..end],
        );
        if measure {
            let s = engine.stats();
            dormant += (s.dormant_modes * (end - pos)) as f64;
            live += (s.live_modes * (end - pos)) as f64;
        }
        pos = end;
    }
    let wall_s = start.elapsed().as_secs_f64();
    black_box((&left, &right));
    let s = engine.stats();
    let p = engine.pruning_stats();
    Run {
        left,
        right,
        wall_s,
        mode_samples: s.computed_mode_samples,
        pruned_share: if live > 0.0 { dormant / live } else { 0.0 },
        analyses: p.analyses,
        candidates: p.candidates,
        analysis_s: p.analysis_ns as f64 * 1e-9,
        wake_s: p.strike_ns as f64 * 1e-9,
        woken: p.woken,
        stats: p,
    }
}

/// For each case's controls, the meters of an untimed render and the fastest of `repeats()` timed
/// ones. The cases take turns, so that a busy spell on a shared machine slows them alike.
fn measure(
    prepared: &Arc<PreparedBank>,
    impacts: &[Impact],
    seconds: f64,
    cases: &[Controls],
) -> Vec<Run> {
    let mut runs: Vec<Run> = cases
        .iter()
        .map(|c| render(prepared, impacts, seconds, c, true))
        .collect();
    // Wall, analysis and wake seconds of each case's fastest render.
    let mut best: Vec<Option<(f64, f64, f64)>> = vec![None; cases.len()];
    for _ in 0..repeats() {
        for (k, c) in cases.iter().enumerate() {
            let r = render(prepared, impacts, seconds, c, false);
            assert!(r.left == runs[k].left, "renders of the same scene differ");
            if best[k].is_none_or(|(wall_s, _, _)| r.wall_s < wall_s) {
                best[k] = Some((r.wall_s, r.analysis_s, r.wake_s));
            }
        }
    }
    for (run, best) in runs.iter_mut().zip(best) {
        (run.wall_s, run.analysis_s, run.wake_s) = best.expect("at least one repeat");
    }
    runs
}

fn main() {
    // `cargo test --benches` runs this without --bench: keep that quick.
    let quick = !std::env::args().any(|a| a == "--bench");
    let seconds = if quick { 1.0 } else { 10.0 };
    let objects = objects();
    let bank = scene_bank(&objects);
    let prepared = Arc::new(PreparedBank::new(&bank));
    let impacts = hail(&objects, seconds, 0x4A11);
    let kernel = Engine::new(prepared.clone()).kernel();
    println!(
        "Hail on a picnic (seed 001 section 6): {} objects, {} modes, {} impacts (energies 1/E \
         over {:.0} dB) in {seconds} s at {} kHz; kernel {}, blocks of up to {BLOCK} samples",
        objects.len(),
        prepared.num_modes(),
        impacts.len(),
        db(ENERGY_RANGE),
        RATE_HZ / 1000.0,
        kernel.name()
    );
    for o in &objects {
        let strike = [Position {
            name: "p".into(),
            coords: vec![0.38, 0.42],
        }];
        let modes = object_modes(o, &strike);
        let (lo, hi) = (modes[0].freq_hz, modes[modes.len() - 1].freq_hz);
        let hits = impacts
            .iter()
            .filter(|i| objects[i.1].name == o.name)
            .count();
        println!(
            "  {:<12} {:>5} modes, {:>6.0} to {:>6.0} Hz, {:<9} {:>3} impacts",
            o.name, o.modes, lo, hi, o.material.display_name, hits
        );
    }
    let c = controls(&bank, objects.len(), None);
    println!(
        "Pruning: playback level {} dB SPL at full scale, analysis frame {} ms",
        c.playback_level_db_spl, c.analysis_frame_ms
    );
    println!();

    // `PRUNING_ONLY=5` renders the pruned case only, for profilers.
    if let Some(av) = std::env::var("PRUNING_ONLY")
        .ok()
        .and_then(|v| v.parse::<f32>().ok())
    {
        let c = controls(&bank, objects.len(), Some(av));
        let mut run = render(&prepared, &impacts, seconds, &c, false);
        for _ in 1..repeats() {
            run = render(&prepared, &impacts, seconds, &c, false);
        }
        println!(
            "a_v {av} dB: {:.1} ms, analyses {:.1} ms, strikes {:.1} ms, {:.1e} mode-samples, {:?}",
            run.wall_s * 1e3,
            run.analysis_s * 1e3,
            run.wake_s * 1e3,
            run.mode_samples as f64,
            run.stats,
        );
        return;
    }
    // `PRUNING_OFFSETS=2.5,5,20` measures other offsets (the targets are read at 5 dB).
    let offsets: Vec<f32> = std::env::var("PRUNING_OFFSETS")
        .ok()
        .map(|v| v.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![2.5, 5.0, 10.0]);
    let mut cases: Vec<(String, Option<f32>)> = vec![("off".into(), None)];
    cases.extend(offsets.iter().map(|&av| (format!("a_v {av} dB"), Some(av))));
    let case_controls: Vec<Controls> = cases
        .iter()
        .map(|&(_, av)| controls(&bank, objects.len(), av))
        .collect();
    let runs = measure(&prepared, &impacts, seconds, &case_controls);
    let off = &runs[0];
    println!(
        "{:<11} {:>13} {:>7} {:>9} {:>7} {:>7} {:>9} {:>10} {:>10} {:>9} {:>10}",
        "case",
        "mode-samples",
        "fewer",
        "wall ms",
        "faster",
        "pruned",
        "analyses",
        "cand/anal",
        "analysis",
        "wakes",
        "overhead"
    );
    for ((name, _), r) in cases.iter().zip(&runs) {
        let overhead_s = r.analysis_s + r.wake_s;
        let synthesis_s = r.wall_s - overhead_s;
        println!(
            "{:<11} {:>13.4e} {:>6.1}x {:>9.1} {:>6.1}x {:>6.1}% {:>9} {:>10.0} {:>8.2}ms {:>7.2}ms {:>9.1}%",
            name,
            r.mode_samples as f64,
            off.mode_samples as f64 / r.mode_samples as f64,
            r.wall_s * 1e3,
            off.wall_s / r.wall_s,
            100.0 * r.pruned_share,
            r.analyses,
            r.candidates as f64 / r.analyses.max(1) as f64,
            r.analysis_s * 1e3,
            r.wake_s * 1e3,
            100.0 * overhead_s / synthesis_s,
        );
    }
    println!(
        "(overhead: analyses and wakes, timed inside the engine, over the rest of the wall time; \
         {} modes woken by strikes in the last case)",
        runs.last().map_or(0, |r| r.woken)
    );
    println!();

    // The difference signal, per critical band.
    let reference: [f64; 25] = {
        let (l, r) = (band_power(&off.left), band_power(&off.right));
        std::array::from_fn(|b| l[b] + r[b])
    };
    let diffs: Vec<[f64; 25]> = runs[1..]
        .iter()
        .map(|run| {
            let dl: Vec<f32> = run.left.iter().zip(&off.left).map(|(a, b)| a - b).collect();
            let dr: Vec<f32> = run
                .right
                .iter()
                .zip(&off.right)
                .map(|(a, b)| a - b)
                .collect();
            let (l, r) = (band_power(&dl), band_power(&dr));
            std::array::from_fn(|b| l[b] + r[b])
        })
        .collect();
    let top = reference.iter().copied().fold(0.0, f64::max);
    println!("Difference (pruned - unpruned) relative to the unpruned signal, per critical band:");
    print!("{:>5} {:>13} {:>12}", "Bark", "Hz", "signal dB");
    for (name, _) in &cases[1..] {
        print!(" {:>11}", name);
    }
    println!();
    for b in 0..25 {
        if reference[b] <= 0.0 {
            continue;
        }
        print!(
            "{:>2}-{:<2} {:>6.0}-{:<6.0} {:>12.1}",
            b,
            b + 1,
            bark_to_hz(b as f64),
            bark_to_hz(b as f64 + 1.0),
            db(reference[b] / top)
        );
        for d in &diffs {
            print!(" {:>11.1}", db(d[b] / reference[b]));
        }
        println!();
    }
    let total_ref: f64 = reference.iter().sum();
    print!("{:<5} {:>13} {:>12}", "all", "", "");
    for d in &diffs {
        print!(" {:>11.1}", db(d.iter().sum::<f64>() / total_ref));
    }
    println!();
    println!("(signal dB: each band's power relative to the strongest band)");
    println!();

    let Some(five) = offsets
        .iter()
        .position(|&av| av == 5.0)
        .map(|i| &runs[i + 1])
    else {
        return;
    };
    let overhead = (five.analysis_s + five.wake_s) / (five.wall_s - five.analysis_s - five.wake_s);
    let verdict = |ok: bool| if ok { "met" } else { "NOT met" };
    let fewer = off.mode_samples as f64 / five.mode_samples as f64;
    let faster = off.wall_s / five.wall_s;
    println!("Targets at a_v = 5 dB:");
    println!(
        "  mode-samples  {fewer:>5.1}x fewer (target 5x): {}",
        verdict(fewer >= 5.0)
    );
    println!(
        "  wall time     {faster:>5.1}x less  (target 4x): {}",
        verdict(faster >= 4.0)
    );
    println!(
        "  overhead      {:>5.1}% of the remaining synthesis (target under 10%): {}",
        100.0 * overhead,
        verdict(overhead < 0.1)
    );
}
