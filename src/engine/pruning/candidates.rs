//! The modes one analysis looks at, structure-of-arrays, with the levels and critical-band rates
//! the masking pass needs.

use std::f64::consts::TAU;

use crate::dsp::masking::{power_to_db, PsychoTable, DB_PER_NEPER};
use crate::dsp::pruning::Verdict;

/// Candidate flag: computed and not to be switched off (fading, or its voice is being driven).
pub(super) const LOCKED: u8 = 1;
/// Candidate flag: dormant.
pub(super) const DORMANT: u8 = 2;
/// Candidate flag: dormant and below the truncation threshold: to be dropped.
pub(super) const DROP: u8 = 4;
/// Candidate flag: audible but beyond the budget.
pub(super) const OVER_BUDGET: u8 = 8;
/// Candidate flag: its level includes a bound on what a strike under way adds, so as a masker
/// it may be louder than it will be.
pub(super) const DRIVEN: u8 = 16;
/// Candidate flag: fading out, switched off already (it takes no place in the budget).
pub(super) const LEAVING: u8 = 32;
/// Flags of a masker not to be relied on past this analysis (its curve may be too high, or it
/// is about to fall silent).
pub(super) const UNSURE_MASKER: u8 = OVER_BUDGET | DRIVEN | LEAVING;

/// The mode in a `voice << 24 | mode` pair.
pub(super) const MODE_MASK: u32 = 0x00ff_ffff;

/// How levels are read this analysis.
#[derive(Debug, Clone, Copy)]
pub(super) struct Reading {
    /// dB SPL of a unit amplitude at the output.
    pub calibration_db: f32,
    /// Hz per radian per sample.
    pub radians_to_hz: f64,
    /// Whether the budget's energy ranking is wanted.
    pub budget: bool,
}

impl Reading {
    pub fn new(calibration_db: f32, sample_rate_hz: f64, budget: bool) -> Self {
        Self {
            calibration_db,
            radians_to_hz: sample_rate_hz / TAU,
            budget,
        }
    }
}

/// Energy still to come in dB (seed 000 eq. 5.15, per-sample units) of a mode of power `raw_db`
/// and pole `(theta, delta)`: `a^2 w^2 / (4 alpha (alpha^2 + w^2))`. What the budget ranks.
pub(super) fn energy_db(raw_db: f32, theta: f64, delta: f64) -> f32 {
    let (w, a) = (theta as f32, (delta as f32).max(1e-12));
    raw_db + power_to_db(w * w / (4.0 * a * (a * a + w * w)))
}

/// The candidates of one analysis.
#[derive(Debug, Clone)]
pub(super) struct Candidates {
    /// Bark and threshold in quiet by frequency.
    table: PsychoTable,
    /// Level of each candidate in dB SPL.
    pub level_db: Vec<f32>,
    /// Critical-band rate of each candidate.
    pub bark: Vec<f32>,
    /// Threshold in quiet at each candidate, dB SPL.
    pub threshold_db: Vec<f32>,
    /// Power of each candidate in dB relative to full scale, before output gain.
    pub raw_db: Vec<f32>,
    /// How fast each candidate's level falls, dB per sample.
    pub fall_db: Vec<f32>,
    /// Pole angle of each candidate, radians per sample.
    pub theta: Vec<f32>,
    /// Energy still to come of each candidate in dB (seed 000 eq. 5.15), for the budget.
    pub energy_db: Vec<f32>,
    /// The masking envelope (or threshold in quiet) at each heard candidate, dB SPL.
    pub envelope_db: Vec<f32>,
    /// `voice << 24 | mode` of each candidate.
    pub who: Vec<u32>,
    /// Flags of each candidate.
    pub flags: Vec<u8>,
    /// The pass's verdicts.
    pub verdicts: Vec<Verdict>,
    /// Number in use.
    pub len: usize,
    /// Modes per voice: the stride of the per-mode tables.
    pub stride: usize,
    /// What is kept of each voice's modes (voice-major), in one place since the modes come in
    /// no order and each is a cache miss.
    per_mode: Vec<PerMode>,
}

/// What the candidates keep of one mode of one voice.
#[derive(Debug, Clone, Copy)]
struct PerMode {
    /// Critical-band rate at the voice's tuning.
    bark: f32,
    /// Threshold in quiet there, dB SPL.
    threshold_db: f32,
    /// The voice generation `bark` and `threshold_db` were worked out for.
    generation: u32,
    /// One more than the mode's candidate index, or 0.
    index: u32,
}

impl PerMode {
    const UNKNOWN: Self = Self {
        bark: 0.0,
        threshold_db: 0.0,
        generation: u32::MAX,
        index: 0,
    };
}

impl Candidates {
    /// Room for every mode of `num_voices` voices of `num_modes` modes. Allocates.
    pub fn new(num_voices: usize, num_modes: usize) -> Self {
        let n = num_voices * num_modes;
        Self {
            table: PsychoTable::new(),
            level_db: vec![0.0; n],
            bark: vec![0.0; n],
            threshold_db: vec![0.0; n],
            raw_db: vec![0.0; n],
            fall_db: vec![0.0; n],
            theta: vec![0.0; n],
            energy_db: vec![0.0; n],
            envelope_db: vec![0.0; n],
            who: vec![0; n],
            flags: vec![0; n],
            verdicts: vec![Verdict::Inaudible; n],
            len: 0,
            stride: num_modes,
            per_mode: vec![PerMode::UNKNOWN; n],
        }
    }

    /// Adds mode `mode` of voice `voice` (of generation `generation`) with power `raw_db` (dB re
    /// full scale) and pole `(theta, delta)`.
    #[allow(clippy::too_many_arguments)] // the fields of one candidate
    #[inline]
    pub fn push(
        &mut self,
        voice: usize,
        generation: u32,
        mode: usize,
        raw_db: f32,
        theta: f64,
        delta: f64,
        flags: u8,
        reading: &Reading,
    ) {
        // Bark and threshold in quiet follow the voice's tuning: kept until it changes.
        let i = self.len;
        let pm = &mut self.per_mode[voice * self.stride + mode];
        if pm.generation != generation {
            (pm.bark, pm.threshold_db) = self.table.lookup((theta * reading.radians_to_hz) as f32);
            pm.generation = generation;
        }
        pm.index = i as u32 + 1;
        let (bark, threshold_db) = (pm.bark, pm.threshold_db);
        self.level_db[i] = raw_db + reading.calibration_db;
        self.raw_db[i] = raw_db;
        self.bark[i] = bark;
        self.threshold_db[i] = threshold_db;
        self.fall_db[i] = DB_PER_NEPER * delta as f32;
        self.theta[i] = theta as f32;
        if reading.budget {
            self.energy_db[i] = energy_db(raw_db, theta, delta);
        }
        self.who[i] = ((voice as u32) << 24) | mode as u32;
        self.flags[i] = flags;
        self.len += 1;
    }

    /// Whether mode `mode` of voice `voice` is a candidate.
    pub fn has(&self, voice: usize, mode: usize) -> bool {
        self.per_mode[voice * self.stride + mode].index != 0
    }

    /// Voice and mode of candidate `i`.
    pub fn voice_mode(&self, i: usize) -> (usize, usize) {
        (
            (self.who[i] >> 24) as usize,
            (self.who[i] & MODE_MASK) as usize,
        )
    }

    /// Empties the list, forgetting which modes were in it.
    pub fn clear(&mut self) {
        for i in 0..self.len {
            let (voice, mode) = self.voice_mode(i);
            self.per_mode[voice * self.stride + mode].index = 0;
        }
        self.len = 0;
    }
}
