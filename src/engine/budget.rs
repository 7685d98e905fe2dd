//! The computation budget (seed 000 sections 5.5 and 6.4): a cap on the modes computed at once,
//! fixed or derived from the engine's own cost measured when it is prepared.

use std::time::Instant;

use super::{Controls, Engine};
use crate::dsp::{Kernel, ModeCoeffs, ResonatorBank, COLUMNS};

/// Seed 000 eq. 6.6: the share of the measured capacity the automatic budget uses, leaving room
/// for everything but the resonators.
const BUDGET_SAFETY: f64 = 0.9;

/// The kernel's measured speed, and the cap the controls ask for.
#[derive(Debug, Clone, Default)]
pub(super) struct Budget {
    /// Measured cost of the kernel, nanoseconds per mode-sample (0 before measuring).
    pub ns_per_mode_sample: f64,
}

impl Budget {
    /// Measures the cost of `kernel` per mode-sample on this machine (seed 000 section 6.4.1: a
    /// short stress test when starting). Allocates; takes about a millisecond.
    pub fn calibrate(&mut self, kernel: Kernel, sample_rate_hz: f64) {
        const MODES: usize = 512;
        const RUN: usize = 256;
        const RUNS: usize = 4;
        const REPEATS: usize = 5;
        let mut bank = ResonatorBank::new(MODES);
        for m in 0..MODES {
            let f = 50.0 + m as f64 * 0.4 * sample_rate_hz / MODES as f64;
            bank.activate(m, ModeCoeffs::from_freq_decay(sample_rate_hz, f, 1.0), 1.0);
        }
        let mut acc = vec![[0.0f32; COLUMNS]; RUN];
        let mut input = vec![0.0f32; RUN];
        input[0] = 1.0;
        bank.process(kernel, Some(&input), &mut acc);
        let mut best = f64::INFINITY;
        for _ in 0..REPEATS {
            let start = Instant::now();
            for _ in 0..RUNS {
                bank.process(kernel, None, &mut acc);
            }
            best = best.min(start.elapsed().as_secs_f64());
            std::hint::black_box(&mut acc);
        }
        self.ns_per_mode_sample = best * 1e9 / (RUNS * RUN * bank.num_computed()) as f64;
    }

    /// The cap on computed modes the controls ask for, if any: the fixed budget, or the modes
    /// whose estimated cost stays under the target load (seed 000 eqs. 6.4-6.6), whichever is
    /// smaller. Row padding is not counted; the safety factor leaves room for it.
    pub fn cap(&self, c: &Controls, sample_rate_hz: f64) -> Option<usize> {
        let fixed = (c.mode_budget > 0).then_some(c.mode_budget);
        let auto = (c.target_load_pct > 0.0 && self.ns_per_mode_sample > 0.0).then(|| {
            // Nanoseconds of work per second of audio for one mode, against the share of a
            // second the target allows.
            let per_mode_ns_per_s = self.ns_per_mode_sample * sample_rate_hz;
            let modes = c.target_load_pct as f64 / 100.0 * 1e9 / per_mode_ns_per_s;
            ((modes * BUDGET_SAFETY) as usize).max(1)
        });
        match (fixed, auto) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
}

impl Engine {
    /// The cost per mode-sample the automatic budget works with, in nanoseconds.
    pub fn ns_per_mode_sample(&self) -> f64 {
        self.budget.ns_per_mode_sample
    }

    /// Replaces the measured cost per mode-sample (so tests can use a fixed one).
    pub fn set_ns_per_mode_sample(&mut self, ns: f64) {
        self.budget.ns_per_mode_sample = ns;
    }

    /// The cap on computed modes the controls ask for now, if any.
    pub fn mode_cap(&self) -> Option<usize> {
        self.budget.cap(&self.controls, self.sample_rate_hz)
    }
}
