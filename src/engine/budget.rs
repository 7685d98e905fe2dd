//! The computation budget (seed 000 sections 5.5 and 6.4): a cap on the modes computed at once,
//! fixed or derived from the engine's own cost per mode-sample, measured once per process and
//! kernel by a short stress test when the first engine is prepared (off the audio thread).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Instant;

use super::{Controls, Engine, NoteEvent, PreparedBank, CONTROL_PERIOD};
use crate::bank::{Bank, Mode, Position};
use crate::dsp::Kernel;

/// Seed 000 eq. 6.6: the share of the measured capacity the automatic budget uses (`C = 0.9`),
/// leaving room for everything but the resonators.
const BUDGET_SAFETY: f64 = 0.9;

/// Modes of the stress-test bank: enough that per-sample work is shared out thin.
const CALIBRATION_MODES: usize = 512;

/// Voices struck in the stress test.
const CALIBRATION_VOICES: u8 = 4;

/// Samples per timed render, and renders timed; the fastest counts (the machine may be busy).
const CALIBRATION_SAMPLES: usize = 2048;
const CALIBRATION_REPEATS: usize = 5;

/// The measured cost of each kernel in nanoseconds per mode-sample, as `f64` bits (0: not yet
/// measured), indexed like [`Kernel::ALL`].
static MEASURED: [AtomicU64; 4] = [const { AtomicU64::new(0) }; 4];

/// The engine's measured speed, and the cap the controls ask for.
#[derive(Debug, Clone, Default)]
pub(super) struct Budget {
    /// Measured cost of the engine, nanoseconds per mode-sample (0 before measuring).
    pub ns_per_mode_sample: f64,
}

impl Budget {
    /// The engine's cost per mode-sample with `kernel`, measured the first time it is asked for
    /// in this process (seed 000 section 6.4.1: a short stress test when starting, a few
    /// milliseconds). Allocates; never call it on the audio thread.
    pub fn calibrate(&mut self, kernel: Kernel, sample_rate_hz: f64) {
        let index = Kernel::ALL.iter().position(|&k| k == kernel).unwrap_or(0);
        let known = f64::from_bits(MEASURED[index].load(Ordering::Relaxed));
        self.ns_per_mode_sample = if known > 0.0 {
            known
        } else {
            let measured = stress_test(kernel, sample_rate_hz);
            MEASURED[index].store(measured.to_bits(), Ordering::Relaxed);
            measured
        };
    }

    /// The cap on computed modes the controls ask for, if any: the fixed budget, or the modes
    /// whose estimated cost stays under the target load (seed 000 eqs. 6.4-6.6), whichever is
    /// smaller.
    pub fn cap(&self, c: &Controls, sample_rate_hz: f64) -> Option<usize> {
        let fixed = (c.mode_budget > 0).then_some(c.mode_budget);
        let auto = (c.target_load_pct > 0.0 && self.ns_per_mode_sample > 0.0)
            .then(|| auto_cap(self.ns_per_mode_sample, c.target_load_pct, sample_rate_hz));
        match (fixed, auto) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
}

/// Modes that cost `target_load_pct` percent of real time at `ns_per_mode_sample`, times the
/// safety factor (seed 000 eqs. 6.4-6.6: `N_max = N / F_allowed * C`); at least one.
pub fn auto_cap(ns_per_mode_sample: f64, target_load_pct: f32, sample_rate_hz: f64) -> usize {
    // Nanoseconds of work per second of audio for one mode, against the share of a second the
    // target allows.
    let per_mode_ns_per_s = ns_per_mode_sample * sample_rate_hz;
    let modes = target_load_pct as f64 / 100.0 * 1e9 / per_mode_ns_per_s;
    ((modes * BUDGET_SAFETY) as usize).max(1)
}

/// Renders a dense bank struck on a few voices through a scratch engine and returns its wall
/// time per mode-sample computed, in nanoseconds: the resonators and everything the engine does
/// per mode (control ticks, truncation, mixing) together.
fn stress_test(kernel: Kernel, sample_rate_hz: f64) -> f64 {
    let bank = Arc::new(PreparedBank::new(&stress_bank(sample_rate_hz)));
    let mut engine = Engine::new(bank);
    engine.kernel = kernel;
    engine.prepare_storage(sample_rate_hz as f32);
    let mut c = engine.controls().clone();
    c.key_tracking = 0.0;
    c.truncation_db = -200.0;
    engine.set_controls(&c);
    let strikes: Vec<NoteEvent> = (0..CALIBRATION_VOICES)
        .map(|k| NoteEvent::on(0, 60 + k, 1.0))
        .collect();
    let (mut l, mut r) = (
        vec![0.0f32; CALIBRATION_SAMPLES],
        vec![0.0f32; CALIBRATION_SAMPLES],
    );
    engine.process(
        &strikes,
        None,
        &mut l[..CONTROL_PERIOD],
        &mut r[..CONTROL_PERIOD],
    );
    let mut best = f64::INFINITY;
    for _ in 0..CALIBRATION_REPEATS {
        let before = engine.stats().computed_mode_samples;
        let start = Instant::now();
        engine.process(&[], None, &mut l, &mut r);
        let elapsed_ns = start.elapsed().as_nanos() as f64;
        let computed = (engine.stats().computed_mode_samples - before).max(1);
        best = best.min(elapsed_ns / computed as f64);
        std::hint::black_box((&l, &r));
    }
    best
}

/// Modes spread over the audible range with long decays: nothing is truncated while timed.
fn stress_bank(sample_rate_hz: f64) -> Bank {
    let mut bank = Bank::new(
        "stress test",
        vec![Position {
            name: "a".into(),
            coords: vec![0.0],
        }],
    );
    let top_hz = 0.4 * sample_rate_hz;
    bank.modes = (0..CALIBRATION_MODES)
        .map(|m| Mode {
            freq_hz: 50.0 + (top_hz - 50.0) * m as f64 / CALIBRATION_MODES as f64,
            decay_per_s: 0.5,
            gains: vec![1.0 / CALIBRATION_MODES as f64],
        })
        .collect();
    bank
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
        self.budget.cap(&self.expressed, self.sample_rate_hz)
    }
}
