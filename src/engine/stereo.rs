//! Where each column of modes sits in the stereo field.

use crate::dsp::COLUMNS;

/// Pan of each accumulator column at full width, -1 (left) to 1 (right), before a bank chooses
/// its own order ([`balanced_pans`]). Modes are sorted by frequency and dealt round the columns,
/// so column 0 holds the lowest mode, usually the strongest: it sits in the centre. The next ones
/// fan out alternately left and right, so partials alternate sides; the last column is centred
/// again.
pub const COLUMN_PAN: [f32; COLUMNS] = [0.0, -0.35, 0.35, -0.7, 0.7, -1.0, 1.0, 0.0];

/// How much a column's distance from the centre costs beside the lean of the whole, in
/// [`balanced_pans`]: enough that the strongest columns take the centre when that balances as
/// well, small enough never to trade much balance for it.
const CENTRE_PREFERENCE: f64 = 0.05;

/// Widths at which [`balanced_pans`] balances a strike: the default and full width.
const BALANCED_WIDTHS: [f32; 2] = [0.5, 1.0];

/// The pans of [`COLUMN_PAN`], dealt to the columns so that a strike whose columns have the
/// covariance `cov` (sums of products of their samples) sounds centred: of every order of the
/// eight pans, the one whose worse lean at the default and at full width (the difference of the
/// right and left energies over their sum, cross terms included, for modes of close frequency in
/// two columns beat differently in the two channels) is least, plus a small preference for the
/// strongest columns near the centre; [`COLUMN_PAN`] itself when it does as well. A sparse bank,
/// whose few strong modes would fall where the default order puts them, is then balanced like a
/// dense one.
pub fn balanced_pans(cov: &[[f64; COLUMNS]; COLUMNS]) -> [f32; COLUMNS] {
    let total: f64 = (0..COLUMNS).map(|j| cov[j][j]).sum();
    if !(total > 0.0 && total.is_finite()) {
        return COLUMN_PAN;
    }
    let cost = |pans: &[f32; COLUMNS]| {
        let mut worst = 0.0f64;
        for width in BALANCED_WIDTHS {
            let (l, r) = lane_weights(width, pans);
            let (mut left, mut right) = (0.0, 0.0);
            for j in 0..COLUMNS {
                for k in 0..COLUMNS {
                    left += (l[j] * l[k]) as f64 * cov[j][k];
                    right += (r[j] * r[k]) as f64 * cov[j][k];
                }
            }
            worst = worst.max((right - left).abs() / (right + left).max(1e-300));
        }
        let spread: f64 = (0..COLUMNS).map(|j| cov[j][j] * pans[j].abs() as f64).sum();
        worst + CENTRE_PREFERENCE * spread / total
    };
    let mut best = (cost(&COLUMN_PAN), COLUMN_PAN);
    // Heap's algorithm: every order of the eight pans, one swap apart.
    let mut pans = COLUMN_PAN;
    let mut counters = [0usize; COLUMNS];
    let mut i = 1;
    while i < COLUMNS {
        if counters[i] < i {
            let j = if i % 2 == 0 { 0 } else { counters[i] };
            pans.swap(j, i);
            let c = cost(&pans);
            // Clearly better only: rounding never moves a bank off the default order.
            if c < best.0 - 1e-9 {
                best = (c, pans);
            }
            counters[i] += 1;
            i = 1;
        } else {
            counters[i] = 0;
            i += 1;
        }
    }
    best.1
}

/// Left and right gains of each column with pans `pans` at full width, at `width` (0 = mono,
/// 1 = full spread). Constant power: `l^2 + r^2 = 2`, so a centred column has gain 1 in each
/// channel.
pub fn lane_weights(width: f32, pans: &[f32; COLUMNS]) -> ([f32; COLUMNS], [f32; COLUMNS]) {
    let mut l = [0.0; COLUMNS];
    let mut r = [0.0; COLUMNS];
    for j in 0..COLUMNS {
        let pan = pans[j] * width.clamp(0.0, 1.0);
        l[j] = (1.0 - pan).sqrt();
        r[j] = (1.0 + pan).sqrt();
    }
    (l, r)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The covariance of uncorrelated columns of these energies.
    fn diagonal(energy: [f64; COLUMNS]) -> [[f64; COLUMNS]; COLUMNS] {
        let mut cov = [[0.0; COLUMNS]; COLUMNS];
        for j in 0..COLUMNS {
            cov[j][j] = energy[j];
        }
        cov
    }

    /// Right energy less left over their sum, at `width`.
    fn lean(cov: &[[f64; COLUMNS]; COLUMNS], pans: &[f32; COLUMNS], width: f32) -> f64 {
        let (l, r) = lane_weights(width, pans);
        let (mut left, mut right) = (0.0, 0.0);
        for j in 0..COLUMNS {
            for k in 0..COLUMNS {
                left += (l[j] * l[k]) as f64 * cov[j][k];
                right += (r[j] * r[k]) as f64 * cov[j][k];
            }
        }
        (right - left) / (right + left)
    }

    #[test]
    fn even_columns_keep_the_default_order() {
        assert_eq!(balanced_pans(&diagonal([1.0; COLUMNS])), COLUMN_PAN);
        assert_eq!(balanced_pans(&diagonal([0.0; COLUMNS])), COLUMN_PAN);
    }

    #[test]
    fn a_sparse_strike_is_balanced_with_the_same_eight_pans() {
        // Two strong partials in the default left columns, one weak on the right.
        let cov = diagonal([0.0, 1.0, 0.1, 0.8, 0.0, 0.0, 0.0, 0.0]);
        assert!(lean(&cov, &COLUMN_PAN, 1.0).abs() > 0.3);
        let pans = balanced_pans(&cov);
        for width in [0.5, 1.0] {
            assert!(lean(&cov, &pans, width).abs() < 0.03, "{pans:?}");
        }
        let mut sorted = pans;
        let mut default = COLUMN_PAN;
        sorted.sort_by(f32::total_cmp);
        default.sort_by(f32::total_cmp);
        assert_eq!(sorted, default);
    }

    #[test]
    fn beating_columns_are_balanced_with_their_cross_term() {
        // Columns 1 and 2 hold nearly opposite copies of one sound: their sum is quiet, but
        // panned apart, their difference is not.
        let mut cov = diagonal([0.1, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        cov[1][2] = -0.95;
        cov[2][1] = -0.95;
        let pans = balanced_pans(&cov);
        for width in [0.5, 1.0] {
            assert!(lean(&cov, &pans, width).abs() < 0.03, "{pans:?}");
        }
    }
}
