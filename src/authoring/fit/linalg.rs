//! Small dense complex linear algebra for the sub-band estimator: the eigen-decomposition of a
//! Hermitian matrix (cyclic Jacobi), the eigenvalues of a general matrix (Hessenberg reduction and
//! shifted QR), and linear solves. Matrices are row-major `n x n` slices; sizes here are tens.

use realfft::num_complex::Complex64;

/// Jacobi sweeps before giving up on smaller off-diagonal entries (each sweep squares the
/// remaining off-diagonal norm once the rotations are small; ten is ample).
const MAX_SWEEPS: usize = 30;

/// Off-diagonal norm, relative to the whole matrix's, at which Jacobi stops.
const JACOBI_TOLERANCE: f64 = 1e-13;

/// QR iterations allowed per eigenvalue before the matrix is taken as converged.
const MAX_QR_ITERATIONS: usize = 60;

/// Rows and columns of a block of [`dots`].
pub const BLOCK: (usize, usize) = (2, 4);

/// The dot product of each of `x` with each of `y`, over the length of `x[0]` (which the others
/// reach), vectorised: each element loaded serves several products.
pub fn dots(x: [&[f64]; BLOCK.0], y: [&[f64]; BLOCK.1]) -> [[f64; BLOCK.1]; BLOCK.0] {
    #[cfg(target_arch = "x86_64")]
    {
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA.
            return unsafe { dots_avx2(x, y) };
        }
    }
    dots_portable(x, y)
}

/// With the block's products in eight registers of four lanes: each step loads the two `x`
/// once for four products and each `y` once for two.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn dots_avx2(x: [&[f64]; BLOCK.0], y: [&[f64]; BLOCK.1]) -> [[f64; BLOCK.1]; BLOCK.0] {
    use std::arch::x86_64::{__m256d, _mm256_fmadd_pd, _mm256_loadu_pd, _mm256_setzero_pd};
    const W: usize = 4;
    let n = x[0].len();
    let x = x.map(|v| &v[..n]);
    let y = y.map(|v| &v[..n]);
    let whole = n - n % W;
    let mut sums: [[__m256d; BLOCK.1]; BLOCK.0] = [[_mm256_setzero_pd(); BLOCK.1]; BLOCK.0];
    let mut i = 0;
    while i < whole {
        // SAFETY: i + W <= whole <= n, and every slice is n long.
        let xs = x.map(|v| unsafe { _mm256_loadu_pd(v.as_ptr().add(i)) });
        for (k, v) in y.iter().enumerate() {
            // SAFETY: as above.
            let ys = unsafe { _mm256_loadu_pd(v.as_ptr().add(i)) };
            for (sums, xs) in sums.iter_mut().zip(&xs) {
                sums[k] = _mm256_fmadd_pd(*xs, ys, sums[k]);
            }
        }
        i += W;
    }
    let mut out = [[0.0; BLOCK.1]; BLOCK.0];
    for (r, row) in out.iter_mut().enumerate() {
        for (k, v) in row.iter_mut().enumerate() {
            // SAFETY: __m256d and [f64; 4] have the same size, and any bits are a valid f64.
            let lanes: [f64; W] = unsafe { std::mem::transmute(sums[r][k]) };
            let tail: f64 = (whole..n).map(|i| x[r][i] * y[k][i]).sum();
            *v = lanes.iter().sum::<f64>() + tail;
        }
    }
    out
}

/// In sums of four lanes for each product.
fn dots_portable(x: [&[f64]; BLOCK.0], y: [&[f64]; BLOCK.1]) -> [[f64; BLOCK.1]; BLOCK.0] {
    const W: usize = 4;
    let n = x[0].len();
    let x = x.map(|v| &v[..n]);
    let y = y.map(|v| &v[..n]);
    let whole = n - n % W;
    let mut sums = [[[0.0; W]; BLOCK.1]; BLOCK.0];
    for i in (0..whole).step_by(W) {
        let xs: [[f64; W]; BLOCK.0] = x.map(|v| v[i..i + W].try_into().expect("W long"));
        for (k, v) in y.iter().enumerate() {
            let ys: [f64; W] = v[i..i + W].try_into().expect("W long");
            for (sums, xs) in sums.iter_mut().zip(&xs) {
                for l in 0..W {
                    sums[k][l] += xs[l] * ys[l];
                }
            }
        }
    }
    let mut out = [[0.0; BLOCK.1]; BLOCK.0];
    for (r, row) in out.iter_mut().enumerate() {
        for (k, v) in row.iter_mut().enumerate() {
            let tail: f64 = (whole..n).map(|i| x[r][i] * y[k][i]).sum();
            *v = sums[r][k].iter().sum::<f64>() + tail;
        }
    }
    out
}

/// Eigenvalues (descending) and unit eigenvectors of the Hermitian `a` (`n x n`, destroyed).
/// Eigenvector `k` is column `k` of the returned row-major matrix.
pub fn hermitian_eigen(a: &mut [Complex64], n: usize) -> (Vec<f64>, Vec<Complex64>) {
    let mut v = identity(n);
    let total: f64 = a.iter().map(|x| x.norm_sqr()).sum::<f64>().max(1e-300);
    for _ in 0..MAX_SWEEPS {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i * n + j].norm_sqr())
            .sum();
        if off <= JACOBI_TOLERANCE * JACOBI_TOLERANCE * total {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                rotate_pair(a, &mut v, n, p, q);
            }
        }
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&i, &j| a[j * n + j].re.total_cmp(&a[i * n + i].re));
    let values = order.iter().map(|&i| a[i * n + i].re).collect();
    let mut vectors = vec![Complex64::new(0.0, 0.0); n * n];
    for (k, &i) in order.iter().enumerate() {
        for r in 0..n {
            vectors[r * n + k] = v[r * n + i];
        }
    }
    (values, vectors)
}

/// One Jacobi step zeroing `a[p][q]`: a phase on index `q` makes the entry real, then a real
/// plane rotation (Numerical Recipes eqs. 11.1.4-11.1.8) removes it.
fn rotate_pair(a: &mut [Complex64], v: &mut [Complex64], n: usize, p: usize, q: usize) {
    let apq = a[p * n + q];
    let r = apq.norm();
    if r < 1e-300 {
        return;
    }
    // D = diag(.., e^{-i phi} at q): column q times e^{-i phi}, row q times e^{i phi}.
    let phase = apq / r;
    let conj_phase = phase.conj();
    for k in 0..n {
        a[k * n + q] *= conj_phase;
        v[k * n + q] *= conj_phase;
    }
    for k in 0..n {
        a[q * n + k] *= phase;
    }
    let (app, aqq) = (a[p * n + p].re, a[q * n + q].re);
    let theta = (aqq - app) / (2.0 * r);
    let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
    let t = if theta == 0.0 { 1.0 } else { t };
    let c = 1.0 / (t * t + 1.0).sqrt();
    let s = t * c;
    for k in 0..n {
        let (x, y) = (a[k * n + p], a[k * n + q]);
        a[k * n + p] = x * c - y * s;
        a[k * n + q] = x * s + y * c;
        let (x, y) = (v[k * n + p], v[k * n + q]);
        v[k * n + p] = x * c - y * s;
        v[k * n + q] = x * s + y * c;
    }
    for k in 0..n {
        let (x, y) = (a[p * n + k], a[q * n + k]);
        a[p * n + k] = x * c - y * s;
        a[q * n + k] = x * s + y * c;
    }
    a[p * n + q] = Complex64::new(0.0, 0.0);
    a[q * n + p] = Complex64::new(0.0, 0.0);
}

/// The `n x n` identity.
fn identity(n: usize) -> Vec<Complex64> {
    let mut m = vec![Complex64::new(0.0, 0.0); n * n];
    for i in 0..n {
        m[i * n + i] = Complex64::new(1.0, 0.0);
    }
    m
}

/// Eigenvalues of the general complex `a` (`n x n`, destroyed), in no particular order.
pub fn eigenvalues(a: &mut [Complex64], n: usize) -> Vec<Complex64> {
    hessenberg(a, n);
    let scale: f64 = a.iter().map(|x| x.norm()).fold(0.0, f64::max).max(1e-300);
    let mut values = Vec::with_capacity(n);
    let mut m = n;
    let mut iterations = 0;
    while m > 0 {
        if m == 1 {
            values.push(a[0]);
            break;
        }
        let sub = a[(m - 1) * n + m - 2].norm();
        let local = a[(m - 1) * n + m - 1].norm() + a[(m - 2) * n + m - 2].norm();
        if sub <= f64::EPSILON * local.max(1e-6 * scale) || iterations >= MAX_QR_ITERATIONS {
            values.push(a[(m - 1) * n + m - 1]);
            m -= 1;
            iterations = 0;
            continue;
        }
        let shift = if iterations > 0 && iterations % 10 == 0 {
            // An exceptional shift breaks a cycle.
            a[(m - 1) * n + m - 1] + Complex64::new(0.75 * sub, 0.25 * sub)
        } else {
            wilkinson_shift(a, n, m)
        };
        qr_step(a, n, m, shift);
        iterations += 1;
    }
    values
}

/// The eigenvalue of the trailing 2 x 2 block of the leading `m x m` part nearer its last
/// diagonal entry.
fn wilkinson_shift(a: &[Complex64], n: usize, m: usize) -> Complex64 {
    let (p, q) = (a[(m - 2) * n + m - 2], a[(m - 2) * n + m - 1]);
    let (r, s) = (a[(m - 1) * n + m - 2], a[(m - 1) * n + m - 1]);
    let half = 0.5 * (p - s);
    let disc = (half * half + q * r).sqrt();
    let (mu1, mu2) = (0.5 * (p + s) + disc, 0.5 * (p + s) - disc);
    if (mu1 - s).norm() < (mu2 - s).norm() {
        mu1
    } else {
        mu2
    }
}

/// One shifted QR step on the leading `m x m` block of the Hessenberg `a`, by Givens rotations.
fn qr_step(a: &mut [Complex64], n: usize, m: usize, shift: Complex64) {
    for i in 0..m {
        a[i * n + i] -= shift;
    }
    let mut rotations = Vec::with_capacity(m);
    for k in 0..m - 1 {
        let (x, y) = (a[k * n + k], a[(k + 1) * n + k]);
        let r = (x.norm_sqr() + y.norm_sqr()).sqrt();
        let (c, s) = if r < 1e-300 {
            (Complex64::new(1.0, 0.0), Complex64::new(0.0, 0.0))
        } else {
            (x / r, y / r)
        };
        for j in k..m {
            let (u, w) = (a[k * n + j], a[(k + 1) * n + j]);
            a[k * n + j] = c.conj() * u + s.conj() * w;
            a[(k + 1) * n + j] = -s * u + c * w;
        }
        rotations.push((c, s));
    }
    for (k, &(c, s)) in rotations.iter().enumerate() {
        for i in 0..(k + 2).min(m) {
            let (u, w) = (a[i * n + k], a[i * n + k + 1]);
            a[i * n + k] = u * c + w * s;
            a[i * n + k + 1] = -u * s.conj() + w * c.conj();
        }
    }
    for i in 0..m {
        a[i * n + i] += shift;
    }
}

/// Reduces `a` to upper Hessenberg form by Householder reflections (same eigenvalues).
fn hessenberg(a: &mut [Complex64], n: usize) {
    for k in 0..n.saturating_sub(2) {
        let norm = (k + 1..n)
            .map(|i| a[i * n + k].norm_sqr())
            .sum::<f64>()
            .sqrt();
        if norm < 1e-300 {
            continue;
        }
        let x0 = a[(k + 1) * n + k];
        let phase = if x0.norm() > 0.0 {
            x0 / x0.norm()
        } else {
            Complex64::new(1.0, 0.0)
        };
        let mut v: Vec<Complex64> = (k + 1..n).map(|i| a[i * n + k]).collect();
        v[0] += phase * norm;
        let vnorm = v.iter().map(|x| x.norm_sqr()).sum::<f64>().sqrt();
        v.iter_mut().for_each(|x| *x /= vnorm);
        // A <- (I - 2 v v^H) A on rows k+1.., then A <- A (I - 2 v v^H) on columns k+1...
        for j in 0..n {
            let dot: Complex64 = v
                .iter()
                .enumerate()
                .map(|(i, vi)| vi.conj() * a[(k + 1 + i) * n + j])
                .sum();
            for (i, vi) in v.iter().enumerate() {
                a[(k + 1 + i) * n + j] -= 2.0 * vi * dot;
            }
        }
        for i in 0..n {
            let dot: Complex64 = v
                .iter()
                .enumerate()
                .map(|(j, vj)| a[i * n + k + 1 + j] * vj)
                .sum();
            for (j, vj) in v.iter().enumerate() {
                a[i * n + k + 1 + j] -= 2.0 * dot * vj.conj();
            }
        }
    }
}

/// Solves `a x = b` (`a` is `n x n`, destroyed) by Gaussian elimination with partial pivoting,
/// for `b` with `cols` right-hand sides (row-major `n x cols`, overwritten by `x`). A singular
/// pivot is replaced by a tiny one, so the result stays finite.
pub fn solve(a: &mut [Complex64], b: &mut [Complex64], n: usize, cols: usize) {
    let scale = a.iter().map(|x| x.norm()).fold(0.0, f64::max).max(1e-300);
    for k in 0..n {
        let pivot = (k..n)
            .max_by(|&i, &j| a[i * n + k].norm().total_cmp(&a[j * n + k].norm()))
            .expect("k < n");
        if pivot != k {
            for j in 0..n {
                a.swap(k * n + j, pivot * n + j);
            }
            for j in 0..cols {
                b.swap(k * cols + j, pivot * cols + j);
            }
        }
        if a[k * n + k].norm() < 1e-14 * scale {
            a[k * n + k] = Complex64::new(1e-14 * scale, 0.0);
        }
        let inv = 1.0 / a[k * n + k];
        for i in k + 1..n {
            let f = a[i * n + k] * inv;
            if f.norm() == 0.0 {
                continue;
            }
            for j in k..n {
                let akj = a[k * n + j];
                a[i * n + j] -= f * akj;
            }
            for j in 0..cols {
                let bkj = b[k * cols + j];
                b[i * cols + j] -= f * bkj;
            }
        }
    }
    for k in (0..n).rev() {
        for j in 0..cols {
            let mut s = b[k * cols + j];
            for i in k + 1..n {
                s -= a[k * n + i] * b[i * cols + j];
            }
            b[k * cols + j] = s / a[k * n + k];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    #[test]
    fn the_blocked_dot_products_are_the_plain_ones() {
        for n in [0, 1, 3, 4, 5, 31, 1000] {
            let column = |k: usize, len: usize| -> Vec<f64> {
                (0..len)
                    .map(|i| (i as f64 * (0.37 + 0.11 * k as f64)).sin() - 0.1 * k as f64)
                    .collect()
            };
            let x: Vec<Vec<f64>> = (0..BLOCK.0).map(|k| column(k, n)).collect();
            // The others may be longer than the first: the products stop where it does.
            let y: Vec<Vec<f64>> = (0..BLOCK.1).map(|k| column(k + 7, n + 3)).collect();
            let x_refs: [&[f64]; BLOCK.0] = std::array::from_fn(|i| &x[i][..]);
            let y_refs: [&[f64]; BLOCK.1] = std::array::from_fn(|j| &y[j][..]);
            let portable = dots_portable(x_refs, y_refs);
            for (path, block) in [("dispatched", dots(x_refs, y_refs)), ("portable", portable)] {
                for i in 0..BLOCK.0 {
                    for j in 0..BLOCK.1 {
                        let plain: f64 = x[i].iter().zip(&y[j]).map(|(a, b)| a * b).sum();
                        let scale: f64 = x[i].iter().zip(&y[j]).map(|(a, b)| (a * b).abs()).sum();
                        assert!(
                            (block[i][j] - plain).abs() <= 1e-14 * scale.max(1.0),
                            "{path}, length {n}, product {i} {j}: {} vs {plain}",
                            block[i][j]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn hermitian_eigenpairs_satisfy_the_equation() {
        let n = 5;
        let mut a = vec![c(0.0, 0.0); n * n];
        for i in 0..n {
            for j in i..n {
                let v = if i == j {
                    c(1.0 + i as f64, 0.0)
                } else {
                    c(0.3 * (i + 2 * j) as f64 % 1.1, 0.2 * (i as f64 - j as f64))
                };
                a[i * n + j] = v;
                a[j * n + i] = v.conj();
            }
        }
        let original = a.clone();
        let (values, vectors) = hermitian_eigen(&mut a, n);
        assert!(values.windows(2).all(|w| w[0] >= w[1]), "{values:?}");
        for k in 0..n {
            for i in 0..n {
                let av: Complex64 = (0..n)
                    .map(|j| original[i * n + j] * vectors[j * n + k])
                    .sum();
                let lv = values[k] * vectors[i * n + k];
                assert!((av - lv).norm() < 1e-10, "pair {k} row {i}: {av} vs {lv}");
            }
        }
    }

    #[test]
    fn eigenvalues_of_a_similar_matrix_are_recovered() {
        // A = S diag(l) S^-1 with a non-unitary S.
        let n = 4;
        let l = [c(0.9, 0.1), c(0.5, -0.7), c(-0.3, 0.2), c(0.95, 0.12)];
        let s = [
            [c(1.0, 0.0), c(0.2, 0.1), c(0.0, 0.3), c(0.5, 0.0)],
            [c(0.1, 0.0), c(1.0, 0.5), c(0.3, 0.0), c(0.0, 0.2)],
            [c(0.0, 0.4), c(0.2, 0.0), c(1.0, 0.0), c(0.1, 0.1)],
            [c(0.3, 0.0), c(0.0, 0.1), c(0.2, 0.2), c(1.0, -0.3)],
        ];
        let mut s_flat: Vec<Complex64> = s.iter().flatten().copied().collect();
        let mut inv = identity(n);
        solve(&mut s_flat, &mut inv, n, n);
        let mut a = vec![c(0.0, 0.0); n * n];
        for i in 0..n {
            for j in 0..n {
                a[i * n + j] = (0..n).map(|k| s[i][k] * l[k] * inv[k * n + j]).sum();
            }
        }
        let found = eigenvalues(&mut a, n);
        for want in l {
            let nearest = found
                .iter()
                .map(|f| (f - want).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(nearest < 1e-9, "{want}: found {found:?}");
        }
    }
}
