//! Coefficients for many modes at once, for control-rate updates during pitch and damping sweeps.
//!
//! [`ModeCoeffs::from_angle_radius`] costs three libm calls per mode; a bend on a chord of large
//! banks recomputes tens of thousands of modes per control tick. Here the same formula runs over
//! arrays with polynomials the compiler vectorises (and with AVX2 when the CPU has it). Angles are
//! at most `2 pi MAX_FREQ_RATIO` (the caller clamps them), so no range reduction is needed; the
//! Taylor series below are accurate to about 1e-13 there, far below the final rounding to `f32`.

use super::coeffs::ModeCoeffs;

/// Above this `delta` (radius `exp(-delta)` below 0.6: a mode that loses 40% of its amplitude
/// per sample) the exponential's series is not used; such modes take the scalar path.
const SERIES_DELTA_MAX: f64 = 0.5;

/// `sin(h)` for `|h| <= pi / 2`: Taylor series to `h^15`.
#[inline(always)]
pub(crate) fn sin_series(h: f64) -> f64 {
    let h2 = h * h;
    let mut p = 1.0 / 1_307_674_368_000.0; // 1/15!
    p = p * -h2 + 1.0 / 6_227_020_800.0; // 1/13!
    p = p * -h2 + 1.0 / 39_916_800.0; // 1/11!
    p = p * -h2 + 1.0 / 362_880.0; // 1/9!
    p = p * -h2 + 1.0 / 5_040.0; // 1/7!
    p = p * -h2 + 1.0 / 120.0; // 1/5!
    p = p * -h2 + 1.0 / 6.0; // 1/3!
    p = p * -h2 + 1.0;
    p * h
}

/// `cos(h)` for `|h| <= pi / 2`: Taylor series to `h^16`.
#[inline(always)]
pub(crate) fn cos_series(h: f64) -> f64 {
    let h2 = h * h;
    let mut p = 1.0 / 20_922_789_888_000.0; // 1/16!
    p = p * -h2 + 1.0 / 87_178_291_200.0; // 1/14!
    p = p * -h2 + 1.0 / 479_001_600.0; // 1/12!
    p = p * -h2 + 1.0 / 3_628_800.0; // 1/10!
    p = p * -h2 + 1.0 / 40_320.0; // 1/8!
    p = p * -h2 + 1.0 / 720.0; // 1/6!
    p = p * -h2 + 1.0 / 24.0; // 1/4!
    p = p * -h2 + 0.5; // 1/2!
    p * -h2 + 1.0
}

/// `exp(-d) - 1` for `|d| <= 0.5`, with full relative precision near 0: Taylor series to `d^14`.
#[inline(always)]
fn expm1_neg_series(d: f64) -> f64 {
    let x = -d;
    let mut p = 1.0;
    let mut k = 14.0;
    while k > 1.0 {
        p = 1.0 + x / k * p;
        k -= 1.0;
    }
    x * p
}

#[inline(always)]
fn batch(theta: &[f64], delta: &[f64], q_re: &mut [f32], q_im: &mut [f32]) {
    for (((&t, &d), qr), qi) in theta
        .iter()
        .zip(delta)
        .zip(q_re.iter_mut())
        .zip(q_im.iter_mut())
    {
        let em1 = expm1_neg_series(d.clamp(-SERIES_DELTA_MAX, SERIES_DELTA_MAX));
        let (s, c) = (sin_series(0.5 * t), cos_series(0.5 * t));
        let two_s2 = 2.0 * s * s;
        *qr = (em1 * (1.0 - two_s2) - two_s2) as f32;
        *qi = ((1.0 + em1) * (2.0 * s * c)) as f32;
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn batch_avx2(theta: &[f64], delta: &[f64], q_re: &mut [f32], q_im: &mut [f32]) {
    batch(theta, delta, q_re, q_im)
}

/// Sets `q_re[i], q_im[i]` to [`ModeCoeffs::from_angle_radius`]`(theta[i], delta[i])` for every
/// `i` (within about one `f32` rounding). `theta` must lie in `0..=2 pi MAX_FREQ_RATIO`; `delta`
/// may be negative (a growing pole, as a mode fading in has). `(0, 0)` gives exactly `(0, 0)`.
pub fn coeffs_batch(theta: &[f64], delta: &[f64], q_re: &mut [f32], q_im: &mut [f32]) {
    let n = theta.len();
    assert!(
        delta.len() == n && q_re.len() == n && q_im.len() == n,
        "coefficient slices differ in length"
    );
    #[cfg(target_arch = "x86_64")]
    {
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA.
            unsafe { batch_avx2(theta, delta, q_re, q_im) };
        } else {
            batch(theta, delta, q_re, q_im);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    batch(theta, delta, q_re, q_im);
    for i in 0..n {
        if delta[i].abs() > SERIES_DELTA_MAX {
            let c = ModeCoeffs::from_angle_radius(theta[i], delta[i]);
            q_re[i] = c.q_re;
            q_im[i] = c.q_im;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bank::format::MAX_FREQ_RATIO;

    #[test]
    fn batch_matches_the_scalar_formula() {
        let theta_max = std::f64::consts::TAU * MAX_FREQ_RATIO;
        let mut theta = Vec::new();
        let mut delta = Vec::new();
        for i in 0..=400 {
            for &d in &[
                0.0, 1e-8, 3e-6, 1e-4, 0.01, 0.3, 0.5, 0.7, 5.0, -1e-6, -0.03, -0.5, -0.9,
            ] {
                theta.push(theta_max * (i as f64 / 400.0).powi(3));
                delta.push(d);
            }
        }
        let n = theta.len();
        let (mut q_re, mut q_im) = (vec![0.0; n], vec![0.0; n]);
        coeffs_batch(&theta, &delta, &mut q_re, &mut q_im);
        for i in 0..n {
            let want = ModeCoeffs::from_angle_radius(theta[i], delta[i]);
            let close = |a: f32, b: f32| (a - b).abs() <= 2.5e-7 * b.abs() || (a - b).abs() < 1e-30;
            assert!(
                close(q_re[i], want.q_re) && close(q_im[i], want.q_im),
                "theta {} delta {}: batch ({}, {}), scalar ({}, {})",
                theta[i],
                delta[i],
                q_re[i],
                q_im[i],
                want.q_re,
                want.q_im
            );
        }
        assert_eq!((q_re[0], q_im[0]), (0.0, 0.0));
    }
}
