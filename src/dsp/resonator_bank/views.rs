//! The modes as the pruner sees them: computed ones with their true power, dormant ones with
//! their level in dB and when the pruner wants to look at them again.

use super::{ResonatorBank, COLUMNS, GHOST, NONE};

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
    /// Whether it is fading out: switched off, on its way to being carried analytically.
    pub leaving: bool,
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
    /// Whether it started from rest at this instant ([`ResonatorBank::start_dormant`]).
    pub from_rest: bool,
}

impl ResonatorBank {
    /// The true power of the ghost of `mode`, if it has one.
    pub(super) fn ghost_power(&self, mode: usize) -> Option<f32> {
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
                    leaving: fade > 0.0,
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
        // The earliest time of all, those visited included: the caller may leave a visited
        // mode's time as it is (the next scan then finds it again, until it is set later).
        let mut earliest = u64::MAX;
        for (d, &recheck_at) in self.dormant[..self.num_dormant]
            .iter()
            .zip(&self.recheck[..self.num_dormant])
        {
            earliest = earliest.min(recheck_at);
            if recheck_at > due {
                continue;
            }
            if self.still_fading_out(d.mode as usize) {
                continue;
            }
            f(DormantMode {
                mode: d.mode as usize,
                level_db: d.level_db_at(now),
                theta: d.theta,
                delta: d.delta,
                recheck_at,
                tag: d.tag,
                from_rest: d.rest_at == now,
            });
        }
        self.earliest_recheck = earliest;
    }
}
