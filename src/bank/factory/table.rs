//! The Markdown table of the factory banks kept in `presets/README.md`.

use super::{factory_file, factory_slug};
use crate::bank::summary::note_name;
use crate::bank::Bank;

/// What a factory bank was made from, for the table: "free-free-bar, steel", or the recording.
fn made_from(bank: &Bank) -> String {
    let field = |key: &str| bank.source_text(key).unwrap_or("").to_string();
    if field("kind") == "fitted" {
        let file = field("file");
        let file = file.rsplit('/').next().unwrap_or("");
        format!(
            "fitted to a recording: {} `{file}`",
            field("debian_package")
        )
    } else if field("kind") == "mesh" {
        format!("the mesh `meshes/{}`, {}", field("mesh"), field("material"))
    } else {
        format!("{}, {}", field("shape"), field("material"))
    }
}

/// The Markdown table of the factory banks, kept in `presets/README.md`.
pub fn factory_table_markdown(banks: &[Bank]) -> String {
    let mut text = String::from(
        "Generated from `src/bank/factory/` by `UPDATE_PRESETS=1 cargo test --test factory_presets`; \
         do not edit by hand. Analytic banks (`source.kind = \"analytic\"`) have the closed-form \
         modes of the object (`src/authoring/shapes/`), decays from the material \
         (`src/authoring/materials.rs`) and gains `Psi_n(p) / omega_n` at each strike position \
         (seed 000 eq. 3.11); fitted banks (`source.kind = \"fitted\"`) were measured from a \
         recording by `modal-resonator fit`; meshed banks (`source.kind = \"mesh\"`) were made \
         by `modal-resonator mesh` from a generated mesh (see below).\n\n\
         | Name | Slug (CLI) | File | Made from | Root | Modes | Licence |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for bank in banks {
        let root_hz = bank.effective_root_hz();
        text.push_str(&format!(
            "| {} | `{}` | `{}` | {} | {:.2} Hz ({}) | {} | {} |\n",
            bank.name,
            factory_slug(bank),
            factory_file(bank),
            made_from(bank),
            root_hz,
            note_name(root_hz),
            bank.modes.len(),
            bank.license,
        ));
    }
    text
}
