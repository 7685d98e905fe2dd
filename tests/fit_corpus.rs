//! Fits of real strikes from the regression corpus (`tests/common/corpus.rs`), scored by the
//! independent measure of `tests/common/fit_score.rs`: each recording stays within a bound a
//! little above the score it reached when the bound was set, so a change that makes the fit
//! sound less like the recording fails. `cargo bench --bench fit` scores the whole corpus.

mod common;

use common::corpus::select;
use common::fit_score::{fitted_modes, score};
use modal_resonator::authoring::fit::{fit_bank, FitOptions};

/// A recording, the highest score (mean absolute dB over all frames) its fit may reach, and
/// the highest median error in cents of the modes nearest its five strongest spectral peaks.
struct Case {
    /// Slug in the corpus.
    slug: &'static str,
    /// Bound on the score over all frames, in dB.
    max_all_db: f64,
    /// Bound on the median peak error, in cents.
    max_cents: f64,
}

/// Bars, a membrane, a block, two recordings cut before their ring dies (a vibraphone the fit
/// once refused, and a triangle whose low modes were once taken for hum), a xylophone whose
/// partials decay fast then slow and a cowbell with partials the band fits leave out.
const CASES: &[Case] = &[
    Case {
        slug: "marimba-c7-fluid",
        max_all_db: 1.2,
        max_cents: 2.0,
    },
    Case {
        slug: "glockenspiel-gs5-freepats",
        max_all_db: 2.4,
        max_cents: 2.0,
    },
    Case {
        slug: "tabla-tun-sonic-pi",
        max_all_db: 2.0,
        max_cents: 5.0,
    },
    Case {
        slug: "claves-freepats",
        max_all_db: 5.6,
        // 50 ms of sound: its strongest peaks are misplaced by about 45 cents since the faster
        // band fits (padding at 2^a 3^b, vectorised sums), whichever way modes are selected.
        max_cents: 50.0,
    },
    Case {
        slug: "vibraphone-a4-fluid",
        max_all_db: 2.8,
        max_cents: 5.0,
    },
    Case {
        slug: "triangle-freepats",
        max_all_db: 2.7,
        max_cents: 2.0,
    },
    Case {
        slug: "xylophone-c5-freepats",
        max_all_db: 3.3,
        max_cents: 8.0,
    },
    // Sounds whose power still falls over their files' last frames: their noise is not their
    // quietest frames.
    Case {
        slug: "claves-fluid",
        max_all_db: 2.6,
        // Its one strong partial (2,161 Hz, some 25 dB above the next peak, gone in 100 ms) is
        // fitted as a cluster of modes within 40 Hz, the nearest 12 cents from the peak since
        // the bands are transformed without doubling their length.
        max_cents: 15.0,
    },
    Case {
        slug: "ride-bell-freepats",
        max_all_db: 2.4,
        max_cents: 2.0,
    },
    Case {
        slug: "cowbell-sonic-pi",
        max_all_db: 3.0,
        max_cents: 2.0,
    },
];

#[test]
fn corpus_recordings_fit_within_their_bounds() {
    let slugs: Vec<String> = CASES.iter().map(|c| c.slug.to_string()).collect();
    let entries = select(&slugs).unwrap();
    let mut failures = Vec::new();
    for (case, entry) in CASES.iter().zip(entries) {
        let recording = entry.load().unwrap();
        let fit = fit_bank(std::slice::from_ref(&recording), &FitOptions::default())
            .unwrap_or_else(|e| panic!("{}: {e}", case.slug));
        let modes = fitted_modes(&fit.bank, 0);
        let s = score(&modes, &recording);
        println!(
            "{}: {:.2} dB (bound {}), attack {:.2} dB, tail {:.2} dB, {} modes, {:.1} cents \
             (bound {})",
            case.slug,
            s.all_db,
            case.max_all_db,
            s.attack_db,
            s.tail_db,
            modes.len(),
            s.peak_cents,
            case.max_cents
        );
        if !(s.all_db <= case.max_all_db && s.peak_cents <= case.max_cents) {
            failures.push(format!(
                "{}: {:.2} dB (bound {}), {:.1} cents (bound {})",
                case.slug, s.all_db, case.max_all_db, s.peak_cents, case.max_cents
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
