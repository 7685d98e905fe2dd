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
use super::validate::validate_bank;
use super::{Bank, Mode, Problem};
use crate::dsp::coeffs::MIN_DECAY_PER_S;

/// Default level below the strongest mode under which modes are dropped, in dB.
pub const DEFAULT_DROP_BELOW_DB: f64 = -80.0;

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
            } => write!(f, "{name} = {value}: expected {expected}"),
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
        if !(self.limen_scale.is_finite() && self.limen_scale >= 0.0) {
            return Err(CompressError::BadOption {
                name: "limen_scale",
                value: self.limen_scale,
                expected: "a number 0 or above",
            });
        }
        match self.drop_below_db {
            Some(db) if !(db.is_finite() && db <= 0.0) => Err(CompressError::BadOption {
                name: "drop_below_db",
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
mod tests {
    use super::*;
    use crate::model::Position;

    fn bank(modes: &[(f64, f64, [f64; 2])]) -> Bank {
        let positions = ["edge", "centre"]
            .iter()
            .enumerate()
            .map(|(i, name)| Position {
                name: name.to_string(),
                coords: vec![i as f64],
            })
            .collect();
        let mut bank = Bank::new("test", positions);
        bank.modes = modes
            .iter()
            .map(|&(freq_hz, decay_per_s, gains)| Mode {
                freq_hz,
                decay_per_s,
                gains: gains.to_vec(),
            })
            .collect();
        bank
    }

    fn no_drop() -> CompressOptions {
        CompressOptions {
            limen_scale: 1.0,
            drop_below_db: None,
        }
    }

    #[test]
    fn modes_within_the_limen_merge_and_sum_their_gains_per_position() {
        // At 2 kHz the limen is 5 Hz (seed 000 section 5.4.1): 2 Hz apart is one mode.
        let input = bank(&[
            (2000.0, 4.0, [0.5, -0.25]),
            (2002.0, 4.0, [0.25, 0.5]),
            (3000.0, 6.0, [0.1, 0.2]),
        ]);
        let (out, report) = compress_bank(&input, &no_drop()).unwrap();
        assert_eq!(out.modes.len(), 2, "{:?}", out.modes);
        let merged = &out.modes[0];
        assert_eq!(merged.gains, vec![0.75, 0.25], "gains summed per position");
        // Energy weights: the first has 0.3125 of summed squared gain, the second 0.3125 as well.
        assert!(
            (merged.freq_hz - 2001.0).abs() < 1e-9,
            "merged frequency {} vs 2001",
            merged.freq_hz
        );
        assert!((merged.decay_per_s - 4.0).abs() < 1e-12);
        assert_eq!(out.modes[1], input.modes[2]);
        assert_eq!(
            report,
            CompressReport {
                modes_before: 3,
                modes_after: 2,
                merged: 1,
                dropped: 0
            }
        );
        assert_eq!(
            report.to_string(),
            "3 modes -> 2 modes (merged 1, dropped 0)"
        );
    }

    #[test]
    fn modes_outside_the_limen_stay_apart() {
        // 8 Hz apart at 2 kHz is beyond the 5 Hz limen; at 8 kHz the limen is 80 Hz, so 70 Hz
        // apart merges there.
        let input = bank(&[
            (2000.0, 4.0, [0.5, 0.5]),
            (2008.0, 4.0, [0.5, 0.5]),
            (8000.0, 9.0, [0.5, 0.5]),
            (8070.0, 9.0, [0.5, 0.5]),
        ]);
        let (out, report) = compress_bank(&input, &no_drop()).unwrap();
        let freqs: Vec<f64> = out.modes.iter().map(|m| m.freq_hz).collect();
        assert_eq!(freqs.len(), 3, "{freqs:?}");
        assert_eq!(&freqs[..2], &[2000.0, 2008.0]);
        assert!((freqs[2] - 8035.0).abs() < 1.0, "{freqs:?}");
        assert_eq!(report.merged, 1);
        // A smaller limen scale keeps even the close pair apart; scale 0 merges nothing.
        for scale in [0.5, 0.0] {
            let options = CompressOptions {
                limen_scale: scale,
                drop_below_db: None,
            };
            let (out, _) = compress_bank(&input, &options).unwrap();
            assert_eq!(out.modes.len(), 4, "limen scale {scale}");
        }
    }

    #[test]
    fn a_dense_run_is_not_chained_into_one_mode() {
        // Modes every 3 Hz from 2 kHz: each is within the 5 Hz limen of the next, but a cluster
        // spans less than one limen, so 20 modes become several, not one.
        let modes: Vec<(f64, f64, [f64; 2])> = (0..20)
            .map(|i| (2000.0 + 3.0 * i as f64, 4.0, [0.1, 0.1]))
            .collect();
        let (out, _) = compress_bank(&bank(&modes), &no_drop()).unwrap();
        assert_eq!(
            out.modes.len(),
            10,
            "pairs 3 Hz apart merge, triples do not"
        );
        for pair in out.modes.windows(2) {
            let gap = pair[1].freq_hz - pair[0].freq_hz;
            assert!(gap > 5.0, "merged modes {gap} Hz apart");
        }
    }

    #[test]
    fn the_stronger_mode_dominates_frequency_and_decay() {
        // A faint fast neighbour barely moves a strong slow mode: its energy weight is
        // (0.05^2 / 50) / (1 / 1) = 5e-5, so the decay moves by 5e-5 * 49 = 0.25%.
        let input = bank(&[(1000.0, 1.0, [1.0, 1.0]), (1001.5, 50.0, [0.05, 0.05])]);
        let (out, _) = compress_bank(&input, &no_drop()).unwrap();
        let m = &out.modes[0];
        assert_eq!(out.modes.len(), 1);
        assert!((m.freq_hz - 1000.0).abs() < 1e-3, "frequency {}", m.freq_hz);
        assert!(
            (m.decay_per_s - 1.0).abs() < 3e-3,
            "decay {}",
            m.decay_per_s
        );
    }

    #[test]
    fn weak_modes_are_dropped_relative_to_the_strongest() {
        // Peak gains relative to the strongest: 0 dB, -40 dB, -79 dB, -81 dB (peak over either
        // position counts).
        let input = bank(&[
            (100.0, 1.0, [0.0, 2.0]),
            (300.0, 1.0, [0.02, 0.0]),
            (700.0, 1.0, [0.0, -2.0 * 10f64.powf(-79.0 / 20.0)]),
            (1100.0, 1.0, [2.0 * 10f64.powf(-81.0 / 20.0), 0.0]),
        ]);
        let (out, report) = compress_bank(&input, &CompressOptions::default()).unwrap();
        let freqs: Vec<f64> = out.modes.iter().map(|m| m.freq_hz).collect();
        assert_eq!(freqs, vec![100.0, 300.0, 700.0]);
        assert_eq!((report.merged, report.dropped), (0, 1));
        let strict = CompressOptions {
            limen_scale: 1.0,
            drop_below_db: Some(-30.0),
        };
        let (out, report) = compress_bank(&input, &strict).unwrap();
        assert_eq!(out.modes.len(), 1);
        assert_eq!(
            report.to_string(),
            "4 modes -> 1 modes (merged 0, dropped 3)"
        );
    }

    #[test]
    fn result_validates_and_keeps_everything_but_the_modes() {
        let mut input = bank(&[
            (440.0, 2.0, [1.0, 0.5]),
            (440.5, 2.0, [0.5, 0.5]),
            (1320.0, 3.0, [0.3, 0.1]),
        ]);
        input.root_hz = Some(440.0);
        input.description = "A test bank.".into();
        let (out, _) = compress_bank(&input, &CompressOptions::default()).unwrap();
        assert!(validate_bank(&out).is_empty(), "{:?}", validate_bank(&out));
        assert_eq!(out.root_hz, input.root_hz);
        assert_eq!(out.positions, input.positions);
        assert_eq!(out.description, input.description);
        let compression = &out.source.as_ref().unwrap()["compression"];
        assert_eq!(compression["modes_before"], 3);
        assert_eq!(compression["drop_below_db"], -80.0);
        // Modes come out ascending, whatever the input order.
        let mut shuffled = input.clone();
        shuffled.modes.reverse();
        let (again, _) = compress_bank(&shuffled, &CompressOptions::default()).unwrap();
        assert_eq!(again.modes, out.modes);
    }

    #[test]
    fn bad_options_are_refused() {
        let input = bank(&[(440.0, 2.0, [1.0, 0.5])]);
        for options in [
            CompressOptions {
                limen_scale: -1.0,
                drop_below_db: None,
            },
            CompressOptions {
                limen_scale: f64::NAN,
                drop_below_db: None,
            },
            CompressOptions {
                limen_scale: 1.0,
                drop_below_db: Some(6.0),
            },
        ] {
            let err = compress_bank(&input, &options).unwrap_err();
            assert!(
                matches!(err, CompressError::BadOption { .. }),
                "{options:?}: {err}"
            );
        }
        // Summed gains beyond the format's range are reported, not saved.
        let huge = bank(&[(440.0, 2.0, [9e5, 0.0]), (440.2, 2.0, [9e5, 0.0])]);
        let err = compress_bank(&huge, &no_drop()).unwrap_err();
        assert!(err.to_string().contains("modes[0].gains[0]"), "{err}");
    }
}
