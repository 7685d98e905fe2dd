//! Dormant modes: switched off by perceptual pruning or a computation budget, their state carried
//! analytically so they can come back in phase. Switching off and on goes through a fade
//! ([`super::fades`]).
//!
//! Without input a mode's phasor evolves as `z[t + n] = p^n z[t]` with `p = exp(-delta + i theta)`
//! (its pole): the amplitude falls by `delta` nepers per sample and the phase turns by `theta`
//! radians. A dormant mode keeps the state it had when it was switched off and accumulates both
//! (in `f64`, piece by piece when its pole changes), so its state at any later time costs one `exp`
//! and one `sin_cos`, and its level in dB one multiply-add. Nothing is spent on it per sample.
//! Fades move the output as a smooth exponential envelope, never stepping by more than
//! `exp(-FADE_DEPTH_NEPERS)` of the mode's amplitude.

use std::f64::consts::{PI, TAU};

use super::{ModeCoeffs, ResonatorBank, COLUMNS, NONE};
use crate::dsp::coeffs_batch::{cos_series, sin_series};
use crate::dsp::masking::{power_to_db, DB_PER_NEPER};

/// Depth of a fade in nepers: `ln 1000`, 60 dB. What is left when a fade out ends, or missing
/// when a fade in starts, is a thousandth of the mode's amplitude.
pub const FADE_DEPTH_NEPERS: f64 = 6.907_755_278_982_137;

/// A mode's state carried without computing it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Dormant {
    /// The mode.
    pub mode: u32,
    /// Its accumulator column, where it returns.
    pub column: u32,
    /// The gain what is left of the pulses under way reaches it with, as the latest strike set
    /// the computed modes' (zero for a mode started from rest until its strike comes).
    pub gain: f32,
    /// Samples it fades over, in and out.
    pub fade_len: u32,
    /// Real part of its state when it was switched off.
    pub re: f32,
    /// Imaginary part of its state when it was switched off.
    pub im: f32,
    /// `10 log10(re^2 + im^2)`: its power in dB when it was switched off.
    pub snap_db: f32,
    /// Radians turned since it was switched off, reduced to `0..2 pi`.
    pub phase: f64,
    /// Nepers of amplitude gained since it was switched off (never positive).
    pub log_gain: f64,
    /// Bank clock up to which `phase` and `log_gain` are accumulated.
    pub at: u64,
    /// Pole angle now, radians per sample.
    pub theta: f64,
    /// Pole radius exponent now: decay per sample.
    pub delta: f64,
    /// The pole itself, `exp(-delta + i theta)`, real part.
    pub p_re: f64,
    /// The pole, imaginary part.
    pub p_im: f64,
    /// The pruner's note about what keeps the mode off (its masker).
    pub tag: u32,
    /// Bank clock at which it started from rest without being computed
    /// ([`ResonatorBank::start_dormant`]), else `u64::MAX`: woken at that instant it has no
    /// ringing of its own to fade back in.
    pub rest_at: u64,
    /// Samples after `at` until the pulses it took analytically end, if its level is to be
    /// bounded until then (its state runs ahead of the truth by what they have not played yet).
    pub pulse_left: u32,
    /// Bound on its power until the pulses end, in dB: its amplitude before them plus all they
    /// can add.
    pub pulse_peak_db: f32,
}

impl Dormant {
    /// An unused record.
    pub const EMPTY: Self = Self {
        mode: NONE,
        column: 0,
        gain: 0.0,
        fade_len: 1,
        re: 0.0,
        im: 0.0,
        snap_db: f32::NEG_INFINITY,
        phase: 0.0,
        log_gain: 0.0,
        at: 0,
        theta: 0.0,
        delta: 0.0,
        p_re: 1.0,
        p_im: 0.0,
        tag: 0,
        rest_at: u64::MAX,
        pulse_left: 0,
        pulse_peak_db: f32::INFINITY,
    };

    /// Takes a new pole from now on (after [`Dormant::advance_to`]).
    pub fn set_pole(&mut self, theta: f64, delta: f64) {
        if (theta, delta) != (self.theta, self.delta) {
            (self.theta, self.delta) = (theta, delta);
            let c = ModeCoeffs::from_angle_radius(theta, delta);
            (self.p_re, self.p_im) = (1.0 + c.q_re as f64, c.q_im as f64);
        }
    }

    /// Accumulates phase and decay up to bank clock `now`.
    pub fn advance_to(&mut self, now: u64) {
        let samples = now.saturating_sub(self.at);
        let n = samples as f64;
        let phase = self.phase + self.theta * n;
        self.phase = phase - TAU * floor(phase * (1.0 / TAU));
        self.log_gain -= self.delta * n;
        self.pulse_left = (self.pulse_left as u64).saturating_sub(samples) as u32;
        self.at = now;
    }

    /// Power `|z|^2` in dB at bank clock `t` (not before `at`). While the pulses it took with a
    /// bound play, its state runs ahead of the truth (louder, or quieter where what they have
    /// still to play works against its ringing): their bound instead.
    #[inline]
    pub fn level_db_at(&self, t: u64) -> f32 {
        if t < self.at + self.pulse_left as u64 {
            return self.pulse_peak_db;
        }
        let log_gain = self.log_gain - self.delta * t.saturating_sub(self.at) as f64;
        // 20 log10 of the amplitude: a neper of amplitude is DB_PER_NEPER dB.
        self.snap_db + (DB_PER_NEPER as f64 * log_gain) as f32
    }

    /// Power `|z|^2` at bank clock `t` (not before `at`).
    pub fn power_at(&self, t: u64) -> f32 {
        let log_gain = self.log_gain - self.delta * t.saturating_sub(self.at) as f64;
        (self.re * self.re + self.im * self.im) * (2.0 * log_gain).exp() as f32
    }

    /// The state at `at`.
    pub fn state(&self) -> (f32, f32) {
        // `phase` is in 0..2 pi: sin and cos of its half-angle about pi by series (to about
        // 1e-13), cheaper than libm's range reduction.
        let h = 0.5 * (self.phase - PI);
        let (sh, ch) = (sin_series(h), cos_series(h));
        let (s, c) = (-2.0 * sh * ch, 2.0 * sh * sh - 1.0);
        let g = self.log_gain.exp();
        let (re, im) = (self.re as f64, self.im as f64);
        (
            (g * (re * c - im * s)) as f32,
            (g * (re * s + im * c)) as f32,
        )
    }
}

/// `x` rounded down, for `|x|` below `2^63`: a truncation and a compare, where `f64::floor` is a
/// library call on x86-64 without SSE4.1.
#[inline]
pub(crate) fn floor(x: f64) -> f64 {
    let t = x as i64 as f64;
    if t > x {
        t - 1.0
    } else {
        t
    }
}

impl ResonatorBank {
    /// Samples processed since the bank was last cleared.
    pub fn clock(&self) -> u64 {
        self.clock
    }

    /// Number of modes switched off and carried analytically (not those still fading out).
    pub fn num_dormant(&self) -> usize {
        self.num_dormant - self.num_fading_out
    }

    /// The modes switched off and carried analytically (not those still fading out).
    pub fn dormant_modes(&self) -> impl Iterator<Item = usize> + '_ {
        self.dormant[..self.num_dormant]
            .iter()
            .map(|d| d.mode as usize)
            .filter(|&m| !self.still_fading_out(m))
    }

    /// Whether `mode`, which has a record, is still fading out: the one case of a mode with a
    /// slot beside its record, so the slot is looked up only while some mode fades out.
    #[inline]
    pub(super) fn still_fading_out(&self, mode: usize) -> bool {
        debug_assert!(self.num_fading_out > 0 || self.slot_of_mode[mode] == NONE);
        self.num_fading_out > 0 && self.slot_of_mode[mode] != NONE
    }

    /// Number of slots fading in or out, ghosts included.
    pub fn num_fading(&self) -> usize {
        self.num_fading
    }

    /// Modes woken with old ringing to fade back in beside them (a ghost) since the bank was
    /// made: by strikes and input, not counting modes a strike started and woke at once.
    pub fn num_woken(&self) -> u64 {
        self.woken
    }

    /// Notes when (in bank clock) the pruner should next look at dormant `mode`, and why it is
    /// off.
    pub fn set_recheck(&mut self, mode: usize, recheck_at: u64, tag: u32) {
        let r = self.dormant_of_mode[mode];
        if r != NONE {
            let recheck_at = self.by_pulse_end(r as usize, recheck_at);
            self.recheck[r as usize] = recheck_at;
            self.dormant[r as usize].tag = tag;
            self.earliest_recheck = self.earliest_recheck.min(recheck_at);
        }
    }

    /// Moves the time the pruner next looks at dormant `mode` to `recheck_at` (bank clock),
    /// keeping its note.
    pub fn set_recheck_time(&mut self, mode: usize, recheck_at: u64) {
        let r = self.dormant_of_mode[mode];
        if r != NONE {
            let recheck_at = self.by_pulse_end(r as usize, recheck_at);
            self.recheck[r as usize] = recheck_at;
            self.earliest_recheck = self.earliest_recheck.min(recheck_at);
        }
    }

    /// `recheck_at`, or the end of the pulses record `r` reads a bound through if sooner: its
    /// level then jumps back to the truth, which a time worked out from the bound misses.
    fn by_pulse_end(&self, r: usize, recheck_at: u64) -> u64 {
        let d = &self.dormant[r];
        let end = d.at + d.pulse_left as u64;
        if end > self.clock {
            recheck_at.min(end)
        } else {
            recheck_at
        }
    }

    /// Starts fading computed `mode` out over `fade_samples`; from then on it is carried
    /// analytically. Modes already fading, or with a ghost, are left alone.
    pub fn switch_off(&mut self, mode: usize, fade_samples: u32, recheck_at: u64, tag: u32) {
        let slot = self.slot_of_mode[mode];
        if slot == NONE || self.fade_delta[slot as usize] != 0.0 || self.ghost_of_mode[mode] != NONE
        {
            return;
        }
        let slot = slot as usize;
        let (theta, delta) = self.pole_of_slot(slot);
        let (re, im) = (self.re[slot], self.im[slot]);
        let len = fade_samples.max(1);
        self.push_record(
            Dormant {
                mode: mode as u32,
                column: (slot % COLUMNS) as u32,
                gain: self.gain[slot],
                fade_len: len,
                re,
                im,
                snap_db: power_to_db(re * re + im * im),
                phase: 0.0,
                log_gain: 0.0,
                at: self.clock,
                theta,
                delta,
                // The pole the kernel ran the mode with.
                p_re: 1.0 + self.q_re[slot] as f64,
                p_im: self.q_im[slot] as f64,
                tag,
                rest_at: u64::MAX,
                pulse_left: 0,
                pulse_peak_db: f32::INFINITY,
            },
            recheck_at,
        );
        (self.theta[slot], self.delta[slot]) = (theta, delta);
        self.start_fade(slot, FADE_DEPTH_NEPERS / len as f64, len);
        self.num_fading_out += 1;
    }

    /// Makes `mode` sound from rest without computing it, unless it already sounds: a strike
    /// about to come then reaches it analytically ([`ResonatorBank::absorb_strike`], which gives
    /// it its gain; until then it takes nothing), and the pruner wakes it at the strike's sample
    /// only if it is heard. Its pole comes with the next [`ResonatorBank::set_poles_with`],
    /// which must precede the strike; `fade_samples` is how long it fades in or out if switched
    /// later. Due for a look now. Returns whether it was added.
    pub fn start_dormant(&mut self, mode: usize, fade_samples: u32) -> bool {
        if self.is_live(mode) {
            return false;
        }
        let column = self.column_for(mode);
        self.claimed[column] += 1;
        let now = self.clock;
        self.push_record(
            Dormant {
                mode: mode as u32,
                column: column as u32,
                gain: 0.0,
                fade_len: fade_samples.max(1),
                snap_db: f32::NEG_INFINITY,
                at: now,
                // The pole at rest (`p = 1`) until the next `set_pole`.
                tag: NONE,
                rest_at: now,
                ..Dormant::EMPTY
            },
            now,
        );
        self.num_started += 1;
        true
    }

    /// Brings dormant `mode` back, fading it in over `fade_samples` so that it reaches its true
    /// state as the fade ends. Modes not dormant (or still fading out) are left alone.
    pub fn switch_on(&mut self, mode: usize, fade_samples: u32) {
        let r = self.dormant_of_mode[mode];
        if r == NONE || self.slot_of_mode[mode] != NONE {
            return;
        }
        let mut d = self.take_record(r as usize);
        d.advance_to(self.clock);
        let (re, im) = d.state();
        let slot = self.push_slot(mode as u32, d.column as usize);
        let start = (-FADE_DEPTH_NEPERS).exp() as f32;
        self.re[slot] = re * start;
        self.im[slot] = im * start;
        self.gain[slot] = d.gain;
        (self.theta[slot], self.delta[slot]) = (d.theta, d.delta);
        let len = fade_samples.max(1);
        self.start_fade(slot, -FADE_DEPTH_NEPERS / len as f64, len);
    }

    /// Forgets dormant `mode` for good (it has fallen below the truncation threshold).
    pub fn drop_dormant(&mut self, mode: usize) {
        let r = self.dormant_of_mode[mode];
        if r != NONE && self.slot_of_mode[mode] == NONE {
            let d = self.take_record(r as usize);
            self.claimed[d.column as usize] -= 1;
        }
    }

    pub(super) fn push_record(&mut self, d: Dormant, recheck_at: u64) {
        let r = self.num_dormant;
        self.dormant_of_mode[d.mode as usize] = r as u32;
        self.dormant[r] = d;
        self.recheck[r] = recheck_at;
        self.earliest_recheck = self.earliest_recheck.min(recheck_at);
        self.num_dormant += 1;
    }

    /// Removes record `r`, moving the last one into its place.
    pub(super) fn take_record(&mut self, r: usize) -> Dormant {
        let d = self.dormant[r];
        self.dormant_of_mode[d.mode as usize] = NONE;
        let last = self.num_dormant - 1;
        if r != last {
            self.dormant[r] = self.dormant[last];
            self.recheck[r] = self.recheck[last];
            self.dormant_of_mode[self.dormant[r].mode as usize] = r as u32;
        }
        self.num_dormant -= 1;
        d
    }
}
