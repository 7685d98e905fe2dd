//! How long a mode takes to fade in or out when it is switched on or off: shared by the voices,
//! which start modes dormant, and by pruning, which switches them.

use super::CONTROL_PERIOD;
use crate::dsp::resonator_bank::{floor, NextTick};

/// Shortest fade in or out, in seconds: short enough to follow the masking.
const FADE_S: f64 = 0.005;

/// Fades last at least this many periods of the mode, so low modes fade smoothly too (a 40 Hz
/// mode over 50 ms).
const FADE_PERIODS: f64 = 2.0;

/// Longest fade, in seconds.
const MAX_FADE_S: f64 = 0.25;

/// Samples of a fade for a mode at `theta` radians per sample: [`FADE_S`] or [`FADE_PERIODS`] of
/// the mode, whichever is longer (at most [`MAX_FADE_S`]), rounded up to whole control periods so
/// fades started on a tick end on one.
pub(in crate::engine) fn fade_samples(theta: f32, sample_rate_hz: f64) -> u32 {
    let periods = FADE_PERIODS * std::f64::consts::TAU / (theta as f64).max(1e-9);
    let samples = (FADE_S * sample_rate_hz)
        .max(periods)
        .min(MAX_FADE_S * sample_rate_hz);
    // Rounded up without `f64::ceil`, a library call on x86-64 without SSE4.1.
    let blocks = -floor(-samples / CONTROL_PERIOD as f64);
    blocks.max(1.0) as u32 * CONTROL_PERIOD as u32
}

/// Where the next control tick lies from engine clock `clock`: fades started between ticks are
/// lengthened to end on one ([`NextTick`]).
pub(in crate::engine) fn next_tick(clock: u64) -> NextTick {
    let period = CONTROL_PERIOD as u64;
    NextTick {
        in_samples: ((period - clock % period) % period) as u32,
        period: CONTROL_PERIOD as u32,
    }
}
