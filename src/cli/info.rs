//! `modal-resonator info`: a bank described.

use modal_resonator::bank::summary::BankSummary;

use super::load_bank;

/// Prints the summary of the bank file or factory bank `bank`.
pub(super) fn run(bank: &str) -> Result<(), String> {
    print!("{}", BankSummary::of(&load_bank(bank)?.bank));
    Ok(())
}
