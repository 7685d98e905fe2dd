//! `modal-resonator schema`: the JSON Schema of the bank format.

use modal_resonator::bank::schema::bank_schema_json;

/// Prints the schema.
pub(super) fn run() -> Result<(), String> {
    print!("{}", bank_schema_json());
    Ok(())
}
