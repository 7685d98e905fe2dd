//! The `modal-resonator` command: plays the instrument standalone, renders banks offline,
//! fits them to recordings, inspects and validates them.
//! Thin over the library: every decision about sound lives in `modal_resonator`.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::{Duration, Instant};

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use modal_resonator::engine::{Controls, PreparedBank};
use modal_resonator::model::factory::{factory_bank, factory_banks, factory_slug};
use modal_resonator::model::fit::{fit_bank, read_wav_recording, save_report_file, FitOptions};
use modal_resonator::model::schema::bank_schema_json;
use modal_resonator::model::summary::BankSummary;
use modal_resonator::model::{load_bank_file, save_bank_file, Bank};
use modal_resonator::render::{
    parse_notes, read_midi_file, render, write_wav, BitDepth, Note, RenderSettings,
};

/// Work after which a progress bar appears, so quick renders print nothing but the summary.
const PROGRESS_DELAY: Duration = Duration::from_secs(1);

/// Steps of the progress bar.
const PROGRESS_STEPS: u64 = 1000;

/// Modal Resonator: modal-synthesis instrument and bank tool.
#[derive(Debug, Parser)]
#[command(name = "modal-resonator", version, about)]
struct Cli {
    /// What to do; with none, plays the instrument standalone (as `play`, taking its options:
    /// `modal-resonator --backend dummy`).
    #[command(subcommand)]
    command: Option<Command>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
enum Command {
    /// Play the instrument standalone: audio and MIDI through JACK or ALSA (`--backend dummy`
    /// runs headless). Options after `play` go to the standalone; `play --help` lists them.
    Play {
        /// Standalone options, e.g. --backend alsa --sample-rate 48000 --period-size 256.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
    /// Render notes or a MIDI file through a bank to a stereo WAV file.
    Render(RenderArgs),
    /// Fit a bank to recordings of an object struck at one or more positions.
    Fit(FitArgs),
    /// Check bank files and print every problem found.
    Validate {
        /// Bank files (JSON).
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Describe a bank: modes, positions, frequency range, T60s.
    Info {
        /// Bank file (JSON) or factory preset name.
        bank: String,
    },
    /// List the factory banks.
    List,
    /// Print the JSON Schema of the bank format.
    Schema,
}

/// Arguments of `render`.
#[derive(Debug, Args)]
#[command(group(clap::ArgGroup::new("input").required(true).args(["notes", "midi"])))]
struct RenderArgs {
    /// Bank file (JSON) or factory preset name.
    bank: String,
    /// Notes as key:velocity@time_s[+duration_s], comma-separated, e.g. "60:0.8@0, 64:0.5@0.25+0.5".
    #[arg(long)]
    notes: Option<String>,
    /// Standard MIDI file to play (all tracks and channels).
    #[arg(long, value_name = "FILE")]
    midi: Option<PathBuf>,
    /// WAV file to write.
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
}

/// Arguments of `fit`.
#[derive(Debug, Args)]
struct FitArgs {
    /// WAV recordings (mono or stereo) of one strike each, one per position, as FILE.wav or
    /// FILE.wav=POSITION; the position is named after the file when not given.
    #[arg(required = true, value_name = "FILE[=POSITION]")]
    recordings: Vec<String>,
    /// Bank file (JSON) to write.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Most modes in the bank: the strongest by energy are kept.
    #[arg(long, default_value_t = 64)]
    modes: usize,
    /// Lowest mode frequency searched, in Hz.
    #[arg(long, default_value_t = 20.0)]
    min_hz: f64,
    /// Highest mode frequency searched, in Hz (never above 0.45 times the sample rate).
    #[arg(long, default_value_t = 20_000.0)]
    max_hz: f64,
    /// Noise floor in dBFS: the weakest mode amplitude trusted, and where decay fits stop.
    /// Estimated from each recording when not given.
    #[arg(long, allow_hyphen_values = true, value_name = "DB")]
    noise_floor_db: Option<f64>,
    /// Analysis window in milliseconds: longer separates closer modes, shorter follows faster
    /// decays.
    #[arg(long, default_value_t = 170.0, value_name = "MS")]
    window_ms: f64,
    /// Longest stretch of each recording analysed after the strike, in seconds.
    #[arg(long, default_value_t = 10.0)]
    max_seconds: f64,
    /// Bank name (default: the output file's name).
    #[arg(long)]
    name: Option<String>,
    /// Author written into the bank.
    #[arg(long, default_value = "")]
    author: String,
    /// SPDX licence of the bank, usually that of the recordings, e.g. CC0-1.0.
    #[arg(long, default_value = "")]
    license: String,
    /// Also write the report to this file: JSON if it ends in .json, else text.
    #[arg(long, value_name = "FILE")]
    report: Option<PathBuf>,
}

fn main() -> ExitCode {
    // Options with no subcommand go to the standalone: `modal-resonator --backend dummy`.
    let argv: Vec<String> = std::env::args().skip(1).collect();
    let standalone_options = argv
        .first()
        .is_some_and(|a| a.starts_with("--") && a != "--help" && a != "--version");
    let cli = if standalone_options {
        Cli {
            command: Some(Command::Play { args: argv }),
        }
    } else {
        Cli::parse()
    };
    let result = match cli.command {
        Some(Command::Render(args)) => run_render(&args),
        Some(Command::Fit(args)) => run_fit(&args),
        Some(Command::Validate { files }) => run_validate(&files),
        Some(Command::Info { bank }) => load_bank(&bank).map(|b| print!("{}", BankSummary::of(&b))),
        Some(Command::List) => {
            for bank in factory_banks() {
                println!(
                    "{:<28} {:>5} modes  {}",
                    factory_slug(&bank),
                    bank.modes.len(),
                    bank.name
                );
            }
            Ok(())
        }
        Some(Command::Schema) => {
            print!("{}", bank_schema_json());
            Ok(())
        }
        Some(Command::Play { args }) => play(args),
        None => play(Vec::new()),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

/// Runs the instrument through nice-plug's standalone wrapper until it is stopped.
#[cfg(feature = "standalone")]
fn play(args: Vec<String>) -> Result<(), String> {
    let argv = std::iter::once("modal-resonator".to_string()).chain(args);
    if nice_plug::prelude::nice_export_standalone_with_args::<modal_resonator::ModalResonator, _>(
        argv,
    ) {
        Ok(())
    } else {
        Err("the standalone could not start an audio backend".to_string())
    }
}

/// Without the standalone feature there is nothing to play: say so.
#[cfg(not(feature = "standalone"))]
fn play(_args: Vec<String>) -> Result<(), String> {
    let _ = <Cli as clap::CommandFactory>::command().print_help();
    Err("this build has no standalone player (build with the `standalone` feature)".to_string())
}

/// Loads the bank named on the command line: a bank file (validated) if `arg` is a path that
/// exists, else the factory bank of that name or slug.
fn load_bank(arg: &str) -> Result<Bank, String> {
    let path = Path::new(arg);
    if path.exists() {
        return load_bank_file(path).map_err(|e| e.to_string());
    }
    factory_bank(arg).ok_or_else(|| {
        let names: Vec<String> = factory_banks().iter().map(factory_slug).collect();
        format!(
            "no bank file or factory preset named \"{arg}\"; factory presets: {}",
            names.join(", ")
        )
    })
}

/// `validate`: every problem of every file; fails if any file has one.
fn run_validate(files: &[PathBuf]) -> Result<(), String> {
    let mut bad = 0;
    for path in files {
        match load_bank_file(path) {
            Ok(bank) => println!(
                "{}: ok ({} modes, {} positions)",
                path.display(),
                bank.modes.len(),
                bank.positions.len()
            ),
            Err(e) => {
                bad += 1;
                println!("{e}");
            }
        }
    }
    match bad {
        0 => Ok(()),
        n => Err(format!("{n} of {} files have problems", files.len())),
    }
}

/// `render`: everything is checked before rendering, and nothing is written on failure.
fn run_render(args: &RenderArgs) -> Result<(), String> {
    let bank = load_bank(&args.bank)?;
    let mut controls = Controls::for_bank(&bank);
    for (name, value) in &args.set {
        controls
            .set_by_name(name, value)
            .map_err(|e| format!("--set {name}={value}: {e}"))?;
    }
    let notes: Vec<Note> = match (&args.notes, &args.midi) {
        (Some(text), _) => parse_notes(text).map_err(|e| format!("--notes: {e}"))?,
        (None, Some(path)) => read_midi_file(path).map_err(|e| e.to_string())?,
        (None, None) => unreachable!("clap requires --notes or --midi"),
    };
    if let Some(late) = notes.iter().position(|n| n.time_s >= args.max_seconds) {
        return Err(format!(
            "note {} starts at {} s, at or after --max-seconds {}",
            late + 1,
            notes[late].time_s,
            args.max_seconds
        ));
    }
    check_output_dir(&args.output)?;
    let inputs = [Some(Path::new(&args.bank)), args.midi.as_deref()];
    for input in inputs.into_iter().flatten() {
        if same_file(input, &args.output) {
            return Err(format!(
                "{}: the output would overwrite an input",
                args.output.display()
            ));
        }
    }
    let settings = RenderSettings {
        sample_rate_hz: args.rate,
        bit_depth: args.bits,
        controls,
        max_seconds: args.max_seconds,
        ..RenderSettings::default()
    };

    let started = Instant::now();
    let bank = Arc::new(PreparedBank::new(&bank));
    let bar = ProgressBar::with_draw_target(Some(PROGRESS_STEPS), ProgressDrawTarget::hidden());
    bar.set_style(
        ProgressStyle::with_template("rendering {bar:40} {percent:>3}% {elapsed}")
            .expect("a valid template"),
    );
    let mut show_bar = std::io::stderr().is_terminal();
    let rendered = render(&bank, &notes, &settings, |done| {
        if show_bar && started.elapsed() >= PROGRESS_DELAY {
            bar.set_draw_target(ProgressDrawTarget::stderr());
            show_bar = false;
        }
        bar.set_position((done * PROGRESS_STEPS as f64) as u64);
    });
    bar.finish_and_clear();
    write_wav(&args.output, &rendered, args.bits, args.rate).map_err(|e| e.to_string())?;

    let peak_dbfs = rendered.peak_dbfs();
    let clipped = args.bits != BitDepth::Float32 && rendered.peak() > 1.0;
    println!(
        "{}: {:.2} s, {} Hz {}, peak {:.1} dBFS{}, up to {} voices, rendered in {:.2} s{}",
        args.output.display(),
        rendered.duration_s(),
        args.rate,
        args.bits.name(),
        peak_dbfs,
        if clipped { " (clipped)" } else { "" },
        rendered.max_voices,
        started.elapsed().as_secs_f64(),
        if rendered.cut_short {
            ", cut at --max-seconds"
        } else {
            ""
        },
    );
    Ok(())
}

/// `fit`: reads every recording, fits, writes the bank (and the report if asked) and prints the
/// report. Nothing is written on failure.
fn run_fit(args: &FitArgs) -> Result<(), String> {
    check_output_dir(&args.output)?;
    let mut recordings = Vec::with_capacity(args.recordings.len());
    for arg in &args.recordings {
        let (path, position) = split_recording_arg(arg);
        if same_file(&path, &args.output) {
            return Err(format!(
                "{}: the output would overwrite an input",
                args.output.display()
            ));
        }
        recordings.push(read_wav_recording(&path, &position).map_err(|e| e.to_string())?);
    }
    if let Some(report) = &args.report {
        check_output_dir(report)?;
    }
    let name = args.name.clone().unwrap_or_else(|| {
        args.output
            .file_stem()
            .map_or("Fitted bank".to_string(), |s| {
                s.to_string_lossy().into_owned()
            })
    });
    let options = FitOptions {
        name,
        max_modes: args.modes,
        min_hz: args.min_hz,
        max_hz: args.max_hz,
        noise_floor_db: args.noise_floor_db,
        window_s: args.window_ms * 1e-3,
        max_seconds: args.max_seconds,
    };
    let mut fit = fit_bank(&recordings, &options).map_err(|e| e.to_string())?;
    fit.bank.author = args.author.clone();
    fit.bank.license = args.license.clone();
    save_bank_file(&fit.bank, &args.output).map_err(|e| e.to_string())?;
    if let Some(path) = &args.report {
        save_report_file(&fit.report, path)
            .map_err(|e| format!("{}: cannot write the report: {e}", path.display()))?;
    }
    print!("{}", fit.report);
    for r in &fit.report.recordings {
        for w in &r.warnings {
            eprintln!("warning: {}: {w}", r.name);
        }
    }
    println!(
        "{}: {} modes, {} positions",
        args.output.display(),
        fit.bank.modes.len(),
        fit.bank.positions.len()
    );
    Ok(())
}

/// `FILE=POSITION` or `FILE`: the file and the position name (the file's stem when not given).
/// A file whose own name holds `=` is taken whole when it exists.
fn split_recording_arg(arg: &str) -> (PathBuf, String) {
    let whole = PathBuf::from(arg);
    if let Some((file, position)) = arg.rsplit_once('=') {
        if !whole.exists() {
            return (PathBuf::from(file), position.to_string());
        }
    }
    let position = whole
        .file_stem()
        .map_or_else(|| arg.to_string(), |s| s.to_string_lossy().into_owned());
    (whole, position)
}

/// Fails early, before a long render, when the output is a directory or its directory does not
/// exist.
fn check_output_dir(output: &Path) -> Result<(), String> {
    if output.is_dir() {
        return Err(format!("{}: is a directory", output.display()));
    }
    match output.parent() {
        Some(dir) if !dir.as_os_str().is_empty() && !dir.is_dir() => Err(format!(
            "{}: directory {} does not exist",
            output.display(),
            dir.display()
        )),
        _ => Ok(()),
    }
}

/// Whether `a` and `b` name the same existing file.
fn same_file(a: &Path, b: &Path) -> bool {
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Parses `NAME=VALUE` for `--set`.
fn parse_assignment(text: &str) -> Result<(String, String), String> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("expected NAME=VALUE, found \"{text}\""))?;
    Ok((name.trim().to_string(), value.trim().to_string()))
}

/// Parses `--bits`.
fn parse_bit_depth(text: &str) -> Result<BitDepth, String> {
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
