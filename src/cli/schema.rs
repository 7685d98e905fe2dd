//! `modal-resonator schema`: the JSON Schema of the bank format, or of the scene format.

use modal_resonator::bank::schema::bank_schema_json;
use modal_resonator::scene::scene_schema_json;

/// Prints the schema: the scene format's if `scene`, else the bank format's.
pub(super) fn run(scene: bool) -> Result<(), String> {
    if scene {
        print!("{}", scene_schema_json());
    } else {
        print!("{}", bank_schema_json());
    }
    Ok(())
}
