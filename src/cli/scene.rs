//! `modal-resonator scene`: a scene file rendered to a WAV file, heard from its listener.

use std::path::PathBuf;
use std::time::Instant;

use clap::Args;

use modal_resonator::bank::staged::StagedFile;
use modal_resonator::render::{BitDepth, WavFile};
use modal_resonator::scene::{render_scene_to, SceneSource, SceneSummary};

use super::check_output;
use super::progress::Progress;
use super::render::parse_bit_depth;

/// Arguments of `scene`.
#[derive(Debug, Args)]
pub(super) struct SceneArgs {
    /// Scene file (JSON, "format": "modal-scene"); bank files it names are found relative to it.
    scene: PathBuf,
    /// WAV file to write.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Sample rate in Hz.
    #[arg(long, default_value_t = 48_000, value_parser = clap::value_parser!(u32).range(8_000..=384_000))]
    rate: u32,
    /// Bits per sample: 16 or 24 (integer) or 32 (float).
    #[arg(long, default_value = "24", value_parser = parse_bit_depth)]
    bits: BitDepth,
    /// Longest render in seconds; the render stops earlier once everything is silent.
    #[arg(long, default_value_t = 60.0)]
    max_seconds: f64,
    /// Also write every event played, given or found by the physics, one JSON object a line
    /// in time order (when it happens at the object, which object, what).
    #[arg(long, value_name = "FILE")]
    events: Option<PathBuf>,
}

/// `scene`: the scene and every bank it names are read and checked before anything renders,
/// and nothing is written on failure.
pub(super) fn run(args: &SceneArgs) -> Result<(), String> {
    if !(args.max_seconds > 0.0 && args.max_seconds <= 3600.0) {
        return Err(format!(
            "--max-seconds: expected over 0 up to 3600, found {}",
            args.max_seconds
        ));
    }
    check_output("-o", &args.output, &[("the scene", args.scene.as_path())])?;
    if let Some(events) = &args.events {
        check_output("--events", events, &[("the scene", args.scene.as_path())])?;
        if events == &args.output {
            return Err("--events: the same file as -o; write the events elsewhere".into());
        }
    }
    let source = SceneSource::from_file(&args.scene).map_err(|e| e.to_string())?;
    let started = Instant::now();
    let mut progress = Progress::new("rendering");
    let mut file =
        WavFile::create(&args.output, args.bits, args.rate).map_err(|e| e.to_string())?;
    let rendered = render_scene_to(
        &source,
        args.rate,
        args.max_seconds,
        |d| progress.set(d),
        |l, r| file.write(l, r),
    )
    .map_err(|e| e.to_string())?;
    progress.finish();
    let elapsed_s = started.elapsed().as_secs_f64();
    let events = match &args.events {
        Some(path) => Some(stage_events(&source, path, args.max_seconds)?),
        None => None,
    };
    file.finish().map_err(|e| e.to_string())?;
    if let Some(staged) = events {
        staged
            .commit()
            .map_err(|e| format!("--events {}: {e}", args.events.as_ref().unwrap().display()))?;
    }
    report(args, &source, &rendered, elapsed_s);
    Ok(())
}

/// Prints what was rendered, and warns of left-out impacts and clipping.
fn report(args: &SceneArgs, source: &SceneSource, rendered: &SceneSummary, elapsed_s: f64) {
    let (steps, physics_s) = source.physics_cost();
    let seconds = rendered.len as f64 / args.rate as f64;
    let peak = rendered.peak;
    let s = rendered.stats;
    println!(
        "{}: {seconds:.2} s, {} Hz {}, peak {:+.1} dBFS; {} object{}, {} impact{}, {} contact{}; \
         rendered in {elapsed_s:.2} s ({:.1}x real time){}",
        args.output.display(),
        args.rate,
        args.bits.name(),
        20.0 * peak.max(1e-30).log10(),
        s.objects,
        if s.objects == 1 { "" } else { "s" },
        s.impacts,
        if s.impacts == 1 { "" } else { "s" },
        s.contacts,
        if s.contacts == 1 { "" } else { "s" },
        seconds / elapsed_s.max(1e-9),
        if rendered.cut_short {
            ", cut at --max-seconds"
        } else {
            ""
        },
    );
    if source.events_capped() {
        eprintln!(
            "warning: the physics found more impacts than a scene may hold ({}); the later ones \
             were left out",
            modal_resonator::scene::format::MAX_EVENTS
        );
    }
    if steps > 0 {
        let simulated_s = source.file().physics.map_or(0.0, |p| p.duration_s);
        println!(
            "physics: {steps} steps ({simulated_s:.2} s) in {physics_s:.2} s ({:.1}x real time)",
            simulated_s / physics_s.max(1e-9)
        );
    }
    if peak > 1.0 && args.bits != BitDepth::Float32 {
        eprintln!(
            "warning: the scene peaks over full scale and is clipped in the {} file: lower the \
             objects' gain_db, or write --bits 32",
            args.bits.name()
        );
    }
}

/// Writes every event of `source` before `max_seconds`, in time order, one JSON object a line,
/// to a temporary file beside `path`; committing it puts it in place.
fn stage_events(
    source: &SceneSource,
    path: &std::path::Path,
    max_seconds: f64,
) -> Result<StagedFile, String> {
    let mut events: Vec<_> = source
        .events()
        .iter()
        .filter(|e| e.time_s < max_seconds)
        .collect();
    events.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    let mut text = String::new();
    for e in events {
        text.push_str(&serde_json::to_string(e).map_err(|e| e.to_string())?);
        text.push('\n');
    }
    StagedFile::write(path, "events", text.as_bytes())
        .map_err(|e| format!("--events {}: {e}", path.display()))
}
