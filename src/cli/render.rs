//! `modal-resonator render`: notes or a MIDI file through a bank to a WAV file.

use std::convert::Infallible;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

use clap::Args;

use modal_resonator::bank::Bank;
use modal_resonator::engine::{Controls, PositionMap, PreparedBank};
use modal_resonator::render::{
    normalizing_scale, parse_notes, read_midi_file, render_to, wav_bytes, BitDepth, Note,
    RenderSettings, RenderSummary, Rendered, Score, TimedMidi, WavFile,
};

use super::progress::Progress;
use super::{check_output, load_bank, STDOUT};

/// Arguments of `render`.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("input").required(true).args(["notes", "midi"])))]
pub(super) struct RenderArgs {
    /// Bank file (JSON) or factory preset name.
    bank: String,
    /// Notes as key:velocity@time_s[+duration_s], comma-separated, e.g.
    /// "60:0.8@0, 64:0.5@0.25+0.5"; a contact note may add speed=A..B (m/s) and force=A..B,
    /// e.g. "60:1@0+2 speed=0.2..1.5".
    #[arg(long, allow_hyphen_values = true)]
    notes: Option<String>,
    /// Standard MIDI file to play (all tracks and channels; bends, pedal, wheel, pressure and
    /// CC 74 as the plugins play them).
    #[arg(long, value_name = "FILE")]
    midi: Option<PathBuf>,
    /// WAV file to write (a symbolic link's target is replaced, an existing file keeps its
    /// permissions); `-` writes the WAV to standard output.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Set a control on top of the bank's defaults, e.g. --set material=wood; repeatable.
    #[arg(long = "set", value_name = "NAME=VALUE", value_parser = parse_assignment)]
    set: Vec<(String, String)>,
    /// Sample rate in Hz.
    #[arg(long, default_value_t = 48_000, value_parser = clap::value_parser!(u32).range(8_000..=384_000))]
    rate: u32,
    /// Bits per sample: 16 or 24 (integer) or 32 (float).
    #[arg(long, default_value = "24", value_parser = parse_bit_depth)]
    bits: BitDepth,
    /// Longest render in seconds; the render stops earlier once everything is silent.
    #[arg(long, default_value_t = 30.0, value_parser = parse_max_seconds)]
    max_seconds: f64,
    /// Scale the render so that its peak is this many dBFS (0 or below), e.g. -1: loud chords
    /// then do not clip.
    #[arg(long, value_name = "DBFS", allow_hyphen_values = true, value_parser = parse_normalize)]
    normalize: Option<f32>,
}

/// Exit status of a render that wrote a silent file: not an error, but not what was asked.
pub(super) const SILENT_EXIT: u8 = 3;

/// `render`: everything is checked before rendering, and nothing is written on failure. A
/// render that clips is written with a warning; one that is silent is written with a warning
/// and [`SILENT_EXIT`].
pub(super) fn run(args: &RenderArgs) -> Result<ExitCode, String> {
    let loaded = load_bank(&args.bank)?;
    let mut inputs: Vec<(&str, &Path)> = Vec::new();
    if let Some(file) = &loaded.file {
        inputs.push(("the bank", file));
    }
    if let Some(midi) = &args.midi {
        inputs.push(("the MIDI file", midi));
    }
    check_output("-o", &args.output, &inputs)?;
    let bank = loaded.bank;
    let controls = controls(args, &bank)?;
    let (notes, midi) = read_score(args, &controls)?;
    let score = if args.notes.is_some() {
        Score::Notes(&notes)
    } else {
        Score::Midi(&midi)
    };
    if let Some((number, time_s)) = score.first_note_from(args.max_seconds) {
        return Err(format!(
            "note {number} starts at {time_s} s, at or after --max-seconds {}",
            args.max_seconds
        ));
    }
    let settings = RenderSettings {
        sample_rate_hz: args.rate,
        bit_depth: args.bits,
        controls,
        max_seconds: args.max_seconds,
        ..RenderSettings::default()
    };
    let mut progress = Progress::new("rendering");
    let bank = Arc::new(PreparedBank::new(&bank));
    let rendered = render_output(args, &bank, score, &settings, &mut progress)?;
    let elapsed = progress.finish();
    Ok(report(args, &rendered, score, elapsed.as_secs_f64()))
}

/// The bank's controls with every `--set` on top; a setting along an axis the bank's positions
/// do not span is warned of.
fn controls(args: &RenderArgs, bank: &Bank) -> Result<Controls, String> {
    let mut controls = Controls::for_bank(bank);
    for (name, value) in &args.set {
        controls
            .set_by_name(name, value)
            .map_err(|e| format!("--set {name}={value}: {e}"))?;
    }
    let coords: Vec<Vec<f64>> = bank.positions.iter().map(|p| p.coords.clone()).collect();
    let positions = PositionMap::new(&coords);
    for (name, _) in &args.set {
        let axis = match name.as_str() {
            "strike_x" => 0,
            "strike_y" => 1,
            _ => continue,
        };
        if !positions.moves_along(axis) {
            eprintln!(
                "warning: --set {name}: every position of this bank lies at the same {}, so the \
                 strike cannot move along it and the setting changes nothing",
                if axis == 0 { "x" } else { "y" }
            );
        }
    }
    Ok(controls)
}

/// The notes of `--notes` or the MIDI of `--midi`; contact curves on the notes of a struck bank
/// are refused.
fn read_score(
    args: &RenderArgs,
    controls: &Controls,
) -> Result<(Vec<Note>, Vec<TimedMidi>), String> {
    let (notes, midi) = match (&args.notes, &args.midi) {
        (Some(text), _) => (
            parse_notes(text).map_err(|e| format!("--notes: {e}"))?,
            Vec::new(),
        ),
        (None, Some(path)) => (Vec::new(), read_midi_file(path).map_err(|e| e.to_string())?),
        (None, None) => unreachable!("clap requires --notes or --midi"),
    };
    if !controls.exciter.is_contact() {
        if let Some(k) = notes
            .iter()
            .position(|n| n.speed_m_per_s.is_some() || n.force.is_some())
        {
            return Err(format!(
                "--notes: note {}: speed= and force= drive a contact (scrape, roll, rub), but \
                 this bank is struck (exciter {}); add --set exciter=scrape (or roll, rub) to \
                 play it by a contact, or leave them out",
                k + 1,
                controls.exciter.name()
            ));
        }
    }
    Ok((notes, midi))
}

/// Renders `score` into the output: a file written as the samples are made (removed on any
/// error), or a WAV built in memory for standard output, which cannot seek back to fill in the
/// header. With `--normalize`, a first pass finds the peak; renders are reproducible, so the
/// second, scaled, has the same samples.
fn render_output(
    args: &RenderArgs,
    bank: &Arc<PreparedBank>,
    score: Score,
    settings: &RenderSettings,
    progress: &mut Progress,
) -> Result<RenderSummary, String> {
    let mut settings = settings.clone();
    let (scale, first_share) = match args.normalize {
        Some(peak_dbfs) => (
            normalizing_scale(bank, score, &mut settings, peak_dbfs, |d| {
                progress.set(0.5 * d)
            }),
            0.5,
        ),
        None => (1.0, 0.0),
    };
    let settings = &settings;
    let share = |done: f64| first_share + (1.0 - first_share) * done;
    if args.output.as_os_str() == STDOUT {
        return render_to_stdout(args, bank, score, settings, scale, |d| {
            progress.set(share(d))
        });
    }
    let mut file =
        WavFile::create(&args.output, args.bits, args.rate).map_err(|e| e.to_string())?;
    let rendered = render_to(
        bank,
        score,
        settings,
        scale,
        |d| progress.set(share(d)),
        |l, r| file.write(l, r),
    )
    .map_err(|e| e.to_string())?;
    file.finish().map_err(|e| e.to_string())?;
    Ok(rendered)
}

/// Renders the whole WAV in memory and writes it to standard output (a pipe cannot be
/// rewound to patch the header's sizes).
fn render_to_stdout(
    args: &RenderArgs,
    bank: &Arc<PreparedBank>,
    score: Score,
    settings: &RenderSettings,
    scale: f32,
    progress: impl FnMut(f64),
) -> Result<RenderSummary, String> {
    let (mut left, mut right) = (Vec::new(), Vec::new());
    let collect = |l: &[f32], r: &[f32]| {
        left.extend_from_slice(l);
        right.extend_from_slice(r);
        Ok::<(), Infallible>(())
    };
    let Ok(rendered) = render_to(bank, score, settings, scale, progress, collect);
    let whole = Rendered {
        left,
        right,
        sample_rate_hz: args.rate,
        max_voices: rendered.max_voices,
        cut_short: rendered.cut_short,
    };
    let bytes = wav_bytes(&whole, args.bits, args.rate)
        .map_err(|e| format!("standard output: cannot write WAV: {e}"))?;
    let mut out = std::io::stdout().lock();
    out.write_all(&bytes)
        .and_then(|()| out.flush())
        .map_err(|e| format!("standard output: {e}"))?;
    Ok(rendered)
}

/// Prints the summary (on standard error when the WAV went to standard output) and warns of
/// peaks over full scale and of silence; the exit status says which.
fn report(args: &RenderArgs, rendered: &RenderSummary, score: Score, elapsed_s: f64) -> ExitCode {
    let to_stdout = args.output.as_os_str() == STDOUT;
    let peak_dbfs = rendered.peak_dbfs();
    let over = rendered.peak > 1.0;
    let clipped = args.bits != BitDepth::Float32 && over;
    let summary = format!(
        "{}: {:.2} s, {} Hz {}, peak {:+.1} dBFS{}, up to {} voice{}, rendered in {:.2} s{}",
        if to_stdout {
            "standard output".into()
        } else {
            args.output.display().to_string()
        },
        rendered.duration_s(),
        args.rate,
        args.bits.name(),
        peak_dbfs,
        if clipped { " (clipped)" } else { "" },
        rendered.max_voices,
        if rendered.max_voices == 1 { "" } else { "s" },
        elapsed_s,
        if rendered.cut_short {
            ", cut at --max-seconds"
        } else {
            ""
        },
    );
    if to_stdout {
        eprintln!("{summary}");
    } else {
        println!("{summary}");
    }
    if clipped {
        let clips = rendered.clipped_samples;
        eprintln!(
            "warning: the render peaks at {peak_dbfs:+.1} dBFS: {clips} sample{} clipped in the \
             {} file. Render again with --normalize -1 (the peak at -1 dBFS), softer notes, \
             --set output_gain_db=-6, or --bits 32 to keep the peaks",
            if clips == 1 { " is" } else { "s are" },
            args.bits.name()
        );
    } else if over {
        eprintln!(
            "warning: the render peaks at {peak_dbfs:+.1} dBFS, over full scale: the float file \
             keeps the peaks, but a player or a conversion to integers will clip them. Render \
             again with --normalize -1 to bring the peak to -1 dBFS"
        );
    }
    // Under half its least level, a sample is written as zero.
    if rendered.peak >= 0.5 * args.bits.least_level() {
        return ExitCode::SUCCESS;
    }
    if score.first_note_from(0.0).is_none() {
        eprintln!(
            "warning: the render is silent: there are no notes to play (a MIDI file with no \
             note-on, or only tempo and other meta events)"
        );
    } else {
        eprintln!(
            "warning: the render is silent: every sample rounds to zero in the {} file. The \
             notes may be too soft, the bank's gains zero, or its modes above the playable \
             range at {} Hz",
            args.bits.name(),
            args.rate
        );
    }
    ExitCode::from(SILENT_EXIT)
}

/// Parses `--normalize`: a level in dBFS from -100 to 0.
fn parse_normalize(text: &str) -> Result<f32, String> {
    text.parse::<f32>()
        .ok()
        .filter(|db| (-100.0..=0.0).contains(db))
        .ok_or_else(|| format!("expected a peak level in dBFS from -100 to 0, found \"{text}\""))
}

/// Parses `NAME=VALUE` for `--set`.
fn parse_assignment(text: &str) -> Result<(String, String), String> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=VALUE, found \"{text}\""))?;
    Ok((name.trim().to_string(), value.trim().to_string()))
}

/// Parses `--bits`.
pub(super) fn parse_bit_depth(text: &str) -> Result<BitDepth, String> {
    text.parse::<u16>()
        .ok()
        .and_then(BitDepth::from_bits)
        .ok_or_else(|| format!("expected 16, 24 or 32, found \"{text}\""))
}

/// Parses `--max-seconds`: a positive number.
fn parse_max_seconds(text: &str) -> Result<f64, String> {
    text.parse::<f64>()
        .ok()
        .filter(|s| s.is_finite() && *s > 0.0)
        .ok_or_else(|| format!("expected a number of seconds above 0, found \"{text}\""))
}
