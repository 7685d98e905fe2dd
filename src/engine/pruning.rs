//! Perceptual mode pruning across all voices (seed 001 section 4), with the computation budget
//! ([`super::budget`]) applied to what it keeps.
//!
//! Every analysis frame (a whole number of control periods, so the output does not depend on how
//! the host cuts blocks), and at the control tick after a strike, the pruner
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
//! A strike decides at once which of its voice's dormant modes it makes audible ([`strike`]):
//! those are woken at its exact sample and take it computed; the others take it analytically and
//! stay dormant. Audio input, which is not known in advance, wakes every dormant mode of the input
//! voice.
//!
//! Most frames look only at what may have changed. Every level falls linearly in dB, so it is
//! known how long each verdict holds: a heard mode cannot sink under today's masking envelope or
//! the threshold in quiet before its margin has decayed away, and a masked mode cannot surface
//! before its masker's curve has fallen below it (`unmask_delay_samples`). A mode is looked at
//! again when that time comes, when its voice is struck, or when its masker's voice changes
//! (retuned, stolen, silenced); the maskers of the other modes carry over from frame to frame.
//! Every [`FULL_EVERY`] frames, and whenever the settings change, every mode is looked at.

mod candidates;
mod maskers;
mod strike;

use std::time::Instant;

use super::voice::{Tuning, Voice, VoiceState};
use crate::dsp::resonator_bank::DormantMode;
use super::{Engine, CONTROL_PERIOD};
use crate::dsp::coeffs::gain_to_db;
use crate::dsp::masking::{curve_spread, unmask_delay_samples};
use crate::dsp::pruning::{keep_most_energetic, MaskingPass, Verdict, PRIOR};
use candidates::{Candidates, Reading, DORMANT, DROP, LOCKED, OVER_BUDGET};
use maskers::Maskers;

/// Shortest fade in or out, in seconds: short enough to follow the masking.
const FADE_S: f64 = 0.005;

/// Fades last at least this many periods of the mode, so low modes fade smoothly too (a 40 Hz
/// mode over 50 ms).
const FADE_PERIODS: f64 = 2.0;

/// Longest fade, in seconds.
const MAX_FADE_S: f64 = 0.25;

/// Every this many analyses, every mode is looked at, so a strike that masks other voices' modes
/// switches them off.
const FULL_EVERY: u32 = 4;

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
    /// Dormant or fading modes woken by strikes and input.
    pub woken: u64,
    /// Dormant modes that took a strike analytically.
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
    /// Budget ranking scratch: energy and candidate index.
    ranked: Vec<(f32, u32)>,
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
    /// Scratch: new recheck times `(mode, bank clock)` a strike sets.
    rechecks: Vec<(u32, u64)>,
    /// Number of `rechecks` in use.
    num_rechecks: usize,
    /// Analyses since every mode was last looked at.
    since_full: u32,
    /// Whether modes may be dormant or fading somewhere.
    engaged: bool,
    /// Whether the input has woken modes since the last analysis.
    pending: bool,
    /// The settings the last full look ran with: a change looks at everything again.
    settings: Option<(f32, bool, Option<usize>)>,
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
            rechecks: Vec::new(),
            num_rechecks: 0,
            since_full: 0,
            engaged: false,
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
        self.forget();
    }

    /// Forgets what it knew about the voices (they have all been freed).
    pub fn forget(&mut self) {
        self.engaged = false;
        self.pending = false;
        self.settings = None;
        self.maskers.len = 0;
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
            let k = vi * self.cands.stride + (m.who[j] & candidates::MODE_MASK) as usize;
            if skip_voice == Some(vi)
                || self.struck[vi]
                || self.generation[vi] != m.generation[j]
                || self.cands.index_of[k] != 0
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
    /// For candidate `i`, found inaudible, masked or over the budget: how long (in samples) until
    /// it could be heard again, the tag naming its masker's voice, and what keeps it off.
    fn when_off(&self, i: usize, offset_db: f32, now: u64) -> (u64, u32, OffReason) {
        let cd = &self.cands;
        let (vi, _) = cd.voice_mode(i);
        let to_truncation = samples_to_cross(cd.raw_db[i] - self.truncation_db[vi], cd.fall_db[i]);
        if cd.flags[i] & OVER_BUDGET != 0 {
            // Over budget: look again next frame; a strike leaves it to that look.
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
                let reason = OffReason {
                    // The envelope of every masker's curve: the masker named is one under it.
                    curve_db: cd.envelope_db[i],
                    fall_db: fall * curve_spread(bark, level, cd.bark[i]),
                    at: now,
                    threshold_db: cd.threshold_db[i],
                    generation: self.generation[vi],
                    masker: if voice as usize == vi {
                        who & candidates::MODE_MASK
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
struct OffReason {
    /// The masking curve at the mode at engine clock `at`, dB SPL.
    curve_db: f32,
    /// How fast the curve falls there, dB per sample.
    fall_db: f32,
    /// Engine clock of `curve_db`.
    at: u64,
    /// The threshold in quiet at the mode, dB SPL.
    threshold_db: f32,
    /// The generation of the mode's voice when judged: a retuned voice has it judged again.
    generation: u32,
    /// The mode whose masking curve it lies under, when that mode is in the same voice (a
    /// strike lifts both), else `u32::MAX`.
    masker: u32,
}

impl OffReason {
    /// Nothing known: a strike has the mode judged again.
    const UNKNOWN: Self = Self {
        curve_db: f32::NEG_INFINITY,
        fall_db: 0.0,
        at: 0,
        threshold_db: f32::NEG_INFINITY,
        generation: u32::MAX,
        masker: u32::MAX,
    };

    /// Off for the budget: a strike leaves it to the next analysis.
    const BUDGET: Self = Self {
        curve_db: f32::INFINITY,
        threshold_db: f32::INFINITY,
        ..Self::UNKNOWN
    };

    /// The level in dB SPL a mode must reach at engine clock `now` to be heard.
    fn level_to_beat(&self, now: u64) -> f32 {
        let curve = self.curve_db - self.fall_db * now.saturating_sub(self.at) as f32;
        curve.max(self.threshold_db)
    }
}

/// Samples per analysis frame: `frame_ms` rounded to whole control periods, at least one.
fn frame_samples(frame_ms: f32, sample_rate_hz: f64) -> u64 {
    let periods = (frame_ms as f64 * 1e-3 * sample_rate_hz / CONTROL_PERIOD as f64).round();
    periods.max(1.0) as u64 * CONTROL_PERIOD as u64
}

/// Samples of a fade for a mode at `theta` radians per sample: [`FADE_S`] or [`FADE_PERIODS`] of
/// the mode, whichever is longer (at most [`MAX_FADE_S`]), rounded up to whole control periods so
/// fades started on a tick end on one.
fn fade_samples(theta: f32, sample_rate_hz: f64) -> u32 {
    let periods = FADE_PERIODS * std::f64::consts::TAU / (theta as f64).max(1e-9);
    let samples = (FADE_S * sample_rate_hz)
        .max(periods)
        .min(MAX_FADE_S * sample_rate_hz);
    (samples / CONTROL_PERIOD as f64).ceil().max(1.0) as u32 * CONTROL_PERIOD as u32
}

/// Samples (as a clock offset) a level `margin_db` above a line can fall at `fall_db` per sample
/// before it reaches it.
fn samples_to_cross(margin_db: f32, fall_db: f32) -> u64 {
    (margin_db.max(0.0) / fall_db.max(1e-12)).min(1e15) as u64
}

impl Engine {
    /// dB SPL of a unit amplitude at the output now: the playback level, through the output gain.
    fn calibration_db(&self) -> f32 {
        self.controls.playback_level_db_spl + gain_to_db(self.smoothed.gain)
    }

    /// Pruning's share of a control tick: analyses on frame boundaries (and after input wakes).
    pub(super) fn prune_tick(&mut self, input_heard: bool) {
        let cap = self.budget.cap(&self.controls, self.sample_rate_hz);
        let wanted = self.controls.pruning || cap.is_some();
        if !wanted && !self.pruner.engaged {
            return;
        }
        let frame = frame_samples(self.controls.analysis_frame_ms, self.sample_rate_hz);
        if !(self.clock.is_multiple_of(frame) || self.pruner.pending) {
            return;
        }
        let start = self.pruner.profiling.then(Instant::now);
        self.analyse(input_heard, cap);
        if let Some(start) = start {
            self.pruner.stats.analysis_ns += start.elapsed().as_nanos() as u64;
        }
    }

    /// One analysis over every voice.
    fn analyse(&mut self, input_heard: bool, cap: Option<usize>) {
        let calibration_db = self.calibration_db();
        let Engine {
            pruner: p,
            voices,
            input_voice,
            controls: c,
            sample_rate_hz,
            clock,
            ..
        } = self;
        let (rate, now) = (*sample_rate_hz, *clock);
        p.pending = false;
        p.stats.analyses += 1;
        let settings = (c.masking_offset_db, c.pruning, cap);
        // A new calibration or setting changes every verdict (levels drift a little with the
        // output gain's smoothing first).
        let recheck_all =
            p.settings != Some(settings) || (calibration_db - p.calibration_db).abs() > 0.5;
        if recheck_all {
            p.settings = Some(settings);
            p.calibration_db = calibration_db;
        }
        let num_voices = voices.len();
        let mut any_changed = false;
        for (i, v) in voices.iter().chain(input_voice.as_ref()).enumerate() {
            let watch = VoiceWatch::of(v);
            if p.watch[i] != watch {
                p.watch[i] = watch;
                p.generation[i] = p.generation[i].wrapping_add(1) & GENERATION_MASK;
                any_changed = true;
            }
            let strikes = (v.modes.num_started(), v.modes.num_woken());
            p.struck[i] |= p.strikes[i] != strikes;
            p.strikes[i] = strikes;
        }
        // A budget ranks everything heard, so it looks at everything.
        let full = recheck_all || any_changed || cap.is_some() || p.since_full + 1 >= FULL_EVERY;
        p.since_full = if full { 0 } else { p.since_full + 1 };
        p.stats.full_analyses += full as u64;

        // Steps 1-4 of seed 001's pseudo-code: the energies of the modes that may change state.
        let reading = Reading::new(calibration_db, rate, cap.is_some());
        let stride = p.cands.stride;
        let mut engaged = false;
        for (vi, v) in voices.iter_mut().chain(input_voice.as_mut()).enumerate() {
            if v.state == VoiceState::Fading || v.modes.num_live() == 0 {
                continue;
            }
            engaged |= v.modes.num_dormant() + v.modes.num_fading() > 0;
            let is_input = vi == num_voices;
            let idle = v.exciter.is_idle();
            let driven = !idle || (is_input && input_heard);
            let every_active = full || p.struck[vi];
            // What the strikes under way add, at most (the seed adds the next frame's
            // excitation energy).
            let pulse = v.exciter.pending_bound();
            let truncation_db =
                c.truncation_db - 10.0 * (v.modes.num_started().max(1) as f32).log10();
            p.truncation_db[vi] = truncation_db;
            let generation = p.generation[vi];
            let (cands, heard_until) = (&mut p.cands, &p.heard_until);
            let wanted = |mode: usize, fading: bool| {
                every_active || fading || driven || heard_until[vi * stride + mode] <= now
            };
            v.modes.for_each_active_where(wanted, |m| {
                let locked = m.fading || driven;
                let power = if driven {
                    let amplitude = m.power.sqrt() + m.gain.abs() * pulse;
                    amplitude * amplitude
                } else {
                    m.power
                };
                let flags = if locked { LOCKED } else { 0 };
                cands.push(
                    vi,
                    generation,
                    m.mode,
                    crate::dsp::masking::power_to_db(power),
                    m.theta,
                    m.delta,
                    flags,
                    &reading,
                );
            });
            let bank_now = v.modes.clock();
            let due = if recheck_all || any_changed {
                u64::MAX
            } else {
                bank_now
            };
            let generations = &p.generation;
            v.modes.for_each_dormant(due, |d| {
                let stale_tag = d.tag != NO_TAG && {
                    let masker = (d.tag >> 24) as usize;
                    generations
                        .get(masker)
                        .is_none_or(|&g| g != d.tag & GENERATION_MASK)
                };
                if !(recheck_all || stale_tag || d.recheck_at <= bank_now) {
                    return;
                }
                // A driven voice cannot fade modes in: its dormant ones wait.
                let flags = if idle && d.level_db < truncation_db {
                    DORMANT | DROP
                } else if driven {
                    DORMANT | LOCKED
                } else {
                    DORMANT
                };
                cands.push(
                    vi, generation, d.mode, d.level_db, d.theta, d.delta, flags, &reading,
                );
            });
        }
        let n = p.cands.len;
        p.stats.candidates += n as u64;

        // The maskers found before, at today's levels, unless their mode is looked at again or
        // their voice has changed.
        let num_prior = if full { 0 } else { p.gather_priors(now, None) };

        // Steps 5-7: sort, threshold of hearing, masking.
        let cd = &mut p.cands;
        if c.pruning {
            p.pass.run_after(
                &p.prior_bark[..num_prior],
                &p.prior_level_db[..num_prior],
                &cd.level_db[..n],
                &cd.bark[..n],
                &cd.threshold_db[..n],
                c.masking_offset_db,
                &mut cd.verdicts[..n],
                Some(&mut cd.envelope_db[..n]),
            );
        } else {
            cd.verdicts[..n].fill(Verdict::Audible { masker: false });
            cd.envelope_db[..n].fill(f32::NEG_INFINITY);
        }

        // The budget: keep the most energetic of what is audible.
        if let Some(cap) = cap {
            p.ranked.clear();
            let mut locked = 0;
            for i in 0..n {
                let f = cd.flags[i];
                if f & DROP != 0 || !(cd.verdicts[i].is_audible() || f & LOCKED != 0) {
                    continue;
                }
                if f & LOCKED != 0 {
                    locked += 1;
                } else {
                    p.ranked.push((cd.energy_db[i], i as u32));
                }
            }
            let keep = cap.saturating_sub(locked);
            if keep < p.ranked.len() {
                keep_most_energetic(&mut p.ranked, keep);
                for &(_, i) in &p.ranked[keep..] {
                    cd.flags[i as usize] |= OVER_BUDGET;
                }
            }
        }

        // Switch modes off and on, and note when to look at each again.
        for i in 0..n {
            let f = p.cands.flags[i];
            if f & LOCKED != 0 {
                continue;
            }
            let (vi, mode) = p.cands.voice_mode(i);
            let bank = if vi == num_voices {
                match input_voice.as_mut() {
                    Some(v) => &mut v.modes,
                    None => continue,
                }
            } else {
                &mut voices[vi].modes
            };
            if f & DROP != 0 {
                bank.drop_dormant(mode);
                p.stats.dropped += 1;
                continue;
            }
            let fade = fade_samples(p.cands.theta[i], rate);
            if p.cands.verdicts[i].is_audible() && f & OVER_BUDGET == 0 {
                if f & DORMANT != 0 {
                    bank.switch_on(mode, fade);
                    p.stats.switched_on += 1;
                } else {
                    // Heard until its margin over the envelope has decayed away.
                    let margin = p.cands.level_db[i] - p.cands.envelope_db[i];
                    p.heard_until[vi * stride + mode] =
                        now + samples_to_cross(margin, p.cands.fall_db[i]);
                }
                continue;
            }
            // Off: when to look again, and what to watch.
            let (delay, tag, reason) = p.when_off(i, c.masking_offset_db, now);
            p.off[vi * stride + mode] = reason;
            let recheck_at = bank.clock() + delay;
            if f & DORMANT != 0 {
                bank.set_recheck(mode, recheck_at, tag);
            } else {
                bank.switch_off(mode, fade, recheck_at, tag);
                p.stats.switched_off += 1;
                engaged = true;
            }
        }

        // The maskers to carry over: those handed in, then the new ones.
        let cd = &mut p.cands;
        if c.pruning {
            let m = &mut p.maskers;
            m.len = 0;
            for jj in 0..num_prior {
                m.move_entry(p.prior_entry[jj] as usize, m.len);
                m.len += 1;
            }
            for &j in p.pass.maskers() {
                if j & PRIOR == 0 {
                    let i = j as usize;
                    let voice = (cd.who[i] >> 24) as usize;
                    m.push(
                        cd.bark[i],
                        cd.level_db[i],
                        cd.fall_db[i],
                        cd.who[i],
                        p.generation[voice],
                        now,
                    );
                }
            }
        } else {
            p.maskers.len = 0;
        }
        p.stats.maskers += p.maskers.len as u64;
        cd.clear();
        p.struck.fill(false);
        p.engaged = engaged;
    }

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
