//! What the bank's modes hold, for meters and voice stealing: power of computed modes (their
//! true state, whatever fade they are in) and of dormant ones (from their records).

use super::{ResonatorBank, GHOST, NONE};

impl ResonatorBank {
    /// Summed squared amplitude `|z|^2` of the live modes, computed or dormant (ghosts and fades
    /// as they are now).
    pub fn energy(&self) -> f32 {
        let computed: f32 = self
            .live_slots()
            .filter(|&s| self.fade_delta[s] <= 0.0)
            .map(|s| self.re[s] * self.re[s] + self.im[s] * self.im[s])
            .sum();
        let now = self.clock;
        let dormant: f32 = self.dormant[..self.num_dormant]
            .iter()
            .map(|d| d.power_at(now))
            .sum();
        computed + dormant
    }

    /// Calls `visit(mode, |z|^2)` for every live mode, computed or dormant, with the power of its
    /// true state: a mode fading out as its record carries it, a mode fading in as it will be
    /// when the fade ends, a ghost's ringing added to its mode's. For meters: reads the state and
    /// changes nothing.
    pub fn visit_energies(&self, mut visit: impl FnMut(usize, f32)) {
        for slot in self.live_slots() {
            let entry = self.mode_of_slot[slot];
            // Ghosts join their modes; a mode fading out is visited through its record.
            if entry & GHOST != 0 || self.fade_delta[slot] > 0.0 {
                continue;
            }
            let mode = entry as usize;
            let (mut re, mut im) = self.true_state(slot);
            let ghost = self.ghost_of_mode[mode];
            if ghost != NONE {
                // The phasor is linear: the old ringing adds to the new.
                let (g_re, g_im) = self.true_state(ghost as usize);
                re += g_re;
                im += g_im;
            }
            visit(mode, re * re + im * im);
        }
        let now = self.clock;
        for d in &self.dormant[..self.num_dormant] {
            visit(d.mode as usize, d.power_at(now));
        }
    }

    /// The state of a slot without what a fade in still holds back: a slot growing by
    /// `-fade_delta` per sample meets its true state when the fade ends.
    pub(super) fn true_state(&self, slot: usize) -> (f32, f32) {
        let fade = self.fade_delta[slot];
        if fade < 0.0 {
            let left = self.fade_end[slot].saturating_sub(self.clock) as f64;
            let k = (-fade * left).exp() as f32;
            (self.re[slot] * k, self.im[slot] * k)
        } else {
            (self.re[slot], self.im[slot])
        }
    }
}
