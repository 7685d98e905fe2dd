//! Analysis by synthesis in one band: every mode's decay, frequency, amplitude and phase refined
//! together against the band's signal (Levenberg-Marquardt with the analytic Jacobian of the
//! damped exponentials), and modes kept only while they lower the description length of the
//! signal (Rissanen's MDL: half the log of the error per sample against half the log of the
//! samples per parameter).
//!
//! The error is weighted by the inverse of the band's envelope plus its noise, so that every
//! stretch of the sound counts alike, as it does to a listener comparing levels in decibels: an
//! unweighted fit follows the loud start and lets the tail go (a fast-then-slow decay would keep
//! only its fast part).

use realfft::num_complex::Complex64;

use super::linalg::solve;

/// Iterations of Levenberg-Marquardt.
const MAX_ITERATIONS: usize = 30;

/// Iterations stop once the error falls by less than this share.
const TOLERANCE: f64 = 1e-7;

/// Starting damping of the Levenberg-Marquardt steps, relative to the normal matrix's diagonal.
const START_LAMBDA: f64 = 1e-3;

/// Real parameters per mode: log-magnitude and angle of the pole, real and imaginary amplitude.
const PARAMS: usize = 4;

/// A pole never grows: its log-magnitude per sample stays at or below this.
const MAX_LOG_MAGNITUDE: f64 = -1e-9;

/// Weight of the parameter count in the description length: 1 is Rissanen's MDL.
const MDL_PENALTY: f64 = 1.0;

/// A damped exponential `c z^n` in a band.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exp {
    /// Pole per sample.
    pub z: Complex64,
    /// Amplitude at sample 0.
    pub c: Complex64,
}

/// The samples of a band fitted, with their weights.
pub struct Target<'a> {
    /// The band's signal.
    pub y: &'a [Complex64],
    /// Samples fitted.
    pub range: std::ops::Range<usize>,
    /// Weight of each sample of `range`.
    pub weights: Vec<f64>,
}

impl<'a> Target<'a> {
    /// Weights `1 / sqrt(envelope^2 + noise_var)` from a running mean of `|y|^2` over `smooth`
    /// samples.
    pub fn new(
        y: &'a [Complex64],
        range: std::ops::Range<usize>,
        noise_var: f64,
        smooth: usize,
    ) -> Self {
        let half = smooth / 2;
        let power: Vec<f64> = y.iter().map(|v| v.norm_sqr()).collect();
        let mut prefix = vec![0.0; power.len() + 1];
        for (i, p) in power.iter().enumerate() {
            prefix[i + 1] = prefix[i] + p;
        }
        let weights = range
            .clone()
            .map(|n| {
                let (lo, hi) = (n.saturating_sub(half), (n + half + 1).min(power.len()));
                let mean = (prefix[hi] - prefix[lo]) / (hi - lo) as f64;
                1.0 / (mean + noise_var).max(1e-300).sqrt()
            })
            .collect();
        Self { y, range, weights }
    }

    /// Weighted squared error of `modes`.
    pub fn error(&self, modes: &[Exp]) -> f64 {
        let mut powers: Vec<Complex64> = modes
            .iter()
            .map(|m| m.c * m.z.powu(self.range.start as u32))
            .collect();
        let mut e = 0.0;
        for (n, w) in self.range.clone().zip(&self.weights) {
            let model: Complex64 = powers.iter().sum();
            e += w * w * (self.y[n] - model).norm_sqr();
            for (p, m) in powers.iter_mut().zip(modes) {
                *p *= m.z;
            }
        }
        e
    }

    /// Description length of `modes` with error `error`, up to a constant.
    pub fn description_length(&self, modes: usize, error: f64) -> f64 {
        let samples = 2.0 * self.range.len() as f64;
        0.5 * samples * (error / samples).max(1e-300).ln()
            + MDL_PENALTY * 0.5 * (PARAMS * modes) as f64 * samples.ln()
    }

    /// The weighted least-squares amplitudes of the poles of `modes`.
    pub fn amplitudes(&self, modes: &mut [Exp]) {
        let k = modes.len();
        if k == 0 {
            return;
        }
        let mut gram = vec![Complex64::new(0.0, 0.0); k * k];
        let mut rhs = vec![Complex64::new(0.0, 0.0); k];
        let mut powers: Vec<Complex64> = modes
            .iter()
            .map(|m| m.z.powu(self.range.start as u32))
            .collect();
        for (n, w) in self.range.clone().zip(&self.weights) {
            let w2 = w * w;
            for a in 0..k {
                let pa = powers[a].conj() * w2;
                rhs[a] += pa * self.y[n];
                for b in a..k {
                    gram[a * k + b] += pa * powers[b];
                }
            }
            for (p, m) in powers.iter_mut().zip(modes.iter()) {
                *p *= m.z;
            }
        }
        for a in 0..k {
            for b in 0..a {
                gram[a * k + b] = gram[b * k + a].conj();
            }
        }
        solve(&mut gram, &mut rhs, k, 1);
        for (m, c) in modes.iter_mut().zip(rhs) {
            m.c = c;
        }
    }

    /// Refines every parameter of `modes` together; returns the final weighted error.
    pub fn refine(&self, modes: &mut [Exp]) -> f64 {
        let mut error = self.error(modes);
        let mut lambda = START_LAMBDA;
        for _ in 0..MAX_ITERATIONS {
            let (normal, gradient) = self.normal_equations(modes);
            let mut improved = false;
            for _ in 0..8 {
                let trial = self.step(modes, &normal, &gradient, lambda);
                let e = self.error(&trial);
                if e < error {
                    let gain = (error - e) / error.max(1e-300);
                    modes.copy_from_slice(&trial);
                    error = e;
                    lambda = (lambda / 3.0).max(1e-12);
                    improved = gain > TOLERANCE;
                    break;
                }
                lambda *= 4.0;
            }
            if !improved {
                break;
            }
        }
        error
    }

    /// `J^T W J` and `J^T W r` for the parameters of `modes` (see [`PARAMS`]).
    fn normal_equations(&self, modes: &[Exp]) -> (Vec<f64>, Vec<f64>) {
        let dim = PARAMS * modes.len();
        let mut normal = vec![0.0; dim * dim];
        let mut gradient = vec![0.0; dim];
        let mut powers: Vec<Complex64> = modes
            .iter()
            .map(|m| m.z.powu(self.range.start as u32))
            .collect();
        let mut columns = vec![Complex64::new(0.0, 0.0); dim];
        let i = Complex64::new(0.0, 1.0);
        for (n, w) in self.range.clone().zip(&self.weights) {
            let model: Complex64 = powers.iter().zip(modes).map(|(p, m)| m.c * p).sum();
            let residual = (self.y[n] - model) * *w;
            for (k, (p, m)) in powers.iter().zip(modes).enumerate() {
                let term = m.c * p * (n as f64 * w);
                columns[PARAMS * k] = term;
                columns[PARAMS * k + 1] = i * term;
                columns[PARAMS * k + 2] = p * *w;
                columns[PARAMS * k + 3] = i * p * *w;
            }
            for a in 0..dim {
                let ca = columns[a].conj();
                gradient[a] += (ca * residual).re;
                for b in a..dim {
                    normal[a * dim + b] += (ca * columns[b]).re;
                }
            }
            for (p, m) in powers.iter_mut().zip(modes) {
                *p *= m.z;
            }
        }
        for a in 0..dim {
            for b in 0..a {
                normal[a * dim + b] = normal[b * dim + a];
            }
        }
        (normal, gradient)
    }

    /// `modes` moved by the damped Gauss-Newton step.
    fn step(&self, modes: &[Exp], normal: &[f64], gradient: &[f64], lambda: f64) -> Vec<Exp> {
        let dim = gradient.len();
        let mut a: Vec<Complex64> = normal.iter().map(|&v| Complex64::new(v, 0.0)).collect();
        for d in 0..dim {
            a[d * dim + d] += lambda * normal[d * dim + d].max(1e-300);
        }
        let mut b: Vec<Complex64> = gradient.iter().map(|&v| Complex64::new(v, 0.0)).collect();
        solve(&mut a, &mut b, dim, 1);
        modes
            .iter()
            .enumerate()
            .map(|(k, m)| {
                let s = m.z.ln();
                let log_mag = (s.re + b[PARAMS * k].re).min(MAX_LOG_MAGNITUDE);
                let angle = s.im + b[PARAMS * k + 1].re;
                Exp {
                    z: Complex64::from_polar(log_mag.exp(), angle),
                    c: m.c + Complex64::new(b[PARAMS * k + 2].re, b[PARAMS * k + 3].re),
                }
            })
            .collect()
    }

    /// Drops modes, the weakest first, while that shortens the description of the signal, then
    /// refines what is left. Returns the modes kept and their weighted error.
    pub fn select(&self, mut modes: Vec<Exp>) -> (Vec<Exp>, f64) {
        let mut error = self.refine(&mut modes);
        loop {
            if modes.is_empty() {
                return (modes, error);
            }
            let length = self.description_length(modes.len(), error);
            let weakest = (0..modes.len())
                .min_by(|&a, &b| self.energy(&modes[a]).total_cmp(&self.energy(&modes[b])))
                .expect("not empty");
            let mut fewer: Vec<Exp> = modes
                .iter()
                .enumerate()
                .filter(|&(k, _)| k != weakest)
                .map(|(_, m)| *m)
                .collect();
            self.amplitudes(&mut fewer);
            let e = self.error(&fewer);
            if self.description_length(fewer.len(), e) >= length {
                return (modes, error);
            }
            error = self.refine(&mut fewer);
            modes = fewer;
        }
    }

    /// Weighted energy of one mode over the samples fitted.
    fn energy(&self, m: &Exp) -> f64 {
        let mut p = m.c * m.z.powu(self.range.start as u32);
        let mut e = 0.0;
        for w in &self.weights {
            e += w * w * p.norm_sqr();
            p *= m.z;
        }
        e
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dsp::rng::Rng;

    #[test]
    fn refinement_recovers_exact_modes_and_selection_drops_a_spurious_one() {
        let truth = [
            Exp {
                z: Complex64::from_polar(0.99, 0.4),
                c: Complex64::new(1.0, 0.5),
            },
            Exp {
                z: Complex64::from_polar(0.9995, 0.41),
                c: Complex64::new(0.0, 0.1),
            },
        ];
        let mut rng = Rng::new(11);
        let y: Vec<Complex64> = (0..800u32)
            .map(|n| {
                let noise = Complex64::new(rng.bipolar() as f64, rng.bipolar() as f64) * 1e-4;
                truth.iter().map(|m| m.c * m.z.powu(n)).sum::<Complex64>() + noise
            })
            .collect();
        let target = Target::new(&y, 0..y.len(), 1e-8, 16);
        let mut start: Vec<Exp> = truth
            .iter()
            .map(|m| Exp {
                z: m.z * Complex64::from_polar(0.999, 0.002),
                c: m.c,
            })
            .collect();
        // A spurious mode where there is only noise.
        start.push(Exp {
            z: Complex64::from_polar(0.95, -1.0),
            c: Complex64::new(1e-4, 0.0),
        });
        target.amplitudes(&mut start);
        let (kept, _) = target.select(start);
        assert_eq!(kept.len(), 2, "{kept:?}");
        for want in truth {
            let got = kept
                .iter()
                .min_by(|a, b| (a.z - want.z).norm().total_cmp(&(b.z - want.z).norm()))
                .unwrap();
            assert!((got.z - want.z).norm() < 1e-5, "{got:?} vs {want:?}");
            assert!(
                (got.c - want.c).norm() < 1e-3 * want.c.norm() + 1e-4,
                "{got:?}"
            );
        }
    }
}
