//! Fitting real strikes: the project's fitter against seed 000's binning method (section 6.2.2)
//! over the corpus of `tests/common/corpus.rs`, both scored by the independent measure of
//! `tests/common/fit_score.rs`.
//!
//! One row per recording: its length, then for each fitter the mean absolute dB difference
//! between the recording and the re-synthesised modes over all frames, the attack (first
//! 200 ms) and the tail, the number of modes, the median error in cents of the modes nearest the
//! five strongest spectral peaks, and the fit's wall time. Then the means, how many files score
//! above 5 dB, how many each refused, how the project's fitter's time compares with the length
//! of the sound, and how often it scores lower.
//!
//! Run with `cargo bench --bench fit`. From the environment: `FIT_ONLY=slug,slug` (a subset),
//! `FIT_CORPUS_DIR=DIR` (also write the recordings as WAV files there; empty for
//! `target/fit-corpus`), and options for the project's fitter: `FIT_MODES`, `FIT_WINDOW_MS`,
//! `FIT_MAX_SECONDS`, `FIT_NOISE_FLOOR_DB`, `FIT_THREADS` (1 unless given; 0 takes one per
//! core). `FIT_SCORE_BANDS=1` prints, for each recording and fitter, the mean signed difference
//! of the re-synthesis from the recording in each band of the score, over the attack and the
//! tail: where a fit is too loud or too quiet.
//!
//! Without `--bench` (as `cargo test --benches` runs it) it decodes the whole corpus, checks every
//! checksum and ending, and scores a few short recordings.

use std::path::PathBuf;
use std::time::Instant;

use modal_resonator::authoring::fit::{fit_bank, FitOptions, Recording};

// Shared with the integration tests, which use other parts of them.
#[allow(dead_code)]
#[path = "../tests/common/corpus.rs"]
mod corpus;
#[allow(dead_code)]
#[path = "../tests/common/decode.rs"]
mod decode;
#[allow(dead_code)]
#[path = "../tests/common/fit_score.rs"]
mod fit_score;
#[path = "fit/reference.rs"]
mod reference;
#[allow(dead_code)]
#[path = "../tests/common/sf2.rs"]
mod sf2;

use corpus::{Ending, Entry};
use fit_score::{fitted_modes, score, Score};

/// Files the quick run scores: short ones, of three packages.
const QUICK_SLUGS: [&str; 3] = ["claves-freepats", "agogo-high-freepats", "claves-fluid"];
/// Recordings at least this long, in seconds, count in the speed summary: a shorter one's fit
/// time is mostly fixed costs.
const SPEED_MIN_S: f64 = 1.0;
/// A file scoring above this, in dB over all frames, is counted as a poor fit.
const POOR_DB: f64 = 5.0;

/// What one fitter made of one recording.
enum Outcome {
    /// The modes' score, how many there were and the fit's wall time in seconds.
    Fitted(Score, usize, f64),
    /// The fitter's error.
    Refused(String),
}

/// The project's fitter's options: the defaults, changed from the environment.
fn options() -> FitOptions {
    let var = |name: &str| -> Option<f64> {
        let v = std::env::var(name).ok()?;
        Some(
            v.parse()
                .unwrap_or_else(|_| panic!("{name}={v}: expected a number")),
        )
    };
    let mut o = FitOptions::default();
    if let Some(v) = var("FIT_MODES") {
        o.max_modes = v as usize;
    }
    if let Some(v) = var("FIT_WINDOW_MS") {
        o.window_s = v / 1e3;
    }
    if let Some(v) = var("FIT_MAX_SECONDS") {
        o.max_seconds = v;
    }
    o.noise_floor_db = var("FIT_NOISE_FLOOR_DB").or(o.noise_floor_db);
    // One core unless asked: the speed target is per core.
    o.threads = var("FIT_THREADS").map_or(1, |v| v as usize);
    o
}

/// Runs the project's fitter on `recording`.
fn ours(recording: &Recording, options: &FitOptions) -> Outcome {
    let start = Instant::now();
    match fit_bank(std::slice::from_ref(recording), options) {
        Ok(fit) => {
            let wall_s = start.elapsed().as_secs_f64();
            let modes = fitted_modes(&fit.bank, 0);
            Outcome::Fitted(score(&modes, recording), modes.len(), wall_s)
        }
        Err(e) => Outcome::Refused(e.to_string()),
    }
}

/// Runs seed 000's method on `recording`.
fn seed_000(recording: &Recording) -> Outcome {
    let start = Instant::now();
    let modes = reference::fit(recording);
    let wall_s = start.elapsed().as_secs_f64();
    if modes.is_empty() {
        return Outcome::Refused("no mode stays over the noise for two frames".into());
    }
    Outcome::Fitted(score(&modes, recording), modes.len(), wall_s)
}

/// Prints the table's heading.
fn print_heading() {
    println!(
        "{:<26} {:>5} {:>4} | {:^39} | {:^39}",
        "recording", "s", "cut", "ours", "seed 000 binning"
    );
    let half = format!(
        "{:>6} {:>6} {:>6} {:>5} {:>6} {:>5}",
        "all dB", "attack", "tail", "modes", "cents", "ms"
    );
    println!("{:<26} {:>5} {:>4} | {half} | {half}", "", "", "");
}

/// `v` to `decimals` places, or "-" where there is nothing to show (a recording with no tail).
fn figure(v: f64, decimals: usize) -> String {
    if v.is_finite() {
        format!("{v:.decimals$}")
    } else {
        "-".into()
    }
}

/// One fitter's half of a row.
fn cells(outcome: &Outcome) -> String {
    match outcome {
        Outcome::Fitted(s, modes, wall_s) => format!(
            "{:>6} {:>6} {:>6} {:>5} {:>6} {:>5.0}",
            figure(s.all_db, 2),
            figure(s.attack_db, 2),
            figure(s.tail_db, 2),
            modes,
            figure(s.peak_cents, 1),
            wall_s * 1e3
        ),
        Outcome::Refused(_) => format!("{:^39}", "refused"),
    }
}

/// Scores both fitters on `entry` and prints its row (and any refusal below it).
fn row(entry: &Entry, recording: &Recording, options: &FitOptions) -> (Outcome, Outcome) {
    let (a, b) = (ours(recording, options), seed_000(recording));
    let cut = if entry.ending == Ending::Ringing {
        "yes"
    } else {
        ""
    };
    println!(
        "{:<26} {:>5.2} {cut:>4} | {} | {}",
        entry.slug,
        seconds(recording),
        cells(&a),
        cells(&b)
    );
    for (who, o) in [("ours", &a), ("seed 000", &b)] {
        if let Outcome::Refused(e) = o {
            println!("    {who} refused: {e}");
        }
    }
    (a, b)
}

/// Length of `recording` in seconds.
fn seconds(recording: &Recording) -> f64 {
    recording.samples.len() as f64 / f64::from(recording.sample_rate_hz)
}

/// Mean of the finite values of `pick` over the fitted outcomes.
fn mean(outcomes: &[&Outcome], pick: impl Fn(&Score, usize) -> f64) -> f64 {
    let values: Vec<f64> = outcomes
        .iter()
        .filter_map(|o| match o {
            Outcome::Fitted(s, m, _) => Some(pick(s, *m)).filter(|v| v.is_finite()),
            Outcome::Refused(_) => None,
        })
        .collect();
    values.iter().sum::<f64>() / values.len() as f64
}

/// Prints one fitter's summary over the corpus.
fn summary(who: &str, outcomes: &[&Outcome]) {
    let fitted: Vec<f64> = outcomes
        .iter()
        .filter_map(|o| match o {
            Outcome::Fitted(s, _, _) => Some(s.all_db),
            Outcome::Refused(_) => None,
        })
        .collect();
    let wall_s: f64 = outcomes
        .iter()
        .map(|o| match o {
            Outcome::Fitted(_, _, w) => *w,
            Outcome::Refused(_) => 0.0,
        })
        .sum();
    println!(
        "{who:<9} mean all {} dB, attack {} dB, tail {} dB; mean {} modes, mean of the median \
         peak errors {} cents; {} of {} files above {POOR_DB} dB; {} refused; fit time {:.1} s \
         in all",
        figure(mean(outcomes, |s, _| s.all_db), 2),
        figure(mean(outcomes, |s, _| s.attack_db), 2),
        figure(mean(outcomes, |s, _| s.tail_db), 2),
        figure(mean(outcomes, |_, m| m as f64), 1),
        figure(mean(outcomes, |s, _| s.peak_cents), 1),
        fitted.iter().filter(|&&v| v > POOR_DB).count(),
        fitted.len(),
        outcomes.len() - fitted.len(),
        wall_s
    );
}

/// Prints how the project's fitter's wall time compares with the length of the sound, over the
/// recordings of at least [`SPEED_MIN_S`] (the target: no longer than the sound lasts).
fn speed(entries: &[&Entry], recordings: &[Recording], pairs: &[(Outcome, Outcome)]) {
    let ratios: Vec<(&str, f64)> = entries
        .iter()
        .zip(recordings)
        .zip(pairs)
        .filter_map(|((e, r), p)| match p.0 {
            Outcome::Fitted(_, _, wall_s) if seconds(r) >= SPEED_MIN_S => {
                Some((e.slug, wall_s / seconds(r)))
            }
            _ => None,
        })
        .collect();
    let Some(&(slowest, worst)) = ratios.iter().max_by(|a, b| a.1.total_cmp(&b.1)) else {
        return;
    };
    println!(
        "ours      on the {} files of at least {SPEED_MIN_S} s: {} fitted slower than they \
         last; slowest {worst:.2} s of fitting per second of sound ({slowest})",
        ratios.len(),
        ratios.iter().filter(|r| r.1 > 1.0).count(),
    );
}

/// Whether the project's fitter did better on a file: a lower score over all frames, or a fit
/// where the reference refused.
fn ours_better(pair: &(Outcome, Outcome)) -> bool {
    match pair {
        (Outcome::Fitted(a, _, _), Outcome::Fitted(b, _, _)) => a.all_db < b.all_db,
        (Outcome::Fitted(..), Outcome::Refused(_)) => true,
        _ => false,
    }
}

/// Scores both fitters over `entries`, printing the table and the summary.
fn compare(entries: &[&Entry], recordings: &[Recording]) {
    let options = options();
    print_heading();
    let pairs: Vec<(Outcome, Outcome)> = entries
        .iter()
        .zip(recordings)
        .map(|(e, r)| row(e, r, &options))
        .collect();
    println!();
    summary("ours", &pairs.iter().map(|p| &p.0).collect::<Vec<_>>());
    summary("seed 000", &pairs.iter().map(|p| &p.1).collect::<Vec<_>>());
    speed(entries, recordings, &pairs);
    println!(
        "ours better (lower all-frames score) on {} of {} files",
        pairs.iter().filter(|p| ours_better(p)).count(),
        pairs.len()
    );
}

/// Loads `entries`, checked; with `FIT_CORPUS_DIR` also writes them as WAV files.
fn load(entries: &[&'static Entry]) -> Vec<Recording> {
    let result = match std::env::var_os("FIT_CORPUS_DIR") {
        Some(dir) => {
            let dir = if dir.is_empty() {
                PathBuf::from(corpus::DEFAULT_EXTRACT_DIR)
            } else {
                PathBuf::from(dir)
            };
            let written = corpus::extract_entries(entries, &dir);
            if written.is_ok() {
                println!("wrote {} WAV files to {}", entries.len(), dir.display());
            }
            written
        }
        None => entries.iter().map(|e| e.load()).collect(),
    };
    result.unwrap_or_else(|e| panic!("{e}"))
}

fn main() {
    // `cargo test --benches` runs this without --bench: keep that quick.
    let quick = !std::env::args().any(|a| a == "--bench");
    if quick {
        let all = corpus::select(&[]).unwrap();
        let recordings = load(&all);
        let seconds: f64 = recordings
            .iter()
            .map(|r| r.samples.len() as f64 / f64::from(r.sample_rate_hz))
            .sum();
        println!(
            "corpus: {} recordings ({seconds:.1} s), checksums and endings as pinned",
            all.len()
        );
        let only: Vec<String> = QUICK_SLUGS.iter().map(|s| s.to_string()).collect();
        let entries = corpus::select(&only).unwrap();
        let picked = entries
            .iter()
            .map(|e| recordings[all.iter().position(|a| a.slug == e.slug).unwrap()].clone())
            .collect::<Vec<_>>();
        compare(&entries, &picked);
        return;
    }
    let only: Vec<String> = std::env::var("FIT_ONLY")
        .map(|v| v.split(',').map(|s| s.trim().to_string()).collect())
        .unwrap_or_default();
    let entries = corpus::select(&only).unwrap_or_else(|e| panic!("{e}"));
    let recordings = load(&entries);
    compare(&entries, &recordings);
}
