//! Banks as data: the preset format, its validation and I/O, and the generators that author banks.
//!
//! Nothing here runs on the audio thread: code in this module may allocate and may fail.

pub mod bank;
pub mod factory;
pub mod materials;
pub mod shapes;

pub use bank::{Bank, BankDefaults, Mode, Position};
