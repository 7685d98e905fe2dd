//! `modal-resonator validate`: every problem in every bank file.

use std::path::PathBuf;

use modal_resonator::model::load_bank_file;

/// `validate`: every problem of every file; fails if any file has one.
pub(super) fn run(files: &[PathBuf]) -> Result<(), String> {
    let mut bad = 0;
    for path in files {
        match load_bank_file(path) {
            Ok(bank) => println!(
                "{}: ok ({} modes, {} positions)",
                path.display(),
                bank.modes.len(),
                bank.positions.len()
            ),
            Err(e) => {
                bad += 1;
                println!("{e}");
            }
        }
    }
    match bad {
        0 => Ok(()),
        n => Err(format!("{n} of {} files have problems", files.len())),
    }
}
