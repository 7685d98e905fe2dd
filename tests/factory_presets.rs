//! The committed factory presets match what `src/model/factory.rs` generates.
//!
//! `UPDATE_PRESETS=1 cargo test factory_presets` rewrites `presets/<slug>.json` and the factory
//! table in `presets/README.md` instead of checking them.

use modal_resonator::model::factory::{
    factory_banks, factory_slug, factory_table_markdown, first_difference, splice_factory_table,
    write_factory_presets, FACTORY_TABLE_FILE,
};
use modal_resonator::model::Bank;
use std::path::PathBuf;

/// Numbers in the committed files may differ from a fresh build in the last bits (a platform's
/// `sin` or `exp`, or the JSON parser's rounding); anything larger is a real change.
const REL_TOL: f64 = 1e-9;

const HOW_TO_UPDATE: &str = "run UPDATE_PRESETS=1 cargo test factory_presets";

fn presets_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("presets")
}

fn updating() -> bool {
    std::env::var("UPDATE_PRESETS").is_ok_and(|value| !value.is_empty() && value != "0")
}

#[test]
fn factory_presets_are_up_to_date() {
    let dir = presets_dir();
    let banks = factory_banks();
    let table = factory_table_markdown(&banks);
    if updating() {
        let paths = write_factory_presets(&dir).expect("writing the factory presets");
        let readme_path = dir.join(FACTORY_TABLE_FILE);
        let readme = std::fs::read_to_string(&readme_path).expect("reading presets/README.md");
        let readme = splice_factory_table(&readme, &table)
            .expect("factory table markers in presets/README.md");
        std::fs::write(readme_path, readme).expect("writing the table");
        eprintln!("wrote {} presets and {FACTORY_TABLE_FILE}", paths.len());
        return;
    }

    let mut stale = Vec::new();
    for bank in &banks {
        let path = dir.join(format!("{}.json", factory_slug(bank)));
        let committed = match std::fs::read_to_string(&path) {
            Ok(text) => text,
            Err(err) => {
                stale.push(format!("{}: {err}", path.display()));
                continue;
            }
        };
        match serde_json::from_str::<Bank>(&committed) {
            Ok(committed) => {
                if let Some(difference) = first_difference(&committed, bank, REL_TOL) {
                    stale.push(format!(
                        "{}: {difference} (committed vs generated)",
                        path.display()
                    ));
                }
            }
            Err(err) => stale.push(format!("{}: {err}", path.display())),
        }
    }
    let table_path = dir.join(FACTORY_TABLE_FILE);
    match std::fs::read_to_string(&table_path) {
        Ok(committed)
            if splice_factory_table(&committed, &table).as_deref() == Some(committed.as_str()) => {}
        Ok(_) => stale.push(format!("{} differs", table_path.display())),
        Err(err) => stale.push(format!("{}: {err}", table_path.display())),
    }
    assert!(
        stale.is_empty(),
        "factory presets are out of date ({HOW_TO_UPDATE}):\n{}",
        stale.join("\n")
    );
}
