//! The transform of a decaying sinusoid cut off at the end of the sound, bin by bin over a band
//! ([`refine`](super::refine) derives it): the inner loop of the band fit, in structure-of-arrays
//! lanes so that it vectorises, and dispatched to AVX2 with FMA where the CPU has them. The
//! complex form in the tests is the oracle.

use realfft::num_complex::Complex64;

/// The bins of a band where its taper is not zero, as lanes: `w^k`, `w^(k L)` and the taper.
#[derive(Debug, Clone, Default)]
pub struct Lanes {
    /// First bin of the band held.
    pub first: usize,
    /// Real and imaginary parts of `w^k`.
    w_re: Vec<f64>,
    w_im: Vec<f64>,
    /// Real and imaginary parts of `w^(k L)`.
    wl_re: Vec<f64>,
    wl_im: Vec<f64>,
    /// Gain of each bin.
    taper: Vec<f64>,
}

impl Lanes {
    /// The lanes of the bins `twiddles` (`w^k`, `w^(k L)`) tapered by `taper`, from the first
    /// to the last bin whose taper is not zero.
    pub fn new(twiddles: &[(Complex64, Complex64)], taper: &[f64]) -> Self {
        let first = taper.iter().position(|&t| t != 0.0).unwrap_or(0);
        let end = taper.iter().rposition(|&t| t != 0.0).map_or(0, |i| i + 1);
        let range = first..end.max(first);
        Self {
            first,
            w_re: twiddles[range.clone()].iter().map(|w| w.0.re).collect(),
            w_im: twiddles[range.clone()].iter().map(|w| w.0.im).collect(),
            wl_re: twiddles[range.clone()].iter().map(|w| w.1.re).collect(),
            wl_im: twiddles[range.clone()].iter().map(|w| w.1.im).collect(),
            taper: taper[range].to_vec(),
        }
    }

    /// Number of bins held.
    pub fn len(&self) -> usize {
        self.taper.len()
    }
}

/// What one mode's bins depend on besides the bin.
#[derive(Debug, Clone, Copy)]
pub struct Pole {
    /// `e^s`, the pole per sample of the sound.
    pub es: Complex64,
    /// `e^(s L)`, the pole over the whole sound.
    pub esl: Complex64,
    /// The pole's log `s` per sample of the sound.
    pub s: Complex64,
    /// `-i/2 e^(-s tau)` and `i/2 e^(-s* tau)`: the mode's two halves at the strike time.
    pub q: Complex64,
    pub qc: Complex64,
    /// Strike time in samples of the sound.
    pub tau: f64,
    /// Samples of the sound, `L`.
    pub len: f64,
    /// Samples of the sound per sample of the band.
    pub scale: f64,
}

/// Where a mode's bins go, each slice as long as the lanes: `unit` gains the bins for `gain`;
/// with `derivatives`, the bins by the log-magnitude and the angle of the pole (for a gain of
/// one) are written to the first two, and the bins by the strike time for `tau_gain` added to
/// the third.
pub struct Out<'a> {
    pub unit: &'a mut [Complex64],
    pub gain: f64,
    pub derivatives: Option<([&'a mut [Complex64]; 3], f64)>,
}

/// Adds a mode's bins to `out` (see [`Out`]).
pub fn mode_bins(lanes: &Lanes, pole: &Pole, out: Out<'_>) {
    #[cfg(target_arch = "x86_64")]
    {
        if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
            // SAFETY: the CPU supports AVX2 and FMA.
            unsafe { mode_bins_avx2(lanes, pole, out) };
            return;
        }
    }
    mode_bins_portable(lanes, pole, out);
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn mode_bins_avx2(lanes: &Lanes, pole: &Pole, out: Out<'_>) {
    mode_bins_portable(lanes, pole, out);
}

#[inline(always)]
fn mode_bins_portable(lanes: &Lanes, pole: &Pole, out: Out<'_>) {
    match out.derivatives {
        None => each_bin::<false>(
            lanes,
            pole,
            out.unit,
            out.gain,
            [&mut [], &mut [], &mut []],
            0.0,
        ),
        Some((d, tau_gain)) => each_bin::<true>(lanes, pole, out.unit, out.gain, d, tau_gain),
    }
}

/// The loop over the bins, in real arithmetic with no branch so that it vectorises.
/// With `a = e^s w^k` and `a_L = e^(sL) w^(kL)`: `P = (1 - a_L) / (1 - a)`,
/// `dP/ds = (a P - L a_L) / (1 - a)`, and the same for the conjugate pole.
#[inline(always)]
fn each_bin<const DERIVATIVES: bool>(
    lanes: &Lanes,
    pole: &Pole,
    unit: &mut [Complex64],
    gain: f64,
    derivatives: [&mut [Complex64]; 3],
    tau_gain: f64,
) {
    let n = lanes.len();
    let unit = &mut unit[..n];
    let [dm, da, dt] = derivatives;
    let (dm, da, dt) = if DERIVATIVES {
        (&mut dm[..n], &mut da[..n], &mut dt[..n])
    } else {
        (dm, da, dt)
    };
    let (w_re, w_im) = (&lanes.w_re[..n], &lanes.w_im[..n]);
    let (wl_re, wl_im, taper) = (&lanes.wl_re[..n], &lanes.wl_im[..n], &lanes.taper[..n]);
    let Pole {
        es,
        esl,
        s,
        q,
        qc,
        tau,
        len,
        scale,
    } = *pole;
    for j in 0..n {
        let (w, wl, t) = ((w_re[j], w_im[j]), (wl_re[j], wl_im[j]), taper[j]);
        // The pole and its conjugate.
        let b = BinTerms::new((es.re, es.im), (esl.re, esl.im), w, wl);
        let c = BinTerms::new((es.re, -es.im), (esl.re, -esl.im), w, wl);
        let ((pr, pi), (pcr, pci)) = (b.p, c.p);
        // u = q P + qc Pc.
        let ur = q.re * pr - q.im * pi + qc.re * pcr - qc.im * pci;
        let ui = q.re * pi + q.im * pr + qc.re * pci + qc.im * pcr;
        let tg = t * gain;
        unit[j].re += ur * tg;
        unit[j].im += ui * tg;
        if DERIVATIVES {
            let ((dpr, dpi), (dpcr, dpci)) = (b.dp(len), c.dp(len));
            // e = q (dP - P tau), ec = qc (dPc - Pc tau).
            let (fr, fi) = (dpr - pr * tau, dpi - pi * tau);
            let (er, ei) = (q.re * fr - q.im * fi, q.re * fi + q.im * fr);
            let (fcr, fci) = (dpcr - pcr * tau, dpci - pci * tau);
            let (ecr, eci) = (qc.re * fcr - qc.im * fci, qc.re * fci + qc.im * fcr);
            let ts = t / scale;
            dm[j].re = (er + ecr) * ts;
            dm[j].im = (ei + eci) * ts;
            // i (e - ec).
            da[j].re = -(ei - eci) * ts;
            da[j].im = (er - ecr) * ts;
            // -(s q P + s* qc Pc).
            let (sqr, sqi) = (s.re * q.re - s.im * q.im, s.re * q.im + s.im * q.re);
            let (sqcr, sqci) = (s.re * qc.re + s.im * qc.im, s.re * qc.im - s.im * qc.re);
            let vr = sqr * pr - sqi * pi + sqcr * pcr - sqci * pci;
            let vi = sqr * pi + sqi * pr + sqcr * pci + sqci * pcr;
            let g = t * scale * tau_gain;
            dt[j].re -= vr * g;
            dt[j].im -= vi * g;
        }
    }
}

/// One pole's terms at one bin, as (real, imaginary) pairs in real arithmetic so that the loop
/// over the bins vectorises.
struct BinTerms {
    /// `a = e^s w^k`.
    a: (f64, f64),
    /// `a_L = e^(sL) w^(kL)`.
    al: (f64, f64),
    /// `1 / (1 - a)`.
    inv: (f64, f64),
    /// `P = (1 - a_L) / (1 - a)`.
    p: (f64, f64),
}

impl BinTerms {
    /// The terms of the pole `e^s = es` (and `e^(sL) = esl`) at the bin where `w^k = w` and
    /// `w^(kL) = wl`.
    #[inline(always)]
    fn new(es: (f64, f64), esl: (f64, f64), w: (f64, f64), wl: (f64, f64)) -> Self {
        let (ar, ai) = (es.0 * w.0 - es.1 * w.1, es.0 * w.1 + es.1 * w.0);
        let (alr, ali) = (esl.0 * wl.0 - esl.1 * wl.1, esl.0 * wl.1 + esl.1 * wl.0);
        let (xr, xi) = (1.0 - ar, -ai);
        let r = 1.0 / (xr * xr + xi * xi);
        let (ir, ii) = (xr * r, -xi * r);
        let (nr, ni) = (1.0 - alr, -ali);
        Self {
            a: (ar, ai),
            al: (alr, ali),
            inv: (ir, ii),
            p: (nr * ir - ni * ii, nr * ii + ni * ir),
        }
    }

    /// `dP/ds = (a P - L a_L) / (1 - a)` for a sound `len` samples long.
    #[inline(always)]
    fn dp(&self, len: f64) -> (f64, f64) {
        let ((ar, ai), (alr, ali), (ir, ii), (pr, pi)) = (self.a, self.al, self.inv, self.p);
        let (yr, yi) = (ar * pr - ai * pi - len * alr, ar * pi + ai * pr - len * ali);
        (yr * ir - yi * ii, yr * ii + yi * ir)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// The closed form in complex arithmetic, bin by bin.
    fn oracle(
        twiddles: &[(Complex64, Complex64)],
        taper: &[f64],
        p: &Pole,
        gain: f64,
        tau_gain: f64,
    ) -> [Vec<Complex64>; 4] {
        let one = Complex64::new(1.0, 0.0);
        let p_and_dp = |a: Complex64, al: Complex64| {
            let inv = (one - a).inv();
            let pp = (one - al) * inv;
            (pp, (a * pp - al * p.len) * inv)
        };
        let mut out: [Vec<Complex64>; 4] = Default::default();
        for (&(w, wl), &t) in twiddles.iter().zip(taper) {
            let (pp, dp) = p_and_dp(p.es * w, p.esl * wl);
            let (pc, dpc) = p_and_dp(p.es.conj() * w, p.esl.conj() * wl);
            let e = p.q * (dp - pp * p.tau);
            let ec = p.qc * (dpc - pc * p.tau);
            out[0].push((p.q * pp + p.qc * pc) * t * gain);
            out[1].push((e + ec) * (t / p.scale));
            out[2].push(Complex64::new(0.0, 1.0) * (e - ec) * (t / p.scale));
            out[3].push(-(p.s * p.q * pp + p.s.conj() * p.qc * pc) * (t * p.scale) * tau_gain);
        }
        out
    }

    #[test]
    fn the_lanes_agree_with_the_complex_closed_form() {
        let (fft_len, first_bin, bins, len) = (4096.0, 300usize, 256usize, 1500.0);
        let twiddles: Vec<(Complex64, Complex64)> = (first_bin..first_bin + bins)
            .map(|k| {
                let k = k as f64;
                (
                    Complex64::from_polar(1.0, -TAU * k / fft_len),
                    Complex64::from_polar(1.0, -TAU * ((k * len) % fft_len) / fft_len),
                )
            })
            .collect();
        // A taper with zero ends, as a band's.
        let taper: Vec<f64> = (0..bins)
            .map(|j| {
                if (5..=240).contains(&j) {
                    0.5 + 0.4 * (j as f64).sin()
                } else {
                    0.0
                }
            })
            .collect();
        let s = Complex64::new(-3e-4, TAU * 330.5 / fft_len);
        let tau = 2.5;
        let pole = Pole {
            es: s.exp(),
            esl: (s * len).exp(),
            s,
            q: Complex64::new(0.0, -0.5) * (-s * tau).exp(),
            qc: Complex64::new(0.0, 0.5) * (-s.conj() * tau).exp(),
            tau,
            len,
            scale: 16.0,
        };
        let want = oracle(&twiddles, &taper, &pole, 0.7, -1.3);
        let lanes = Lanes::new(&twiddles, &taper);
        assert_eq!((lanes.first, lanes.len()), (5, 236));
        let zero = Complex64::new(0.0, 0.0);
        let mut got: [Vec<Complex64>; 4] = std::array::from_fn(|_| vec![zero; lanes.len()]);
        let [unit, dm, da, dt] = &mut got;
        mode_bins(
            &lanes,
            &pole,
            Out {
                unit,
                gain: 0.7,
                derivatives: Some(([dm, da, dt], -1.3)),
            },
        );
        let mut only_unit = vec![zero; lanes.len()];
        mode_bins(
            &lanes,
            &pole,
            Out {
                unit: &mut only_unit,
                gain: 0.7,
                derivatives: None,
            },
        );
        for (which, (w, g)) in want.iter().zip(&got).enumerate() {
            let peak = w.iter().map(|v| v.norm()).fold(0.0, f64::max);
            assert!(peak > 0.0);
            for (j, v) in w.iter().enumerate() {
                let g = if (lanes.first..lanes.first + lanes.len()).contains(&j) {
                    g[j - lanes.first]
                } else {
                    assert_eq!(*v, zero, "output {which} bin {j} is outside the taper");
                    continue;
                };
                assert!(
                    (g - v).norm() <= 1e-12 * peak,
                    "output {which} bin {j}: {g} vs {v}"
                );
            }
        }
        assert_eq!(only_unit, got[0]);
    }
}
