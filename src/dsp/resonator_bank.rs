//! A bank of modal resonators for one voice: structure-of-arrays state, coefficients and gains,
//! with the live modes packed so work follows the number of modes still sounding.
//!
//! A mode keeps its column (its accumulator lane, and with it its place in the stereo field) for
//! as long as it sounds, however the bank is re-packed. Within a column, live modes occupy the
//! first rows; a mode that dies is replaced by the column's last live mode. The kernels run over
//! as many rows as the fullest column needs, so a mode starting from rest goes to its own column
//! `m % COLUMNS` when that column is among the emptiest, else to the next emptiest one: modes
//! sorted by frequency are dealt round the columns, and a bank where every other mode is silent
//! (a string struck at its middle) still fills every lane.

use super::coeffs::ModeCoeffs;
use super::coeffs_batch::coeffs_batch;
pub use super::kernels::COLUMNS;
use super::kernels::{self, Kernel, Rows, ROW_BLOCK};

/// Marks a mode that has no slot, or a slot that holds no mode.
const NONE: u32 = u32::MAX;

/// The resonators of one voice.
#[derive(Debug, Clone)]
pub struct ResonatorBank {
    /// Real part of each slot's phasor.
    re: Vec<f32>,
    /// Imaginary part of each slot's phasor: the mode's output.
    im: Vec<f32>,
    /// `R cos(theta) - 1` of each slot.
    q_re: Vec<f32>,
    /// `R sin(theta)` of each slot.
    q_im: Vec<f32>,
    /// Input gain of each slot: the mode's amplitude for a unit impulse.
    gain: Vec<f32>,
    /// The mode held by each slot, or `NONE`.
    mode_of_slot: Vec<u32>,
    /// The slot of each mode, or `NONE` when the mode is not sounding.
    slot_of_mode: Vec<u32>,
    /// Number of live modes in each column.
    live: [u32; COLUMNS],
    /// Rows handed to the kernel: the fullest column, rounded up to whole row blocks.
    rows_active: usize,
    /// Modes started since the bank was last cleared (counting restarts).
    num_started: usize,
    /// Scratch: pole angle of each slot, for batch coefficient updates.
    theta: Vec<f64>,
    /// Scratch: pole radius exponent of each slot, for batch coefficient updates.
    delta: Vec<f64>,
}

impl ResonatorBank {
    /// Storage for `num_modes` modes, all silent. Allocates.
    pub fn new(num_modes: usize) -> Self {
        let rows = num_modes.div_ceil(COLUMNS).div_ceil(ROW_BLOCK) * ROW_BLOCK;
        let slots = rows * COLUMNS;
        Self {
            re: vec![0.0; slots],
            im: vec![0.0; slots],
            q_re: vec![0.0; slots],
            q_im: vec![0.0; slots],
            gain: vec![0.0; slots],
            mode_of_slot: vec![NONE; slots],
            slot_of_mode: vec![NONE; num_modes],
            live: [0; COLUMNS],
            rows_active: 0,
            num_started: 0,
            theta: vec![0.0; slots],
            delta: vec![0.0; slots],
        }
    }

    /// Number of modes the bank can hold.
    pub fn num_modes(&self) -> usize {
        self.slot_of_mode.len()
    }

    /// Number of modes currently sounding.
    pub fn num_live(&self) -> usize {
        self.live.iter().map(|&n| n as usize).sum()
    }

    /// Number of modes the kernel advances per sample (live modes plus padding).
    pub fn num_computed(&self) -> usize {
        self.rows_active * COLUMNS
    }

    /// Modes started since the bank was last cleared, counting a mode started again after it
    /// was retired.
    pub fn num_started(&self) -> usize {
        self.num_started
    }

    /// Whether mode `mode` is sounding.
    pub fn is_live(&self, mode: usize) -> bool {
        self.slot_of_mode[mode] != NONE
    }

    /// The phasor state `(re, im)` of a mode, or `None` when it is not sounding.
    pub fn state(&self, mode: usize) -> Option<(f32, f32)> {
        let slot = self.slot_of_mode[mode];
        (slot != NONE).then(|| (self.re[slot as usize], self.im[slot as usize]))
    }

    /// Makes `mode` sound (from rest) with `coeffs`, unless it already does. Returns whether it
    /// was added.
    pub fn activate(&mut self, mode: usize, coeffs: ModeCoeffs, gain: f32) -> bool {
        if self.is_live(mode) {
            return false;
        }
        let fewest = self.live.iter().copied().min().unwrap_or(0);
        let column = (0..COLUMNS)
            .map(|i| (mode + i) % COLUMNS)
            .find(|&c| self.live[c] == fewest)
            .unwrap_or(mode % COLUMNS);
        let slot = self.live[column] as usize * COLUMNS + column;
        self.live[column] += 1;
        self.re[slot] = 0.0;
        self.im[slot] = 0.0;
        self.q_re[slot] = coeffs.q_re;
        self.q_im[slot] = coeffs.q_im;
        self.gain[slot] = gain;
        self.mode_of_slot[slot] = mode as u32;
        self.slot_of_mode[mode] = slot as u32;
        self.num_started += 1;
        self.update_rows();
        true
    }

    /// Sets the coefficients of every live mode to those of the pole `pole_of(mode) = (theta,
    /// delta)` (angle in radians per sample, radius `exp(-delta)`; see
    /// [`ModeCoeffs::from_angle_radius`]), computed for all modes at once.
    pub fn set_poles_with(&mut self, mut pole_of: impl FnMut(usize) -> (f64, f64)) {
        let n = self.rows_active * COLUMNS;
        for slot in 0..n {
            let mode = self.mode_of_slot[slot];
            // A pole at (0, 0) gives coefficients (0, 0): empty slots stay silent.
            (self.theta[slot], self.delta[slot]) = if mode == NONE {
                (0.0, 0.0)
            } else {
                pole_of(mode as usize)
            };
        }
        coeffs_batch(
            &self.theta[..n],
            &self.delta[..n],
            &mut self.q_re[..n],
            &mut self.q_im[..n],
        );
    }

    /// Sets the input gain of every live mode to `gain_of(mode)`.
    pub fn set_gains_with(&mut self, mut gain_of: impl FnMut(usize) -> f32) {
        for slot in self.live_slots() {
            self.gain[slot] = gain_of(self.mode_of_slot[slot] as usize);
        }
    }

    /// The live modes, in slot order.
    pub fn live_modes(&self) -> impl Iterator<Item = usize> + '_ {
        self.live_slots()
            .map(|slot| self.mode_of_slot[slot] as usize)
    }

    fn live_slots(&self) -> impl Iterator<Item = usize> + 'static {
        let live = self.live;
        (0..COLUMNS).flat_map(move |c| (0..live[c] as usize).map(move |r| r * COLUMNS + c))
    }

    /// Advances every live mode over `acc.len()` samples, driven by `input` when given, adding
    /// each mode's output into its column's lane of `acc`.
    #[inline]
    pub fn process(&mut self, kernel: Kernel, input: Option<&[f32]>, acc: &mut [[f32; COLUMNS]]) {
        let n = self.rows_active * COLUMNS;
        kernels::process(
            kernel,
            Rows {
                re: &mut self.re[..n],
                im: &mut self.im[..n],
                q_re: &self.q_re[..n],
                q_im: &self.q_im[..n],
                gain: &self.gain[..n],
            },
            input,
            acc,
        );
    }

    /// Stops every mode whose amplitude `|z|` is below `threshold` and re-packs the columns.
    /// Returns the summed squared amplitude of the modes that remain.
    pub fn retire_below(&mut self, threshold: f32) -> f32 {
        let threshold_sq = threshold * threshold;
        let mut energy = 0.0;
        let mut changed = false;
        for column in 0..COLUMNS {
            // Downwards, so the mode moved into a freed slot has already been checked.
            for row in (0..self.live[column] as usize).rev() {
                let slot = row * COLUMNS + column;
                let e = self.re[slot] * self.re[slot] + self.im[slot] * self.im[slot];
                // A state that is not a number is retired too.
                if e.is_nan() || e < threshold_sq {
                    self.remove_slot(slot);
                    changed = true;
                } else {
                    energy += e;
                }
            }
        }
        if changed {
            self.update_rows();
        }
        energy
    }

    /// Summed squared amplitude `|z|^2` of the live modes.
    pub fn energy(&self) -> f32 {
        self.live_slots()
            .map(|s| self.re[s] * self.re[s] + self.im[s] * self.im[s])
            .sum()
    }

    /// Each live mode with its squared amplitude `|z|^2`, in slot order. For meters: it reads the
    /// state and changes nothing.
    pub fn live_energies(&self) -> impl Iterator<Item = (usize, f32)> + '_ {
        self.live_slots().map(|s| {
            let mode = self.mode_of_slot[s] as usize;
            (mode, self.re[s] * self.re[s] + self.im[s] * self.im[s])
        })
    }

    /// Silences every mode.
    pub fn clear(&mut self) {
        for slot in self.live_slots() {
            self.clear_slot(slot);
        }
        self.live = [0; COLUMNS];
        self.rows_active = 0;
        self.num_started = 0;
        self.slot_of_mode.fill(NONE);
    }

    /// Removes the mode in `slot`, moving its column's last live mode into the gap.
    fn remove_slot(&mut self, slot: usize) {
        let column = slot % COLUMNS;
        let last = (self.live[column] as usize - 1) * COLUMNS + column;
        self.slot_of_mode[self.mode_of_slot[slot] as usize] = NONE;
        if last != slot {
            self.re[slot] = self.re[last];
            self.im[slot] = self.im[last];
            self.q_re[slot] = self.q_re[last];
            self.q_im[slot] = self.q_im[last];
            self.gain[slot] = self.gain[last];
            let moved = self.mode_of_slot[last];
            self.mode_of_slot[slot] = moved;
            self.slot_of_mode[moved as usize] = slot as u32;
        }
        self.clear_slot(last);
        self.live[column] -= 1;
    }

    /// Zeroes a slot so the kernel computes silence there.
    fn clear_slot(&mut self, slot: usize) {
        self.re[slot] = 0.0;
        self.im[slot] = 0.0;
        self.q_re[slot] = 0.0;
        self.q_im[slot] = 0.0;
        self.gain[slot] = 0.0;
        self.mode_of_slot[slot] = NONE;
    }

    fn update_rows(&mut self) {
        let fullest = self.live.iter().copied().max().unwrap_or(0) as usize;
        self.rows_active = fullest.div_ceil(ROW_BLOCK) * ROW_BLOCK;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn coeffs(mode: usize) -> ModeCoeffs {
        ModeCoeffs::from_freq_decay(48_000.0, 100.0 + 37.0 * mode as f64, 3.0 + mode as f64)
    }

    #[test]
    fn repacking_keeps_each_mode_with_its_state() {
        let mut bank = ResonatorBank::new(100);
        for m in 0..100 {
            bank.activate(m, coeffs(m), 1.0 + m as f32);
        }
        let mut acc = vec![[0.0; COLUMNS]; 32];
        let input: Vec<f32> = (0..32).map(|n| if n == 0 { 1.0 } else { 0.0 }).collect();
        bank.process(Kernel::Scalar, Some(&input), &mut acc);
        let before: Vec<_> = (0..100).map(|m| bank.state(m).unwrap()).collect();
        // Silence every third mode, then retire the silent ones.
        let mut kept = bank.clone();
        for m in (0..100).filter(|m| m % 3 == 0) {
            let slot = kept.slot_of_mode[m] as usize;
            kept.re[slot] = 0.0;
            kept.im[slot] = 0.0;
        }
        kept.retire_below(1e-10);
        for (m, state) in before.iter().enumerate() {
            if m % 3 == 0 {
                assert!(!kept.is_live(m), "mode {m} should be retired");
            } else {
                assert_eq!(kept.state(m), Some(*state), "mode {m} lost its state");
                assert_eq!(
                    kept.slot_of_mode[m] as usize % COLUMNS,
                    m % COLUMNS,
                    "mode {m} changed column"
                );
            }
        }
        assert_eq!(kept.num_live(), 100 - 34);
    }

    #[test]
    fn skipped_modes_do_not_leave_lanes_empty() {
        // Only even modes sound, as when a string is struck at its middle.
        let mut bank = ResonatorBank::new(256);
        for m in (0..256).step_by(2) {
            bank.activate(m, coeffs(m), 1.0);
        }
        assert_eq!(bank.live, [16; COLUMNS]);
        assert_eq!(bank.num_computed(), 128);
    }
}
