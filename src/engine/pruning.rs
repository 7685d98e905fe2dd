//! Perceptual mode pruning across all voices (seed 001 section 4), with the computation budget
//! ([`super::budget`]) applied to what it keeps.
//!
//! Every analysis frame (a whole number of control periods, so the output does not depend on how
//! the host cuts blocks), and under a budget also at the control tick after a strike, the pruner
//!
//! 1. estimates each mode's energy: `|z|^2 / 2` of its phasor, which is seed 001 eq. 3 exactly
//!    (the sum of potential and kinetic energy), plus a bound on what the strikes under way will
//!    add; calibrated so that a full-scale sine plays at the playback level in dB SPL;
//! 2. runs the masking pass ([`crate::dsp::pruning`]): modes below the threshold of hearing or
//!    under a louder mode's masking curve are switched off;
//! 3. if more modes remain than the budget allows, keeps those with the most energy still to
//!    come (seed 000 eq. 5.15);
//! 4. fades the modes switched off out (their state then evolves analytically) and fades modes
//!    that have become audible back in, in phase.
//!
//! A strike decides at once which of its voice's dormant modes it makes audible ([`strike`]),
//! the modes it starts from rest among them (they start dormant): those are woken at its exact
//! sample and take it computed (under a budget, as many as the budget would keep); the others
//! take it analytically and stay dormant, never computed. Audio input, which is not known in
//! advance, wakes every dormant mode of the input voice.
//!
//! Most frames look only at what may have changed. Every level falls linearly in dB, so it is
//! known how long each verdict holds: a heard mode cannot sink under today's masking envelope or
//! the threshold in quiet before its margin has decayed away, and a masked mode cannot surface
//! before its masker's curve has fallen below it (`unmask_delay_samples`). A mode is looked at
//! again when that time comes, when its voice is struck, or when its masker's voice changes
//! (retuned, stolen, silenced); the maskers of the other modes carry over from frame to frame.
//! Every [`FULL_EVERY`] frames every computed mode is looked at, and about every
//! [`DORMANT_FULL_S`] every dormant one too, whatever its recheck time says (except those under
//! the threshold in quiet, which only get quieter until struck); whenever the settings change,
//! everything is.

mod analysis;
mod candidates;
mod maskers;
mod off_reason;
mod strike;

use super::mode_fade::fade_samples;
use super::voice::{Tuning, Voice, VoiceState};
use super::{Engine, CONTROL_PERIOD};
use crate::dsp::pruning::MaskingPass;
use crate::dsp::resonator_bank::DormantMode;
use candidates::Candidates;
use maskers::Maskers;
use off_reason::OffReason;

/// Every this many analyses, every mode is looked at, so a strike that masks other voices' modes
/// switches them off.
const FULL_EVERY: u32 = 4;

/// At least this often (in seconds of audio), every dormant mode is looked at too: a safety net
/// under the predicted recheck times (a masker that has since gone dormant itself masks nothing).
const DORMANT_FULL_S: f64 = 1.0;

/// A masker tag meaning "nothing to watch".
const NO_TAG: u32 = u32::MAX;

/// Voice generations are kept to 24 bits, to share a tag with the voice index.
const GENERATION_MASK: u32 = 0x00ff_ffff;

/// What pruning has done, for meters and benchmarks.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PruningStats {
    /// Analyses run.
    pub analyses: u64,
    /// Of which looked at every mode.
    pub full_analyses: u64,
    /// Modes classified, summed over the analyses (and the strikes' decisions).
    pub candidates: u64,
    /// Maskers carried from analysis to analysis, summed.
    pub maskers: u64,
    /// Modes switched off.
    pub switched_off: u64,
    /// Dormant modes switched back on.
    pub switched_on: u64,
    /// Dormant modes dropped for good below the truncation threshold.
    pub dropped: u64,
    /// Dormant or fading modes woken by strikes and input, with old ringing to fade back in (not
    /// modes a strike started from rest and woke at once).
    pub woken: u64,
    /// Dormant modes that took a strike analytically, modes the strike started from rest among
    /// them.
    pub absorbed: u64,
    /// Nanoseconds spent in the analyses, measured only while profiling is on
    /// ([`Engine::set_profiling`]).
    pub analysis_ns: u64,
    /// Nanoseconds spent deciding and settling strikes on dormant modes, measured only while
    /// profiling is on.
    pub strike_ns: u64,
}

/// What a voice was at the last analysis: when it changes, modes masked by it are looked at again.
#[derive(Debug, Clone, Copy, PartialEq)]
struct VoiceWatch {
    /// Allocation order (changes when the voice plays a new note).
    age: u64,
    /// Coefficients in use.
    applied: Option<Tuning>,
    /// Whether it is fading out after being stolen.
    stolen: bool,
    /// Whether it has stopped sounding.
    silent: bool,
}

impl VoiceWatch {
    const NEW: Self = Self {
        age: 0,
        applied: None,
        stolen: false,
        silent: true,
    };

    fn of(v: &Voice) -> Self {
        Self {
            age: v.age,
            applied: v.applied,
            stolen: v.state == VoiceState::Fading,
            silent: v.modes.num_live() == 0,
        }
    }
}

/// The pruner's scratch storage and state. Sized in `reserve`; nothing allocates while playing.
#[derive(Debug, Clone)]
pub(super) struct Pruner {
    /// The masking pass.
    pass: MaskingPass,
    /// The modes the analysis in hand looks at.
    cands: Candidates,
    /// Budget ranking scratch: energy and candidate index (at a strike, mode).
    ranked: Vec<(f32, u32)>,
    /// Scratch for a strike under a budget: the energies of the modes computed now.
    computed_energy: Vec<f32>,
    /// Maskers carried over.
    maskers: Maskers,
    /// Bark of the maskers handed to a pass.
    prior_bark: Vec<f32>,
    /// Their levels now.
    prior_level_db: Vec<f32>,
    /// Their index in `maskers`.
    prior_entry: Vec<u32>,
    /// Each voice as the last analysis saw it.
    watch: Vec<VoiceWatch>,
    /// Each voice's generation: bumped when it changes, so tags naming it go stale.
    generation: Vec<u32>,
    /// `(modes started, modes woken)` of each voice at the last analysis: a change means it was
    /// struck.
    strikes: Vec<(usize, u64)>,
    /// Whether each voice was struck since the last analysis.
    struck: Vec<bool>,
    /// Each voice's truncation level for dormant modes, power in dB.
    truncation_db: Vec<f32>,
    /// Engine clock before which a heard mode need not be looked at again (voice-major).
    heard_until: Vec<u64>,
    /// Why each dormant mode is off (voice-major), so a strike can tell at once which it lifts
    /// into hearing.
    off: Vec<OffReason>,
    /// Scratch: the dormant modes of a struck voice.
    dormant_scratch: Vec<DormantMode>,
    /// Scratch for a strike: how far it can lift each masker of the struck voice's modes, at
    /// most and at least (a fall, when the strike meets the masker's ringing out of phase), in
    /// dB, after the strike it was worked out for (`lift_stamp`).
    lift_db: Vec<(u32, f32, f32)>,
    /// Counts the strikes judged, to tell `lift_db` entries of this one from stale ones.
    lift_stamp: u32,
    /// Scratch: new recheck times `(mode, bank clock)` a strike sets.
    rechecks: Vec<(u32, u64)>,
    /// Number of `rechecks` in use.
    num_rechecks: usize,
    /// Analyses since every mode was last looked at.
    since_full: u32,
    /// Analyses since every dormant mode was last looked at.
    since_dormant_full: u32,
    /// Whether modes may be dormant or fading somewhere.
    engaged: bool,
    /// Whether a strike has found a voice changed (a new note, a new tuning) since the last
    /// analysis: the next one looks at what it masked.
    changed: bool,
    /// Whether the next control tick is to analyse: the input has woken modes, or a strike
    /// came under a budget.
    pending: bool,
    /// The settings the last full look ran with (masking offset, pruning, budget, truncation): a
    /// change looks at everything again.
    settings: Option<(f32, bool, Option<usize>, f32)>,
    /// Calibration (dB SPL of a unit amplitude at the output) of the last full look.
    calibration_db: f32,
    /// Whether analyses and strikes are timed.
    profiling: bool,
    /// Counters.
    stats: PruningStats,
}

impl Pruner {
    /// An empty pruner; [`Pruner::reserve`] sizes it.
    pub fn new() -> Self {
        Self {
            pass: MaskingPass::default(),
            cands: Candidates::new(0, 0),
            ranked: Vec::new(),
            computed_energy: Vec::new(),
            maskers: Maskers::default(),
            prior_bark: Vec::new(),
            prior_level_db: Vec::new(),
            prior_entry: Vec::new(),
            watch: Vec::new(),
            generation: Vec::new(),
            strikes: Vec::new(),
            struck: Vec::new(),
            truncation_db: Vec::new(),
            heard_until: Vec::new(),
            off: Vec::new(),
            dormant_scratch: Vec::new(),
            lift_db: Vec::new(),
            lift_stamp: 0,
            rechecks: Vec::new(),
            num_rechecks: 0,
            since_full: 0,
            since_dormant_full: 0,
            engaged: false,
            changed: false,
            pending: false,
            settings: None,
            calibration_db: 0.0,
            profiling: false,
            stats: PruningStats::default(),
        }
    }

    /// Sizes the scratch for `num_voices` voices of `num_modes` modes. Allocates.
    pub fn reserve(&mut self, num_voices: usize, num_modes: usize) {
        let n = num_voices * num_modes;
        // Candidates and the maskers carried over together.
        self.pass = MaskingPass::with_capacity(2 * n);
        self.cands = Candidates::new(num_voices, num_modes);
        self.ranked = Vec::with_capacity(n);
        self.computed_energy = Vec::with_capacity(n);
        self.maskers = Maskers::with_capacity(n);
        self.prior_bark = vec![0.0; n];
        self.prior_level_db = vec![0.0; n];
        self.prior_entry = vec![0; n];
        self.watch = vec![VoiceWatch::NEW; num_voices];
        self.generation = vec![0; num_voices];
        self.strikes = vec![(0, 0); num_voices];
        self.struck = vec![false; num_voices];
        self.truncation_db = vec![0.0; num_voices];
        self.heard_until = vec![0; n];
        self.off = vec![OffReason::UNKNOWN; n];
        self.rechecks = vec![(0, 0); num_modes];
        self.dormant_scratch = vec![DormantMode::default(); num_modes];
        self.lift_db = vec![(0, 0.0, 0.0); num_modes];
        self.lift_stamp = 0;
        self.forget();
    }

    /// Forgets what it knew about the voices (they have all been freed).
    pub fn forget(&mut self) {
        self.engaged = false;
        self.changed = false;
        self.pending = false;
        self.settings = None;
        self.maskers.len = 0;
    }

    /// Notes what voice `i` is now. If that has changed since last noted, its generation moves
    /// on: verdicts, maskers and cached psychoacoustics of the old one no longer hold. Returns
    /// whether it did.
    fn watch_voice(&mut self, i: usize, v: &Voice) -> bool {
        let watch = VoiceWatch::of(v);
        if self.watch[i] == watch {
            return false;
        }
        self.watch[i] = watch;
        self.generation[i] = self.generation[i].wrapping_add(1) & GENERATION_MASK;
        true
    }

    /// The input has woken modes: look again at the next tick.
    pub fn note_input(&mut self) {
        self.pending = true;
    }

    /// Gathers the carried maskers at engine clock `now` into the prior arrays, leaving out
    /// those of voices struck or changed, of `skip_voice`, and of modes that are candidates.
    /// Returns how many.
    fn gather_priors(&mut self, now: u64, skip_voice: Option<usize>) -> usize {
        let m = &self.maskers;
        let mut num = 0;
        for j in 0..m.len {
            let vi = (m.who[j] >> 24) as usize;
            let mode = (m.who[j] & candidates::MODE_MASK) as usize;
            if skip_voice == Some(vi)
                || self.struck[vi]
                || self.generation[vi] != m.generation[j]
                || self.cands.has(vi, mode)
            {
                continue;
            }
            self.prior_bark[num] = m.bark[j];
            self.prior_level_db[num] = m.level_at(j, now);
            self.prior_entry[num] = j as u32;
            num += 1;
        }
        num
    }
}

impl Pruner {
    /// The masking pass over the candidates in hand, after the first `num_prior` prior maskers:
    /// verdicts and envelopes into the candidates.
    fn run_pass(&mut self, num_prior: usize, offset_db: f32) {
        let n = self.cands.len;
        let cd = &mut self.cands;
        self.pass.run_after(
            &self.prior_bark[..num_prior],
            &self.prior_level_db[..num_prior],
            &cd.level_db[..n],
            &cd.bark[..n],
            &cd.threshold_db[..n],
            offset_db,
            &mut cd.verdicts[..n],
            Some(&mut cd.envelope_db[..n]),
        );
    }
}

/// Samples per analysis frame: `frame_ms` rounded to whole control periods, at least one.
fn frame_samples(frame_ms: f32, sample_rate_hz: f64) -> u64 {
    let periods = (frame_ms as f64 * 1e-3 * sample_rate_hz / CONTROL_PERIOD as f64).round();
    periods.max(1.0) as u64 * CONTROL_PERIOD as u64
}

/// Samples (as a clock offset) a level `margin_db` above a line can fall at `fall_db` per sample
/// before it reaches it.
fn samples_to_cross(margin_db: f32, fall_db: f32) -> u64 {
    (margin_db.max(0.0) / fall_db.max(1e-12)).min(1e15) as u64
}

impl Engine {
    /// What pruning has done so far.
    pub fn pruning_stats(&self) -> PruningStats {
        let mut s = self.pruner.stats;
        s.woken = self
            .voices
            .iter()
            .chain(self.input_voice.as_ref())
            .map(|v| v.modes.num_woken())
            .sum();
        s
    }

    /// Calls `visit(mode)` for every mode that pruning or the budget has switched off (its
    /// state carried analytically), once per voice it sounds in; modes numbered as in
    /// [`crate::engine::PreparedBank`]. Does not allocate.
    pub fn visit_switched_off_modes(&self, mut visit: impl FnMut(usize)) {
        for v in self.voices.iter().chain(self.input_voice.as_ref()) {
            v.modes.dormant_modes().for_each(&mut visit);
        }
    }

    /// Times the pruning analyses and strikes from now on (reported in [`PruningStats`]); for
    /// benchmarks. Reading the clock does not allocate.
    pub fn set_profiling(&mut self, on: bool) {
        self.pruner.profiling = on;
    }
}
