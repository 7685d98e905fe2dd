//! The arithmetic of a strike taken analytically, for every dormant record of a bank at once.
//!
//! Each record's state is brought to the strike (an exponential for its decay, a sine and cosine
//! for its phase), the pulse's contribution is added and the new power is read in dB. The
//! records' numbers are gathered into arrays, and all of it runs over them as branch-free
//! polynomials the compiler vectorises (with AVX2 when the CPU has it): the sine and cosine
//! series of [`super::dormant::Dormant::state`], and [`exp_series`] for the decay.

use std::f64::consts::PI;

use crate::dsp::coeffs_batch::{cos_series, sin_series};
use crate::dsp::masking::power_to_db;

/// The numbers of the records a strike brings up to date, structure-of-arrays. Sized once;
/// nothing allocates while playing.
#[derive(Debug, Clone, Default)]
pub(super) struct AbsorbScratch {
    /// Phase turned since each record's snapshot, radians in `0..2 pi`.
    pub phase: Vec<f64>,
    /// Nepers of amplitude gained since the snapshot (never positive).
    pub log_gain: Vec<f64>,
    /// Real part of the snapshot.
    pub re: Vec<f32>,
    /// Imaginary part of the snapshot.
    pub im: Vec<f32>,
    /// Real part of what the pulse adds, referred to the strike.
    pub add_re: Vec<f64>,
    /// Imaginary part of what the pulse adds.
    pub add_im: Vec<f64>,
    /// The record each entry came from.
    pub record: Vec<u32>,
    /// Records to be woken rather than take the strike, in ascending order.
    pub waking: Vec<u32>,
    /// The new state, real part.
    pub out_re: Vec<f32>,
    /// The new state, imaginary part.
    pub out_im: Vec<f32>,
    /// The new power in dB.
    pub out_db: Vec<f32>,
}

impl AbsorbScratch {
    /// Room for `n` records. Allocates.
    pub fn new(n: usize) -> Self {
        Self {
            phase: vec![0.0; n],
            log_gain: vec![0.0; n],
            re: vec![0.0; n],
            im: vec![0.0; n],
            add_re: vec![0.0; n],
            add_im: vec![0.0; n],
            record: vec![0; n],
            waking: vec![0; n],
            out_re: vec![0.0; n],
            out_im: vec![0.0; n],
            out_db: vec![0.0; n],
        }
    }

    /// Works out the new state and power of the first `n` entries.
    pub fn run(&mut self, n: usize) {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
                // SAFETY: the CPU supports AVX2 and FMA.
                unsafe { run_avx2(self, n) };
                return;
            }
        }
        run(self, n);
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn run_avx2(s: &mut AbsorbScratch, n: usize) {
    run(s, n)
}

/// The state `g (re + i im) e^(i phase) + add`, with `g = e^log_gain`: what
/// [`super::dormant::Dormant::state`] gives, rounded to `f32` as there, plus the pulse (`g`
/// from [`exp_series`], within a unit in the last place of `f64::exp`).
#[inline(always)]
fn run(s: &mut AbsorbScratch, n: usize) {
    let (phase, log_gain) = (&s.phase[..n], &s.log_gain[..n]);
    let (re, im) = (&s.re[..n], &s.im[..n]);
    let (add_re, add_im) = (&s.add_re[..n], &s.add_im[..n]);
    let (out_re, out_im, out_db) = (&mut s.out_re[..n], &mut s.out_im[..n], &mut s.out_db[..n]);
    for k in 0..n {
        // Sine and cosine of the phase from its half-angle about pi, as `Dormant::state` does.
        let h = 0.5 * (phase[k] - PI);
        let (sh, ch) = (sin_series(h), cos_series(h));
        let (sin, cos) = (-2.0 * sh * ch, 2.0 * sh * sh - 1.0);
        let g = exp_series(log_gain[k]);
        let (r, i) = (re[k] as f64, im[k] as f64);
        let state_re = (g * (r * cos - i * sin)) as f32;
        let state_im = (g * (r * sin + i * cos)) as f32;
        let z_re = (state_re as f64 + add_re[k]) as f32;
        let z_im = (state_im as f64 + add_im[k]) as f32;
        // A pole decaying hundreds of nepers within the pulse overflows the pulse referred back
        // to its start: such a mode is silent by the pulse's end, and is left silent.
        let finite = (z_re * z_re + z_im * z_im).is_finite();
        let (z_re, z_im) = if finite { (z_re, z_im) } else { (0.0, 0.0) };
        out_re[k] = z_re;
        out_im[k] = z_im;
        out_db[k] = power_to_db(z_re * z_re + z_im * z_im);
    }
}

/// `e^x` for `x` clamped to `-700..=700`, to within a few units in the last place: `2^k` (built
/// in the exponent bits) times a Taylor series in the remainder `|r| <= ln 2 / 2`. Branch-free,
/// so it vectorises. Not a number gives not a number.
#[inline(always)]
pub(super) fn exp_series(x: f64) -> f64 {
    // Adding 1.5 * 2^52 rounds to an integer, left in the low bits of the mantissa.
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    // ln 2 in two parts, the first with trailing zero bits so `k * LN2_HI` is exact.
    const LN2_HI: f64 = 0.693_147_180_369_123_8;
    const LN2_LO: f64 = 1.908_214_929_270_587_7e-10;
    let x = x.clamp(-700.0, 700.0);
    let shifted = x * std::f64::consts::LOG2_E + SHIFT;
    let k = shifted - SHIFT;
    let r = (x - k * LN2_HI) - k * LN2_LO;
    // Taylor series to r^12: the next term is below 2e-16 for |r| <= 0.347.
    let mut p = 1.0 / 479_001_600.0;
    p = p * r + 1.0 / 39_916_800.0;
    p = p * r + 1.0 / 3_628_800.0;
    p = p * r + 1.0 / 362_880.0;
    p = p * r + 1.0 / 40_320.0;
    p = p * r + 1.0 / 5_040.0;
    p = p * r + 1.0 / 720.0;
    p = p * r + 1.0 / 120.0;
    p = p * r + 1.0 / 24.0;
    p = p * r + 1.0 / 6.0;
    p = p * r + 0.5;
    p = p * r + 1.0;
    p = p * r + 1.0;
    // 2^k: k + 1023 in the exponent field (k is within -1010..=1010, so it stays in range).
    let scale = f64::from_bits((shifted.to_bits() << 52).wrapping_add(1023 << 52));
    p * scale
}

#[cfg(test)]
mod tests {
    use super::super::dormant::Dormant;
    use super::*;

    #[test]
    fn exp_series_matches_libm() {
        let mut x = -700.0;
        while x <= 700.0 {
            let (got, want) = (exp_series(x), x.exp());
            assert!(
                (got - want).abs() <= 4e-16 * want,
                "exp({x}): {got} against {want}"
            );
            x += 0.173_1;
        }
        for x in [
            0.0,
            -1e-300,
            1e-12,
            -0.346_573_590_279_972_6,
            0.346_573_590_279_972_6,
        ] {
            assert!(
                (exp_series(x) - x.exp()).abs() <= 4e-16 * x.exp(),
                "exp({x})"
            );
        }
        // Clamped, not wrapped round.
        assert_eq!(exp_series(-1e6), (-700.0f64).exp());
        assert!(exp_series(f64::NAN).is_nan());
    }

    #[test]
    fn a_batch_matches_one_record_at_a_time() {
        // The portable loop, and the dispatch (AVX2 where the CPU has it).
        check_batch(run);
        check_batch(|s, n| s.run(n));
    }

    #[test]
    fn a_pulse_too_big_to_refer_back_leaves_the_mode_silent() {
        let dispatch = |s: &mut AbsorbScratch, n: usize| s.run(n);
        for run_batch in [run as fn(&mut AbsorbScratch, usize), dispatch] {
            let mut s = AbsorbScratch::new(4);
            s.re[..4].fill(0.1);
            s.add_re[..4].copy_from_slice(&[1e300, f64::INFINITY, f64::NAN, 0.5]);
            run_batch(&mut s, 4);
            for k in 0..3 {
                assert_eq!((s.out_re[k], s.out_im[k]), (0.0, 0.0), "entry {k}");
                assert_eq!(s.out_db[k], power_to_db(0.0), "entry {k}");
            }
            // At phase 0 the state is the snapshot: 0.1 + 0.5.
            assert!((s.out_re[3] - 0.6).abs() < 1e-6 && s.out_im[3].abs() < 1e-6);
        }
    }

    fn check_batch(run_batch: impl Fn(&mut AbsorbScratch, usize)) {
        let n = 103;
        let mut s = AbsorbScratch::new(n);
        for k in 0..n {
            let t = k as f64 / n as f64;
            s.phase[k] = std::f64::consts::TAU * t;
            s.log_gain[k] = -60.0 * t * t;
            s.re[k] = (0.3 - t) as f32;
            s.im[k] = (0.7 * t) as f32;
            s.add_re[k] = 1e-3 * (k % 7) as f64;
            s.add_im[k] = -2e-4 * (k % 3) as f64;
        }
        run_batch(&mut s, n);
        let mut inexact = 0;
        for k in 0..n {
            // The record's own state, brought to the strike, plus the pulse, rounded as there.
            let d = Dormant {
                re: s.re[k],
                im: s.im[k],
                phase: s.phase[k],
                log_gain: s.log_gain[k],
                ..Dormant::EMPTY
            };
            let (state_re, state_im) = d.state();
            let want_re = (state_re as f64 + s.add_re[k]) as f32;
            let want_im = (state_im as f64 + s.add_im[k]) as f32;
            // The exponentials may differ in the last bit of an f64, which changes an f32 only
            // now and then, and by one unit in its last place.
            inexact += ((s.out_re[k], s.out_im[k]) != (want_re, want_im)) as usize;
            let scale = want_re.hypot(want_im).max(1e-30);
            assert!(
                (s.out_re[k] - want_re).abs() <= 1.2e-7 * scale
                    && (s.out_im[k] - want_im).abs() <= 1.2e-7 * scale,
                "entry {k}: ({}, {}) against ({want_re}, {want_im})",
                s.out_re[k],
                s.out_im[k]
            );
            let want_db = 10.0
                * ((want_re * want_re + want_im * want_im) as f64)
                    .max(1e-30)
                    .log10();
            assert!(
                (s.out_db[k] as f64 - want_db).abs() < 0.01,
                "entry {k}: {} dB against {want_db}",
                s.out_db[k]
            );
        }
        assert!(
            inexact <= 2,
            "{inexact} of {n} states differ from the record's own"
        );
    }
}
