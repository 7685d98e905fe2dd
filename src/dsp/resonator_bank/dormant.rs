//! Dormant modes: switched off by perceptual pruning or a computation budget, their state carried
//! analytically so they can come back in phase; and the fades in and out.
//!
//! Without input a mode's phasor evolves as `z[t + n] = p^n z[t]` with `p = exp(-delta + i theta)`
//! (its pole): the amplitude falls by `delta` nepers per sample and the phase turns by `theta`
//! radians. A dormant mode keeps the state it had when it was switched off and accumulates both
//! (in `f64`, piece by piece when its pole changes), so its state at any later time costs one `exp`
//! and one `sin_cos`, and its level in dB one multiply-add. Nothing is spent on it per sample.
//!
//! Fades act through the pole, so they cost nothing per sample either. Fading out adds decay until
//! the output is [`FADE_DEPTH_NEPERS`] down (the mode's true state is its record's). Fading in starts
//! the state that far below the truth and lets it grow at the same rate, so it meets the truth as
//! the fade ends. Either way the output moves as a smooth exponential envelope and never steps by
//! more than `exp(-FADE_DEPTH_NEPERS)` of the mode's amplitude.

use std::f64::consts::TAU;

use super::{ResonatorBank, COLUMNS, NONE};
use crate::dsp::masking::DB_PER_NEPER;

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
    /// Bank clock before which the pruner need not look at this mode again.
    pub recheck_at: u64,
    /// The pruner's note about what keeps the mode off (its masker).
    pub tag: u32,
}

impl Dormant {
    /// An unused record.
    pub const EMPTY: Self = Self {
        mode: NONE,
        column: 0,
        gain: 0.0,
        re: 0.0,
        im: 0.0,
        snap_db: f32::NEG_INFINITY,
        phase: 0.0,
        log_gain: 0.0,
        at: 0,
        theta: 0.0,
        delta: 0.0,
        recheck_at: 0,
        tag: 0,
    };

    /// Accumulates phase and decay up to bank clock `now`.
    pub fn advance_to(&mut self, now: u64) {
        let n = now.saturating_sub(self.at) as f64;
        self.phase = (self.phase + self.theta * n).rem_euclid(TAU);
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
    fn state(&self) -> (f32, f32) {
        let (s, c) = self.phase.sin_cos();
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
    /// Its power `|z|^2` now; while it fades, that of its true state.
    pub power: f32,
    /// Pole angle, radians per sample.
    pub theta: f64,
    /// Decay per sample.
    pub delta: f64,
    /// Whether it is fading in or out.
    pub fading: bool,
}

/// A dormant mode, as the pruner sees it.
#[derive(Debug, Clone, Copy)]
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

    /// Number of modes fading in or out.
    pub fn num_fading(&self) -> usize {
        self.num_fading
    }

    /// Earliest recheck time of the dormant modes, in bank clock (`u64::MAX` without any).
    pub fn earliest_recheck(&self) -> u64 {
        self.dormant[..self.num_dormant]
            .iter()
            .filter(|d| self.slot_of_mode[d.mode as usize] == NONE)
            .map(|d| d.recheck_at)
            .min()
            .unwrap_or(u64::MAX)
    }

    /// Calls `f` for every computed mode.
    pub fn for_each_active(&self, mut f: impl FnMut(ActiveMode)) {
        let now = self.clock;
        for c in 0..COLUMNS {
            for r in 0..self.live[c] as usize {
                let slot = r * COLUMNS + c;
                let mode = self.mode_of_slot[slot] as usize;
                let fade = self.fade_delta[slot];
                let power = if fade > 0.0 {
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
                let (theta, delta) = self.pole_of_slot(slot);
                f(ActiveMode {
                    mode,
                    power,
                    theta,
                    delta,
                    fading: fade != 0.0,
                });
            }
        }
    }

    /// Calls `f` for every dormant mode (not those still fading out).
    pub fn for_each_dormant(&self, mut f: impl FnMut(DormantMode)) {
        let now = self.clock;
        for d in &self.dormant[..self.num_dormant] {
            if self.slot_of_mode[d.mode as usize] != NONE {
                continue;
            }
            f(DormantMode {
                mode: d.mode as usize,
                level_db: d.level_db_at(now),
                theta: d.theta,
                delta: d.delta,
                recheck_at: d.recheck_at,
                tag: d.tag,
            });
        }
    }

    /// Notes when the pruner should next look at dormant `mode`, and why it is off.
    pub fn set_recheck(&mut self, mode: usize, recheck_at: u64, tag: u32) {
        let r = self.dormant_of_mode[mode];
        if r != NONE {
            let d = &mut self.dormant[r as usize];
            d.recheck_at = recheck_at;
            d.tag = tag;
        }
    }

    /// Starts fading computed `mode` out over `fade_samples`; from then on it is carried
    /// analytically. Modes already fading are left alone.
    pub fn switch_off(&mut self, mode: usize, fade_samples: u32, recheck_at: u64, tag: u32) {
        let slot = self.slot_of_mode[mode];
        if slot == NONE || self.fade_delta[slot as usize] != 0.0 {
            return;
        }
        let slot = slot as usize;
        let (theta, delta) = self.pole_of_slot(slot);
        let (re, im) = (self.re[slot], self.im[slot]);
        self.push_record(Dormant {
            mode: mode as u32,
            column: (slot % COLUMNS) as u32,
            gain: self.gain[slot],
            re,
            im,
            snap_db: crate::dsp::masking::power_to_db(re * re + im * im),
            phase: 0.0,
            log_gain: 0.0,
            at: self.clock,
            theta,
            delta,
            recheck_at,
            tag,
        });
        (self.theta[slot], self.delta[slot]) = (theta, delta);
        let len = fade_samples.max(1);
        self.fade_delta[slot] = FADE_DEPTH_NEPERS / len as f64;
        self.fade_end[slot] = self.clock + len as u64;
        self.num_fading += 1;
        self.num_fading_out += 1;
        self.set_slot_coeffs(slot);
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
        let slot = self.push_slot(mode, d.column as usize);
        let start = (-FADE_DEPTH_NEPERS).exp() as f32;
        self.re[slot] = re * start;
        self.im[slot] = im * start;
        self.gain[slot] = d.gain;
        (self.theta[slot], self.delta[slot]) = (d.theta, d.delta);
        let len = fade_samples.max(1);
        self.fade_delta[slot] = -FADE_DEPTH_NEPERS / len as f64;
        self.fade_end[slot] = self.clock + len as u64;
        self.num_fading += 1;
        self.set_slot_coeffs(slot);
    }

    /// Forgets dormant `mode` for good (it has fallen below the truncation threshold).
    pub fn drop_dormant(&mut self, mode: usize) {
        let r = self.dormant_of_mode[mode];
        if r != NONE && self.slot_of_mode[mode] == NONE {
            self.take_record(r as usize);
        }
    }

    /// Ends the fades due by now: modes faded out leave the rows, modes faded in become steady.
    pub fn finish_fades(&mut self) {
        if self.num_fading == 0 {
            return;
        }
        let now = self.clock;
        let mut removed = false;
        for column in 0..COLUMNS {
            // Downwards, so the mode moved into a freed slot has already been checked.
            for row in (0..self.live[column] as usize).rev() {
                let slot = row * COLUMNS + column;
                let fade = self.fade_delta[slot];
                if fade == 0.0 || self.fade_end[slot] > now {
                    continue;
                }
                if fade > 0.0 {
                    self.remove_slot(slot);
                    removed = true;
                } else {
                    self.fade_delta[slot] = 0.0;
                    self.num_fading -= 1;
                    self.set_slot_coeffs(slot);
                }
            }
        }
        if removed {
            self.update_rows();
        }
    }

    /// Computes every mode again from now, exactly: fades end at once (in their true state) and
    /// dormant modes return to their columns. Called before anything drives the bank, since a
    /// dormant mode cannot take input.
    pub fn wake_all(&mut self) {
        if self.num_dormant == 0 && self.num_fading == 0 {
            return;
        }
        let now = self.clock;
        for column in 0..COLUMNS {
            for row in 0..self.live[column] as usize {
                let slot = row * COLUMNS + column;
                let fade = self.fade_delta[slot];
                if fade > 0.0 {
                    let mode = self.mode_of_slot[slot] as usize;
                    let mut d = self.take_record(self.dormant_of_mode[mode] as usize);
                    d.advance_to(now);
                    (self.re[slot], self.im[slot]) = d.state();
                } else if fade < 0.0 {
                    let left = self.fade_end[slot].saturating_sub(now) as f64;
                    let grow = (-fade * left).exp() as f32;
                    self.re[slot] *= grow;
                    self.im[slot] *= grow;
                }
                self.fade_delta[slot] = 0.0;
            }
        }
        self.num_fading = 0;
        self.num_fading_out = 0;
        while self.num_dormant > 0 {
            let mut d = self.take_record(self.num_dormant - 1);
            d.advance_to(now);
            let (re, im) = d.state();
            let slot = self.push_slot(d.mode as usize, d.column as usize);
            self.re[slot] = re;
            self.im[slot] = im;
            self.gain[slot] = d.gain;
            (self.theta[slot], self.delta[slot]) = (d.theta, d.delta);
        }
        self.refresh_coeffs();
    }

    fn push_record(&mut self, d: Dormant) {
        let r = self.num_dormant;
        self.dormant_of_mode[d.mode as usize] = r as u32;
        self.dormant[r] = d;
        self.num_dormant += 1;
    }

    /// Removes record `r`, moving the last one into its place.
    fn take_record(&mut self, r: usize) -> Dormant {
        let d = self.dormant[r];
        self.dormant_of_mode[d.mode as usize] = NONE;
        let last = self.num_dormant - 1;
        if r != last {
            self.dormant[r] = self.dormant[last];
            self.dormant_of_mode[self.dormant[r].mode as usize] = r as u32;
        }
        self.num_dormant -= 1;
        d
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Kernel, ModeCoeffs};
    use super::*;

    const RATE: f64 = 48_000.0;

    /// A bank of `n` ringing modes, and its twin to compare with.
    fn ringing(n: usize) -> ResonatorBank {
        let mut bank = ResonatorBank::new(n);
        for m in 0..n {
            bank.activate(m, ModeCoeffs::from_freq_decay(RATE, 1.0, 1.0), 0.0);
        }
        bank.set_poles_with(|m| {
            let f = 100.0 + 173.0 * m as f64;
            (TAU * f / RATE, (2.0 + m as f64) / RATE)
        });
        bank.set_gains_with(|m| 1.0 / (1.0 + m as f32));
        let mut acc = vec![[0.0; COLUMNS]; 64];
        let mut x = vec![0.0; 64];
        x[0] = 1.0;
        bank.process(Kernel::Scalar, Some(&x), &mut acc);
        bank
    }

    fn run(bank: &mut ResonatorBank, samples: usize) -> Vec<f32> {
        let mut out = Vec::new();
        for _ in 0..samples / 64 {
            let mut acc = vec![[0.0; COLUMNS]; 64];
            bank.process(Kernel::Scalar, None, &mut acc);
            bank.finish_fades();
            out.extend(acc.iter().map(|a| a.iter().sum::<f32>()));
        }
        out
    }

    #[test]
    fn a_mode_switched_off_and_on_returns_in_phase() {
        let mut pruned = ringing(20);
        let mut reference = pruned.clone();
        for m in [3, 7, 11] {
            pruned.switch_off(m, 256, 0, 0);
        }
        assert_eq!(pruned.num_fading(), 3);
        run(&mut pruned, 512);
        run(&mut reference, 512);
        assert_eq!(pruned.num_dormant(), 3);
        assert_eq!(pruned.num_active(), 17);
        assert_eq!(pruned.num_live(), 20);
        // Dormant, the mode's level follows its decay.
        pruned.for_each_dormant(|d| {
            let want = 10.0
                * reference
                    .state(d.mode)
                    .map_or(0.0, |(r, i)| r * r + i * i)
                    .log10();
            assert!(
                (d.level_db - want).abs() < 0.01,
                "mode {}: {} dB, expected {want}",
                d.mode,
                d.level_db
            );
        });
        for m in [3, 7, 11] {
            pruned.switch_on(m, 256);
        }
        run(&mut pruned, 5 * 64);
        run(&mut reference, 5 * 64);
        assert_eq!(pruned.num_fading(), 0);
        for m in 0..20 {
            let (a, b) = (pruned.state(m).unwrap(), reference.state(m).unwrap());
            let scale = b.0.hypot(b.1);
            assert!(
                (a.0 - b.0).abs() < 1e-4 * scale && (a.1 - b.1).abs() < 1e-4 * scale,
                "mode {m}: {a:?} vs {b:?}"
            );
        }
    }

    #[test]
    fn waking_restores_every_mode_exactly_and_poles_changed_while_dormant_count() {
        let mut pruned = ringing(30);
        let mut reference = pruned.clone();
        for m in (0..30).step_by(2) {
            pruned.switch_off(m, 64, 0, 0);
        }
        run(&mut pruned, 640);
        run(&mut reference, 640);
        // A pitch change while dormant.
        let bend = |m: usize| {
            let f = 1.05 * (100.0 + 173.0 * m as f64);
            (TAU * f / RATE, (2.0 + m as f64) / RATE)
        };
        pruned.set_poles_with(bend);
        reference.set_poles_with(bend);
        run(&mut pruned, 640);
        run(&mut reference, 640);
        // One mode still fading in, one fading out, the rest dormant.
        pruned.switch_on(4, 256);
        pruned.switch_off(5, 256, 0, 0);
        run(&mut pruned, 64);
        run(&mut reference, 64);
        pruned.wake_all();
        assert_eq!((pruned.num_dormant(), pruned.num_fading()), (0, 0));
        assert_eq!(pruned.num_active(), 30);
        for m in 0..30 {
            let (a, b) = (pruned.state(m).unwrap(), reference.state(m).unwrap());
            let scale = b.0.hypot(b.1);
            assert!(
                (a.0 - b.0).abs() < 1e-4 * scale && (a.1 - b.1).abs() < 1e-4 * scale,
                "mode {m}: {a:?} vs {b:?}"
            );
        }
        // And they ring on with the right poles.
        let (x, y) = (run(&mut pruned, 640), run(&mut reference, 640));
        let peak = y.iter().fold(0.0f32, |a, v| a.max(v.abs()));
        for (n, (a, b)) in x.iter().zip(&y).enumerate() {
            assert!((a - b).abs() < 1e-4 * peak, "sample {n}: {a} vs {b}");
        }
    }

    #[test]
    fn fades_are_smooth_envelopes() {
        let mut pruned = ringing(1);
        let mut reference = pruned.clone();
        pruned.switch_off(0, 256, 0, 0);
        let (x, y) = (run(&mut pruned, 512), run(&mut reference, 512));
        // Exactly the reference under an exponential envelope 60 dB deep over 256 samples.
        for n in 0..256 {
            let env = (-FADE_DEPTH_NEPERS * (n + 1) as f64 / 256.0).exp() as f32;
            assert!(
                (x[n] - env * y[n]).abs() < 1e-5,
                "sample {n}: {} vs {}",
                x[n],
                env * y[n]
            );
        }
        assert!(x[256..].iter().all(|&v| v == 0.0));
        assert_eq!(pruned.num_active(), 0);
        assert_eq!(pruned.num_live(), 1);
    }
}
