//! Bessel functions of the first kind of integer order, ordinary and modified, and their zeros.
//!
//! `J_0 .. J_n` at one argument come from Miller's backward recurrence
//! `J_(k-1)(x) = (2k / x) J_k(x) - J_(k+1)(x)`, normalised with `J_0 + 2 sum J_(2k) = 1`
//! (Abramowitz & Stegun 9.1.27 and 9.1.87; the algorithm as in *Numerical Recipes*, `bessj`).
//! Started well above both the order and the argument, the recurrence runs in the direction in
//! which `J` is the dominant solution, so it stays accurate for any argument, where the power
//! series loses every digit to cancellation once `x` passes about 20.
//!
//! The modified functions `I_0 .. I_n` come from the same recurrence with a plus sign,
//! `I_(k-1)(x) = (2k / x) I_k(x) + I_(k+1)(x)`, normalised with `I_0 + 2 sum I_k = e^x`
//! (A&S 9.6.26 and 9.6.37; *Numerical Recipes*, `bessi`). They grow like `e^x`, so they are
//! returned scaled by `e^-x`, which keeps plate mode shapes finite at any frequency.

/// Relative size beyond which the recurrence rescales its values to stay inside f64.
const RESCALE_ABOVE: f64 = 1e200;

/// Step of the sign-change scan for zeros. Consecutive zeros of `J_m` are more than 3 apart, so
/// a step of 0.5 cannot step over two of them.
const ZERO_SCAN_STEP: f64 = 0.5;

/// `[J_0(x), J_1(x), ..., J_order_max(x)]`.
pub fn bessel_j_upto(order_max: usize, x: f64) -> Vec<f64> {
    let mut out = vec![0.0; order_max + 1];
    if x == 0.0 {
        out[0] = 1.0;
        return out;
    }
    let ax = x.abs();
    // Start far enough above both the order and the argument that the start values do not
    // matter: past k = x, J_k falls faster than exponentially.
    let top_f = (order_max as f64).max(ax);
    let mut start = top_f.ceil() as usize + 20 + (40.0 * top_f).sqrt().ceil() as usize;
    start += start % 2; // even, so the normalisation sum ends on J_0.

    let mut j_above = 0.0; // J_(k+1)
    let mut j_here = 1e-30; // J_k, arbitrary small start
    let mut norm_sum = 0.0; // J_0 + 2 (J_2 + J_4 + ...) in the current scale
    for k in (1..=start).rev() {
        // The even terms of the normalisation, taken at k as it is reached.
        if k % 2 == 0 {
            norm_sum += 2.0 * j_here;
        }
        if k <= order_max {
            out[k] = j_here;
        }
        let j_below = 2.0 * k as f64 / ax * j_here - j_above;
        j_above = j_here;
        j_here = j_below;
        if j_here.abs() > RESCALE_ABOVE {
            let scale = 1.0 / RESCALE_ABOVE;
            j_here *= scale;
            j_above *= scale;
            norm_sum *= scale;
            for value in out.iter_mut() {
                *value *= scale;
            }
        }
    }
    out[0] = j_here;
    norm_sum += j_here;
    for value in out.iter_mut() {
        *value /= norm_sum;
    }
    // J_k(-x) = (-1)^k J_k(x).
    if x < 0.0 {
        for (k, value) in out.iter_mut().enumerate() {
            if k % 2 == 1 {
                *value = -*value;
            }
        }
    }
    out
}

/// `J_order(x)`.
pub fn bessel_j(order: usize, x: f64) -> f64 {
    bessel_j_upto(order, x)[order]
}

/// `[I_0(x), I_1(x), ..., I_order_max(x)]` times `e^-x`, for `x >= 0`.
pub fn bessel_i_scaled_upto(order_max: usize, x: f64) -> Vec<f64> {
    debug_assert!(x >= 0.0);
    let mut out = vec![0.0; order_max + 1];
    if x == 0.0 {
        out[0] = 1.0;
        return out;
    }
    let top_f = (order_max as f64).max(x);
    let start = top_f.ceil() as usize + 20 + (40.0 * top_f).sqrt().ceil() as usize;

    let mut i_above = 0.0; // I_(k+1)
    let mut i_here = 1e-30; // I_k, arbitrary small start
    let mut norm_sum = 0.0; // I_0 + 2 (I_1 + I_2 + ...) in the current scale
    for k in (1..=start).rev() {
        norm_sum += 2.0 * i_here;
        if k <= order_max {
            out[k] = i_here;
        }
        let i_below = 2.0 * k as f64 / x * i_here + i_above;
        i_above = i_here;
        i_here = i_below;
        if i_here > RESCALE_ABOVE {
            let scale = 1.0 / RESCALE_ABOVE;
            i_here *= scale;
            i_above *= scale;
            norm_sum *= scale;
            for value in out.iter_mut() {
                *value *= scale;
            }
        }
    }
    out[0] = i_here;
    norm_sum += i_here;
    // norm_sum stands for e^x: dividing by it gives e^-x I_k.
    for value in out.iter_mut() {
        *value /= norm_sum;
    }
    out
}

/// The roots of `f` in `(from, to]`, ascending, found where `f` changes sign between samples
/// `step` apart and refined by bisection to the resolution of f64. Roots closer together than
/// `step` may be missed: callers choose `step` below the spacing of the roots they seek.
pub fn roots_by_scan(f: impl Fn(f64) -> f64, from: f64, to: f64, step: f64) -> Vec<f64> {
    let mut roots = Vec::new();
    let mut a = from;
    let mut fa = f(a);
    while a < to {
        let b = (a + step).min(to);
        let fb = f(b);
        if fb == 0.0 {
            roots.push(b);
        } else if fa != 0.0 && fa.signum() != fb.signum() {
            let (mut lo, mut flo, mut hi) = (a, fa, b);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break;
                }
                let fm = f(mid);
                if fm == 0.0 {
                    lo = mid;
                    hi = mid;
                    break;
                }
                if fm.signum() == flo.signum() {
                    lo = mid;
                    flo = fm;
                } else {
                    hi = mid;
                }
            }
            roots.push(0.5 * (lo + hi));
        }
        a = b;
        fa = fb;
    }
    roots
}

/// The positive zeros of `J_order` below `x_max`, ascending.
pub fn bessel_zeros_below(order: usize, x_max: f64) -> Vec<f64> {
    let mut zeros = Vec::new();
    // J_m is positive on (0, j_m1) and j_m1 > m: start there (at the origin for m = 0).
    let mut a = order as f64;
    let mut fa = if order == 0 { 1.0 } else { bessel_j(order, a) };
    while a < x_max {
        let b = (a + ZERO_SCAN_STEP).min(x_max);
        let fb = bessel_j(order, b);
        if fb == 0.0 {
            zeros.push(b);
        } else if fa.signum() != fb.signum() && fa != 0.0 {
            zeros.push(refine_zero(order, a, fa, b));
        }
        a = b;
        fa = fb;
    }
    zeros
}

/// Bisection of a bracketed zero of `J_order` to the resolution of f64.
fn refine_zero(order: usize, mut a: f64, mut fa: f64, mut b: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (a + b);
        if mid <= a || mid >= b {
            break;
        }
        let fm = bessel_j(order, mid);
        if fm == 0.0 {
            return mid;
        }
        if fm.signum() == fa.signum() {
            a = mid;
            fa = fm;
        } else {
            b = mid;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: Bessel's integral `J_m(x) = (1/2pi) int_0^2pi cos(m t - x sin t) dt`. The
    /// integrand is periodic and analytic, so the trapezoid rule converges geometrically; with
    /// more points than `x + m + 40` it is exact to rounding.
    fn bessel_j_integral(order: usize, x: f64) -> f64 {
        let points = (x.abs() + order as f64) as usize * 2 + 64;
        let sum: f64 = (0..points)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / points as f64;
                (order as f64 * t - x * t.sin()).cos()
            })
            .sum();
        sum / points as f64
    }

    #[test]
    fn matches_the_integral_representation() {
        for &x in &[
            1e-3,
            0.1,
            0.5,
            1.0,
            2.404825557695773,
            5.0,
            10.0,
            25.0,
            40.0,
            77.7,
            -3.5,
        ] {
            let all = bessel_j_upto(45, x);
            for (order, &value) in all.iter().enumerate() {
                let expected = bessel_j_integral(order, x);
                assert!(
                    (value - expected).abs() < 1e-12,
                    "J_{order}({x}) = {value}, integral gives {expected}"
                );
            }
        }
    }

    /// Oracle: `e^-x I_m(x) = (1/pi) int_0^pi exp(x (cos t - 1)) cos(m t) dt` (A&S 9.6.19),
    /// by the trapezoid rule over the whole period, which is exact to rounding for this periodic
    /// analytic integrand with enough points.
    fn bessel_i_scaled_integral(order: usize, x: f64) -> f64 {
        let points = (x.abs() + order as f64) as usize * 4 + 200;
        let sum: f64 = (0..points)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / points as f64;
                (x * (t.cos() - 1.0)).exp() * (order as f64 * t).cos()
            })
            .sum();
        sum / points as f64
    }

    #[test]
    fn modified_functions_match_the_integral_representation() {
        for &x in &[1e-3, 0.1, 1.0, 3.2, 10.0, 25.0, 60.0, 150.0] {
            let all = bessel_i_scaled_upto(40, x);
            for (order, &value) in all.iter().enumerate() {
                let expected = bessel_i_scaled_integral(order, x);
                assert!(
                    (value - expected).abs() < 1e-13,
                    "e^-x I_{order}({x}) = {value}, integral gives {expected}"
                );
            }
        }
        // A&S table 9.8: I_0(1) = 1.266065878, I_1(1) = 0.565159104.
        let at_1 = bessel_i_scaled_upto(1, 1.0);
        let e = std::f64::consts::E;
        assert!((at_1[0] * e - 1.266_065_877_752_008_4).abs() < 1e-14);
        assert!((at_1[1] * e - 0.565_159_103_992_485_1).abs() < 1e-14);
        assert_eq!(bessel_i_scaled_upto(2, 0.0), vec![1.0, 0.0, 0.0]);
    }

    #[test]
    fn scanning_finds_the_roots_of_sine() {
        let roots = roots_by_scan(f64::sin, 0.5, 10.0, 0.3);
        assert_eq!(roots.len(), 3, "{roots:?}");
        for (k, root) in roots.iter().enumerate() {
            let want = std::f64::consts::PI * (k + 1) as f64;
            assert!((root - want).abs() < 1e-12, "{root} vs {want}");
        }
    }

    #[test]
    fn known_values() {
        // Abramowitz & Stegun table 9.1.
        assert!((bessel_j(0, 1.0) - 0.765_197_686_557_966_6).abs() < 1e-14);
        assert!((bessel_j(1, 1.0) - 0.440_050_585_744_933_5).abs() < 1e-14);
        assert!((bessel_j(2, 10.0) - 0.254_630_313_685_120_7).abs() < 1e-13);
        assert_eq!(bessel_j(0, 0.0), 1.0);
        assert_eq!(bessel_j(3, 0.0), 0.0);
    }

    #[test]
    fn zeros_match_tables() {
        // Abramowitz & Stegun table 9.5.
        let expected: [(usize, &[f64]); 4] = [
            (
                0,
                &[
                    2.404_825_557_695_773,
                    5.520_078_110_286_311,
                    8.653_727_912_911_012,
                ],
            ),
            (
                1,
                &[
                    3.831_705_970_207_512,
                    7.015_586_669_815_619,
                    10.173_468_135_062_72,
                ],
            ),
            (2, &[5.135_622_301_840_683, 8.417_244_140_399_865]),
            (10, &[14.475_500_686_554_54]),
        ];
        for (order, table) in expected {
            let zeros = bessel_zeros_below(order, table.last().unwrap() + 0.1);
            assert_eq!(zeros.len(), table.len(), "zeros of J_{order}: {zeros:?}");
            for (found, want) in zeros.iter().zip(table) {
                assert!((found - want).abs() < 1e-11, "J_{order}: {found} vs {want}");
            }
        }
    }

    #[test]
    fn zeros_are_simple_and_spaced() {
        for order in 0..30 {
            let zeros = bessel_zeros_below(order, 80.0);
            assert!(!zeros.is_empty() || order as f64 > 75.0);
            for pair in zeros.windows(2) {
                assert!(pair[1] - pair[0] > 2.9, "J_{order}: {pair:?}");
            }
            for &z in &zeros {
                assert!(bessel_j(order, z).abs() < 1e-13, "J_{order}({z})");
            }
        }
    }
}
