//! `modal-resonator list`: the factory banks.

use modal_resonator::model::factory::{factory_banks, factory_slug};

/// Prints one line per factory bank: slug, number of modes, licence and name.
pub(super) fn run() -> Result<(), String> {
    for bank in factory_banks() {
        println!(
            "{:<28} {:>5} modes  {:<17} {}",
            factory_slug(&bank),
            bank.modes.len(),
            bank.license,
            bank.name
        );
    }
    Ok(())
}
