//! Mode compression: fewer modes that sound the same, to make large banks cheaper to play.
//!
//! Two steps, both offline (seed 000 section 5.4.1, after Raghuvanshi and Lin):
//!
//! 1. **Merge** modes closer in frequency than the difference limen ([`difference_limen_hz`]):
//!    a listener hears them as one. The merged mode's gain at each position is the sum of the
//!    members' gains there (the seed: "replace the corresponding columns with a single column
//!    equating to the sum"), so every strike position keeps its own response. Its frequency is the
//!    members' average weighted by their energy (seed 000 eq. 5.15), so a faint neighbour barely
//!    moves a strong mode; its decay is the members' average ("average the dampings"), with the
//!    same weights for the same reason: a plain mean would let a faint, fast-dying neighbour
//!    shorten the ring of a strong, long one several-fold.
//! 2. **Drop** modes whose largest gain over all positions lies more than a set level below the
//!    strongest mode's: at -80 dB they are below the truncation threshold of any strike that is
//!    not at full scale, and far below what the strongest mode masks.
//!
//! A cluster of modes to merge spans less than the limen: a mode joins the cluster when it lies
//! within the limen (at the pair's mean frequency) of the cluster's lowest member, so a dense
//! run of modes each close to the next is not chained into one mode spanning a wide band.

use std::f64::consts::TAU;
use std::fmt;

use serde_json::json;

use super::limen::difference_limen_hz;
use crate::bank::format::MIN_DECAY_PER_S;
use crate::bank::validate::validate_bank;
use crate::bank::{Bank, Mode, Problem};

/// Default level below the strongest mode under which modes are dropped, in dB.
pub const DEFAULT_DROP_BELOW_DB: f64 = -80.0;

/// Largest limen scale: modes ten limens apart are heard as clearly apart, and merging them
/// would change the sound, not only its cost.
pub const MAX_LIMEN_SCALE: f64 = 10.0;

/// What to compress and how far.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompressOptions {
    /// Scale of the difference limen within which modes merge: 1 merges what a listener cannot
    /// tell apart, 0 merges nothing, 2 merges twice as far.
    pub limen_scale: f64,
    /// Modes whose largest gain over the positions is this many dB (a negative number) below the
    /// strongest mode's are dropped; `None` drops nothing.
    pub drop_below_db: Option<f64>,
}

impl Default for CompressOptions {
    fn default() -> Self {
        Self {
            limen_scale: 1.0,
            drop_below_db: Some(DEFAULT_DROP_BELOW_DB),
        }
    }
}

/// What compression did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CompressReport {
    /// Modes in the bank before.
    pub modes_before: usize,
    /// Modes in the bank after.
    pub modes_after: usize,
    /// Modes removed by merging (a cluster of three merged into one counts two).
    pub merged: usize,
    /// Modes removed because they were too weak.
    pub dropped: usize,
}

impl fmt::Display for CompressReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} modes -> {} modes (merged {}, dropped {})",
            self.modes_before, self.modes_after, self.merged, self.dropped
        )
    }
}

/// Why a bank could not be compressed.
#[derive(Debug, Clone, PartialEq)]
pub enum CompressError {
    /// An option is out of range.
    BadOption {
        /// Name of the option.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What was expected.
        expected: &'static str,
    },
    /// The compressed bank breaks a rule of the format (for example, summed gains out of range).
    Invalid(Vec<Problem>),
}

impl fmt::Display for CompressError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadOption {
                name,
                value,
                expected,
            } => write!(f, "{name} {value}: expected {expected}"),
            Self::Invalid(problems) => {
                write!(f, "the compressed bank is not valid:")?;
                for problem in problems {
                    write!(f, "\n  {problem}")?;
                }
                Ok(())
            }
        }
    }
}

impl std::error::Error for CompressError {}

impl CompressOptions {
    /// `Ok` when every option is in range.
    pub fn check(&self) -> Result<(), CompressError> {
        if !(0.0..=MAX_LIMEN_SCALE).contains(&self.limen_scale) {
            return Err(CompressError::BadOption {
                name: "--limen-scale",
                value: self.limen_scale,
                expected: "a number from 0 to 10 (1 merges what a listener cannot tell apart)",
            });
        }
        match self.drop_below_db {
            Some(db) if !(db.is_finite() && db <= 0.0) => Err(CompressError::BadOption {
                name: "--drop-below-db",
                value: db,
                expected: "a level in dB, 0 or below",
            }),
            _ => Ok(()),
        }
    }
}

/// `bank` with indistinguishable modes merged and weak ones dropped, modes ascending in frequency,
/// and what was done. Everything but the modes is kept; `source.compression` records the options.
/// The result is validated.
pub fn compress_bank(
    bank: &Bank,
    options: &CompressOptions,
) -> Result<(Bank, CompressReport), CompressError> {
    options.check()?;
    let merged_modes = merge_modes(&bank.modes, options.limen_scale);
    let merged = bank.modes.len() - merged_modes.len();
    let kept = match options.drop_below_db {
        Some(db) => drop_weak_modes(merged_modes, db),
        None => merged_modes,
    };
    let report = CompressReport {
        modes_before: bank.modes.len(),
        modes_after: kept.len(),
        merged,
        dropped: bank.modes.len() - merged - kept.len(),
    };

    let mut out = bank.clone();
    out.modes = kept;
    out.source.get_or_insert_with(Default::default).insert(
        "compression".into(),
        json!({
            "limen_scale": options.limen_scale,
            "drop_below_db": options.drop_below_db,
            "modes_before": report.modes_before,
        }),
    );
    let problems = validate_bank(&out);
    if !problems.is_empty() {
        return Err(CompressError::Invalid(problems));
    }
    Ok((out, report))
}

/// Largest absolute gain of a mode over the positions.
pub fn peak_gain(mode: &Mode) -> f64 {
    mode.gains.iter().fold(0.0f64, |peak, g| peak.max(g.abs()))
}

/// Energy of a mode summed over the positions, up to a constant (seed 000 eq. 5.15:
/// `E = (1/4) w^2 a^2 / (alpha (alpha^2 + w^2))`), with the decay at least
/// [`MIN_DECAY_PER_S`] so that an undamped mode has a finite weight.
fn energy(mode: &Mode) -> f64 {
    let omega = TAU * mode.freq_hz;
    let alpha = mode.decay_per_s.max(MIN_DECAY_PER_S);
    let sum_sq: f64 = mode.gains.iter().map(|g| g * g).sum();
    0.25 * omega * omega * sum_sq / (alpha * (alpha * alpha + omega * omega))
}

/// The modes sorted by frequency, with each cluster closer than `limen_scale` limens merged.
fn merge_modes(modes: &[Mode], limen_scale: f64) -> Vec<Mode> {
    let mut sorted = modes.to_vec();
    sorted.sort_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
    let mut out: Vec<Mode> = Vec::with_capacity(sorted.len());
    let mut cluster: Vec<Mode> = Vec::new();
    for mode in sorted {
        let joins = cluster.first().is_some_and(|first| {
            let mean_hz = 0.5 * (first.freq_hz + mode.freq_hz);
            mode.freq_hz - first.freq_hz < limen_scale * difference_limen_hz(mean_hz)
        });
        if !joins && !cluster.is_empty() {
            out.push(merge_cluster(&cluster));
            cluster.clear();
        }
        cluster.push(mode);
    }
    if !cluster.is_empty() {
        out.push(merge_cluster(&cluster));
    }
    out
}

/// One mode standing for `cluster`: gains summed per position, frequency and decay averaged with
/// the members' energies as weights (equal weights if every member is silent).
fn merge_cluster(cluster: &[Mode]) -> Mode {
    if let [single] = cluster {
        return single.clone();
    }
    let energies: Vec<f64> = cluster.iter().map(energy).collect();
    let total: f64 = energies.iter().sum();
    let weights: Vec<f64> = if total > 0.0 && total.is_finite() {
        energies.iter().map(|e| e / total).collect()
    } else {
        vec![1.0 / cluster.len() as f64; cluster.len()]
    };
    let average = |value: fn(&Mode) -> f64| -> f64 {
        cluster
            .iter()
            .zip(&weights)
            .map(|(m, w)| w * value(m))
            .sum()
    };
    let num_positions = cluster[0].gains.len();
    Mode {
        freq_hz: average(|m| m.freq_hz),
        decay_per_s: average(|m| m.decay_per_s),
        gains: (0..num_positions)
            .map(|k| {
                cluster
                    .iter()
                    .map(|m| m.gains.get(k).copied().unwrap_or(0.0))
                    .sum()
            })
            .collect(),
    }
}

/// The modes whose peak gain is no more than `drop_below_db` below the strongest's. The strongest
/// is always kept; a bank whose gains are all zero keeps every mode.
fn drop_weak_modes(modes: Vec<Mode>, drop_below_db: f64) -> Vec<Mode> {
    let strongest = modes.iter().map(peak_gain).fold(0.0f64, f64::max);
    if strongest <= 0.0 {
        return modes;
    }
    let floor = strongest * 10f64.powf(drop_below_db / 20.0);
    modes
        .into_iter()
        .filter(|m| peak_gain(m) >= floor)
        .collect()
}

#[cfg(test)]
mod tests;
