//! Analysis by synthesis in one band: every mode's decay, frequency and amplitude, and the time
//! of the strike, refined together against the band's signal (Levenberg-Marquardt with the
//! analytic Jacobian of the damped exponentials), and modes kept only while they lower the
//! description length of the signal (Rissanen's MDL: half the log of the error per sample
//! against half the log of the samples per parameter).
//!
//! The modes are those of an impulse at the strike time `t_s`, as the bank plays them: each
//! `a exp(-d (t - t_s)) sin(w (t - t_s))` with a real, signed gain `a`. Free phases would let
//! several close modes describe one partial by interfering in ways a bank (whose modes all start
//! in sine phase) cannot play back. A finite mallet contact delays every mode alike, which the
//! strike time takes up.
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

/// Real parameters per mode: log-magnitude and angle of the pole, and the gain.
const PARAMS: usize = 3;

/// The strike is found at most this many times the samples left out at the band's start before
/// or after the onset.
const MAX_STRIKE_SHIFT: f64 = 0.5;

/// A pole never grows: its log-magnitude per sample stays at or below this.
const MAX_LOG_MAGNITUDE: f64 = -1e-9;

/// Most a mode may decay, in nepers (half its amplitude), between the onset and the first
/// sample fitted: a faster one is not measured there but extrapolated, and its amplitude at the
/// onset could grow without bound while it fits the band's start.
pub const MAX_UNSEEN_NEPERS: f64 = std::f64::consts::LN_2;

/// Two poles closer than this share of a frequency bin of the samples fitted (`1 / N` cycles
/// per sample), and as close in decay, are one mode to the data.
const RESOLUTION_SHARE: f64 = 0.5;

/// A mode louder where the fit starts than this many times the band's loudest sample is
/// cancelling another.
const MAX_OVER_PEAK: f64 = 2.0;

/// Weight of the parameter count in the description length: 1 is Rissanen's MDL.
const MDL_PENALTY: f64 = 1.0;

/// A mode of a band: `gain * q * z^(n - tau)`, where `q = -i/2 exp(-i beta tau)` shifts the
/// band's base frequency `beta` (radians per sample) back over the strike's delay `tau`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exp {
    /// Pole per sample, relative to the band's base frequency.
    pub z: Complex64,
    /// Signed gain of the mode at the strike, in the recording's full scale.
    pub gain: f64,
}

/// Modes of a band and the time of the strike they start at.
#[derive(Debug, Clone, PartialEq)]
pub struct Modes {
    /// The modes.
    pub modes: Vec<Exp>,
    /// Time of the strike after the onset, in samples of the band.
    pub tau: f64,
}

/// The samples of a band fitted, with their weights.
pub struct Target<'a> {
    /// The band's signal.
    pub y: &'a [Complex64],
    /// Samples fitted.
    pub range: std::ops::Range<usize>,
    /// Weight of each sample of `range`.
    pub weights: Vec<f64>,
    /// The band's base frequency in radians per sample.
    pub beta: f64,
}

impl<'a> Target<'a> {
    /// Weights `1 / sqrt(envelope^2 + noise_var)` from a running mean of `|y|^2` over `smooth`
    /// samples; `beta` is the band's base frequency in radians per sample.
    pub fn new(
        y: &'a [Complex64],
        range: std::ops::Range<usize>,
        noise_var: f64,
        smooth: usize,
        beta: f64,
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
        Self {
            y,
            range,
            weights,
            beta,
        }
    }

    /// Lowest log-magnitude of a pole per sample: see [`MAX_UNSEEN_NEPERS`].
    pub fn min_log_magnitude(&self) -> f64 {
        -MAX_UNSEEN_NEPERS / self.range.start.max(1) as f64
    }

    /// Each mode's value at the first sample fitted for a gain of 1: `q z^(start - tau)`.
    fn unit_starts(&self, fit: &Modes) -> Vec<Complex64> {
        let q = Complex64::new(0.0, -0.5) * Complex64::from_polar(1.0, -self.beta * fit.tau);
        fit.modes
            .iter()
            .map(|m| q * (m.z.ln() * (self.range.start as f64 - fit.tau)).exp())
            .collect()
    }

    /// Weighted squared error of `fit`.
    pub fn error(&self, fit: &Modes) -> f64 {
        let mut terms: Vec<Complex64> = self
            .unit_starts(fit)
            .iter()
            .zip(&fit.modes)
            .map(|(u, m)| u * m.gain)
            .collect();
        let mut e = 0.0;
        for (n, w) in self.range.clone().zip(&self.weights) {
            let model: Complex64 = terms.iter().sum();
            e += w * w * (self.y[n] - model).norm_sqr();
            for (t, m) in terms.iter_mut().zip(&fit.modes) {
                *t *= m.z;
            }
        }
        e
    }

    /// Description length of `modes` modes with error `error`, up to a constant.
    pub fn description_length(&self, modes: usize, error: f64) -> f64 {
        let samples = 2.0 * self.range.len() as f64;
        0.5 * samples * (error / samples).max(1e-300).ln()
            + MDL_PENALTY * 0.5 * (PARAMS * modes + 1) as f64 * samples.ln()
    }

    /// The weighted least-squares gains of the poles of `fit`.
    pub fn gains(&self, fit: &mut Modes) {
        let k = fit.modes.len();
        if k == 0 {
            return;
        }
        let mut gram = vec![Complex64::new(0.0, 0.0); k * k];
        let mut rhs = vec![Complex64::new(0.0, 0.0); k];
        let mut units = self.unit_starts(fit);
        for (n, w) in self.range.clone().zip(&self.weights) {
            let w2 = w * w;
            for a in 0..k {
                let ua = units[a].conj() * w2;
                rhs[a] += (ua * self.y[n]).re;
                for b in a..k {
                    gram[a * k + b] += (ua * units[b]).re;
                }
            }
            for (u, m) in units.iter_mut().zip(&fit.modes) {
                *u *= m.z;
            }
        }
        for a in 0..k {
            for b in 0..a {
                gram[a * k + b] = gram[b * k + a];
            }
        }
        solve(&mut gram, &mut rhs, k, 1);
        for (m, g) in fit.modes.iter_mut().zip(rhs) {
            m.gain = g.re;
        }
    }

    /// Refines every parameter of `fit` together; returns the final weighted error.
    pub fn refine(&self, fit: &mut Modes) -> f64 {
        let mut error = self.error(fit);
        let mut lambda = START_LAMBDA;
        for _ in 0..MAX_ITERATIONS {
            let (normal, gradient) = self.normal_equations(fit);
            let mut improved = false;
            for _ in 0..8 {
                let trial = self.step(fit, &normal, &gradient, lambda);
                let e = self.error(&trial);
                if e < error {
                    let gain = (error - e) / error.max(1e-300);
                    *fit = trial;
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

    /// `J^T W J` and `J^T W r` for the parameters of `fit`: [`PARAMS`] per mode, then `tau`.
    fn normal_equations(&self, fit: &Modes) -> (Vec<f64>, Vec<f64>) {
        let modes = &fit.modes;
        let dim = PARAMS * modes.len() + 1;
        let mut normal = vec![0.0; dim * dim];
        let mut gradient = vec![0.0; dim];
        let mut units = self.unit_starts(fit);
        // d/dtau of z^(n - tau) exp(-i beta tau) is -(ln z + i beta) times it.
        let tau_factors: Vec<Complex64> = modes
            .iter()
            .map(|m| -(m.z.ln() + Complex64::new(0.0, self.beta)))
            .collect();
        let mut columns = vec![Complex64::new(0.0, 0.0); dim];
        let i = Complex64::new(0.0, 1.0);
        for (n, w) in self.range.clone().zip(&self.weights) {
            let model: Complex64 = units.iter().zip(modes).map(|(u, m)| u * m.gain).sum();
            let residual = (self.y[n] - model) * *w;
            let lag = n as f64 - fit.tau;
            let mut d_tau = Complex64::new(0.0, 0.0);
            for (k, (u, m)) in units.iter().zip(modes).enumerate() {
                let term = u * (m.gain * w);
                columns[PARAMS * k] = term * lag;
                columns[PARAMS * k + 1] = i * term * lag;
                columns[PARAMS * k + 2] = u * *w;
                d_tau += term * tau_factors[k];
            }
            columns[dim - 1] = d_tau;
            for a in 0..dim {
                let ca = columns[a].conj();
                gradient[a] += (ca * residual).re;
                for b in a..dim {
                    normal[a * dim + b] += (ca * columns[b]).re;
                }
            }
            for (u, m) in units.iter_mut().zip(modes) {
                *u *= m.z;
            }
        }
        for a in 0..dim {
            for b in 0..a {
                normal[a * dim + b] = normal[b * dim + a];
            }
        }
        (normal, gradient)
    }

    /// `fit` moved by the damped Gauss-Newton step.
    fn step(&self, fit: &Modes, normal: &[f64], gradient: &[f64], lambda: f64) -> Modes {
        let dim = gradient.len();
        let mut a: Vec<Complex64> = normal.iter().map(|&v| Complex64::new(v, 0.0)).collect();
        for d in 0..dim {
            a[d * dim + d] += lambda * normal[d * dim + d].max(1e-300);
        }
        let mut b: Vec<Complex64> = gradient.iter().map(|&v| Complex64::new(v, 0.0)).collect();
        solve(&mut a, &mut b, dim, 1);
        let modes = fit
            .modes
            .iter()
            .enumerate()
            .map(|(k, m)| {
                let s = m.z.ln();
                let log_mag = (s.re + b[PARAMS * k].re)
                    .min(MAX_LOG_MAGNITUDE)
                    .max(self.min_log_magnitude());
                let angle = s.im + b[PARAMS * k + 1].re;
                Exp {
                    z: Complex64::from_polar(log_mag.exp(), angle),
                    gain: m.gain + b[PARAMS * k + 2].re,
                }
            })
            .collect();
        let max_tau = MAX_STRIKE_SHIFT * self.range.start.max(1) as f64;
        Modes {
            modes,
            tau: (fit.tau + b[dim - 1].re).clamp(-max_tau, max_tau),
        }
    }

    /// Drops modes, the weakest first, while that shortens the description of the signal, then
    /// refines what is left. Returns the fit kept and its weighted error.
    pub fn select(&self, mut fit: Modes) -> (Modes, f64) {
        let mut error = self.refine(&mut fit);
        while let Some(k) = self.unresolved(&fit) {
            fit.modes.remove(k);
            self.gains(&mut fit);
            error = self.refine(&mut fit);
        }
        loop {
            if fit.modes.is_empty() {
                return (fit, error);
            }
            let length = self.description_length(fit.modes.len(), error);
            let energies = self.energies(&fit);
            let weakest = (0..fit.modes.len())
                .min_by(|&a, &b| energies[a].total_cmp(&energies[b]))
                .expect("not empty");
            let mut fewer = fit.clone();
            fewer.modes.remove(weakest);
            self.gains(&mut fewer);
            let e = self.error(&fewer);
            if self.description_length(fewer.modes.len(), e) >= length {
                return (fit, error);
            }
            error = self.refine(&mut fewer);
            fit = fewer;
        }
    }

    /// A mode the data cannot tell from another, if any: the weaker of two poles closer than
    /// half the resolution of the samples fitted in both frequency and decay, or a mode whose
    /// level where the fit starts exceeds the band's loudest sample (it cancels another).
    fn unresolved(&self, fit: &Modes) -> Option<usize> {
        let modes = &fit.modes;
        let resolution = RESOLUTION_SHARE / self.range.len().max(1) as f64;
        let peak = self
            .range
            .clone()
            .map(|n| self.y[n].norm())
            .fold(0.0, f64::max);
        let starts = self.unit_starts(fit);
        if let Some(k) =
            (0..modes.len()).find(|&k| (starts[k] * modes[k].gain).norm() > MAX_OVER_PEAK * peak)
        {
            return Some(k);
        }
        let energies = self.energies(fit);
        for a in 0..modes.len() {
            for b in a + 1..modes.len() {
                let (sa, sb) = (modes[a].z.ln(), modes[b].z.ln());
                let d_angle = (sa.im - sb.im).abs() / std::f64::consts::TAU;
                if d_angle < resolution && (sa.re - sb.re).abs() < resolution {
                    return Some(if energies[a] < energies[b] { a } else { b });
                }
            }
        }
        None
    }

    /// Weighted energy of each mode over the samples fitted.
    fn energies(&self, fit: &Modes) -> Vec<f64> {
        self.unit_starts(fit)
            .iter()
            .zip(&fit.modes)
            .map(|(u, m)| {
                let mut p = u * m.gain;
                let mut e = 0.0;
                for w in &self.weights {
                    e += w * w * p.norm_sqr();
                    p *= m.z;
                }
                e
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dsp::rng::Rng;

    #[test]
    fn refinement_recovers_exact_modes_and_selection_drops_a_spurious_one() {
        let beta = 0.3;
        let truth = Modes {
            modes: vec![
                Exp {
                    z: Complex64::from_polar(0.99, 0.4),
                    gain: 1.0,
                },
                Exp {
                    z: Complex64::from_polar(0.9995, 0.41),
                    gain: -0.1,
                },
            ],
            tau: 0.7,
        };
        let mut rng = Rng::new(11);
        let clean: Vec<Complex64> = {
            let t = Target::new(&[], 0..0, 1.0, 1, beta);
            let q = Complex64::new(0.0, -0.5) * Complex64::from_polar(1.0, -beta * truth.tau);
            let _ = t;
            (0..800)
                .map(|n| {
                    truth
                        .modes
                        .iter()
                        .map(|m| q * m.gain * (m.z.ln() * (n as f64 - truth.tau)).exp())
                        .sum()
                })
                .collect()
        };
        let y: Vec<Complex64> = clean
            .iter()
            .map(|v| v + Complex64::new(rng.bipolar() as f64, rng.bipolar() as f64) * 1e-4)
            .collect();
        let target = Target::new(&y, 4..y.len(), 1e-8, 16, beta);
        let mut start = Modes {
            modes: truth
                .modes
                .iter()
                .map(|m| Exp {
                    z: m.z * Complex64::from_polar(0.999, 0.002),
                    gain: 0.0,
                })
                .collect(),
            tau: 0.0,
        };
        // A spurious mode where there is only noise.
        start.modes.push(Exp {
            z: Complex64::from_polar(0.95, -1.0),
            gain: 0.0,
        });
        target.gains(&mut start);
        let (kept, _) = target.select(start);
        assert_eq!(kept.modes.len(), 2, "{kept:?}");
        assert!((kept.tau - truth.tau).abs() < 0.05, "{kept:?}");
        for want in &truth.modes {
            let got = kept
                .modes
                .iter()
                .min_by(|a, b| (a.z - want.z).norm().total_cmp(&(b.z - want.z).norm()))
                .unwrap();
            assert!((got.z - want.z).norm() < 1e-5, "{got:?} vs {want:?}");
            assert!((got.gain - want.gain).abs() < 1e-3, "{got:?} vs {want:?}");
        }
    }
}
