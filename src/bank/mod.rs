//! The bank as data, what every part of the program plays: the preset format, its validation,
//! its I/O, its summary for people and the factory banks (files built into the program).
//!
//! The tools that make banks live in [`crate::authoring`]; nothing here imports them. Nothing
//! here runs on the audio thread: code in this module may allocate and may fail.

pub mod factory;
pub mod format;
pub mod io;
pub mod schema;
pub mod staged;
pub mod summary;
pub mod validate;

pub use format::{Bank, BankDefaults, Mode, Position};
pub use io::{
    load_bank_file, parse_bank_str, save_bank_file, stage_bank_file, BankError, BankErrorKind,
    MAX_BANK_FILE_BYTES, MAX_JSON_VALUES,
};
pub use staged::{commit_all, StagedFile};
pub use validate::Problem;
