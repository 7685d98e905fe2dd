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
//! Run with `cargo bench --bench pruning`.

use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

use modal_resonator::dsp::masking::hz_to_bark;
use modal_resonator::dsp::ExciterKind;
use modal_resonator::engine::{Controls, Engine, NoteEvent, PreparedBank};
use modal_resonator::model::materials::{self, Material};
use modal_resonator::model::shapes::{ModeLimits, RectangularPlate, Shape, MAX_AUDIBLE_HZ};
use modal_resonator::model::{Bank, Mode, Position};

const RATE_HZ: f64 = 48_000.0;
/// Longest block handed to the engine (blocks are also cut at every impact).
const BLOCK: usize = 256;
/// Timed renders per case; the fastest counts (the machine is shared).
const REPEATS: usize = 3;

fn repeats() -> usize {
    std::env::var("PRUNING_REPEATS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(REPEATS)
}
/// Mean impacts per second over the whole scene.
const IMPACTS_PER_S: f64 = 30.0;

fn impacts_per_s() -> f64 {
    std::env::var("PRUNING_RATE")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(IMPACTS_PER_S)
}
/// Span of impact energies: the 1/E law runs over this ratio (40 dB).
const ENERGY_RANGE: f64 = 1e4;
/// MIDI key of the first object; object `k` plays on `FIRST_KEY + k`.
const FIRST_KEY: u8 = 48;

/// One object of the scene.
struct Object {
    name: &'static str,
    plate: RectangularPlate,
    material: &'static Material,
    modes: usize,
    /// Level of the object's loudest mode relative to the others', in dB.
    level_db: f64,
    /// Relative chance of being hit.
    exposure: f64,
}

fn objects() -> Vec<Object> {
    let plate = |x: f64, y: f64, h: f64| RectangularPlate {
        length_x_m: x,
        length_y_m: y,
        thickness_m: h,
    };
    vec![
        Object {
            name: "roof pane 1",
            plate: plate(0.9, 0.6, 2.0e-3),
            material: &materials::ALUMINIUM,
            modes: 100,
            level_db: -6.0,
            exposure: 3.0,
        },
        Object {
            name: "roof pane 2",
            plate: plate(1.1, 0.7, 2.5e-3),
            material: &materials::ALUMINIUM,
            modes: 150,
            level_db: -6.0,
            exposure: 3.0,
        },
        Object {
            name: "roof pane 3",
            plate: plate(1.2, 0.8, 3.0e-3),
            material: &materials::STEEL,
            modes: 200,
            level_db: -4.0,
            exposure: 3.0,
        },
        Object {
            name: "roof pane 4",
            plate: plate(1.5, 1.0, 1.5e-3),
            material: &materials::STEEL,
            modes: 1050,
            level_db: -3.0,
            exposure: 3.0,
        },
        Object {
            name: "plate 1",
            plate: plate(0.25, 0.25, 1.2e-3),
            material: &materials::STEEL,
            modes: 200,
            level_db: -10.0,
            exposure: 1.0,
        },
        Object {
            name: "plate 2",
            plate: plate(0.3, 0.3, 1.5e-3),
            material: &materials::STEEL,
            modes: 200,
            level_db: -10.0,
            exposure: 1.0,
        },
        Object {
            name: "plate 3",
            plate: plate(0.35, 0.35, 1.8e-3),
            material: &materials::BRASS,
            modes: 200,
            level_db: -10.0,
            exposure: 1.0,
        },
        Object {
            name: "table",
            plate: plate(1.6, 0.8, 30e-3),
            material: &materials::SPRUCE,
            modes: 100,
            level_db: -2.0,
            exposure: 2.0,
        },
        Object {
            name: "can",
            plate: plate(1.2, 0.5, 0.8e-3),
            material: &materials::STEEL,
            modes: 1100,
            level_db: 0.0,
            exposure: 1.5,
        },
    ]
}

/// Modes of the scene's objects start here: what lies below hearing is left out of a model.
const LOWEST_HZ: f64 = 20.0;

/// The lowest `o.modes` audible modes of object `o` struck at `strike`.
fn object_modes(o: &Object, strike: &[Position]) -> Vec<Mode> {
    let limits = ModeLimits {
        max_freq_hz: MAX_AUDIBLE_HZ,
        max_modes: o.modes + 32,
    };
    let mut modes = Shape::RectangularPlate(o.plate.clone())
        .modes(o.material, strike, &limits)
        .unwrap_or_else(|e| panic!("{}: {e}", o.name));
    modes.retain(|m| m.freq_hz >= LOWEST_HZ);
    assert!(modes.len() >= o.modes, "{} has too few modes", o.name);
    modes.truncate(o.modes);
    modes
}

/// The scene as one bank: position `k` is object `k`, struck off-centre.
fn scene_bank(objects: &[Object]) -> Bank {
    let positions: Vec<Position> = (0..objects.len())
        .map(|k| Position {
            name: objects[k].name.into(),
            coords: vec![k as f64],
        })
        .collect();
    let mut bank = Bank::new("hail on a picnic", positions);
    let strike = [Position {
        name: "off-centre".into(),
        coords: vec![0.38, 0.42],
    }];
    for (k, o) in objects.iter().enumerate() {
        let modes = object_modes(o, &strike);
        let scale = 10f64.powf(o.level_db / 20.0);
        for m in modes {
            let mut gains = vec![0.0; objects.len()];
            gains[k] = m.gains[0] * scale;
            bank.modes.push(Mode { gains, ..m });
        }
    }
    bank
}

/// One impact: sample, object, velocity.
type Impact = (usize, usize, f32);

/// A Poisson rain of impacts on objects chosen by exposure, energies drawn from a 1/E law
/// (log-uniform over `ENERGY_RANGE`), seeded.
fn hail(objects: &[Object], seconds: f64, seed: u64) -> Vec<Impact> {
    let mut s = seed;
    let mut uniform = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    };
    let total: f64 = objects.iter().map(|o| o.exposure).sum();
    let mut t = 0.0;
    let mut out = Vec::new();
    loop {
        t += -(1.0 - uniform()).ln() / impacts_per_s();
        if t >= seconds {
            break;
        }
        let mut pick = uniform() * total;
        let object = objects
            .iter()
            .position(|o| {
                pick -= o.exposure;
                pick < 0.0
            })
            .unwrap_or(objects.len() - 1);
        // Energy E / E_max = range^-u: density proportional to 1/E. Velocity is the amplitude.
        let energy = ENERGY_RANGE.powf(-uniform());
        out.push(((t * RATE_HZ) as usize, object, energy.sqrt() as f32));
    }
    out
}

/// What one render measured.
struct Run {
    left: Vec<f32>,
    right: Vec<f32>,
    wall_s: f64,
    mode_samples: u64,
    /// Time-average of dormant over live modes.
    pruned_share: f64,
    analyses: u64,
    candidates: u64,
    analysis_s: f64,
    wake_s: f64,
    woken: u64,
    stats: modal_resonator::engine::PruningStats,
}

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

/// The fastest of `REPEATS` timed renders, with the meters of an untimed one.
fn measure(prepared: &Arc<PreparedBank>, impacts: &[Impact], seconds: f64, c: &Controls) -> Run {
    let mut run = render(prepared, impacts, seconds, c, true);
    let mut best: Option<Run> = None;
    for _ in 0..repeats() {
        let r = render(prepared, impacts, seconds, c, false);
        assert!(r.left == run.left, "renders of the same scene differ");
        if best.as_ref().is_none_or(|b| r.wall_s < b.wall_s) {
            best = Some(r);
        }
    }
    let best = best.expect("at least one repeat");
    run.wall_s = best.wall_s;
    run.analysis_s = best.analysis_s;
    run.wake_s = best.wake_s;
    run
}

/// In-place iterative radix-2 FFT of `re`, `im` (length a power of two).
fn fft(re: &mut [f64], im: &mut [f64]) {
    let n = re.len();
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            re.swap(i, j);
            im.swap(i, j);
        }
    }
    let twiddles: Vec<(f64, f64)> = (0..n / 2)
        .map(|k| (-std::f64::consts::TAU * k as f64 / n as f64).sin_cos())
        .collect();
    let mut len = 2;
    while len <= n {
        let stride = n / len;
        for start in (0..n).step_by(len) {
            for k in 0..len / 2 {
                let (s, c) = twiddles[k * stride];
                let (a, b) = (start + k, start + k + len / 2);
                let (tr, ti) = (re[b] * c - im[b] * s, re[b] * s + im[b] * c);
                re[b] = re[a] - tr;
                im[b] = im[a] - ti;
                re[a] += tr;
                im[a] += ti;
            }
        }
        len <<= 1;
    }
}

/// Power of `x` in each critical band (Bark 0-1, 1-2, ... 24-25), averaged over Hann-windowed
/// frames (Welch).
fn band_power(x: &[f32]) -> [f64; 25] {
    const N: usize = 4096;
    let window: Vec<f64> = (0..N)
        .map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / N as f64).cos())
        .collect();
    let band_of: Vec<usize> = (0..N / 2)
        .map(|k| (hz_to_bark(k as f64 * RATE_HZ / N as f64) as usize).min(24))
        .collect();
    let mut bands = [0.0; 25];
    let (mut re, mut im) = (vec![0.0; N], vec![0.0; N]);
    for frame in x.chunks_exact(N / 2).collect::<Vec<_>>().windows(2) {
        for i in 0..N / 2 {
            re[i] = frame[0][i] as f64 * window[i];
            re[i + N / 2] = frame[1][i] as f64 * window[i + N / 2];
        }
        im.fill(0.0);
        fft(&mut re, &mut im);
        for k in 1..N / 2 {
            bands[band_of[k]] += re[k] * re[k] + im[k] * im[k];
        }
    }
    bands
}

fn db(x: f64) -> f64 {
    10.0 * x.max(1e-300).log10()
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

    // `PRUNING_ONLY=5` renders one pruned case and stops, for profilers.
    if let Some(av) = std::env::var("PRUNING_ONLY")
        .ok()
        .and_then(|v| v.parse::<f32>().ok())
    {
        let c = controls(&bank, objects.len(), Some(av));
        let run = render(&prepared, &impacts, seconds, &c, false);
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
    let runs: Vec<Run> = cases
        .iter()
        .map(|&(_, av)| {
            measure(
                &prepared,
                &impacts,
                seconds,
                &controls(&bank, objects.len(), av),
            )
        })
        .collect();
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
    let edge_hz = |bark: f64| {
        // Invert the Bark scale by bisection.
        let (mut lo, mut hi) = (0.0, 30_000.0);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if hz_to_bark(mid) < bark {
                lo = mid
            } else {
                hi = mid
            }
        }
        lo
    };
    for b in 0..25 {
        if reference[b] <= 0.0 {
            continue;
        }
        print!(
            "{:>2}-{:<2} {:>6.0}-{:<6.0} {:>12.1}",
            b,
            b + 1,
            edge_hz(b as f64),
            edge_hz(b as f64 + 1.0),
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
