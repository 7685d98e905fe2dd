//! Why a mode is off, and when it could be heard again: the masker's curve over it, falling as
//! the masker decays (`unmask_delay_samples`), or the threshold in quiet, until truncation.

use super::candidates::{MODE_MASK, OVER_BUDGET, UNSURE_MASKER};
use super::{samples_to_cross, Pruner, NO_TAG};
use crate::dsp::masking::{curve_spread, unmask_delay_samples};
use crate::dsp::pruning::{Verdict, PRIOR};

impl Pruner {
    /// For candidate `i`, found inaudible, masked or over the budget: how long (in samples) until
    /// it could be heard again, the tag naming its masker's voice, and what keeps it off.
    pub(super) fn when_off(&self, i: usize, offset_db: f32, now: u64) -> (u64, u32, OffReason) {
        let cd = &self.cands;
        let (vi, _) = cd.voice_mode(i);
        let to_truncation = samples_to_cross(cd.raw_db[i] - self.truncation_db[vi], cd.fall_db[i]);
        if cd.flags[i] & OVER_BUDGET != 0 {
            // Over budget: look again next frame, or when its voice is struck.
            return (0, NO_TAG, OffReason::BUDGET);
        }
        match cd.verdicts[i] {
            Verdict::Masked { by } => {
                let (bark, level, fall, who, generation) = if by & PRIOR != 0 {
                    let jj = (by & !PRIOR) as usize;
                    let j = self.prior_entry[jj] as usize;
                    let m = &self.maskers;
                    (
                        m.bark[j],
                        self.prior_level_db[jj],
                        m.fall_db[j],
                        m.who[j],
                        m.generation[j],
                    )
                } else {
                    let j = by as usize;
                    let voice = cd.who[j] >> 24;
                    (
                        cd.bark[j],
                        cd.level_db[j],
                        cd.fall_db[j],
                        cd.who[j],
                        self.generation[voice as usize],
                    )
                };
                let voice = who >> 24;
                let delay = unmask_delay_samples(
                    bark,
                    level,
                    fall,
                    offset_db,
                    cd.bark[i],
                    cd.level_db[i],
                    cd.fall_db[i],
                );
                let delay = (delay.clamp(0.0, 1e15) as u64).min(to_truncation);
                // A masker silenced by the budget, fading out, or whose level holds a strike's
                // bound, may not mask as long as its curve says: look again at the next analysis.
                let unsure = by & PRIOR == 0 && cd.flags[by as usize] & UNSURE_MASKER != 0;
                let delay = if unsure { 0 } else { delay };
                let reason = OffReason {
                    // The envelope of every masker's curve: the masker named is one under it.
                    curve_db: cd.envelope_db[i],
                    fall_db: fall * curve_spread(bark, level, cd.bark[i]),
                    at: now,
                    threshold_db: cd.threshold_db[i],
                    generation: self.generation[vi],
                    masker: if voice as usize == vi {
                        who & MODE_MASK
                    } else {
                        u32::MAX
                    },
                };
                (delay, (voice << 24) | generation, reason)
            }
            // Below the threshold of hearing it only gets quieter, unless struck.
            Verdict::Inaudible => (
                to_truncation,
                NO_TAG,
                OffReason {
                    curve_db: f32::NEG_INFINITY,
                    fall_db: 0.0,
                    at: now,
                    threshold_db: cd.threshold_db[i],
                    generation: self.generation[vi],
                    masker: u32::MAX,
                },
            ),
            Verdict::Audible { .. } => (0, NO_TAG, OffReason::UNKNOWN),
        }
    }
}

/// What keeps a dormant mode off: the masking curve over it (falling as its masker decays) and
/// the threshold in quiet, in dB SPL. A strike that leaves the mode under both leaves it off.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct OffReason {
    /// The masking curve at the mode at engine clock `at`, dB SPL.
    pub curve_db: f32,
    /// How fast the curve falls there, dB per sample.
    pub fall_db: f32,
    /// Engine clock of `curve_db`.
    pub at: u64,
    /// The threshold in quiet at the mode, dB SPL.
    pub threshold_db: f32,
    /// The generation of the mode's voice when judged: a retuned voice has it judged again.
    pub generation: u32,
    /// The mode whose masking curve it lies under, when that mode is in the same voice (a
    /// strike lifts both), else `u32::MAX`.
    pub masker: u32,
}

impl OffReason {
    /// Nothing known: a strike has the mode judged again.
    pub const UNKNOWN: Self = Self {
        curve_db: f32::NEG_INFINITY,
        fall_db: 0.0,
        at: 0,
        threshold_db: f32::NEG_INFINITY,
        generation: u32::MAX,
        masker: u32::MAX,
    };

    /// Off for the budget: a strike on its voice may wake it, if the budget has room.
    pub const BUDGET: Self = Self {
        curve_db: f32::INFINITY,
        threshold_db: f32::INFINITY,
        ..Self::UNKNOWN
    };

    /// The level in dB SPL a mode must reach at engine clock `now` to be heard.
    pub fn level_to_beat(&self, now: u64) -> f32 {
        let curve = self.curve_db - self.fall_db * now.saturating_sub(self.at) as f32;
        curve.max(self.threshold_db)
    }
}
