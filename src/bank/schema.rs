//! The JSON Schema of the bank format, generated from the Rust types.
//!
//! `presets/modal-bank.schema.json` holds a copy for editors: associated with bank files in an
//! editor's settings, it gives completion and type checks while typing. It describes the shape
//! only: the limits, the uniqueness of position names and the gains-per-position rule are checked
//! by [`validate`](super::validate) and documented in `presets/README.md`. A test keeps the
//! committed copy equal to [`bank_schema_json`]; `UPDATE_SCHEMA=1 cargo test --test bank_format`
//! rewrites it.

use schemars::schema_for;

use super::format::Bank;

/// The JSON Schema of [`Bank`], pretty-printed, with a final newline.
pub fn bank_schema_json() -> String {
    let schema = schema_for!(Bank);
    // A schema is a JSON object with string keys: serializing it cannot fail.
    let mut json = serde_json::to_string_pretty(&schema).expect("a JSON Schema always serializes");
    json.push('\n');
    json
}
