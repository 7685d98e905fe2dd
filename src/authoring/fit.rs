//! Banks from recordings of struck objects (seed 000 sections 3.3 and 6.2, improved).
//!
//! One recording per strike position. For each: find the onset ([`onset`]), split the sound
//! into frequency bands ([`subband`]), find each band's modes by ESPRIT ([`esprit`]) and refine
//! them, with the time of the strike, against the band's signal, keeping those that shorten its
//! description ([`refine`], [`bandfit`]); leave out hum ([`analyse`]); then match each mode's
//! level over time to the recording's, in dB, and give the partials still missing a mode
//! ([`levels`]). Then match modes across recordings and measure every mode's gain in every
//! recording ([`combine`]), and score each recording against the bank re-synthesised at its
//! position ([`fidelity`]). The noise spectrum ([`noise`]) and the per-mode tracks ([`track`])
//! feed the report.
//!
//! Gains are in the bank format's units: the amplitude, in full scale of the recording, of the
//! mode at the strike, `y_k(t) = sum_n a_nk exp(-d_n t) sin(2 pi f_n t)`. The engine normalises a
//! bank's loudness when it plays it, so only the ratios between gains (across modes and across
//! positions) change the sound.

mod analyse;
mod analysis;
mod bandfit;
mod closed_form;
mod combine;
mod error;
mod esprit;
mod fidelity;
mod levels;
mod linalg;
mod lsq;
mod noise;
mod onset;
mod refine;
mod report;
mod stft;
mod subband;
mod track;
mod warnings;
mod wav;

use std::collections::HashSet;

use serde_json::{json, Map};

pub use error::FitError;
pub use fidelity::{synthesize_strike, Fidelity};
pub use report::{save_report_file, stage_report_file, FitReport, ModeReport, RecordingReport};
pub use wav::read_wav_recording;

use self::analyse::{analyse, prepare};
use self::analysis::Analysis;
use self::combine::{combine, Combined};
use self::fidelity::fidelity;
use self::lsq::Shape;
use crate::bank::format::MAX_FREQ_RATIO;
use crate::bank::format::{Bank, Mode, Position};
use crate::units::decay_to_t60_s;

/// Most modes in a fitted bank by default: a bound, not a target (the fit keeps the modes that
/// measurably improve the resynthesis), high enough for a bell or a plate, low enough that a
/// voice stays cheap.
pub const DEFAULT_MAX_MODES: usize = 200;

/// Share of a fit's progress the analyses of the recordings stand for; combining them and the
/// report take the rest.
const ANALYSIS_SHARE: f64 = 0.9;

/// Highest frequency searched by default, in Hz: the top of hearing.
pub const DEFAULT_MAX_HZ: f64 = 20_000.0;

/// One recording of the object struck at one position.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Name of the strike position, for example "edge"; unique among the recordings.
    pub name: String,
    /// Mono samples, full scale 1.
    pub samples: Vec<f32>,
    /// Sample rate in Hz.
    pub sample_rate_hz: u32,
    /// Notes about how the samples were read (for example a stereo mix), passed to the report.
    pub notes: Vec<String>,
    /// Where the recording came from, for error messages: its file and position name, or the
    /// position name alone for a recording made in memory.
    pub origin: String,
}

impl Recording {
    /// A mono recording with no notes.
    pub fn new(name: impl Into<String>, samples: Vec<f32>, sample_rate_hz: u32) -> Self {
        let name = name.into();
        Self {
            origin: name.clone(),
            name,
            samples,
            sample_rate_hz,
            notes: Vec::new(),
        }
    }
}

/// How to fit.
#[derive(Debug, Clone, PartialEq)]
pub struct FitOptions {
    /// Name of the bank.
    pub name: String,
    /// Most modes in the bank: the fit keeps the modes that measurably improve the
    /// resynthesis, and the strongest by energy of those when there are more.
    pub max_modes: usize,
    /// Lowest mode frequency searched, in Hz.
    pub min_hz: f64,
    /// Highest mode frequency searched, in Hz; never above 0.45 times a recording's sample rate
    /// (the engine plays nothing higher).
    pub max_hz: f64,
    /// Noise floor as the amplitude, in dBFS, of the weakest mode envelope trusted; `None`
    /// estimates it from each recording.
    pub noise_floor_db: Option<f64>,
    /// Window of the noise estimate and of the report's per-mode tracks, in seconds (rounded
    /// to a power of two of samples).
    pub window_s: f64,
    /// Longest stretch of each recording analysed after the strike, in seconds.
    pub max_seconds: f64,
    /// Threads that fit a recording's bands at once; 0 takes one per core. The bank does not
    /// depend on it.
    pub threads: usize,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            name: "Fitted bank".to_string(),
            max_modes: DEFAULT_MAX_MODES,
            min_hz: 20.0,
            max_hz: DEFAULT_MAX_HZ,
            noise_floor_db: None,
            window_s: 0.17,
            max_seconds: 10.0,
            threads: 0,
        }
    }
}

impl FitOptions {
    /// Highest frequency searched in a recording at `sample_rate_hz`.
    pub fn max_hz(&self, sample_rate_hz: u32) -> f64 {
        self.max_hz.min(MAX_FREQ_RATIO * sample_rate_hz as f64)
    }

    /// Checks every option, saying what is wrong.
    fn check(&self) -> Result<(), FitError> {
        let bad = |message: String| Err(FitError::BadOption { message });
        if self.name.trim().is_empty() {
            return bad("the bank name is empty: give a name with a visible character".into());
        }
        if !(1..=crate::bank::validate::MAX_MODES).contains(&self.max_modes) {
            return bad(format!(
                "--modes {}: expected 1 to {}",
                self.max_modes,
                crate::bank::validate::MAX_MODES
            ));
        }
        let lowest = crate::bank::validate::MODE_FREQ_HZ.min;
        if !(self.min_hz.is_finite() && self.min_hz >= lowest && self.max_hz > self.min_hz) {
            return bad(format!(
                "frequency range {} Hz to {} Hz: expected {lowest} <= --min-hz < --max-hz",
                self.min_hz, self.max_hz
            ));
        }
        if let Some(db) = self.noise_floor_db {
            if !(db.is_finite() && (-200.0..0.0).contains(&db)) {
                return bad(format!(
                    "--noise-floor-db {db}: expected a level in dBFS from -200 to below 0"
                ));
            }
        }
        if !(self.window_s.is_finite() && (0.005..=2.0).contains(&self.window_s)) {
            return bad(format!(
                "--window-ms {}: expected 5 ms to 2000 ms",
                self.window_s * 1e3
            ));
        }
        if !(self.max_seconds.is_finite() && self.max_seconds > 0.0) {
            return bad(format!(
                "--max-seconds {}: expected a positive number of seconds",
                self.max_seconds
            ));
        }
        Ok(())
    }
}

/// A fitted bank and its report.
#[derive(Debug, Clone, PartialEq)]
pub struct FitResult {
    /// The bank: one position per recording, in the order given.
    pub bank: Bank,
    /// How it was measured and how close it comes to the recordings.
    pub report: FitReport,
}

/// Fits a bank to `recordings` of one object, one per strike position.
pub fn fit_bank(recordings: &[Recording], options: &FitOptions) -> Result<FitResult, FitError> {
    fit_bank_with_progress(recordings, options, |_| {})
}

/// [`fit_bank`], telling `progress` the share of the analysis done (0 to 1) as it goes.
pub fn fit_bank_with_progress(
    recordings: &[Recording],
    options: &FitOptions,
    mut progress: impl FnMut(f64),
) -> Result<FitResult, FitError> {
    options.check()?;
    if recordings.is_empty() {
        return Err(FitError::NoRecordings);
    }
    let mut names = HashSet::new();
    for r in recordings {
        if r.name.trim().is_empty() {
            return Err(FitError::EmptyName);
        }
        if !names.insert(r.name.as_str()) {
            return Err(FitError::DuplicateName {
                name: r.name.clone(),
            });
        }
    }
    let count = recordings.len() as f64;
    let analyses = recordings
        .iter()
        .enumerate()
        .map(|(k, r)| {
            analyse(r, options, &mut |done| {
                progress(ANALYSIS_SHARE * (k as f64 + done) / count)
            })
        })
        .collect::<Result<Vec<Analysis>, FitError>>()?;
    let modes_found: usize = analyses.iter().map(|a| a.modes.len()).sum();
    let modes = combine(&analyses, options.max_modes);
    if modes.is_empty() {
        let floor = median_floor_dbfs(
            &analyses[0],
            options.min_hz,
            options.max_hz(recordings[0].sample_rate_hz),
        );
        return Err(FitError::NoModes {
            noise_floor_db: floor,
        });
    }
    let bank = build_bank(recordings, options, &modes);
    let report = build_report(&analyses, options, &modes, &bank, modes_found);
    progress(1.0);
    Ok(FitResult { bank, report })
}

/// How close `bank` comes to each of `recordings`: the log-spectral distance and level of the
/// bank re-synthesised by `resynthesize` (the bank, the position named like the recording, the
/// recording's rate and length) as the fit's report gives them. For scoring a bank after
/// editing, or a stored bank against the recordings it came from: `render::resynthesize`
/// plays it as the engine does, with its default controls; [`synthesize_strike`] plays its
/// modes alone.
pub fn compare(
    bank: &Bank,
    recordings: &[Recording],
    options: &FitOptions,
    resynthesize: impl Fn(&Bank, usize, u32, usize) -> Vec<f64>,
) -> Result<Vec<Fidelity>, FitError> {
    options.check()?;
    recordings
        .iter()
        .map(|r| {
            let position = bank
                .positions
                .iter()
                .position(|p| p.name == r.name)
                .ok_or_else(|| FitError::BadOption {
                    message: format!(
                        "the bank has no position named \"{}\" to compare the recording with",
                        r.name
                    ),
                })?;
            let a = prepare(r, options)?;
            let max_hz = options.max_hz(r.sample_rate_hz);
            let synth = resynthesize(bank, position, r.sample_rate_hz, a.signal.len());
            Ok(fidelity(&synth, &a, options.min_hz, max_hz))
        })
        .collect()
}

/// The bank of `modes`, with the recordings and options in its `source`.
fn build_bank(recordings: &[Recording], options: &FitOptions, modes: &[Combined]) -> Bank {
    let positions = recordings
        .iter()
        .enumerate()
        .map(|(k, r)| Position {
            name: r.name.clone(),
            coords: vec![k as f64],
        })
        .collect();
    let mut bank = Bank::new(options.name.clone(), positions);
    let names: Vec<&str> = recordings.iter().map(|r| r.name.as_str()).collect();
    bank.description = format!("Fitted from recordings of strikes at {}.", names.join(", "));
    let mut source = Map::new();
    source.insert("kind".into(), json!("fitted"));
    source.insert("recordings".into(), json!(names));
    source.insert("max_modes".into(), json!(options.max_modes));
    source.insert("min_hz".into(), json!(options.min_hz));
    source.insert("max_hz".into(), json!(options.max_hz));
    if let Some(db) = options.noise_floor_db {
        source.insert("noise_floor_db".into(), json!(db));
    }
    bank.source = Some(source);
    bank.modes = modes
        .iter()
        .map(|m| Mode {
            freq_hz: m.freq_hz,
            decay_per_s: m.decay_per_s,
            gains: m.gains.clone(),
        })
        .collect();
    bank
}

/// The report: per mode from the combination, per recording from the analysis and the
/// comparison with the bank.
fn build_report(
    analyses: &[Analysis],
    options: &FitOptions,
    modes: &[Combined],
    bank: &Bank,
    modes_found: usize,
) -> FitReport {
    let largest = modes
        .iter()
        .flat_map(|m| m.gains.iter())
        .fold(0.0f64, |a, g| a.max(g.abs()));
    let shapes: Vec<Shape> = modes
        .iter()
        .map(|m| Shape {
            freq_hz: m.freq_hz,
            decay_per_s: m.decay_per_s,
        })
        .collect();
    let recordings = analyses
        .iter()
        .enumerate()
        .map(|(k, a)| {
            let rate = a.sample_rate_hz;
            let max_hz = options.max_hz(rate as u32);
            let synth = synthesize_strike(bank, k, rate as u32, a.signal.len());
            let score = fidelity(&synth, a, options.min_hz, max_hz);
            let inside: Vec<Shape> = shapes
                .iter()
                .copied()
                .filter(|s| s.freq_hz < 0.5 * rate)
                .collect();
            let amplitudes = a.amplitudes(&inside);
            let residual = a.residual(&inside, &amplitudes);
            let energy = |x: &[f64]| x[a.start.min(x.len())..].iter().map(|v| v * v).sum::<f64>();
            RecordingReport {
                name: a.name.clone(),
                sample_rate_hz: rate as u32,
                onset_s: a.strike.onset as f64 / rate,
                sound_s: a.signal.len() as f64 / rate,
                window_samples: a.window_len,
                snr_db: a.strike.snr_db,
                noise_floor_dbfs: median_floor_dbfs(a, options.min_hz, max_hz),
                modes_found: a.modes.len(),
                lsd_db: score.lsd_db,
                level_db: score.level_db,
                residual_db: 10.0 * (energy(&residual) / energy(&a.signal).max(1e-300)).log10(),
                warnings: a.warnings.clone(),
            }
        })
        .collect();
    let modes = modes
        .iter()
        .map(|m| ModeReport {
            freq_hz: m.freq_hz,
            decay_per_s: m.decay_per_s,
            t60_s: if m.decay_per_s > 0.0 {
                decay_to_t60_s(m.decay_per_s)
            } else {
                f64::INFINITY
            },
            gains_db: m
                .gains
                .iter()
                .map(|&g| (g != 0.0).then(|| 20.0 * (g.abs() / largest).log10()))
                .collect(),
            measured_in: analyses[m.source].name.clone(),
            fit_frames: m.track.frames,
            fit_error_db: m.track.rms_error_db,
            snr_db: m.track.snr_db,
            findings: m.findings,
        })
        .collect();
    FitReport {
        recordings,
        modes,
        range_hz: (options.min_hz, options.max_hz),
        max_modes: options.max_modes,
        modes_found,
    }
}

/// Median over the frequency range of a recording's noise floor, as a mode amplitude in dBFS.
fn median_floor_dbfs(a: &Analysis, min_hz: f64, max_hz: f64) -> f64 {
    const STEPS: usize = 200;
    let mut floors: Vec<f64> = (0..=STEPS)
        .map(|i| {
            let f = min_hz * (max_hz / min_hz).powf(i as f64 / STEPS as f64);
            20.0 * a.floor_amplitude(f).max(1e-300).log10()
        })
        .collect();
    floors.sort_by(f64::total_cmp);
    floors[STEPS / 2]
}
