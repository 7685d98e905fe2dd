//! `modal-resonator validate`: every problem in every bank file.

use std::path::PathBuf;

use modal_resonator::bank::factory::factory_bank;
use modal_resonator::bank::load_bank_file;
use modal_resonator::bank::validate::validate_bank;

/// `validate`: every problem of every file; fails if any file has one. A name that is no file
/// but a factory preset's (as `info` takes) checks that preset.
pub(super) fn run(files: &[PathBuf]) -> Result<(), String> {
    let mut bad = 0;
    for path in files {
        let factory = (!path.exists())
            .then(|| path.to_str().and_then(factory_bank))
            .flatten();
        if let Some(bank) = factory {
            let problems = validate_bank(&bank);
            if problems.is_empty() {
                println!(
                    "{}: ok (factory preset \"{}\", {} modes, {} positions)",
                    path.display(),
                    bank.name,
                    bank.modes.len(),
                    bank.positions.len()
                );
            } else {
                bad += 1;
                for problem in problems {
                    println!("{}: {problem}", path.display());
                }
            }
            continue;
        }
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
