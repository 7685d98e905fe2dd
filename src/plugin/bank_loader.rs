//! Building the engine for the bank the plugin state holds, off the audio thread.

use std::sync::Arc;

use crate::bank::Bank;
use crate::engine::{Engine, PreparedBank};

/// An engine built for a bank, on its way to the audio thread.
pub struct LoadedEngine {
    /// Which version of the saved bank it was built from.
    pub generation: u64,
    /// The activation it was asked for in.
    pub epoch: u64,
    /// The engine, prepared for the current sample rate.
    pub engine: Box<Engine>,
}

/// An engine playing `bank` with voices for `polyphony` notes at once, prepared for
/// `sample_rate_hz` and blocks of up to `max_block`. Allocates: never call it on the audio
/// thread.
pub fn build_engine(
    bank: &Bank,
    polyphony: usize,
    sample_rate_hz: f32,
    max_block: usize,
) -> Box<Engine> {
    let mut engine = Box::new(Engine::new(Arc::new(PreparedBank::new(bank))));
    engine.reserve_voices(polyphony);
    engine.prepare(sample_rate_hz, max_block);
    engine
}
