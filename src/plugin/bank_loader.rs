//! Turning the bank saved in the plugin state into a ready engine, off the audio thread.

use std::sync::Arc;

use crate::engine::{Engine, PreparedBank};
use crate::model::factory::factory_bank;
use crate::model::{parse_bank_str, Bank};

/// The factory bank played when the state holds none.
pub const DEFAULT_FACTORY_BANK: &str = "rosewood-marimba-bar";

/// An engine built for a bank, on its way to the audio thread.
pub struct LoadedEngine {
    /// Which version of the saved bank it was built from.
    pub generation: u64,
    /// The activation it was asked for in.
    pub epoch: u64,
    /// The engine, prepared for the current sample rate.
    pub engine: Box<Engine>,
}

/// The bank saved as `json` (the default factory bank when empty). Errors name what is wrong.
pub fn bank_from_state(json: &str) -> Result<Bank, String> {
    if json.trim().is_empty() {
        return factory_bank(DEFAULT_FACTORY_BANK)
            .ok_or_else(|| format!("factory bank {DEFAULT_FACTORY_BANK} is missing"));
    }
    parse_bank_str(json, "saved bank").map_err(|e| e.to_string())
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
