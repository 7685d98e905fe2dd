//! Perceptual pruning on two busy scenes.
//!
//! Hail on a picnic (seed 001 section 6): nine objects (four roof panes, three plates, a table and
//! a can; two banks of over a thousand modes, 3,300 modes in all) built from the analytic plate,
//! struck by a random rain of impacts whose energies follow a 1/E law, for ten seconds. Each
//! object is one voice of one engine: the scene is a bank whose strike positions are the objects
//! (an object's modes have gain only in its own column), played with key tracking off, one key
//! per object.
//!
//! Chords and rolls: a steel sheet of 2,200 modes played as a musician would, sixteen voices at
//! eleven pitches, a four-note chord every 0.75 s and a roll between chords.
//!
//! Printed in one run, for each scene: mode-samples computed and wall time with pruning off and
//! at a_v = 0, 2.5, 5, 10 and 20 dB (what each setting costs and buys); the share of live modes
//! pruned; the pruning overhead (analyses and wakes, timed) against the rest of the synthesis;
//! the level of the difference between each pruned render and the unpruned one relative to the
//! unpruned signal, per critical band; the noise-to-mask ratio of that difference, per 20 ms
//! frame and critical band, against the masking threshold of the unpruned signal at the playback
//! level; and its worst click, the difference's high band at the control ticks after strikes
//! against the signal's own. Then the targets at a_v = 5 dB.
//!
//! Run with `cargo bench --bench pruning`. Settings for experiments, from the environment:
//! `PRUNING_REPEATS` (timed renders per case, default 5, the cases taking turns; the fastest of
//! each counts), `PRUNING_OFFSETS=2.5,5,20` (other masking offsets; the targets are read at
//! 5 dB), `PRUNING_FRAME_MS` (another analysis frame), `PRUNING_SCENE=hail` or `dense` (one
//! scene), `PRUNING_ONLY=5` (pruned renders only, `PRUNING_REPEATS` of them, with every
//! counter of the last, for profilers), `PRUNING_WHERE=1` (where the frame-bands over the
//! mask lie: by band, by time since a strike, and the worst frame band by band) and
//! `PRUNING_MASK_HOLD_MS=50` (the noise-to-mask ratio with each band's masker held at its highest
//! over that long before, a crude forward masking; the targets are read without).

use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;

use modal_resonator::bank::{Bank, Position};
use modal_resonator::dsp::ExciterKind;
use modal_resonator::engine::{Controls, Engine, NoteEvent, PreparedBank, CONTROL_PERIOD};

#[path = "pruning/bands.rs"]
mod bands;
#[path = "pruning/scene.rs"]
mod scene;

use bands::{band_power, bark_to_hz, db, nmr, worst_click, Nmr};
use scene::{
    chords_and_rolls, dense_bank, hail, hail_hits, object_modes, objects, scene_bank, Hit,
    DENSE_MODES, DENSE_VOICES, ENERGY_RANGE,
};

/// Sample rate of the renders.
pub const RATE_HZ: f64 = 48_000.0;
/// Longest block handed to the engine (blocks are also cut at every impact).
const BLOCK: usize = 256;
/// Timed renders per case; the fastest counts (the machine is shared).
const REPEATS: usize = 5;

/// Timed renders per case: `PRUNING_REPEATS`, else [`REPEATS`] (one in the quick run that
/// `cargo test --benches` makes).
fn repeats() -> usize {
    let quick = !std::env::args().any(|a| a == "--bench");
    std::env::var("PRUNING_REPEATS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(if quick { 1 } else { REPEATS })
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

/// A scene's controls: mallet strikes, a voice per object (hail, with no key tracking) or
/// [`DENSE_VOICES`]; pruning at `masking_offset_db` when given.
fn controls(bank: &Bank, voices: usize, hail: bool, masking_offset_db: Option<f32>) -> Controls {
    let mut c = Controls::for_bank(bank);
    if hail {
        c.key_tracking = 0.0;
    }
    c.velocity_sensitivity = 0.5;
    c.velocity_to_hardness = 0.0;
    c.exciter = ExciterKind::Mallet;
    c.hardness_ms = 0.3;
    c.polyphony = voices;
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
    hits: &[Hit],
    seconds: f64,
    base: &Controls,
    measure: bool,
) -> Run {
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
        let mut events = [NoteEvent::AllNotesOff { time: 0 }; 8];
        let mut num_events = 0;
        // The strikes due: a block starts at each new strike position.
        while num_events < events.len()
            && next < hits.len()
            && hits[next].at <= pos
            && (num_events == 0 || hits[next].strike_x == c.strike_x)
        {
            let hit = hits[next];
            if num_events == 0 && hit.strike_x != c.strike_x {
                c.strike_x = hit.strike_x;
                engine.set_controls(&c);
            }
            events[num_events] = NoteEvent::on(0, hit.key, hit.velocity);
            num_events += 1;
            next += 1;
        }
        if next < hits.len() {
            end = end.min(hits[next].at.max(pos + 1));
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
    hits: &[Hit],
    seconds: f64,
    cases: &[Controls],
) -> Vec<Run> {
    let mut runs: Vec<Run> = cases
        .iter()
        .map(|c| render(prepared, hits, seconds, c, true))
        .collect();
    // Wall, analysis and wake seconds of each case's fastest render.
    let mut best: Vec<Option<(f64, f64, f64)>> = vec![None; cases.len()];
    for _ in 0..repeats() {
        for (k, c) in cases.iter().enumerate() {
            let r = render(prepared, hits, seconds, c, false);
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

/// What a scene's pruned render at a_v = 5 dB measured against its unpruned one.
struct Summary {
    /// Times fewer mode-samples.
    fewer: f64,
    /// Times less wall time.
    faster: f64,
    /// Pruning's time over the rest of the synthesis.
    overhead: f64,
    /// The difference's noise-to-mask ratio.
    nmr: Nmr,
    /// The difference's level over the signal's in the band where it is highest, in dB.
    worst_band_db: f64,
    /// The worst click ([`worst_click`]): the difference's high band at a control tick after a
    /// strike over the signal's own, both channels.
    click: f64,
}

/// Power in each critical band of a stereo signal, both channels summed.
fn stereo_band_power(left: &[f32], right: &[f32]) -> [f64; 25] {
    let (l, r) = (band_power(left), band_power(right));
    std::array::from_fn(|b| l[b] + r[b])
}

/// Renders a scene with pruning off and at each offset, prints what each measured, and returns
/// the summary at a_v = 5 dB if it was among the offsets.
fn scene_report(
    prepared: &Arc<PreparedBank>,
    hits: &[Hit],
    seconds: f64,
    cases: &[(String, Controls)],
) -> Option<Summary> {
    let case_controls: Vec<Controls> = cases.iter().map(|(_, c)| c.clone()).collect();
    let runs = measure(prepared, hits, seconds, &case_controls);
    let off = &runs[0];
    print_runs(cases, &runs);

    // The difference signal, per critical band over the whole render.
    let reference = stereo_band_power(&off.left, &off.right);
    let differences: Vec<(Vec<f32>, Vec<f32>)> = runs[1..]
        .iter()
        .map(|run| {
            let d = |a: &[f32], b: &[f32]| a.iter().zip(b).map(|(a, b)| a - b).collect();
            (d(&run.left, &off.left), d(&run.right, &off.right))
        })
        .collect();
    let diffs: Vec<[f64; 25]> = differences
        .iter()
        .map(|(l, r)| stereo_band_power(l, r))
        .collect();
    print_bands(cases, &reference, &diffs);

    // The difference against the masking threshold of the unpruned signal, frame by frame.
    println!(
        "Noise-to-mask ratio of the difference, per 20 ms frame and critical band; clicks: the \
         difference's high band at control ticks 1-50 ms after strikes, over the signal's own:"
    );
    let strikes: Vec<usize> = hits.iter().map(|h| h.at).collect();
    let mut ratios = Vec::new();
    for (((name, c), (l, r)), run) in cases[1..].iter().zip(&differences).zip(&runs[1..]) {
        let m = nmr(
            [&off.left, &off.right],
            [l, r],
            c.playback_level_db_spl as f64,
            c.masking_offset_db as f64,
        );
        let click = [(&off.left, l), (&off.right, r)]
            .iter()
            .map(|(s, d)| worst_click(s, d, &strikes, CONTROL_PERIOD))
            .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a });
        println!(
            "  {name:<11} {:>6.2}% of {} frame-bands at or below 0 dB; 99th percentile {:>6.1} dB; \
             worst {:>+6.1} dB (Bark {}, {:.2} s); worst click {:.1}x ({:.3} s)",
            100.0 * m.share_ok,
            m.cells,
            m.p99_db,
            m.worst.0,
            m.worst.1,
            m.worst.2,
            click.0,
            click.1 as f64 / RATE_HZ
        );
        if std::env::var("PRUNING_WHERE").is_ok() {
            print_where(&m, &strikes);
        }
        ratios.push((c.masking_offset_db, m, run, click.0));
    }
    println!();

    let five = ratios
        .into_iter()
        .enumerate()
        .find(|(_, (av, _, _, _))| *av == 5.0)?;
    let (k, (_, m, r, click)) = five;
    let overhead = (r.analysis_s + r.wake_s) / (r.wall_s - r.analysis_s - r.wake_s);
    let worst_band_db = (0..25)
        .filter(|&b| reference[b] > 0.0)
        .map(|b| db(diffs[k][b] / reference[b]))
        .fold(f64::NEG_INFINITY, f64::max);
    Some(Summary {
        fewer: off.mode_samples as f64 / r.mode_samples as f64,
        faster: off.wall_s / r.wall_s,
        overhead,
        nmr: m,
        worst_band_db,
        click,
    })
}

/// Prints where the frame-bands over the mask lie: by critical band, by the time since the last
/// strike, and the worst frame band by band.
fn print_where(m: &Nmr, strikes: &[usize]) {
    let frame = (bands::NMR_FRAME_S * RATE_HZ) as usize;
    let (mut by_band, mut by_age) = ([0usize; 25], [0usize; 6]);
    let mut louder = 0;
    for &(start_s, b, over_signal_db) in &m.over {
        by_band[b] += 1;
        louder += (over_signal_db > 0.0) as usize;
        let start = (start_s * RATE_HZ) as usize;
        // Frames since the last strike before the frame's end (0: a strike within it).
        let age = strikes
            .iter()
            .filter(|&&s| s < start + frame)
            .max()
            .map_or(5, |&s| start.saturating_sub(s) / frame);
        by_age[age.min(5)] += 1;
    }
    println!(
        "    over the mask: {} frame-bands, {louder} of them with the difference louder than the \
         signal (which cancels itself there); by band: {by_band:?}",
        m.over.len()
    );
    println!(
        "    by frames since the last strike (0: one within the frame; 5: five or more): {by_age:?}"
    );
    for (b, [signal, diff, mask, quiet]) in m.worst_frame.iter().enumerate() {
        println!(
            "    worst frame ({:.2} s), Bark {b:>2}: signal {signal:>6.1}, difference {diff:>6.1}, \
             mask {mask:>6.1}, threshold in quiet {quiet:>6.1} dB SPL",
            m.worst.2
        );
    }
}

/// Prints what each case's render measured, against the first (pruning off).
fn print_runs(cases: &[(String, Controls)], runs: &[Run]) {
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
    for ((name, _), r) in cases.iter().zip(runs) {
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
}

/// Prints each case's difference from the unpruned render relative to the unpruned signal, per
/// critical band over the whole render.
fn print_bands(cases: &[(String, Controls)], reference: &[f64; 25], diffs: &[[f64; 25]]) {
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
        for d in diffs {
            print!(" {:>11.1}", db(d[b] / reference[b]));
        }
        println!();
    }
    let total_ref: f64 = reference.iter().sum();
    print!("{:<5} {:>13} {:>12}", "all", "", "");
    for d in diffs {
        print!(" {:>11.1}", db(d.iter().sum::<f64>() / total_ref));
    }
    println!();
    println!("(signal dB: each band's power relative to the strongest band)");
}

/// Prints the targets at a_v = 5 dB for the scenes measured.
fn print_targets(hail: Option<&Summary>, dense: Option<&Summary>) {
    println!("Targets at a_v = 5 dB:");
    let transparent = |name: &str, s: &Summary| {
        target(
            &format!(
                "{name}: noise-to-mask ratio at or below 0 dB in {:.2}% of frame-bands (target \
                 99%)",
                100.0 * s.nmr.share_ok
            ),
            s.nmr.share_ok >= 0.99,
        );
        target(
            &format!(
                "{name}: difference over the signal in its worst band {:+.1} dB (target below \
                 0 dB)",
                s.worst_band_db
            ),
            s.worst_band_db < 0.0,
        );
        target(
            &format!(
                "{name}: no click, the difference's high band at control ticks after strikes at \
                 most {:.1}x the signal's own (target at most 2x)",
                s.click
            ),
            s.click <= 2.0,
        );
    };
    if let Some(s) = hail {
        target(
            &format!("hail: mode-samples {:.1}x fewer (target 5x)", s.fewer),
            s.fewer >= 5.0,
        );
        target(
            &format!("hail: wall time {:.1}x less (target 4x, aim 6x)", s.faster),
            s.faster >= 4.0,
        );
        target(
            &format!(
                "hail: pruning {:.1}% of the remaining synthesis (target at most 25%)",
                100.0 * s.overhead
            ),
            s.overhead <= 0.25,
        );
        transparent("hail", s);
    }
    if let Some(s) = dense {
        target(
            &format!(
                "chords and rolls: wall time {:.1}x less (target 3x)",
                s.faster
            ),
            s.faster >= 3.0,
        );
        transparent("chords and rolls", s);
    }
}

/// Prints what the hail scene holds: its objects, their modes and how often each is hit.
fn print_hail_scene(
    objects: &[scene::Object],
    prepared: &PreparedBank,
    impacts: &[scene::Impact],
    seconds: f64,
) {
    println!(
        "Hail on a picnic (seed 001 section 6): {} objects, {} modes, {} impacts (energies \
         1/E over {:.0} dB) in {seconds} s",
        objects.len(),
        prepared.num_modes(),
        impacts.len(),
        db(ENERGY_RANGE),
    );
    for o in objects {
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
}

/// Renders the pruned hail `repeats()` times and prints the last render's counters.
fn profile(prepared: &Arc<PreparedBank>, hits: &[Hit], seconds: f64, c: &Controls, av: f32) {
    let mut run = render(prepared, hits, seconds, c, false);
    for _ in 1..repeats() {
        run = render(prepared, hits, seconds, c, false);
    }
    println!(
        "a_v {av} dB: {:.1} ms, analyses {:.1} ms, strikes {:.1} ms, {:.1e} mode-samples, {:?}",
        run.wall_s * 1e3,
        run.analysis_s * 1e3,
        run.wake_s * 1e3,
        run.mode_samples as f64,
        run.stats,
    );
}

/// A scene's cases: pruning off, then at each masking offset.
fn cases(bank: &Bank, voices: usize, hail: bool, offsets: &[f32]) -> Vec<(String, Controls)> {
    let mut cases = vec![("off".to_string(), controls(bank, voices, hail, None))];
    cases.extend(offsets.iter().map(|&av| {
        (
            format!("a_v {av} dB"),
            controls(bank, voices, hail, Some(av)),
        )
    }));
    cases
}

/// Prints one target and whether it is met.
fn target(what: &str, ok: bool) {
    println!("  {what}: {}", if ok { "met" } else { "NOT met" });
}

/// Checks the levels the noise-to-mask ratio reads: a 1 kHz sine of amplitude 0.5 has a mean
/// square of 0.125 over the bands of every frame, 6 dB under the playback level.
fn check_levels() {
    let sine: Vec<f32> = (0..(0.2 * RATE_HZ) as usize)
        .map(|n| 0.5 * (std::f64::consts::TAU * 1000.0 * n as f64 / RATE_HZ).sin() as f32)
        .collect();
    for frame in bands::frame_band_power([&sine, &sine]) {
        let total: f64 = frame.iter().sum();
        let level = bands::spl(total, 90.0);
        assert!(
            (total / 0.125 - 1.0).abs() < 0.02 && (level - (90.0 - 6.02)).abs() < 0.1,
            "a sine of amplitude 0.5 reads {total} ({level} dB SPL at 90)"
        );
    }
}

fn main() {
    check_levels();
    // `cargo test --benches` runs this without --bench: keep that quick.
    let quick = !std::env::args().any(|a| a == "--bench");
    let seconds = if quick { 1.0 } else { 10.0 };
    let only = std::env::var("PRUNING_SCENE").ok();
    let wanted = |scene: &str| only.as_deref().is_none_or(|o| o == scene);
    // `PRUNING_OFFSETS=2.5,5,20` measures other offsets (the targets are read at 5 dB).
    let offsets: Vec<f32> = std::env::var("PRUNING_OFFSETS")
        .ok()
        .map(|v| v.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![0.0, 2.5, 5.0, 10.0, 20.0]);

    let objects = objects();
    let bank = scene_bank(&objects);
    let prepared = Arc::new(PreparedBank::new(&bank));
    let impacts = hail(&objects, seconds, 0x4A11);
    let hits = hail_hits(&impacts, objects.len());
    let kernel = Engine::new(prepared.clone()).kernel();
    let c = controls(&bank, objects.len(), true, None);
    println!(
        "Kernel {}, blocks of up to {BLOCK} samples at {} kHz; pruning: playback level {} dB SPL \
         at full scale, analysis frame {} ms",
        kernel.name(),
        RATE_HZ / 1000.0,
        c.playback_level_db_spl,
        c.analysis_frame_ms
    );
    println!();

    // `PRUNING_ONLY=5` renders the pruned hail only, for profilers.
    if let Some(av) = std::env::var("PRUNING_ONLY")
        .ok()
        .and_then(|v| v.parse::<f32>().ok())
    {
        let c = controls(&bank, objects.len(), true, Some(av));
        return profile(&prepared, &hits, seconds, &c, av);
    }
    let cases = |bank: &Bank, voices: usize, hail: bool| cases(bank, voices, hail, &offsets);

    let mut hail_summary = None;
    if wanted("hail") {
        print_hail_scene(&objects, &prepared, &impacts, seconds);
        println!();
        hail_summary = scene_report(
            &prepared,
            &hits,
            seconds,
            &cases(&bank, objects.len(), true),
        );
    }

    let mut dense_summary = None;
    if wanted("dense") {
        let bank = dense_bank();
        let prepared = Arc::new(PreparedBank::new(&bank));
        let hits = chords_and_rolls(seconds, 0xC4057);
        println!(
            "Chords and rolls: a steel sheet of {DENSE_MODES} modes ({:.0} to {:.0} Hz), \
             {DENSE_VOICES} voices, {} strikes in {seconds} s",
            bank.modes[0].freq_hz,
            bank.modes[bank.modes.len() - 1].freq_hz,
            hits.len(),
        );
        println!();
        dense_summary = scene_report(
            &prepared,
            &hits,
            seconds,
            &cases(&bank, DENSE_VOICES, false),
        );
    }

    print_targets(hail_summary.as_ref(), dense_summary.as_ref());
}
