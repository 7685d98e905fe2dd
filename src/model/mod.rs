//! Banks as data: the preset format, its validation and I/O, and the generators that author banks.
//!
//! Nothing here runs on the audio thread: code in this module may allocate and may fail.

pub mod bank;
pub mod compress;
pub mod factory;
pub mod fit;
pub mod io;
pub mod limen;
pub mod materials;
pub mod mesh;
pub mod schema;
pub mod shapes;
pub mod staged;
pub mod summary;
pub mod validate;

pub use bank::{Bank, BankDefaults, Mode, Position};
pub use io::{
    load_bank_file, parse_bank_str, save_bank_file, stage_bank_file, BankError, BankErrorKind,
    MAX_BANK_FILE_BYTES, MAX_JSON_VALUES,
};
pub use staged::{commit_all, StagedFile};
pub use validate::Problem;
