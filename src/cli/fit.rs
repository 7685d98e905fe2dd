//! `modal-resonator fit`: a bank from recordings of an object struck at one or more positions.

use std::path::{Path, PathBuf};

use clap::Args;

use modal_resonator::authoring::fit::{
    fit_bank_with_progress, read_wav_recording, stage_report_file, FitOptions, DEFAULT_MAX_MODES,
};
use modal_resonator::bank::{commit_all, stage_bank_file};

use modal_resonator::bank::validate::validate_bank;

use super::progress::Progress;
use super::{check_output, is_stdout, output_name, same_file, save_bank_output, say};

/// Arguments of `fit`.
#[derive(Debug, Args)]
pub(super) struct FitArgs {
    /// WAV recordings (mono or stereo) of one strike each, one per position, as FILE.wav or
    /// FILE.wav=POSITION; the position is named after the file when not given.
    #[arg(required = true, value_name = "FILE[=POSITION]")]
    recordings: Vec<String>,
    /// Bank file (JSON) to write; - writes it to standard output.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Most modes in the bank: the fit keeps the modes that measurably improve the
    /// resynthesis, and the strongest by energy of those when there are more.
    #[arg(long, default_value_t = DEFAULT_MAX_MODES)]
    modes: usize,
    /// Lowest mode frequency searched, in Hz (at least 1, the lowest a bank may hold).
    #[arg(long, default_value_t = 20.0)]
    min_hz: f64,
    /// Highest mode frequency searched, in Hz (never above 0.45 times the sample rate).
    #[arg(long, default_value_t = 20_000.0)]
    max_hz: f64,
    /// Noise floor in dBFS: the weakest mode amplitude kept. Judged band by band from each
    /// recording when not given.
    #[arg(long, allow_hyphen_values = true, value_name = "DB")]
    noise_floor_db: Option<f64>,
    /// Window of the noise estimate and of the report's per-mode tracks, in milliseconds.
    #[arg(long, default_value_t = 170.0, value_name = "MS")]
    window_ms: f64,
    /// Longest stretch of each recording analysed after the strike, in seconds.
    #[arg(long, default_value_t = 10.0)]
    max_seconds: f64,
    /// Threads fitting at once (0: one per core). The bank is the same on any number.
    #[arg(long, default_value_t = 0, value_name = "N")]
    threads: usize,
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

/// `fit`: reads every recording, fits, writes the bank (and the report if asked) and prints the
/// report. Nothing is written on failure: both files are staged before either is put in place.
pub(super) fn run(args: &FitArgs) -> Result<(), String> {
    let split: Vec<(PathBuf, String)> = args
        .recordings
        .iter()
        .map(|arg| split_recording_arg(arg))
        .collect();
    let inputs: Vec<(&str, &Path)> = split
        .iter()
        .map(|(path, _)| ("the recording", path.as_path()))
        .collect();
    check_output("-o", &args.output, &inputs)?;
    if let Some(report) = &args.report {
        check_output("--report", report, &inputs)?;
        if same_file(report, &args.output) {
            return Err(format!(
                "{}: the report and the bank would be the same file; name another --report",
                report.display()
            ));
        }
    }
    let mut recordings = Vec::with_capacity(split.len());
    for (path, position) in &split {
        recordings.push(read_wav_recording(path, position).map_err(|e| e.to_string())?);
    }
    let name = args.name.clone().unwrap_or_else(|| {
        let stem = args.output.file_stem().filter(|_| !is_stdout(&args.output));
        stem.map_or("Fitted bank".to_string(), |s| {
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
        threads: args.threads,
    };
    let mut progress = Progress::new("fitting");
    let fit = fit_bank_with_progress(&recordings, &options, |done| progress.set(done));
    progress.finish();
    let mut fit = fit.map_err(|e| e.to_string())?;
    fit.bank.author = args.author.clone();
    fit.bank.license = args.license.clone();
    let cannot_write = |path: &std::path::Path, e: std::io::Error| {
        format!("{}: cannot write: {e}", path.display())
    };
    let mut files = Vec::new();
    if !is_stdout(&args.output) {
        files.push(stage_bank_file(&fit.bank, &args.output).map_err(|e| e.to_string())?);
    } else if let Some(problem) = validate_bank(&fit.bank).first() {
        return Err(format!("the fitted bank is not valid: {problem}"));
    }
    if let Some(path) = &args.report {
        files.push(stage_report_file(&fit.report, path).map_err(|e| cannot_write(path, e))?);
    }
    commit_all(files).map_err(|(path, e)| cannot_write(&path, e))?;
    if is_stdout(&args.output) {
        save_bank_output(&fit.bank, &args.output)?;
    }
    say(&args.output, fit.report.to_string().trim_end());
    for r in &fit.report.recordings {
        for w in &r.warnings {
            eprintln!("warning: {}: {w}", r.name);
        }
    }
    say(
        &args.output,
        &format!(
            "{}: {} modes, {} positions",
            output_name(&args.output),
            fit.bank.modes.len(),
            fit.bank.positions.len()
        ),
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
