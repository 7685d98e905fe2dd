//! Dormant modes: switched off by perceptual pruning or a computation budget, their state carried
//! analytically so they can come back in phase; the fades in and out; and ghosts.
//!
//! Without input a mode's phasor evolves as `z[t + n] = p^n z[t]` with `p = exp(-delta + i theta)`
//! (its pole): the amplitude falls by `delta` nepers per sample and the phase turns by `theta`
//! radians. A dormant mode keeps the state it had when it was switched off and accumulates both
//! (in `f64`, piece by piece when its pole changes), so its state at any later time costs one `exp`
//! and one `sin_cos`, and its level in dB one multiply-add. Nothing is spent on it per sample.
//!
//! Fades act through the pole, so they cost nothing per sample either. Fading out adds decay until
//! the output is [`FADE_DEPTH_NEPERS`] down (the mode's true state is its record's). Fading in
//! starts the state that far below the truth and lets it grow at the same rate, so it meets the
//! truth as the fade ends. Either way the output moves as a smooth exponential envelope and never
//! steps by more than `exp(-FADE_DEPTH_NEPERS)` of the mode's amplitude.
//!
//! A strike cannot wait for a fade: the struck mode must take its input from the strike's first
//! sample, at its true gain. So a strike wakes a dormant mode into two slots: the mode itself, from
//! rest, taking the strike; and a *ghost* with its old ringing fading in (a growing pole, with no
//! input, so the strike is not scaled by the growth). When the fade ends the ghost's state, now the
//! old ringing exactly, is added to the mode's (the phasor is linear) and the ghost goes.

use std::f64::consts::{PI, TAU};

use super::{ModeCoeffs, PulseShape, ResonatorBank, COLUMNS, GHOST, NONE};
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
    /// Its input gain.
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
    /// This pole's response to a unit pulse of `response_len` samples of `response_shape`,
    /// referred to the sample before the pulse (`None` until a strike asks for it): strikes on
    /// an object usually repeat their mallet.
    pub response: Option<(PulseShape, u32, f64, f64)>,
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
        response: None,
    };

    /// Takes a new pole from now on (after [`Dormant::advance_to`]).
    pub fn set_pole(&mut self, theta: f64, delta: f64) {
        if (theta, delta) != (self.theta, self.delta) {
            (self.theta, self.delta) = (theta, delta);
            let c = ModeCoeffs::from_angle_radius(theta, delta);
            (self.p_re, self.p_im) = (1.0 + c.q_re as f64, c.q_im as f64);
            self.response = None;
        }
    }

    /// Accumulates phase and decay up to bank clock `now`.
    pub fn advance_to(&mut self, now: u64) {
        let n = now.saturating_sub(self.at) as f64;
        let phase = self.phase + self.theta * n;
        self.phase = phase - TAU * (phase * (1.0 / TAU)).floor();
        self.log_gain -= self.delta * n;
        self.at = now;
    }

    /// Power `|z|^2` in dB at bank clock `t` (not before `at`).
    #[inline]
    pub fn level_db_at(&self, t: u64) -> f32 {
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

/// A computed mode, as the pruner sees it.
#[derive(Debug, Clone, Copy)]
pub struct ActiveMode {
    /// The mode.
    pub mode: usize,
    /// Its power `|z|^2` now; while it fades, that of its true state (with its ghost's, a bound).
    pub power: f32,
    /// Pole angle, radians per sample.
    pub theta: f64,
    /// Decay per sample.
    pub delta: f64,
    /// Its input gain.
    pub gain: f32,
    /// Whether it is fading in or out, or has a ghost fading in: it is not to be switched now.
    pub fading: bool,
}

/// A dormant mode, as the pruner sees it.
#[derive(Debug, Clone, Copy, Default)]
pub struct DormantMode {
    /// The mode.
    pub mode: usize,
    /// Its power `|z|^2` now, in dB.
    pub level_db: f32,
    /// Pole angle, radians per sample.
    pub theta: f64,
    /// Decay per sample.
    pub delta: f64,
    /// Bank clock before which the pruner need not look at it again.
    pub recheck_at: u64,
    /// The pruner's note.
    pub tag: u32,
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
            .filter(|&m| self.slot_of_mode[m] == NONE)
    }

    /// Number of slots fading in or out, ghosts included.
    pub fn num_fading(&self) -> usize {
        self.num_fading
    }

    /// Modes brought back by [`ResonatorBank::wake_all`] since the bank was made.
    pub fn num_woken(&self) -> u64 {
        self.woken
    }

    /// The true power of the ghost of `mode`, if it has one.
    fn ghost_power(&self, mode: usize) -> Option<f32> {
        let g = self.ghost_of_mode[mode];
        (g != NONE).then(|| {
            let g = g as usize;
            let left = self.fade_end[g].saturating_sub(self.clock) as f64;
            let p = self.re[g] * self.re[g] + self.im[g] * self.im[g];
            p * (-2.0 * self.fade_delta[g] * left).exp() as f32
        })
    }

    /// Calls `f` for every computed mode (not ghosts).
    pub fn for_each_active(&self, f: impl FnMut(ActiveMode)) {
        self.for_each_active_where(|_, _| true, f);
    }

    /// Calls `f` for every computed mode (not ghosts) for which `wanted(mode, fading)` holds;
    /// the others cost a look at their slot only.
    pub fn for_each_active_where(
        &self,
        mut wanted: impl FnMut(usize, bool) -> bool,
        mut f: impl FnMut(ActiveMode),
    ) {
        let now = self.clock;
        for c in 0..COLUMNS {
            for r in 0..self.live[c] as usize {
                let slot = r * COLUMNS + c;
                let entry = self.mode_of_slot[slot];
                if entry & GHOST != 0 {
                    continue;
                }
                let mode = entry as usize;
                let fade = self.fade_delta[slot];
                let has_ghost = self.ghost_of_mode[mode] != NONE;
                if !wanted(mode, fade != 0.0 || has_ghost) {
                    continue;
                }
                let mut power = if fade > 0.0 {
                    self.dormant[self.dormant_of_mode[mode] as usize].power_at(now)
                } else {
                    let p = self.re[slot] * self.re[slot] + self.im[slot] * self.im[slot];
                    if fade < 0.0 {
                        let left = self.fade_end[slot].saturating_sub(now) as f64;
                        p * (-2.0 * fade * left).exp() as f32
                    } else {
                        p
                    }
                };
                let ghost = self.ghost_power(mode);
                if let Some(g) = ghost {
                    let a = power.sqrt() + g.sqrt();
                    power = a * a;
                }
                let (theta, delta) = self.pole_of_slot(slot);
                f(ActiveMode {
                    mode,
                    power,
                    theta,
                    delta,
                    gain: self.gain[slot],
                    fading: fade != 0.0 || ghost.is_some(),
                });
            }
        }
    }

    /// Calls `f` for every dormant mode (not those still fading out) whose recheck time is at
    /// most `due` in bank clock (`u64::MAX` for all). The times are scanned apart from the
    /// records, so skipping the others costs little.
    pub fn for_each_dormant(&mut self, due: u64, mut f: impl FnMut(DormantMode)) {
        if due < self.earliest_recheck {
            return;
        }
        let now = self.clock;
        // The earliest of the times not due now; those due are set again by the pruner.
        let mut earliest = u64::MAX;
        for (d, &recheck_at) in self.dormant[..self.num_dormant]
            .iter()
            .zip(&self.recheck[..self.num_dormant])
        {
            if recheck_at > due {
                earliest = earliest.min(recheck_at);
                continue;
            }
            if self.slot_of_mode[d.mode as usize] != NONE {
                continue;
            }
            f(DormantMode {
                mode: d.mode as usize,
                level_db: d.level_db_at(now),
                theta: d.theta,
                delta: d.delta,
                recheck_at,
                tag: d.tag,
            });
        }
        self.earliest_recheck = earliest;
    }

    /// Notes when (in bank clock) the pruner should next look at dormant `mode`, and why it is
    /// off.
    pub fn set_recheck(&mut self, mode: usize, recheck_at: u64, tag: u32) {
        let r = self.dormant_of_mode[mode];
        if r != NONE {
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
            self.recheck[r as usize] = recheck_at;
            self.earliest_recheck = self.earliest_recheck.min(recheck_at);
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
                response: None,
            },
            recheck_at,
        );
        (self.theta[slot], self.delta[slot]) = (theta, delta);
        self.start_fade(slot, FADE_DEPTH_NEPERS / len as f64, len);
        self.num_fading_out += 1;
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

    /// Ends the fades due by now: modes faded out leave the rows, modes faded in become steady,
    /// ghosts join their modes.
    pub fn finish_fades(&mut self) {
        if self.num_fading == 0 || self.clock < self.next_fade_end {
            return;
        }
        let now = self.clock;
        let mut removed = false;
        let mut next = u64::MAX;
        for column in 0..COLUMNS {
            // Downwards, so the slot moved into a freed one has already been checked.
            for row in (0..self.live[column] as usize).rev() {
                let slot = row * COLUMNS + column;
                let fade = self.fade_delta[slot];
                if fade == 0.0 {
                    continue;
                }
                if self.fade_end[slot] > now {
                    next = next.min(self.fade_end[slot]);
                    continue;
                }
                if fade < 0.0 {
                    // A fade started between control ticks ends between them too: take back
                    // the growth since, so the state is the truth exactly.
                    let over = (now - self.fade_end[slot]) as f64;
                    let back = (fade * over).exp() as f32;
                    self.re[slot] *= back;
                    self.im[slot] *= back;
                }
                let entry = self.mode_of_slot[slot];
                if entry & GHOST != 0 {
                    let target = self.slot_of_mode[(entry & !GHOST) as usize];
                    if target != NONE {
                        let target = target as usize;
                        self.re[target] += self.re[slot];
                        self.im[target] += self.im[slot];
                        self.remove_slot(slot);
                        removed = true;
                    } else {
                        // No mode to join (it cannot be retired while it has a ghost, so this
                        // does not happen): the ghost carries on as the mode itself.
                        let mode = (entry & !GHOST) as usize;
                        self.mode_of_slot[slot] = mode as u32;
                        self.slot_of_mode[mode] = slot as u32;
                        self.ghost_of_mode[mode] = NONE;
                        self.num_ghosts -= 1;
                        self.end_fade(slot);
                    }
                } else if fade > 0.0 {
                    self.remove_slot(slot);
                    removed = true;
                } else {
                    self.end_fade(slot);
                }
            }
        }
        if removed {
            self.update_rows();
        }
        self.next_fade_end = next;
    }

    /// Wakes every mode that is not steadily computed, before a strike or input drives the bank
    /// (a dormant mode cannot take input): each computes the drive exactly from now on, and its
    /// old ringing fades back in beside it in a ghost slot, joining it in phase when the fade
    /// ends. A mode fading in or out continues its envelope from where it is.
    pub fn wake_all(&mut self) {
        if self.num_dormant == 0 && self.num_fading == 0 {
            return;
        }
        self.wake_fading();
        while self.num_dormant > 0 {
            self.wake_record(self.num_dormant - 1);
        }
    }

    /// Wakes the modes fading in or out (through their poles they would take input wrongly):
    /// each computes from rest beside a ghost that carries its ringing on from where its
    /// envelope is.
    pub fn wake_fading(&mut self) {
        if self.num_fading == self.num_ghosts {
            return;
        }
        let now = self.clock;
        let start = self.live;
        for (column, &rows) in start.iter().enumerate() {
            for row in 0..rows as usize {
                let slot = row * COLUMNS + column;
                let entry = self.mode_of_slot[slot];
                let fade = self.fade_delta[slot];
                if entry & GHOST != 0 || fade == 0.0 {
                    continue;
                }
                let mode = entry as usize;
                let left = self.fade_end[slot].saturating_sub(now) as f64;
                let (len, depth) = if fade > 0.0 {
                    // Fading out: the slot is its record's truth under the envelope so far.
                    let d = self.take_record(self.dormant_of_mode[mode] as usize);
                    self.num_fading_out -= 1;
                    (d.fade_len, FADE_DEPTH_NEPERS - fade * left)
                } else {
                    let len = (-FADE_DEPTH_NEPERS / fade).round() as u32;
                    (len, -fade * left)
                };
                if depth <= 1e-9 {
                    // Nothing faded yet: the slot simply stays.
                    self.fade_delta[slot] = 0.0;
                    self.num_fading -= 1;
                    continue;
                }
                // The slot turns into the ghost, growing back over a full fade from where it
                // is; the mode itself starts from rest beside it.
                self.woken += 1;
                let (theta, delta, gain) = (self.theta[slot], self.delta[slot], self.gain[slot]);
                self.mode_of_slot[slot] = entry | GHOST;
                self.slot_of_mode[mode] = NONE;
                self.ghost_of_mode[mode] = slot as u32;
                self.num_ghosts += 1;
                self.gain[slot] = 0.0;
                let len = len.max(1);
                self.fade_delta[slot] = -depth / len as f64;
                self.fade_end[slot] = now + len as u64;
                self.next_fade_end = self.next_fade_end.min(now + len as u64);
                let fresh = self.push_slot(mode as u32, column);
                (self.theta[fresh], self.delta[fresh]) = (theta, delta);
                self.gain[fresh] = gain;
            }
        }
        self.coeffs_stale = true;
    }

    /// Wakes dormant `mode` (not one fading out; see [`ResonatorBank::wake_fading`]): it computes
    /// from rest beside a ghost that fades its ringing back in.
    pub fn wake(&mut self, mode: usize) {
        let r = self.dormant_of_mode[mode];
        if r != NONE && self.slot_of_mode[mode] == NONE {
            self.wake_record(r as usize);
        }
    }

    fn wake_record(&mut self, r: usize) {
        let now = self.clock;
        let mut d = self.take_record(r);
        d.advance_to(now);
        let (re, im) = self.undo_pending_pulses(&d, d.state());
        self.woken += 1;
        let column = d.column as usize;
        let fresh = self.push_slot(d.mode, column);
        (self.theta[fresh], self.delta[fresh]) = (d.theta, d.delta);
        self.gain[fresh] = d.gain;
        let ghost = self.push_slot(d.mode | GHOST, column);
        let start = (-FADE_DEPTH_NEPERS).exp() as f32;
        self.re[ghost] = re * start;
        self.im[ghost] = im * start;
        (self.theta[ghost], self.delta[ghost]) = (d.theta, d.delta);
        let len = d.fade_len.max(1) as u64;
        self.fade_delta[ghost] = -FADE_DEPTH_NEPERS / len as f64;
        self.fade_end[ghost] = now + len;
        self.next_fade_end = self.next_fade_end.min(now + len);
        self.num_fading += 1;
        // New slots' coefficients all at once (a strike's retune usually does it first).
        self.coeffs_stale = true;
    }

    /// Starts a fade of `len` samples adding `fade_delta` to a steady slot's decay.
    fn start_fade(&mut self, slot: usize, fade_delta: f64, len: u32) {
        self.fade_delta[slot] = fade_delta;
        self.fade_end[slot] = self.clock + len as u64;
        self.next_fade_end = self.next_fade_end.min(self.fade_end[slot]);
        self.num_fading += 1;
        self.set_slot_coeffs(slot);
    }

    /// Makes a fading slot steady.
    fn end_fade(&mut self, slot: usize) {
        self.fade_delta[slot] = 0.0;
        self.num_fading -= 1;
        self.set_slot_coeffs(slot);
    }

    fn push_record(&mut self, d: Dormant, recheck_at: u64) {
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
