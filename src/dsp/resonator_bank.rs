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
//!
//! A mode can also be *dormant*, switched off by perceptual pruning or a budget: it leaves the
//! rows the kernels run over and its state is carried analytically ([`dormant`]), so it can come
//! back in phase. Switching off and on fades the mode's output through its pole, at no cost per
//! sample. A mode woken by a strike computes the strike from rest at once, while its old ringing
//! fades back in beside it in a *ghost* slot that ignores input, and joins it when the fade ends
//! (a mode the strike itself started has no old ringing, and no ghost).

mod absorb;
mod dormant;
mod fades;
mod meters;
mod poles;
mod strike;
#[cfg(test)]
mod tests;
mod views;

pub(crate) use dormant::floor;
pub use dormant::FADE_DEPTH_NEPERS;
pub use fades::NextTick;
pub use strike::{Pulse, PulseShape};
pub use views::{ActiveMode, DormantMode};

use super::coeffs::ModeCoeffs;
use super::coeffs_batch::coeffs_batch;
pub use super::kernels::COLUMNS;
use super::kernels::{self, Kernel, Rows, ROW_BLOCK};
use dormant::Dormant;

/// Marks a mode that has no slot, or a slot that holds no mode.
const NONE: u32 = u32::MAX;

/// Set in `mode_of_slot` for a ghost slot: a mode's old ringing fading back in beside it.
const GHOST: u32 = 1 << 30;

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
    /// The mode held by each slot (with `GHOST` set for a ghost), or `NONE`.
    mode_of_slot: Vec<u32>,
    /// The slot of each mode, or `NONE` when the mode is not computed.
    slot_of_mode: Vec<u32>,
    /// The ghost slot of each mode, or `NONE`.
    ghost_of_mode: Vec<u32>,
    /// Number of slots in use in each column, ghosts included.
    live: [u32; COLUMNS],
    /// Number of slots in use in all columns, ghosts included: the sum of `live`.
    num_slots: usize,
    /// Number of modes belonging to each column, computed or dormant: new modes go to the
    /// emptiest, so a column never holds more than its share.
    claimed: [u32; COLUMNS],
    /// Rows the fullest column needs (the kernel takes them rounded up to its row block).
    rows_active: usize,
    /// Modes started since the bank was last cleared (counting restarts).
    num_started: usize,
    /// Pole angle of each slot's mode in radians per sample, without any fade; NaN when the mode
    /// was given coefficients directly (then read back from them when needed).
    theta: Vec<f64>,
    /// Pole radius exponent (decay per sample) of each slot's mode, without any fade.
    delta: Vec<f64>,
    /// Extra decay per sample of a slot while it fades: positive fading out, negative fading in,
    /// zero when steady.
    fade_delta: Vec<f64>,
    /// Bank clock at which a slot's fade ends.
    fade_end: Vec<u64>,
    /// Scratch: each slot's pole radius exponent with its fade, for batch coefficient updates.
    pole_delta: Vec<f64>,
    /// Whether some slot's coefficients lag its pole or fade (they are brought up to date, all
    /// at once, before the next samples are computed).
    coeffs_stale: bool,
    /// Number of slots fading, ghosts included.
    num_fading: usize,
    /// Bank clock before which no fade ends.
    next_fade_end: u64,
    /// Number of ghost slots.
    num_ghosts: usize,
    /// Samples processed since the bank was last cleared: the time base of dormant modes.
    clock: u64,
    /// Records of modes whose state is carried analytically; the first `num_dormant` are in use.
    dormant: Vec<Dormant>,
    /// Bank clock at which the pruner next looks at each record (parallel to `dormant`).
    recheck: Vec<u64>,
    /// No record is due before this bank clock (a lower bound, made exact by each full scan).
    earliest_recheck: u64,
    /// Number of records in use (including those of modes still fading out).
    num_dormant: usize,
    /// Index into `dormant` of each mode's record, or `NONE`.
    dormant_of_mode: Vec<u32>,
    /// Number of modes fading out: they have both a slot and a record.
    num_fading_out: usize,
    /// Modes brought back with old ringing to fade in beside them (a ghost), ever.
    woken: u64,
    /// Mode-samples the kernels have computed, ever (row padding included).
    computed: u64,
    /// Strikes dormant modes took analytically whose pulses may still be playing: their start
    /// (bank clock) and shape.
    pulses: [(u64, Pulse); strike::MAX_PULSES],
    /// Scratch for a strike taken by every dormant record at once.
    absorb: absorb::AbsorbScratch,
    /// Each mode's response to the last pulse it took analytically.
    responses: Vec<strike::CachedResponse>,
    /// Number of `pulses` in use.
    num_pulses: usize,
}

impl ResonatorBank {
    /// Storage for `num_modes` modes, all silent. Allocates.
    pub fn new(num_modes: usize) -> Self {
        let rows = num_modes.div_ceil(COLUMNS).div_ceil(ROW_BLOCK) * ROW_BLOCK;
        // Room for a ghost beside every mode.
        let slots = 2 * rows * COLUMNS;
        Self {
            re: vec![0.0; slots],
            im: vec![0.0; slots],
            q_re: vec![0.0; slots],
            q_im: vec![0.0; slots],
            gain: vec![0.0; slots],
            mode_of_slot: vec![NONE; slots],
            slot_of_mode: vec![NONE; num_modes],
            ghost_of_mode: vec![NONE; num_modes],
            live: [0; COLUMNS],
            num_slots: 0,
            claimed: [0; COLUMNS],
            rows_active: 0,
            num_started: 0,
            theta: vec![0.0; slots],
            delta: vec![0.0; slots],
            fade_delta: vec![0.0; slots],
            fade_end: vec![0; slots],
            pole_delta: vec![0.0; slots],
            coeffs_stale: false,
            num_fading: 0,
            next_fade_end: u64::MAX,
            num_ghosts: 0,
            clock: 0,
            dormant: vec![Dormant::EMPTY; num_modes],
            recheck: vec![0; num_modes],
            earliest_recheck: u64::MAX,
            num_dormant: 0,
            dormant_of_mode: vec![NONE; num_modes],
            num_fading_out: 0,
            woken: 0,
            computed: 0,
            pulses: [(0, Pulse::NONE); strike::MAX_PULSES],
            absorb: absorb::AbsorbScratch::new(num_modes),
            responses: vec![strike::CachedResponse::EMPTY; num_modes],
            num_pulses: 0,
        }
    }

    /// Number of modes the bank can hold.
    pub fn num_modes(&self) -> usize {
        self.slot_of_mode.len()
    }

    /// Number of modes currently sounding, computed or dormant.
    pub fn num_live(&self) -> usize {
        self.num_active() + self.num_dormant - self.num_fading_out
    }

    /// Number of modes the kernels compute (fading ones included, ghosts not).
    pub fn num_active(&self) -> usize {
        self.num_slots - self.num_ghosts
    }

    /// Number of modes `kernel` advances per sample: live modes and ghosts, plus padding to the
    /// rows the fullest column needs in whole row blocks of the kernel.
    pub fn num_computed(&self, kernel: Kernel) -> usize {
        self.rows_active.next_multiple_of(kernel.row_block()) * COLUMNS
    }

    /// Mode-samples the kernels have computed since the bank was made (row padding included).
    pub fn computed_mode_samples(&self) -> u64 {
        self.computed
    }

    /// Modes started since the bank was last cleared, counting a mode started again after it
    /// was retired.
    pub fn num_started(&self) -> usize {
        self.num_started
    }

    /// Whether mode `mode` is sounding, computed or dormant.
    pub fn is_live(&self, mode: usize) -> bool {
        self.slot_of_mode[mode] != NONE || self.dormant_of_mode[mode] != NONE
    }

    /// Each column's sum of its computed modes' amplitudes `|z|` (ghosts included): undriven,
    /// no later sample of the column can exceed it, since every mode decays.
    pub fn column_amplitudes(&self) -> [f32; COLUMNS] {
        let mut sum = [0.0f32; COLUMNS];
        for slot in self.live_slots() {
            sum[slot % COLUMNS] += self.re[slot].hypot(self.im[slot]);
        }
        sum
    }

    /// The phasor state `(re, im)` of a mode's slot, or `None` when it is not computed.
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
        let column = self.column_for(mode);
        self.claimed[column] += 1;
        let slot = self.push_slot(mode as u32, column);
        self.q_re[slot] = coeffs.q_re;
        self.q_im[slot] = coeffs.q_im;
        self.gain[slot] = gain;
        // The pole is read back from the coefficients if it is ever needed.
        self.theta[slot] = f64::NAN;
        self.num_started += 1;
        true
    }

    /// The column a mode starting from rest goes to: its own when that is among the emptiest.
    fn column_for(&self, mode: usize) -> usize {
        let fewest = self.claimed.iter().copied().min().unwrap_or(0);
        (0..COLUMNS)
            .map(|i| (mode + i) % COLUMNS)
            .find(|&c| self.claimed[c] == fewest)
            .unwrap_or(mode % COLUMNS)
    }

    /// Puts `entry` (a mode, or a mode's ghost) at the end of `column`, at rest, steady, without
    /// coefficients. Returns its slot.
    fn push_slot(&mut self, entry: u32, column: usize) -> usize {
        let slot = self.live[column] as usize * COLUMNS + column;
        self.live[column] += 1;
        self.num_slots += 1;
        self.clear_slot(slot);
        self.mode_of_slot[slot] = entry;
        let mode = (entry & !GHOST) as usize;
        if entry & GHOST != 0 {
            self.ghost_of_mode[mode] = slot as u32;
            self.num_ghosts += 1;
        } else {
            self.slot_of_mode[mode] = slot as u32;
        }
        self.update_rows();
        slot
    }

    /// Sets the input gain of every computed mode to `gain_of(mode)` (dormant modes take theirs
    /// with the strike, [`ResonatorBank::absorb_strike`]).
    pub fn set_gains_with(&mut self, mut gain_of: impl FnMut(usize) -> f32) {
        for slot in self.live_slots() {
            let entry = self.mode_of_slot[slot];
            // Ghosts take no input.
            if entry & GHOST == 0 {
                self.gain[slot] = gain_of(entry as usize);
            }
        }
    }

    /// The computed modes, in slot order.
    pub fn live_modes(&self) -> impl Iterator<Item = usize> + '_ {
        self.live_slots()
            .map(|slot| self.mode_of_slot[slot])
            .filter(|entry| entry & GHOST == 0)
            .map(|entry| entry as usize)
    }

    fn live_slots(&self) -> impl Iterator<Item = usize> + 'static {
        let live = self.live;
        (0..COLUMNS).flat_map(move |c| (0..live[c] as usize).map(move |r| r * COLUMNS + c))
    }

    /// Advances every live mode over `acc.len()` samples, driven by `input` when given, adding
    /// each mode's output into its column's lane of `acc`.
    #[inline]
    pub fn process(&mut self, kernel: Kernel, input: Option<&[f32]>, acc: &mut [[f32; COLUMNS]]) {
        if self.coeffs_stale {
            self.refresh_coeffs();
        }
        self.clock += acc.len() as u64;
        // Storage rows come in whole `ROW_BLOCK`s, and the rows past `rows_active` hold silence.
        let n = self.num_computed(kernel);
        self.computed += (n * acc.len()) as u64;
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

    /// Like [`ResonatorBank::process`], but one sample at a time, each sample's input being
    /// `input`'s plus the force `friction` returns from the object's velocity at the contact
    /// point and the sum of the gains' magnitudes: a rub ([`crate::dsp::contact`]). A mode's
    /// velocity is the real part of its phasor (the imaginary part, its output, is its
    /// displacement); each counts with the sign of its gain, so that every mode moves the contact
    /// point the way the force pushes it. The velocity is the state before the sample, which the
    /// sample's input first reaches.
    pub fn process_rubbed(
        &mut self,
        kernel: Kernel,
        input: &[f32],
        mut friction: impl FnMut(f32, f32) -> f32,
        acc: &mut [[f32; COLUMNS]],
    ) {
        let n = self.num_computed(kernel);
        let gain_sum: f32 = self.gain[..n].iter().map(|g| g.abs()).sum();
        for (x, sum) in input.iter().zip(acc.iter_mut()) {
            let velocity = signed_sum(&self.re[..n], &self.gain[..n]);
            let drive = x + friction(velocity, gain_sum);
            self.process(
                kernel,
                Some(std::slice::from_ref(&drive)),
                std::slice::from_mut(sum),
            );
        }
    }

    /// Stops every steady computed mode whose amplitude `|z|` is below `threshold` and re-packs
    /// the columns (fading modes, and modes with a ghost, finish their fades first). Returns how
    /// many modes stopped.
    pub fn retire_below(&mut self, threshold: f32) -> usize {
        let threshold_sq = threshold * threshold;
        // Usually nothing is due: one pass over the states finds out. The slots past each
        // column's live ones hold zeros, so they are at or below any threshold: when no more
        // slots than those are, no live one is. (Fading modes and ghosts found here are passed
        // over below.)
        let n = self.rows_active * COLUMNS;
        // Two-row kernels may compute one row past the fullest column's.
        debug_assert!(
            (0..self.rows_active.next_multiple_of(ROW_BLOCK) * COLUMNS)
                .all(|slot| slot / COLUMNS < self.live[slot % COLUMNS] as usize
                    || (self.re[slot], self.im[slot]) == (0.0, 0.0)),
            "an empty slot holds a state"
        );
        if count_not_above(&self.re[..n], &self.im[..n], threshold_sq) <= n - self.num_slots {
            return 0;
        }
        let mut retired = 0;
        for column in 0..COLUMNS {
            // Downwards, so the mode moved into a freed slot has already been checked.
            for row in (0..self.live[column] as usize).rev() {
                let slot = row * COLUMNS + column;
                let entry = self.mode_of_slot[slot];
                if self.fade_delta[slot] != 0.0
                    || entry & GHOST != 0
                    || self.ghost_of_mode[entry as usize] != NONE
                {
                    continue;
                }
                let e = self.re[slot] * self.re[slot] + self.im[slot] * self.im[slot];
                if below(e, threshold_sq) {
                    self.remove_slot(slot);
                    self.claimed[column] -= 1;
                    retired += 1;
                }
            }
        }
        if retired > 0 {
            self.update_rows();
        }
        retired
    }

    /// Silences every mode.
    pub fn clear(&mut self) {
        for slot in self.live_slots() {
            self.clear_slot(slot);
        }
        self.live = [0; COLUMNS];
        self.num_slots = 0;
        self.claimed = [0; COLUMNS];
        self.rows_active = 0;
        self.num_started = 0;
        self.slot_of_mode.fill(NONE);
        self.ghost_of_mode.fill(NONE);
        for d in &self.dormant[..self.num_dormant] {
            self.dormant_of_mode[d.mode as usize] = NONE;
        }
        self.num_dormant = 0;
        self.earliest_recheck = u64::MAX;
        self.num_fading = 0;
        self.next_fade_end = u64::MAX;
        self.num_fading_out = 0;
        self.num_ghosts = 0;
        self.coeffs_stale = false;
        self.num_pulses = 0;
        self.clock = 0;
    }

    /// Removes what `slot` holds, moving its column's last slot into the gap. The column's claim
    /// is the caller's to settle.
    fn remove_slot(&mut self, slot: usize) {
        let column = slot % COLUMNS;
        let last = (self.live[column] as usize - 1) * COLUMNS + column;
        let entry = self.mode_of_slot[slot];
        if entry & GHOST != 0 {
            self.ghost_of_mode[(entry & !GHOST) as usize] = NONE;
            self.num_ghosts -= 1;
        } else {
            self.slot_of_mode[entry as usize] = NONE;
        }
        if self.fade_delta[slot] != 0.0 {
            self.num_fading -= 1;
            // A mode fading out stays on as its record alone.
            self.num_fading_out -= (self.fade_delta[slot] > 0.0 && entry & GHOST == 0) as usize;
        }
        if last != slot {
            self.re[slot] = self.re[last];
            self.im[slot] = self.im[last];
            self.q_re[slot] = self.q_re[last];
            self.q_im[slot] = self.q_im[last];
            self.gain[slot] = self.gain[last];
            self.theta[slot] = self.theta[last];
            self.delta[slot] = self.delta[last];
            self.fade_delta[slot] = self.fade_delta[last];
            self.fade_end[slot] = self.fade_end[last];
            let moved = self.mode_of_slot[last];
            self.mode_of_slot[slot] = moved;
            if moved & GHOST != 0 {
                self.ghost_of_mode[(moved & !GHOST) as usize] = slot as u32;
            } else {
                self.slot_of_mode[moved as usize] = slot as u32;
            }
        }
        self.clear_slot(last);
        self.live[column] -= 1;
        self.num_slots -= 1;
    }

    /// Zeroes a slot so the kernel computes silence there.
    fn clear_slot(&mut self, slot: usize) {
        self.re[slot] = 0.0;
        self.im[slot] = 0.0;
        self.q_re[slot] = 0.0;
        self.q_im[slot] = 0.0;
        self.gain[slot] = 0.0;
        self.theta[slot] = 0.0;
        self.delta[slot] = 0.0;
        self.fade_delta[slot] = 0.0;
        self.fade_end[slot] = 0;
        self.mode_of_slot[slot] = NONE;
    }

    fn update_rows(&mut self) {
        let fullest = self.live.iter().copied().max().unwrap_or(0) as usize;
        debug_assert_eq!(
            self.num_slots,
            self.live.iter().map(|&n| n as usize).sum::<usize>()
        );
        self.rows_active = fullest;
    }
}

/// The sum of `re` with the signs of `gain`, in eight independent lanes (so it vectorises).
fn signed_sum(re: &[f32], gain: &[f32]) -> f32 {
    let mut lanes = [0.0f32; COLUMNS];
    for (r, g) in re.chunks_exact(COLUMNS).zip(gain.chunks_exact(COLUMNS)) {
        for j in 0..COLUMNS {
            lanes[j] += f32::from_bits(r[j].to_bits() ^ (g[j].to_bits() & 0x8000_0000));
        }
    }
    lanes.iter().sum()
}

/// How many of the states `re + i im` have `|z|^2` not above `threshold_sq` (not-a-number
/// counts).
fn count_not_above(re: &[f32], im: &[f32], threshold_sq: f32) -> usize {
    #[cfg(target_arch = "x86_64")]
    {
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA.
            return unsafe { count_not_above_avx2(re, im, threshold_sq) };
        }
    }
    count_not_above_portable(re, im, threshold_sq)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn count_not_above_avx2(re: &[f32], im: &[f32], threshold_sq: f32) -> usize {
    count_not_above_portable(re, im, threshold_sq)
}

/// Branch-free over whole rows, so it vectorises. `!(e > t)` is meant: it holds when either is
/// not a number.
#[inline(always)]
#[allow(clippy::neg_cmp_op_on_partial_ord)]
fn count_not_above_portable(re: &[f32], im: &[f32], threshold_sq: f32) -> usize {
    let mut counts = [0u32; COLUMNS];
    for (r, i) in re.chunks_exact(COLUMNS).zip(im.chunks_exact(COLUMNS)) {
        for j in 0..COLUMNS {
            let e = r[j] * r[j] + i[j] * i[j];
            counts[j] += !(e > threshold_sq) as u32;
        }
    }
    counts.iter().map(|&c| c as usize).sum()
}

/// Whether power `e` is under `threshold_sq`, or not a number (a state gone bad is retired too).
#[inline]
fn below(e: f32, threshold_sq: f32) -> bool {
    !matches!(
        e.partial_cmp(&threshold_sq),
        Some(std::cmp::Ordering::Greater | std::cmp::Ordering::Equal)
    )
}
