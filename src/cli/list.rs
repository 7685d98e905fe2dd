//! `modal-resonator list`: the factory banks.

use modal_resonator::bank::factory::{factory_banks, factory_slug};

/// Prints one line per factory bank: slug, number of modes, licence and name, in columns as
/// wide as their longest entry.
pub(super) fn run() -> Result<(), String> {
    let rows: Vec<(String, usize, String, String)> = factory_banks()
        .into_iter()
        .map(|bank| {
            (
                factory_slug(&bank),
                bank.modes.len(),
                bank.license,
                bank.name,
            )
        })
        .collect();
    let slug_width = rows.iter().map(|r| r.0.chars().count()).max().unwrap_or(0);
    let modes_width = rows
        .iter()
        .map(|r| r.1.to_string().len())
        .max()
        .unwrap_or(0);
    let license_width = rows.iter().map(|r| r.2.chars().count()).max().unwrap_or(0);
    for (slug, modes, license, name) in rows {
        println!(
            "{slug:<slug_width$}  {modes:>modes_width$} modes  {license:<license_width$}  {name}"
        );
    }
    Ok(())
}
