//! The committed analytic presets are what their recipes (`src/authoring/factory_recipes/`)
//! design and the factory plays exactly those files, and every factory
//! bank, analytic or fitted, validates and plays: non-silent, finite, and peaking near -6 dBFS
//! when struck at full velocity on its root key with its own defaults.
//!
//! `UPDATE_PRESETS=1 cargo test --test factory_presets` rewrites `presets/<slug>.json` and the factory
//! table in `presets/README.md` instead of checking them. (The fitted banks in `presets/fitted/`
//! are rewritten by `tests/fit_recordings.rs`.)

mod common;

use modal_resonator::authoring::factory_recipes::{designed_factory_banks, write_factory_presets};
use modal_resonator::bank::factory::{
    analytic_factory_banks, factory_banks, factory_slug, factory_table_markdown, first_difference,
    splice_factory_table, FACTORY_TABLE_FILE,
};
use modal_resonator::bank::Bank;
use std::path::PathBuf;

/// Numbers in the committed files may differ from a fresh build in the last bits (a platform's
/// `sin` or `exp`, or the JSON parser's rounding); anything larger is a real change.
const REL_TOL: f64 = 1e-9;

const HOW_TO_UPDATE: &str = "run UPDATE_PRESETS=1 cargo test --test factory_presets";

fn presets_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("presets")
}

fn updating() -> bool {
    std::env::var("UPDATE_PRESETS").is_ok_and(|value| !value.is_empty() && value != "0")
}

#[test]
fn factory_presets_are_up_to_date() {
    let dir = presets_dir();
    let table = factory_table_markdown(&factory_banks());
    let banks = designed_factory_banks();
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
    // The factory plays the files in `src/bank/factory/analytic.rs`: the recipes' list, in order.
    let designed: Vec<String> = banks.iter().map(factory_slug).collect();
    let played: Vec<String> = analytic_factory_banks().iter().map(factory_slug).collect();
    if played != designed {
        stale.push(format!(
            "src/bank/factory/analytic.rs embeds {played:?}, the recipes design {designed:?}"
        ));
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

/// How far from -6 dBFS a full-velocity strike on the root key may peak, in dB: the engine
/// normalises each bank to -6 dBFS at its default strike position and root pitch; the nearest
/// key for a root between keys, and the sample rate, move the peak a little.
const PEAK_TOLERANCE_DB: f32 = 1.5;

#[test]
fn every_factory_bank_validates_and_plays_near_minus_6_dbfs_at_its_root() {
    use modal_resonator::bank::validate::validate_bank;
    use modal_resonator::units::{gain_to_db, hz_to_midi_key};

    let rate = 48_000.0;
    let banks = factory_banks();
    assert!(banks.len() >= 24, "{} factory banks", banks.len());
    let mut report = Vec::new();
    for bank in &banks {
        let what = &bank.name;
        assert!(
            validate_bank(bank).is_empty(),
            "{what}: {:?}",
            validate_bank(bank)
        );
        let key = hz_to_midi_key(bank.effective_root_hz()).round() as u8;
        let mut e = common::engine(bank, rate);
        // A bank played by a contact is levelled for a mallet strike, which the contact at its
        // defaults matches within a few dB (checked below).
        let contact = e.controls().exciter.is_contact();
        if contact {
            // Taken once settled, over seconds 2 to 4: a rub's song takes a moment to build, and
            // a scrape's modes (damped by the scraper's hand) or a roll's a moment to fill.
            let rub = e.controls().exciter == modal_resonator::dsp::ExciterKind::Rub;
            let held = common::render(&mut e, &[common::on(0, key, 1.0)], 4.0, 512).0;
            let level = gain_to_db(common::peak(&held[held.len() - 96_000..]));
            report.push(format!("{what}: held contact {level:.2} dBFS"));
            if rub {
                // It sings: at its root, the lowest mode.
                let root = bank.effective_root_hz();
                let tail = &held[held.len() - 48_000..];
                let hz = common::spectral_peak_hz(tail, rate as f64, 0.8 * root, 1.25 * root);
                let cents = 1200.0 * (hz / root).log2();
                report.push(format!("{what}: sings at {hz:.2} Hz ({cents:+.1} cents)"));
                assert!(
                    cents.abs() < 5.0,
                    "{what}: sings at {hz:.2} Hz, root {root:.2}"
                );
            }
            assert!(
                (-18.0..=-3.0).contains(&level),
                "{what}: a held contact peaks at {level:.2} dBFS"
            );
            let mut c = e.controls().clone();
            c.exciter = modal_resonator::dsp::ExciterKind::Mallet;
            e = common::engine(bank, rate);
            e.set_controls(&c);
        }
        let (l, r) = common::render(&mut e, &[common::on(0, key, 1.0)], 0.5, 512);
        assert!(
            l.iter().chain(&r).all(|v| v.is_finite()),
            "{what}: not finite"
        );
        let peak_db = gain_to_db(common::peak(&l).max(common::peak(&r)));
        report.push(format!("{what}: {peak_db:.2} dBFS"));
        assert!(
            (peak_db + 6.0).abs() <= PEAK_TOLERANCE_DB,
            "{what}: peak {peak_db:.2} dBFS on key {key}, expected -6 +- {PEAK_TOLERANCE_DB}"
        );
        // Still sounding a tenth of a second in: a ring, not a click.
        let tail = common::peak(&l[4800..9600]).max(common::peak(&r[4800..9600]));
        assert!(tail > 1e-3, "{what}: silent after 0.1 s ({tail})");
    }
    println!("{}", report.join("\n"));
}

/// Most a single note of a factory bank may lean to one side at the default width, in dB of
/// left-to-right energy over its first two seconds and over its first half second.
const BALANCE_TOLERANCE_DB: f64 = 1.0;

#[test]
fn every_factory_bank_sounds_centred_at_the_default_width() {
    use modal_resonator::units::hz_to_midi_key;

    let rate = 48_000.0;
    let energy = |x: &[f32]| x.iter().map(|&v| v as f64 * v as f64).sum::<f64>();
    let mut report = Vec::new();
    let mut worst = (0.0f64, String::new());
    for bank in &factory_banks() {
        let what = &bank.name;
        let key = hz_to_midi_key(bank.effective_root_hz()).round() as u8;
        let mut e = common::engine(bank, rate);
        let (l, r) = common::render(&mut e, &[common::on(0, key, 1.0)], 2.0, 512);
        let lean_db = 10.0 * (energy(&r) / energy(&l)).log10();
        // And over its first half second, where the strike is.
        let onset_db = 10.0 * (energy(&r[..24_000]) / energy(&l[..24_000])).log10();
        // The same bank at full width, for the report.
        let mut e = common::engine(bank, rate);
        let mut controls = e.controls().clone();
        controls.width = 1.0;
        e.set_controls(&controls);
        let (l_full, r_full) = common::render(&mut e, &[common::on(0, key, 1.0)], 2.0, 512);
        let full_db = 10.0 * (energy(&r_full) / energy(&l_full)).log10();
        report.push(format!(
            "{what}: {lean_db:+.2} dB to the right at the default width ({onset_db:+.2} dB over \
             the first 0.5 s), {full_db:+.2} dB at full width"
        ));
        for lean in [lean_db, onset_db] {
            if lean.abs() > worst.0 {
                worst = (lean.abs(), what.clone());
            }
        }
    }
    println!("{}", report.join("\n"));
    assert!(
        worst.0 <= BALANCE_TOLERANCE_DB,
        "{} leans {:.2} dB to one side, expected at most {BALANCE_TOLERANCE_DB}:\n{}",
        worst.1,
        worst.0,
        report.join("\n")
    );
}
