//! ESPRIT: the poles of a sum of damped complex exponentials in noise, from the rotational
//! invariance of its signal subspace (Roy and Kailath 1989; applied to impact sounds in
//! sub-bands by Sirdey et al., DAFx 2011).
//!
//! The vectors `h_n = (y[n], ..., y[n + L - 1])` of a sum of `K` exponentials `c_k z_k^n` span a
//! `K`-dimensional space, the top eigenvectors `U` of their covariance. Dropping the first row of
//! `U` gives the same as dropping the last and multiplying by a `K x K` matrix whose eigenvalues
//! are the poles `z_k`. The order `K` is the number of eigenvalues standing clearly above the
//! noise's.

use realfft::num_complex::Complex64;

use super::linalg::{eigenvalues, hermitian_eigen, solve};

/// Rows of the data vectors: well above the most modes a band may hold (24, see
/// [`bandfit`](super::bandfit)).
const MAX_ROWS: usize = 40;

/// An eigenvalue counts as a mode when it stands this many times above the noise's.
const ORDER_FACTOR: f64 = 12.0;

/// Fewest samples an estimate is made from.
pub const MIN_SAMPLES: usize = 12;

/// Poles found in a band, and the noise they stand in.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// Poles per sample, in no particular order.
    pub poles: Vec<Complex64>,
    /// Variance of the noise per complex sample.
    pub noise_var: f64,
}

/// Poles of at most `max_order` exponentials in `y`, or `None` when `y` is too short.
pub fn esprit(y: &[Complex64], max_order: usize) -> Option<Estimate> {
    if y.len() < MIN_SAMPLES {
        return None;
    }
    let rows = MAX_ROWS.min(y.len() / 3).max(2);
    let vectors = y.len() - rows + 1;
    let mut r = covariance(y, rows);
    let (values, u) = hermitian_eigen(&mut r, rows);
    // Noise: the median of the lower half of the eigenvalues, each about `vectors` times the
    // noise variance.
    let noise_eig = values[rows - 1 - (rows / 2) / 2]
        .max(values[0] * 1e-16)
        .max(1e-300);
    let order = values
        .iter()
        .take_while(|&&v| v > ORDER_FACTOR * noise_eig)
        .count()
        .min(max_order)
        .min(rows - 1);
    let noise_var = noise_eig / vectors as f64;
    if order == 0 {
        return Some(Estimate {
            poles: Vec::new(),
            noise_var,
        });
    }
    Some(Estimate {
        poles: shift_invariance(&u, rows, order),
        noise_var,
    })
}

/// `R[i][j] = sum_n y[n + i] conj(y[n + j])` over the `y.len() - rows + 1` vectors: the first
/// row directly, the rest along the diagonals, each entry from the one up and to the left.
fn covariance(y: &[Complex64], rows: usize) -> Vec<Complex64> {
    let count = y.len() - rows + 1;
    let mut r = vec![Complex64::new(0.0, 0.0); rows * rows];
    for j in 0..rows {
        r[j] = (0..count).map(|n| y[n] * y[n + j].conj()).sum();
    }
    for i in 1..rows {
        for j in i..rows {
            let prev = r[(i - 1) * rows + j - 1];
            r[i * rows + j] =
                prev - y[i - 1] * y[j - 1].conj() + y[count + i - 1] * y[count + j - 1].conj();
        }
    }
    for i in 0..rows {
        for j in 0..i {
            r[i * rows + j] = r[j * rows + i].conj();
        }
        r[i * rows + i].im = 0.0;
    }
    r
}

/// The eigenvalues of `Phi = (U1^H U1)^-1 U1^H U2` for the first `order` columns of `u`.
fn shift_invariance(u: &[Complex64], rows: usize, order: usize) -> Vec<Complex64> {
    let at = |i: usize, k: usize| u[i * rows + k];
    let mut gram = vec![Complex64::new(0.0, 0.0); order * order];
    let mut cross = vec![Complex64::new(0.0, 0.0); order * order];
    for a in 0..order {
        for b in 0..order {
            gram[a * order + b] = (0..rows - 1).map(|i| at(i, a).conj() * at(i, b)).sum();
            cross[a * order + b] = (0..rows - 1).map(|i| at(i, a).conj() * at(i + 1, b)).sum();
        }
    }
    solve(&mut gram, &mut cross, order, order);
    eigenvalues(&mut cross, order)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    #[test]
    fn resolves_two_close_damped_exponentials_in_noise() {
        let z1 = Complex64::from_polar(0.995, 0.30);
        let z2 = Complex64::from_polar(0.98, 0.33);
        let mut rng = Rng::new(5);
        let y: Vec<Complex64> = (0..600)
            .map(|n| {
                let noise = Complex64::new(rng.bipolar() as f64, rng.bipolar() as f64) * 1e-3;
                z1.powu(n) + Complex64::new(0.0, 0.7) * z2.powu(n) + noise
            })
            .collect();
        let e = esprit(&y, 8).unwrap();
        assert_eq!(e.poles.len(), 2, "{:?}", e.poles);
        for want in [z1, z2] {
            let err = e
                .poles
                .iter()
                .map(|p| (p - want).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(err < 1e-4, "{want}: {:?}", e.poles);
        }
        // Uniform noise of half-width 1e-3 per part: variance 2 (1e-3)^2 / 3 per sample.
        let expected = 2.0 * 1e-6 / 3.0;
        assert!(
            (e.noise_var / expected).log10().abs() < 0.3,
            "{} vs {expected}",
            e.noise_var
        );
    }
}
