//! A strike on a voice with dormant modes.
//!
//! The strike is known in full when it comes (an impulse or a mallet pulse of known area and
//! length), so every dormant mode of the struck voice, and every mode it starts from rest (they
//! start dormant, with no reason yet to be off), takes it analytically
//! ([`crate::dsp::ResonatorBank::absorb_strike`]) and its level afterwards is known (exactly, or
//! through a long pulse on a fast-decaying mode, as a bound until the pulse ends). Most stay
//! under what kept them off (the masking curve over them, falling as its masker decays, or the
//! threshold in quiet), and stay dormant: a comparison each. The few lifted above it, and the
//! modes started, are judged by the masking pass, against the maskers carried over from the last
//! analysis and the voice's own computed modes as the strike leaves them; those found audible are
//! woken at the strike's exact sample and compute it from its first sample, their old ringing (a
//! mode started by the strike has none) fading back in beside them. Modes decaying too fast to
//! take the pulse analytically are computed through it. A noise burst is not known in advance: it
//! wakes them all.
//!
//! A voice that has taken a new note or tuning since the last analysis is judged as it is now:
//! its generation moves on at the strike, and the next analysis looks again at what it masked.
//!
//! Under a budget, only as many are woken as the budget would keep, ranked by energy with the
//! modes computed now and not fading out; the next control tick ranks everything again. With the
//! budget alone the modes judged are those the strike lifts as far as it would start a silent one.

use std::time::Instant;

use super::candidates::{energy_db, Reading, DORMANT, DRIVEN};
use super::{samples_to_cross, OffReason, NO_TAG};
use crate::dsp::masking::{power_to_db, DB_PER_NEPER};
use crate::dsp::prefetch::{self, prefetch};
use crate::dsp::resonator_bank::Pulse;
use crate::dsp::ExciterKind;
use crate::engine::mode_fade::next_tick;
use crate::engine::voice::start_threshold;
use crate::engine::voice::VoiceState;
use crate::engine::Engine;
use crate::units::db_to_gain;

impl Engine {
    /// Before voice `i` is struck by `kind`: modes fading in or out are woken (through their
    /// poles they cannot take input), and every dormant one too for noise. Dormant modes left
    /// (and those the strike starts dormant) take it analytically with [`Engine::settle_strike`].
    pub(in crate::engine) fn prepare_strike(&mut self, i: usize, kind: ExciterKind) {
        self.pruner.struck[i] = true;
        // Under a budget, the modes the strike starts are ranked at the next control tick rather
        // than a frame later, so the cap holds within a control period.
        if self
            .budget
            .cap(&self.expressed, self.sample_rate_hz)
            .is_some()
        {
            self.pruner.pending = true;
        }
        let modes = &mut self.voices[i].modes;
        if modes.num_dormant() + modes.num_fading() == 0 {
            return;
        }
        let start = self.pruner.profiling.then(Instant::now);
        let tick = next_tick(self.clock);
        match kind.pulse_shape() {
            Some(_) => modes.wake_fading(tick),
            None => modes.wake_all(tick),
        }
        if let Some(start) = start {
            self.pruner.stats.strike_ns += start.elapsed().as_nanos() as u64;
        }
    }

    /// After voice `i` has been struck by `kind` of `amplitude` over `len` samples with the gains
    /// in `strike_gains`: its dormant modes take the pulse analytically, and those it makes
    /// audible are woken (under a budget, as many as it would keep).
    pub(in crate::engine) fn settle_strike(
        &mut self,
        i: usize,
        kind: ExciterKind,
        amplitude: f32,
        len: u32,
    ) {
        let Some(shape) = kind.pulse_shape() else {
            return;
        };
        let start = self.pruner.profiling.then(Instant::now);
        let pulse = Pulse {
            shape,
            amplitude,
            len,
        };
        let gains = &self.strike_gains;
        let tick = next_tick(self.clock);
        let modes = &mut self.voices[i].modes;
        // With pruning the modes are judged below; with a budget alone, ranked by energy;
        // otherwise the next analysis looks at them.
        let pruning = self.expressed.pruning;
        self.pruner.stats.absorbed +=
            modes.absorb_strike(pulse, !pruning, tick, |m| gains[m]) as u64;
        if modes.num_dormant() > 0 {
            // Dormant modes are left whatever comes of it: the analyses must go on even if
            // pruning and the budget are turned off before the next one, to bring them back.
            self.pruner.engaged = true;
            let bound = amplitude * kind.peak_bound(len);
            let cap = self.budget.cap(&self.expressed, self.sample_rate_hz);
            if pruning {
                self.judge_struck(i, bound, cap);
            } else if let Some(cap) = cap {
                self.wake_within_budget(i, bound, cap);
            }
        }
        if let Some(start) = start {
            self.pruner.stats.strike_ns += start.elapsed().as_nanos() as u64;
        }
    }

    /// Under a budget alone: of the dormant modes of voice `i` (all switched off by the budget),
    /// those a strike adding up to `bound` times each mode's gain in `strike_gains` lifts as far
    /// as it would start a silent one are woken, as many as the budget would keep.
    fn wake_within_budget(&mut self, i: usize, bound: f32, cap: usize) {
        let threshold = start_threshold(
            db_to_gain(self.expressed.truncation_db),
            self.bank.num_modes(),
        );
        let Engine {
            pruner: p,
            voices,
            strike_gains: gains,
            ..
        } = self;
        p.ranked.clear();
        let ranked = &mut p.ranked;
        voices[i].modes.for_each_dormant(u64::MAX, |d| {
            if gains[d.mode].abs() * bound >= threshold {
                ranked.push((energy_db(d.level_db, d.theta, d.delta), d.mode as u32));
            }
        });
        let n = self.best_within_budget(cap);
        let tick = next_tick(self.clock);
        let Engine { pruner, voices, .. } = self;
        for &(_, mode) in &pruner.ranked[..n] {
            voices[i].modes.wake(mode as usize, tick);
        }
    }

    /// Sorts the lifted modes in `pruner.ranked` (energy, and what they are) by energy and
    /// returns how many of the first rank within the budget `cap` among them and every mode
    /// computed now and not fading out (at its level with the strikes under way added): at most
    /// as many as the next ranking keeps, which leaves out computed modes not heard too. The
    /// modes woken go on at once; the next control tick ranks everything again.
    fn best_within_budget(&mut self, cap: usize) -> usize {
        let Engine {
            pruner: p,
            voices,
            input_voice,
            ..
        } = self;
        if p.ranked.is_empty() {
            return 0;
        }
        p.computed_energy.clear();
        for v in voices.iter().chain(input_voice.as_ref()) {
            // The ranking leaves out voices fading after being stolen.
            if v.state == VoiceState::Fading {
                continue;
            }
            let pending = v.exciter.pending_bound();
            let energies = &mut p.computed_energy;
            v.modes.for_each_active(|m| {
                // A mode fading out takes no place in the ranking.
                if !m.leaving {
                    let a = m.power.sqrt() + m.gain.abs() * pending;
                    energies.push(energy_db(power_to_db(a * a), m.theta, m.delta));
                }
            });
        }
        // Loudest first; NaN last.
        let key = |e: f32| if e.is_nan() { f32::NEG_INFINITY } else { e };
        p.ranked
            .sort_unstable_by(|a, b| key(b.0).total_cmp(&key(a.0)));
        p.computed_energy
            .sort_unstable_by(|a, b| key(*b).total_cmp(&key(*a)));
        // Lifted mode `j` is kept if it and the computed modes at least as energetic fit.
        let mut louder = 0;
        let mut fit = 0;
        for (j, &(e, _)) in p.ranked.iter().enumerate() {
            while louder < p.computed_energy.len() && key(p.computed_energy[louder]) >= key(e) {
                louder += 1;
            }
            if j + louder >= cap {
                break;
            }
            fit = j + 1;
        }
        fit
    }

    /// Wakes the dormant modes of voice `i` that a strike adding up to `bound` times each
    /// mode's gain in `strike_gains` (already taken by the dormant modes) makes audible: under
    /// a budget `cap`, only as many as it would keep, the others being left to the next
    /// analysis.
    fn judge_struck(&mut self, i: usize, bound: f32, cap: Option<usize>) {
        let calibration_db = self.calibration_db();
        let Engine {
            pruner: p,
            voices,
            controls: c,
            sample_rate_hz,
            clock,
            strike_gains: gains,
            ..
        } = self;
        let now = *clock;
        let tick = next_tick(now);
        let reading = Reading::new(calibration_db, *sample_rate_hz, cap.is_some());
        // A voice taking a new note (or retuned) since the last analysis is judged as what it is
        // now, not by what was worked out for the old one.
        p.changed |= p.watch_voice(i, &voices[i]);
        let generation = p.generation[i];
        let stride = p.cands.stride;
        let modes = &mut voices[i].modes;
        let bank_now = modes.clock();
        // Each dormant mode against what kept it off; those lifted above it are judged again.
        let mut num_dormant = 0;
        let scratch = &mut p.dormant_scratch;
        modes.for_each_dormant(u64::MAX, |d| {
            scratch[num_dormant] = d;
            num_dormant += 1;
        });
        p.num_rechecks = 0;
        // A new stamp for this strike's lifts (every entry is stale after a wrap, as after
        // `reserve`).
        p.lift_stamp = p.lift_stamp.wrapping_add(1);
        if p.lift_stamp == 0 {
            p.lift_db.fill((0, 0.0, 0.0));
            p.lift_stamp = 1;
        }
        let dormant = &p.dormant_scratch[..num_dormant];
        for (k, d) in dormant.iter().enumerate() {
            // The records are in no order of mode: ask early for a later one's reason.
            if let Some(ahead) = dormant.get(k + prefetch::AHEAD) {
                prefetch(&p.off, i * stride + ahead.mode);
            }
            // A mode off for the budget is judged like a lifted one (its reason names no
            // voice generation).
            let reason = p.off[i * stride + d.mode];
            let stale_tag = d.tag != NO_TAG && {
                let masker = (d.tag >> 24) as usize;
                p.generation
                    .get(masker)
                    .is_none_or(|&g| g != d.tag & super::GENERATION_MASK)
            };
            let level_db = d.level_db + calibration_db;
            // A masker in this voice takes the strike too: its curve rises with it, by at most
            // `lift_db` (in phase) and at least `least_lift_db` (out of phase, a fall). A masker
            // no longer computed is not known, and the mode is judged again.
            // Worked out once per masker: many modes lie under the same few.
            let (lift_db, least_lift_db) = if reason.masker == u32::MAX {
                (0.0, 0.0)
            } else {
                let masker = reason.masker as usize;
                match p.lift_db[masker] {
                    (stamp, lift, least) if stamp == p.lift_stamp => (lift, least),
                    _ => {
                        let (lift, least) = match modes.state(masker) {
                            Some((re, im)) => {
                                let a = (re * re + im * im).sqrt();
                                let pulse = gains[masker].abs() * bound;
                                let (most, least) = (a + pulse, (a - pulse).max(0.0));
                                let now_db = power_to_db(a * a);
                                (
                                    power_to_db(most * most) - now_db,
                                    power_to_db(least * least) - now_db,
                                )
                            }
                            None => (f32::NEG_INFINITY, f32::NEG_INFINITY),
                        };
                        p.lift_db[masker] = (p.lift_stamp, lift, least);
                        (lift, least)
                    }
                }
            };
            let to_beat = reason.level_to_beat(now) + lift_db;
            // A mode started from rest by this strike has no reason yet.
            if !d.from_rest && reason.generation == generation && !stale_tag && level_db < to_beat {
                // Still off. Under the lowest curve the strike can leave, it surfaces no sooner
                // than its margin under the curve allows.
                let unlifted = reason.curve_db - reason.fall_db * (now - reason.at) as f32;
                let curve = unlifted + lift_db;
                let fall = DB_PER_NEPER * d.delta as f32;
                let closing = reason.fall_db - fall;
                let lowest = (unlifted + least_lift_db).max(reason.threshold_db);
                let recheck_at = if level_db >= lowest {
                    // Off only if its masker takes the strike well enough in phase: the next
                    // analysis reads the masker as it is.
                    bank_now
                } else if curve > reason.threshold_db && closing > 0.0 {
                    bank_now + samples_to_cross(curve - level_db, closing)
                } else {
                    d.recheck_at
                };
                let recheck_at = d.recheck_at.min(recheck_at);
                if recheck_at != d.recheck_at {
                    p.rechecks[p.num_rechecks] = (d.mode as u32, recheck_at);
                    p.num_rechecks += 1;
                }
                continue;
            }
            p.cands.push(
                i, generation, d.mode, d.level_db, d.theta, d.delta, DORMANT, &reading,
            );
        }
        for &(mode, recheck_at) in &p.rechecks[..p.num_rechecks] {
            modes.set_recheck_time(mode as usize, recheck_at);
        }
        let num_dormant = p.cands.len;
        if num_dormant == 0 {
            return;
        }
        // The voice's computed modes as the strike leaves them, to mask the lifted ones.
        let cands = &mut p.cands;
        modes.for_each_active(|m| {
            let a = m.power.sqrt() + gains[m.mode].abs() * bound;
            cands.push(
                i,
                generation,
                m.mode,
                power_to_db(a * a),
                m.theta,
                m.delta,
                DRIVEN,
                &reading,
            );
        });
        let n = cands.len;
        p.stats.candidates += n as u64;
        let num_prior = p.gather_priors(now, Some(i));
        p.run_pass(num_prior, c.masking_offset_db);
        p.ranked.clear();
        for k in 0..num_dormant {
            let mode = p.cands.voice_mode(k).1;
            if !p.cands.verdicts[k].is_audible() {
                let (delay, tag, reason) = p.when_off(k, c.masking_offset_db, now);
                p.off[i * stride + mode] = reason;
                modes.set_recheck(mode, bank_now + delay, tag);
            } else if cap.is_some() {
                p.ranked.push((p.cands.energy_db[k], mode as u32));
            } else {
                modes.wake(mode, tick);
            }
        }
        p.cands.clear();
        if let Some(cap) = cap {
            let n = self.best_within_budget(cap);
            let Engine {
                pruner: p, voices, ..
            } = self;
            let modes = &mut voices[i].modes;
            for (j, &(_, mode)) in p.ranked.iter().enumerate() {
                if j < n {
                    modes.wake(mode as usize, tick);
                } else {
                    // Heard, but not within the budget now: the next analysis ranks it.
                    p.off[i * stride + mode as usize] = OffReason::BUDGET;
                    modes.set_recheck(mode as usize, bank_now, NO_TAG);
                }
            }
        }
    }
}
