//! `modal-resonator schema`: the JSON Schema of the bank format.

use modal_resonator::model::schema::bank_schema_json;

/// Prints the schema.
pub(super) fn run() -> Result<(), String> {
    print!("{}", bank_schema_json());
    Ok(())
}
