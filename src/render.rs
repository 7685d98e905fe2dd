//! Offline rendering over the engine.
