//! Fades and wakes. Fades act through the pole, so they cost nothing per sample: fading out adds
//! decay until the output is [`FADE_DEPTH_NEPERS`] down; fading in starts the state that far below
//! its truth and lets it grow at the same rate, so it meets the truth as the fade ends. A mode
//! woken to take input (a strike or audio) computes it from rest at once, while its old ringing
//! fades back in beside it in a *ghost* slot that takes no input, and joins it (the phasor is
//! linear) when the fade ends.

use super::dormant::FADE_DEPTH_NEPERS;
use super::{ResonatorBank, COLUMNS, GHOST, NONE};

/// Where the next call of [`ResonatorBank::finish_fades`] (the next control tick) lies from now,
/// for fades started between two: a fade ends only there, and a fade in running on past its end
/// would grow its mode over the truth (by `FADE_DEPTH_NEPERS` per fade length) and then drop
/// back, a click. Fades started now are lengthened to end on a tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NextTick {
    /// Samples from now to the next tick (0: now is a tick).
    pub in_samples: u32,
    /// Samples from one tick to the next.
    pub period: u32,
}

impl NextTick {
    /// Every sample is a tick: fades keep their lengths.
    pub const EVERY_SAMPLE: Self = Self {
        in_samples: 0,
        period: 1,
    };

    /// The shortest length of at least `len` that ends on a tick.
    pub fn fade_len(self, len: u64) -> u64 {
        let period = self.period.max(1) as u64;
        let to = self.in_samples as u64 % period;
        len + (to + period - len % period) % period
    }
}

impl ResonatorBank {
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
                    // A fade that ended before this call (none does when its start was given the
                    // right `NextTick`): take back the growth since, so the state is the truth.
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
    pub fn wake_all(&mut self, tick: NextTick) {
        if self.num_dormant == 0 && self.num_fading == 0 {
            return;
        }
        self.wake_fading(tick);
        while self.num_dormant > 0 {
            self.wake_record(self.num_dormant - 1, tick);
        }
    }

    /// Wakes the modes fading in or out (through their poles they would take input wrongly):
    /// each computes from rest beside a ghost that carries its ringing on from where its
    /// envelope is.
    pub fn wake_fading(&mut self, tick: NextTick) {
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
                let len = tick.fade_len(len.max(1) as u64);
                self.fade_delta[slot] = -depth / len as f64;
                self.fade_end[slot] = now + len;
                self.next_fade_end = self.next_fade_end.min(now + len);
                let fresh = self.push_slot(mode as u32, column);
                (self.theta[fresh], self.delta[fresh]) = (theta, delta);
                self.gain[fresh] = gain;
            }
        }
        self.coeffs_stale = true;
    }

    /// Wakes dormant `mode` (not one fading out; see [`ResonatorBank::wake_fading`]): it computes
    /// from rest beside a ghost that fades its ringing back in. A mode started from rest at this
    /// instant ([`ResonatorBank::start_dormant`]) has no ringing yet: it simply computes.
    pub fn wake(&mut self, mode: usize, tick: NextTick) {
        let r = self.dormant_of_mode[mode];
        if r != NONE && self.slot_of_mode[mode] == NONE {
            self.wake_record(r as usize, tick);
        }
    }

    pub(super) fn wake_record(&mut self, r: usize, tick: NextTick) {
        let now = self.clock;
        let mut d = self.take_record(r);
        let column = d.column as usize;
        let fresh = self.push_slot(d.mode, column);
        (self.theta[fresh], self.delta[fresh]) = (d.theta, d.delta);
        self.gain[fresh] = d.gain;
        // New slots' coefficients all at once (a strike's retune usually does it first).
        self.coeffs_stale = true;
        if d.rest_at == now {
            // Started from rest at this instant: all it holds is what the strike under way
            // adds, which the slot computes. Nothing to fade back in.
            return;
        }
        d.advance_to(now);
        let (re, im) = self.undo_pending_pulses(&d, d.state());
        self.woken += 1;
        let ghost = self.push_slot(d.mode | GHOST, column);
        let start = (-FADE_DEPTH_NEPERS).exp() as f32;
        self.re[ghost] = re * start;
        self.im[ghost] = im * start;
        (self.theta[ghost], self.delta[ghost]) = (d.theta, d.delta);
        let len = tick.fade_len(d.fade_len.max(1) as u64);
        self.fade_delta[ghost] = -FADE_DEPTH_NEPERS / len as f64;
        self.fade_end[ghost] = now + len;
        self.next_fade_end = self.next_fade_end.min(now + len);
        self.num_fading += 1;
    }

    /// Starts a fade of `len` samples adding `fade_delta` to a steady slot's decay.
    pub(super) fn start_fade(&mut self, slot: usize, fade_delta: f64, len: u32) {
        self.fade_delta[slot] = fade_delta;
        self.fade_end[slot] = self.clock + len as u64;
        self.next_fade_end = self.next_fade_end.min(self.fade_end[slot]);
        self.num_fading += 1;
        self.set_slot_coeffs(slot);
    }

    /// Makes a fading slot steady.
    pub(super) fn end_fade(&mut self, slot: usize) {
        self.fade_delta[slot] = 0.0;
        self.num_fading -= 1;
        self.set_slot_coeffs(slot);
    }
}
