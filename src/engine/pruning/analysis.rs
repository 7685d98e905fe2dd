//! One analysis over every voice: steps 1 to 8 of seed 001's pseudo-code, with the budget, on
//! analysis frame boundaries.

use std::time::Instant;

use super::candidates::{
    Reading, DORMANT, DRIVEN, DROP, LEAVING, LOCKED, OVER_BUDGET, UNSURE_MASKER,
};
use super::{fade_samples, frame_samples, samples_to_cross};
use super::{DORMANT_FULL_S, FULL_EVERY, GENERATION_MASK, NO_TAG};
use crate::dsp::pruning::{keep_most_energetic, Verdict, PRIOR};
use crate::engine::voice::VoiceState;
use crate::engine::Engine;
use crate::units::gain_to_db;

impl Engine {
    /// dB SPL of a unit amplitude at the output now: the playback level, through the output gain.
    pub(super) fn calibration_db(&self) -> f32 {
        self.expressed.playback_level_db_spl + gain_to_db(self.smoothed.gain)
    }

    /// Pruning's share of a control tick: analyses on frame boundaries (and after input wakes).
    pub(in crate::engine) fn prune_tick(&mut self, input_heard: bool) {
        let cap = self.budget.cap(&self.expressed, self.sample_rate_hz);
        let wanted = self.expressed.pruning || cap.is_some();
        if !wanted && !self.pruner.engaged {
            return;
        }
        let frame = frame_samples(self.expressed.analysis_frame_ms, self.sample_rate_hz);
        if !(self.clock.is_multiple_of(frame) || self.pruner.pending) {
            return;
        }
        let start = self.pruner.profiling.then(Instant::now);
        self.analyse(input_heard, cap, frame);
        if let Some(start) = start {
            self.pruner.stats.analysis_ns += start.elapsed().as_nanos() as u64;
        }
    }

    /// One analysis over every voice, analyses being `frame` samples apart.
    fn analyse(&mut self, input_heard: bool, cap: Option<usize>, frame: u64) {
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
        let settings = (c.masking_offset_db, c.pruning, cap, c.truncation_db);
        // A new calibration or setting changes every verdict (levels drift a little with the
        // output gain's smoothing first).
        let recheck_all =
            p.settings != Some(settings) || (calibration_db - p.calibration_db).abs() > 0.5;
        if recheck_all {
            p.settings = Some(settings);
            p.calibration_db = calibration_db;
        }
        let num_voices = voices.len();
        // A voice a strike found changed since the last analysis counts as changed now.
        let mut any_changed = std::mem::take(&mut p.changed);
        for (i, v) in voices.iter().chain(input_voice.as_ref()).enumerate() {
            any_changed |= p.watch_voice(i, v);
            let strikes = (v.modes.num_started(), v.modes.num_woken());
            p.struck[i] |= p.strikes[i] != strikes;
            p.strikes[i] = strikes;
        }
        // A budget ranks everything heard, so it looks at everything.
        let full = recheck_all || any_changed || cap.is_some() || p.since_full + 1 >= FULL_EVERY;
        p.since_full = if full { 0 } else { p.since_full + 1 };
        let dormant_every = (DORMANT_FULL_S * rate / frame as f64).ceil() as u32;
        let dormant_full = recheck_all || p.since_dormant_full + 1 >= dormant_every;
        p.since_dormant_full = if dormant_full {
            0
        } else {
            p.since_dormant_full + 1
        };
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
                let flags = if locked { LOCKED } else { 0 }
                    | if driven { DRIVEN } else { 0 }
                    | if m.leaving { LEAVING } else { 0 };
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
            let due = if dormant_full || any_changed {
                u64::MAX
            } else {
                bank_now
            };
            let (generations, off) = (&p.generation, &p.off);
            v.modes.for_each_dormant(due, |d| {
                let stale_tag = d.tag != NO_TAG && {
                    let masker = (d.tag >> 24) as usize;
                    generations
                        .get(masker)
                        .is_none_or(|&g| g != d.tag & GENERATION_MASK)
                };
                if !(dormant_full || stale_tag || d.recheck_at <= bank_now) {
                    return;
                }
                // Under the threshold in quiet at its tuning, a mode only gets quieter until its
                // voice is struck (judged then) or its recheck time (at the latest, truncation)
                // comes: the sweep and a masker's change pass it over.
                if !recheck_all && d.recheck_at > bank_now {
                    let reason = &off[vi * stride + d.mode];
                    if reason.generation == generation
                        && d.level_db + calibration_db < reason.threshold_db
                    {
                        return;
                    }
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
        if c.pruning {
            p.run_pass(num_prior, c.masking_offset_db);
        } else {
            let cd = &mut p.cands;
            cd.verdicts[..n].fill(Verdict::Audible { masker: false });
            cd.envelope_db[..n].fill(f32::NEG_INFINITY);
        }
        let cd = &mut p.cands;

        // The budget: keep the `cap` most energetic of what is audible. A mode that cannot be
        // switched now (fading, or in a voice being driven) stays computed wherever it ranks,
        // but takes no place from a stronger one: it runs over the cap until it can be switched.
        // One already fading out takes no place, nor does one not heard (switched off when it
        // can be, if still unheard).
        if let Some(cap) = cap {
            p.ranked.clear();
            for i in 0..n {
                let f = cd.flags[i];
                // A dormant mode waiting for its voice's drive to end is not computed.
                let waiting = f & (DORMANT | LOCKED) == DORMANT | LOCKED;
                if waiting || f & (DROP | LEAVING) != 0 || !cd.verdicts[i].is_audible() {
                    continue;
                }
                p.ranked.push((cd.energy_db[i], i as u32));
            }
            if cap < p.ranked.len() {
                keep_most_energetic(&mut p.ranked, cap);
                for &(_, i) in &p.ranked[cap..] {
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
            let fade = || fade_samples(p.cands.theta[i], rate);
            if p.cands.verdicts[i].is_audible() && f & OVER_BUDGET == 0 {
                if f & DORMANT != 0 {
                    bank.switch_on(mode, fade());
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
                bank.switch_off(mode, fade(), recheck_at, tag);
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
                // Maskers silenced by the budget, lifted by a strike's bound or fading out are not
                // carried.
                if j & PRIOR == 0 && cd.flags[j as usize] & UNSURE_MASKER == 0 {
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
}
