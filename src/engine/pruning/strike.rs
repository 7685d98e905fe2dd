//! A strike on a voice with dormant modes.
//!
//! The strike is known in full when it comes (an impulse or a mallet pulse of known area and
//! length), so the masking pass can judge the struck voice's modes at once: each mode's level is
//! bounded by its amplitude now plus what the strike can add (`|g| A`), against the masking
//! curves of the maskers carried over from the last analysis and of the voice's own louder modes.
//! Dormant modes the strike makes audible are woken at its exact sample, and take it computed
//! (their old ringing fading back in beside them); the others take it analytically
//! ([`crate::dsp::ResonatorBank::absorb_strike`]) and stay dormant. A noise burst is not known in
//! advance: it wakes them all.

use std::time::Instant;

use super::candidates::{Reading, DORMANT};
use super::Engine;
use crate::dsp::masking::{power_to_db, DB_PER_NEPER};
use crate::dsp::resonator_bank::{Pulse, PulseShape};
use crate::dsp::ExciterKind;
use crate::engine::PositionWeights;

impl Engine {
    /// Before voice `i` is struck by `kind` of `amplitude` over `len` samples at strike point
    /// `weights`: wakes the dormant modes the strike makes audible (all of them for noise).
    /// Returns the pulse the other dormant modes are to take, with
    /// [`Engine::settle_strike`] once the voice has been struck.
    pub(in crate::engine) fn wake_for_strike(
        &mut self,
        i: usize,
        kind: ExciterKind,
        amplitude: f32,
        len: u32,
        weights: &PositionWeights,
    ) -> Option<Pulse> {
        self.pruner.struck[i] = true;
        let modes = &self.voices[i].modes;
        if modes.num_dormant() + modes.num_fading() == 0 {
            return None;
        }
        let start = self.pruner.profiling.then(Instant::now);
        let shape = match kind {
            ExciterKind::Impulse => Some(PulseShape::Impulse),
            ExciterKind::Mallet => Some(PulseShape::Mallet),
            ExciterKind::Noise => None,
        };
        let pulse = match shape {
            Some(shape) => {
                // Modes fading in or out cannot take input through their poles.
                self.voices[i].modes.wake_fading();
                if self.voices[i].modes.num_dormant() > 0 {
                    self.wake_audible(i, amplitude * kind.peak_bound(len), weights);
                }
                Some(Pulse {
                    shape,
                    amplitude,
                    len,
                })
            }
            None => {
                self.voices[i].modes.wake_all();
                None
            }
        };
        if let Some(start) = start {
            self.pruner.stats.strike_ns += start.elapsed().as_nanos() as u64;
        }
        pulse.filter(|_| self.voices[i].modes.num_dormant() > 0)
    }

    /// After voice `i` has been struck: its dormant modes take `pulse` at strike point `weights`.
    pub(in crate::engine) fn settle_strike(
        &mut self,
        i: usize,
        pulse: Option<Pulse>,
        weights: &PositionWeights,
    ) {
        let Some(pulse) = pulse else {
            return;
        };
        let start = self.pruner.profiling.then(Instant::now);
        let bank = &self.bank;
        let modes = &mut self.voices[i].modes;
        self.pruner.stats.absorbed += modes.num_dormant() as u64;
        // With pruning the strike's verdicts have set when to look again; a budget alone looks
        // at the next frame.
        let due = !self.controls.pruning;
        modes.absorb_strike(pulse, due, |m| bank.gain_at(m, weights));
        if let Some(start) = start {
            self.pruner.stats.strike_ns += start.elapsed().as_nanos() as u64;
        }
    }

    /// Runs the masking pass over voice `i` as it will be after a strike adding up to `bound`
    /// times each mode's gain at `weights`, and wakes the dormant modes it finds audible.
    fn wake_audible(&mut self, i: usize, bound: f32, weights: &PositionWeights) {
        let calibration_db = self.calibration_db();
        let Engine {
            pruner: p,
            voices,
            controls: c,
            sample_rate_hz,
            clock,
            bank,
            ..
        } = self;
        if !c.pruning {
            // Only a budget: the next analysis brings back what fits.
            return;
        }
        let reading = Reading::new(calibration_db, *sample_rate_hz, false);
        let generation = p.generation[i];
        p.truncation_db[i] =
            c.truncation_db - 10.0 * (voices[i].modes.num_started().max(1) as f32).log10();
        let cands = &mut p.cands;
        let modes = &mut voices[i].modes;
        modes.for_each_active(|m| {
            let a = m.power.sqrt() + bank.gain_at(m.mode, weights).abs() * bound;
            cands.push(
                i,
                generation,
                m.mode,
                power_to_db(a * a),
                m.theta,
                m.delta,
                0,
                &reading,
            );
        });
        modes.for_each_dormant(u64::MAX, |d| {
            let a = (d.level_db / DB_PER_NEPER).exp() + bank.gain_at(d.mode, weights).abs() * bound;
            cands.push(
                i,
                generation,
                d.mode,
                power_to_db(a * a),
                d.theta,
                d.delta,
                DORMANT,
                &reading,
            );
        });
        let n = cands.len;
        p.stats.candidates += n as u64;
        let num_prior = p.gather_priors(*clock, Some(i));
        let cd = &mut p.cands;
        p.pass.run_after(
            &p.prior_bark[..num_prior],
            &p.prior_level_db[..num_prior],
            &cd.level_db[..n],
            &cd.bark[..n],
            &cd.threshold_db[..n],
            c.masking_offset_db,
            &mut cd.verdicts[..n],
            None,
        );
        let bank_now = modes.clock();
        for k in 0..n {
            if p.cands.flags[k] & DORMANT == 0 {
                continue;
            }
            let mode = p.cands.voice_mode(k).1;
            if p.cands.verdicts[k].is_audible() {
                modes.wake(mode);
            } else {
                // It takes the strike analytically; its level with the strike is at most the
                // bound judged here, so it is looked at again no later than it has to be.
                let (delay, tag) = p.when_off(k, c.masking_offset_db);
                modes.set_recheck(mode, bank_now + delay, tag);
            }
        }
        p.cands.clear();
    }
}
