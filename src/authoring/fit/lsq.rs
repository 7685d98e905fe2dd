//! Amplitudes and phases of all modes at once, by linear least squares, given their frequencies
//! and decays.
//!
//! With `z_m = exp((-d_m + i w_m) / fs)` fixed, the model `x[n] = sum_m Re(c_m z_m^n)` is linear
//! in the complex amplitudes `c_m`: each mode contributes the two real columns
//! `|z_m|^n cos(w_m n)` and `|z_m|^n sin(w_m n)`. Their inner products are geometric series with a
//! closed form, so the normal equations cost `O(M^2)` to build and the projections of the signal
//! `O(N M)`. Solving them jointly accounts for the overlap of modes closer than a bin, which a
//! mode-by-mode estimate cannot.

use std::f64::consts::TAU;

use realfft::num_complex::Complex64;

/// A mode's shape over time: what the least squares holds fixed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shape {
    /// Frequency in Hz.
    pub freq_hz: f64,
    /// Decay rate in 1/s.
    pub decay_per_s: f64,
}

impl Shape {
    /// `z = exp((-d + i w) / fs)`, the factor by which the mode's phasor moves each sample.
    fn pole(&self, sample_rate_hz: f64) -> Complex64 {
        Complex64::from_polar(
            (-self.decay_per_s / sample_rate_hz).exp(),
            TAU * self.freq_hz / sample_rate_hz,
        )
    }
}

/// Samples after which a phasor running by repeated multiplication is recomputed exactly.
const RESYNC: usize = 1024;

/// Relative ridge added to the normal equations: keeps them solvable when two modes nearly
/// coincide, far below anything a real signal resolves.
const RIDGE: f64 = 1e-10;

/// `z^n` for `n` in `range`, passed to `f` with `n`.
fn for_each_power(
    z: Complex64,
    range: std::ops::Range<usize>,
    mut f: impl FnMut(usize, Complex64),
) {
    let (r, theta) = (z.norm(), z.arg());
    let exact = |n: usize| Complex64::from_polar(r.powf(n as f64), theta * n as f64);
    let mut p = exact(range.start);
    for n in range {
        if n % RESYNC == 0 {
            p = exact(n);
        }
        f(n, p);
        p *= z;
    }
}

/// The complex amplitudes `c_m` minimising `sum (x[n] - sum_m Re(c_m z_m^n))^2` over
/// `n` in `start..x.len()`, time 0 at `x[0]`. The mode's envelope amplitude at time 0 is `|c_m|`;
/// a mode in sine phase at time 0, `a sin(w t)`, has `c = -i a`.
pub fn fit_amplitudes(
    x: &[f64],
    sample_rate_hz: f64,
    start: usize,
    shapes: &[Shape],
) -> Vec<Complex64> {
    let m = shapes.len();
    if m == 0 || start >= x.len() {
        return vec![Complex64::new(0.0, 0.0); m];
    }
    let poles: Vec<Complex64> = shapes.iter().map(|s| s.pole(sample_rate_hz)).collect();
    let (n0, n1) = (start, x.len());
    // Columns 2m (cosine) and 2m + 1 (sine) of mode m.
    let dim = 2 * m;
    let mut gram = vec![0.0; dim * dim];
    for a in 0..m {
        for b in a..m {
            let d = poles[a].norm() * poles[b].norm();
            let (wa, wb) = (poles[a].arg(), poles[b].arg());
            let diff = geometric_sum(Complex64::from_polar(d, wa - wb), n0, n1);
            let sum = geometric_sum(Complex64::from_polar(d, wa + wb), n0, n1);
            let uu = 0.5 * (diff.re + sum.re);
            let uv = 0.5 * (sum.im - diff.im);
            let vu = 0.5 * (sum.im + diff.im);
            let vv = 0.5 * (diff.re - sum.re);
            let entries = [(0, 0, uu), (0, 1, uv), (1, 0, vu), (1, 1, vv)];
            for (i, j, v) in entries {
                gram[(2 * a + i) * dim + 2 * b + j] = v;
                gram[(2 * b + j) * dim + 2 * a + i] = v;
            }
        }
    }
    let mut rhs = vec![0.0; dim];
    for (k, &z) in poles.iter().enumerate() {
        let (mut cu, mut cv) = (0.0, 0.0);
        for_each_power(z, n0..n1, |n, p| {
            cu += x[n] * p.re;
            cv += x[n] * p.im;
        });
        rhs[2 * k] = cu;
        rhs[2 * k + 1] = cv;
    }
    let solution = solve_spd(&mut gram, &rhs, dim);
    (0..m)
        .map(|k| Complex64::new(solution[2 * k], -solution[2 * k + 1]))
        .collect()
}

/// Modes synthesised side by side by [`add_modes`]: their phasors advance in lanes that
/// vectorise, each independent of the others.
const SYNTH_LANES: usize = 8;

/// Adds `sum_m Re(c_m z_m^n)` for `n` in `0..out.len()` to `out`.
pub fn add_modes(out: &mut [f64], sample_rate_hz: f64, shapes: &[Shape], amplitudes: &[Complex64]) {
    #[cfg(target_arch = "x86_64")]
    {
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA.
            unsafe { add_modes_avx2(out, sample_rate_hz, shapes, amplitudes) };
            return;
        }
    }
    add_modes_portable(out, sample_rate_hz, shapes, amplitudes);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn add_modes_avx2(
    out: &mut [f64],
    sample_rate_hz: f64,
    shapes: &[Shape],
    amplitudes: &[Complex64],
) {
    add_modes_portable(out, sample_rate_hz, shapes, amplitudes);
}

/// [`SYNTH_LANES`] modes at a time, each phasor `c z^n` recomputed exactly every [`RESYNC`]
/// samples.
#[inline(always)]
fn add_modes_portable(
    out: &mut [f64],
    sample_rate_hz: f64,
    shapes: &[Shape],
    amplitudes: &[Complex64],
) {
    const L: usize = SYNTH_LANES;
    for (shapes, amplitudes) in shapes.chunks(L).zip(amplitudes.chunks(L)) {
        // Lanes past the last mode hold a phasor of 0.
        let (mut z_re, mut z_im) = ([0.0; L], [0.0; L]);
        let (mut p_re, mut p_im) = ([0.0; L], [0.0; L]);
        let poles: Vec<Complex64> = shapes.iter().map(|s| s.pole(sample_rate_hz)).collect();
        for (l, z) in poles.iter().enumerate() {
            (z_re[l], z_im[l]) = (z.re, z.im);
        }
        for (block, samples) in out.chunks_mut(RESYNC).enumerate() {
            let n = (block * RESYNC) as f64;
            for (l, (z, c)) in poles.iter().zip(amplitudes).enumerate() {
                let p = c * Complex64::from_polar(z.norm().powf(n), z.arg() * n);
                (p_re[l], p_im[l]) = (p.re, p.im);
            }
            for o in samples {
                let mut sum = 0.0;
                for l in 0..L {
                    sum += p_re[l];
                    let re = p_re[l] * z_re[l] - p_im[l] * z_im[l];
                    p_im[l] = p_re[l] * z_im[l] + p_im[l] * z_re[l];
                    p_re[l] = re;
                }
                *o += sum;
            }
        }
    }
}

/// `sum_{n = n0}^{n1 - 1} r^n` in closed form.
fn geometric_sum(r: Complex64, n0: usize, n1: usize) -> Complex64 {
    let count = (n1 - n0) as f64;
    let one_minus = Complex64::new(1.0, 0.0) - r;
    let power = |n: usize| Complex64::from_polar(r.norm().powf(n as f64), r.arg() * n as f64);
    if one_minus.norm() * count < 1e-6 {
        // r is within rounding of 1: the series is the count, to first order in (r - 1).
        return power(n0) * count;
    }
    (power(n0) - power(n1)) / one_minus
}

/// Solves `A p = b` for the symmetric positive semi-definite `A` (`dim` x `dim`, row-major,
/// overwritten) by Cholesky with a small ridge; grows the ridge if rounding leaves `A`
/// indefinite.
fn solve_spd(a: &mut [f64], b: &[f64], dim: usize) -> Vec<f64> {
    let scale = (0..dim)
        .map(|i| a[i * dim + i])
        .fold(0.0, f64::max)
        .max(1e-300);
    let original = a.to_vec();
    let mut ridge = RIDGE;
    loop {
        a.copy_from_slice(&original);
        for i in 0..dim {
            a[i * dim + i] += ridge * scale;
        }
        if cholesky(a, dim) {
            break;
        }
        ridge *= 100.0;
    }
    // Forward then back substitution with the lower factor L (A = L L^T).
    let mut y = b.to_vec();
    for i in 0..dim {
        let s: f64 = (0..i).map(|k| a[i * dim + k] * y[k]).sum();
        y[i] = (y[i] - s) / a[i * dim + i];
    }
    for i in (0..dim).rev() {
        let s: f64 = (i + 1..dim).map(|k| a[k * dim + i] * y[k]).sum();
        y[i] = (y[i] - s) / a[i * dim + i];
    }
    y
}

/// In-place Cholesky factorisation: the lower triangle of `a` becomes L. False if `a` is not
/// positive definite.
fn cholesky(a: &mut [f64], dim: usize) -> bool {
    for j in 0..dim {
        let s: f64 = (0..j).map(|k| a[j * dim + k] * a[j * dim + k]).sum();
        let d = a[j * dim + j] - s;
        if d <= 0.0 || !d.is_finite() {
            return false;
        }
        let d = d.sqrt();
        a[j * dim + j] = d;
        for i in j + 1..dim {
            let s: f64 = (0..j).map(|k| a[i * dim + k] * a[j * dim + k]).sum();
            a[i * dim + j] = (a[i * dim + j] - s) / d;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn separates_two_modes_closer_than_a_bin() {
        let rate = 48_000.0;
        let shapes = [
            Shape {
                freq_hz: 1000.0,
                decay_per_s: 3.0,
            },
            Shape {
                freq_hz: 1004.0,
                decay_per_s: 5.0,
            },
            Shape {
                freq_hz: 2500.0,
                decay_per_s: 0.0,
            },
        ];
        let truth = [
            Complex64::new(0.0, -0.5),
            Complex64::from_polar(0.2, 1.0),
            Complex64::new(0.01, 0.0),
        ];
        let mut x = vec![0.0; 24_000];
        add_modes(&mut x, rate, &shapes, &truth);
        // The sine-phase convention: the first mode is 0.5 sin(w t).
        let expected = 0.5 * (-3.0 / rate).exp() * (TAU * 1000.0 / rate).sin();
        assert!(
            (x[1]
                - expected
                - (truth[1] * shapes[1].pole(rate)).re
                - 0.01 * (TAU * 2500.0 / rate).cos())
            .abs()
                < 1e-12
        );
        let found = fit_amplitudes(&x, rate, 10, &shapes);
        for (i, (f, t)) in found.iter().zip(&truth).enumerate() {
            assert!((f - t).norm() < 1e-8, "mode {i}: found {f}, expected {t}");
        }
    }

    #[test]
    fn synthesis_in_lanes_is_the_sum_of_exact_modes() {
        // More modes than one set of lanes holds and more samples than one block between exact
        // recomputations, on top of what the output held.
        let rate = 44_100.0;
        let shapes: Vec<Shape> = (0..11)
            .map(|m| Shape {
                freq_hz: 97.0 + 1234.5 * m as f64,
                decay_per_s: 0.5 + 7.0 * m as f64,
            })
            .collect();
        let amplitudes: Vec<Complex64> = (0..11)
            .map(|m| Complex64::from_polar(1.0 / (m + 1) as f64, 0.7 * m as f64))
            .collect();
        let len = 2 * RESYNC + 77;
        let exact = |n: usize| -> f64 {
            let t = n as f64 / rate;
            0.25 + shapes
                .iter()
                .zip(&amplitudes)
                .map(|(s, c)| {
                    let phasor = Complex64::new(-s.decay_per_s, TAU * s.freq_hz) * t;
                    (c * phasor.exp()).re
                })
                .sum::<f64>()
        };
        let mut dispatched = vec![0.25; len];
        add_modes(&mut dispatched, rate, &shapes, &amplitudes);
        let mut portable = vec![0.25; len];
        add_modes_portable(&mut portable, rate, &shapes, &amplitudes);
        for n in 0..len {
            for (path, x) in [("dispatched", &dispatched), ("portable", &portable)] {
                assert!(
                    (x[n] - exact(n)).abs() < 1e-10,
                    "{path}, sample {n}: {} vs {}",
                    x[n],
                    exact(n)
                );
            }
        }
    }

    #[test]
    fn geometric_sums_match_direct_sums() {
        for r in [
            Complex64::from_polar(0.9999, 0.3),
            Complex64::from_polar(1.0, 0.0),
            Complex64::from_polar(0.99, 2.0),
        ] {
            let direct: Complex64 = (5..500).map(|n| r.powu(n as u32)).sum();
            let closed = geometric_sum(r, 5, 500);
            assert!(
                (direct - closed).norm() < 1e-9 * direct.norm().max(1.0),
                "{r}: {direct} vs {closed}"
            );
        }
    }
}
