//! Analysis by synthesis in one band: every mode's decay, frequency and amplitude, and the time
//! of the strike, refined together against the band's signal (Levenberg-Marquardt with the
//! analytic Jacobian), and modes kept only while they lower the description length of the
//! signal (Rissanen's MDL: half the log of the error per sample against half the log of the
//! samples per parameter).
//!
//! The model is exact: each mode is synthesised as the band holds it, not as a bare exponential.
//! A mode `a exp(-d (t - t_s)) sin(w (t - t_s))`, sounding from the first sample of the sound
//! to its last (where a recording cut short stops it), has a closed-form transform: with
//! `x_n = Re(c e^(s n))` for `0 <= n < L`, bin `k` of the `N`-point transform holds
//! `c/2 P(s) + c*/2 P(s*)`, where `P(s) = (1 - (e^s w^k)^L) / (1 - e^s w^k)` and
//! `w = e^(-2 pi i / N)`. The band tapers those bins and transforms them back, as it does the
//! recording's ([`subband`](super::subband)). So the fit runs from the band's very first sample:
//! the band filter's smear of the onset and of the end is part of the model, and quick decays
//! the smear would hide are measured.
//!
//! The modes are those of an impulse at the strike time `t_s`, as the bank plays them: each
//! with a real, signed gain `a`. Free phases would let several close modes describe one partial
//! by interfering in ways a bank (whose modes all start in sine phase) cannot play back. A finite
//! mallet contact delays every mode alike, which the strike time takes up.
//!
//! The error is weighted by the inverse of the band's envelope plus its noise, so that every
//! stretch of the sound counts alike, as it does to a listener comparing levels in decibels: an
//! unweighted fit follows the loud start and lets the tail go (a fast-then-slow decay would keep
//! only its fast part).

use std::cell::RefCell;
use std::f64::consts::TAU;
use std::sync::Arc;

use realfft::num_complex::Complex64;
use rustfft::{Fft, FftPlanner};

use super::closed_form::{self, Lanes};
use super::linalg::{dots, solve, BLOCK};
use super::subband::Band;

/// Iterations of Levenberg-Marquardt.
const MAX_ITERATIONS: usize = 30;

/// Iterations of Levenberg-Marquardt after each mode dropped as one the data cannot tell from
/// another: the last fit kept is refined in full.
const SELECTION_ITERATIONS: usize = 10;

/// Iterations of Levenberg-Marquardt on all the modes, before any is dropped.
const FIRST_ITERATIONS: usize = 10;

/// Iterations of Levenberg-Marquardt on the modes left after the clear drops.
const SECOND_ITERATIONS: usize = 20;

/// A mode is clearly of no use when dropping it shortens the description by this many nats
/// (a mode's three parameters cost about 14 over 9,000 samples).
const CLEAR_DROP: f64 = 10.0;

/// Iterations stop once the error falls by less than this share.
const TOLERANCE: f64 = 1e-7;

/// Starting damping of the Levenberg-Marquardt steps, relative to the normal matrix's diagonal.
const START_LAMBDA: f64 = 1e-3;

/// Real parameters per mode: log-magnitude and angle of the pole, and the gain.
const PARAMS: usize = 3;

/// The strike is found at most this long before or after the onset, in seconds.
const MAX_STRIKE_SHIFT_S: f64 = 0.001;

/// A pole never grows: its log-magnitude per sample stays at or below this.
const MAX_LOG_MAGNITUDE: f64 = -1e-9;

/// Fastest decay of a mode, as its bandwidth (`d / pi`) over the width of its band's core: a
/// quicker one is no longer a resonance of the band but a click spread over several.
const MAX_BANDWIDTH_CORES: f64 = 2.0;

/// Two poles closer than this share of a frequency bin of the samples fitted (`1 / N` cycles
/// per sample), and as close in decay, are one mode to the data.
const RESOLUTION_SHARE: f64 = 0.5;

/// A mode louder than this many times the band's loudest sample is cancelling another.
const MAX_OVER_PEAK: f64 = 2.0;

/// Rows of the Jacobian taken at once in its normal equations.
const ROWS_AT_ONCE: usize = 512;

/// Weight of the parameter count in the description length: 1 is Rissanen's MDL.
const MDL_PENALTY: f64 = 1.0;

/// A mode of a band.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Exp {
    /// Logarithm of the pole per sample of the band, its angle counted from the band's base
    /// frequency (see [`Band::mode_of_log_pole`]).
    pub s: Complex64,
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

/// A mode's part of the band, transformed back to the band's samples (over the samples fitted).
struct Column {
    /// For a gain of 1.
    unit: Vec<Complex64>,
    /// Derivatives by the pole's log-magnitude and angle, for the mode's gain.
    d_log_magnitude: Vec<Complex64>,
    d_angle: Vec<Complex64>,
}

/// The samples of a band fitted, with their weights.
pub struct Target<'a> {
    /// The band.
    band: &'a Band,
    /// Samples fitted.
    pub range: std::ops::Range<usize>,
    /// Weight of each sample of `range`.
    weights: Vec<f64>,
    /// Inverse transform as long as the band.
    inverse: Arc<dyn Fft<f64>>,
    /// Bins of the band's transform.
    bins: usize,
    /// Per bin of the band where its taper is not zero: `w^k`, `w^(k L)` and the taper.
    lanes: Lanes,
    /// Scratch space of `inverse`.
    scratch: RefCell<Vec<Complex64>>,
    /// Work buffers as long as the band's transform.
    work: RefCell<[Vec<Complex64>; 4]>,
    /// The weighted Jacobian and residual of the last normal equations, kept for the next.
    jacobian: RefCell<(Vec<f64>, Vec<f64>)>,
}

impl<'a> Target<'a> {
    /// Fits `band` over `range`, weighted by `1 / sqrt(envelope^2 + noise_var)` from a running
    /// mean of `|y|^2` over `smooth` samples.
    pub fn new(
        band: &'a Band,
        range: std::ops::Range<usize>,
        noise_var: f64,
        smooth: usize,
    ) -> Self {
        let y = &band.samples;
        let half = smooth / 2;
        let mut prefix = vec![0.0; y.len() + 1];
        for (i, v) in y.iter().enumerate() {
            prefix[i + 1] = prefix[i] + v.norm_sqr();
        }
        let weights = range
            .clone()
            .map(|n| {
                let (lo, hi) = (n.saturating_sub(half), (n + half + 1).min(y.len()));
                let mean = (prefix[hi] - prefix[lo]) / (hi - lo).max(1) as f64;
                1.0 / (mean + noise_var).max(1e-300).sqrt()
            })
            .collect();
        let bins = band.taper.len();
        let n = band.fft_len as f64;
        let len = band.sound_len as f64;
        let twiddles: Vec<(Complex64, Complex64)> = (band.first_bin..band.first_bin + bins)
            .map(|k| {
                let k = k as f64;
                (
                    Complex64::from_polar(1.0, -TAU * k / n),
                    Complex64::from_polar(1.0, -TAU * ((k * len) % n) / n),
                )
            })
            .collect();
        let inverse = FftPlanner::new().plan_fft_inverse(bins);
        Self {
            band,
            range,
            weights,
            scratch: RefCell::new(vec![
                Complex64::new(0.0, 0.0);
                inverse.get_inplace_scratch_len()
            ]),
            work: RefCell::default(),
            jacobian: RefCell::default(),
            inverse,
            bins,
            lanes: Lanes::new(&twiddles, &band.taper),
        }
    }

    /// Lowest log-magnitude of a pole per sample of the band: see [`MAX_BANDWIDTH_CORES`].
    pub fn min_log_magnitude(&self) -> f64 {
        let core_hz = self.band.core_hz.1 - self.band.core_hz.0;
        -std::f64::consts::PI * MAX_BANDWIDTH_CORES * core_hz * self.band.dt_s
    }

    /// Highest angle of a pole per sample of the band: the top of its passband. A mode never
    /// leaves the band, where only the tails of its spectrum would reach the band's samples.
    fn max_angle(&self) -> f64 {
        let passband = self.band.taper.iter().rposition(|&t| t > 0.0).unwrap_or(0) + 1;
        TAU * passband as f64 / self.band.taper.len() as f64
    }

    /// Most the strike may move from the onset, in samples of the band.
    fn max_tau(&self) -> f64 {
        MAX_STRIKE_SHIFT_S / self.band.dt_s
    }

    /// The pole of `s` per sample of the sound, with its angle in absolute terms.
    fn full_rate(&self, s: Complex64) -> Complex64 {
        let scale = self.band.decimation();
        Complex64::new(
            s.re / scale,
            s.im / scale + TAU * self.band.first_bin as f64 / self.band.fft_len as f64,
        )
    }

    /// The band's samples over `range` from bins `bins` (transformed in place).
    fn back(&self, bins: &mut [Complex64]) -> Vec<Complex64> {
        let mut scratch = self.scratch.borrow_mut();
        self.inverse.process_with_scratch(bins, &mut scratch);
        bins[self.range.clone()].to_vec()
    }

    /// Adds to `unit` the bins of a mode `m` starting at `tau` for a gain of `gain`; with
    /// `derivatives`, writes its bins by its pole's log-magnitude and angle (for a gain of 1) to
    /// the first two and adds its bins by the strike time (for its own gain) to the third. Bins
    /// outside the band are left alone.
    fn mode_bins(
        &self,
        m: &Exp,
        tau: f64,
        gain: f64,
        unit: &mut [Complex64],
        derivatives: Option<[&mut [Complex64]; 3]>,
    ) {
        let scale = self.band.decimation();
        let len = self.band.sound_len as f64;
        let s = self.full_rate(m.s);
        let tau_f = tau * scale;
        let pole = closed_form::Pole {
            es: s.exp(),
            esl: Complex64::from_polar((s.re * len).exp(), (s.im * len) % TAU),
            s,
            q: Complex64::new(0.0, -0.5) * (-s * tau_f).exp(),
            qc: Complex64::new(0.0, 0.5) * (-s.conj() * tau_f).exp(),
            tau: tau_f,
            len,
            scale,
        };
        let live = self.lanes.first..self.lanes.first + self.lanes.len();
        closed_form::mode_bins(
            &self.lanes,
            &pole,
            closed_form::Out {
                unit: &mut unit[live.clone()],
                gain,
                derivatives: derivatives.map(|[dm, da, dt]| {
                    (
                        [
                            &mut dm[live.clone()],
                            &mut da[live.clone()],
                            &mut dt[live.clone()],
                        ],
                        m.gain,
                    )
                }),
            },
        );
    }

    /// A work buffer as long as the band's transform, zeroed.
    fn zeroed(&self, buffer: &mut Vec<Complex64>) {
        buffer.clear();
        buffer.resize(self.bins, Complex64::new(0.0, 0.0));
    }

    /// Each mode's part of the band for a gain of 1, over the samples fitted.
    fn units(&self, fit: &Modes) -> Vec<Vec<Complex64>> {
        let mut work = self.work.borrow_mut();
        let [bins, ..] = &mut *work;
        fit.modes
            .iter()
            .map(|m| {
                self.zeroed(bins);
                self.mode_bins(m, fit.tau, 1.0, bins, None);
                self.back(bins)
            })
            .collect()
    }

    /// Each mode's part of the band and its derivatives, over the samples fitted, and the
    /// derivative of the whole band by the strike time.
    fn columns(&self, fit: &Modes) -> (Vec<Column>, Vec<Complex64>) {
        let mut work = self.work.borrow_mut();
        let [unit, dm, da, dt] = &mut *work;
        self.zeroed(dt);
        let columns = fit
            .modes
            .iter()
            .map(|m| {
                self.zeroed(unit);
                self.zeroed(dm);
                self.zeroed(da);
                self.mode_bins(m, fit.tau, 1.0, unit, Some([&mut *dm, &mut *da, &mut *dt]));
                Column {
                    unit: self.back(unit),
                    d_log_magnitude: self.back(dm),
                    d_angle: self.back(da),
                }
            })
            .collect();
        (columns, self.back(dt))
    }

    /// The model of the band over the samples fitted.
    fn model(&self, fit: &Modes) -> Vec<Complex64> {
        let mut work = self.work.borrow_mut();
        let [bins, ..] = &mut *work;
        self.zeroed(bins);
        for m in &fit.modes {
            self.mode_bins(m, fit.tau, m.gain, bins, None);
        }
        self.back(bins)
    }

    /// Weighted squared error of `fit`.
    pub fn error(&self, fit: &Modes) -> f64 {
        let model = self.model(fit);
        self.range
            .clone()
            .zip(&self.weights)
            .zip(model)
            .map(|((n, w), m)| w * w * (self.band.samples[n] - m).norm_sqr())
            .sum()
    }

    /// Description length of `modes` modes with error `error`, up to a constant.
    pub fn description_length(&self, modes: usize, error: f64) -> f64 {
        let samples = 2.0 * self.range.len() as f64;
        0.5 * samples * (error / samples).max(1e-300).ln()
            + MDL_PENALTY * 0.5 * (PARAMS * modes + 1) as f64 * samples.ln()
    }

    /// The weighted least-squares gains of the poles of `fit`.
    pub fn gains(&self, fit: &mut Modes) {
        if fit.modes.is_empty() {
            return;
        }
        let units = self.units(fit);
        let all: Vec<usize> = (0..fit.modes.len()).collect();
        let (gram, rhs) = self.gram(&units);
        for (m, g) in fit.modes.iter_mut().zip(subset_gains(&gram, &rhs, &all)) {
            m.gain = g;
        }
    }

    /// `U^T W U` and `U^T W y` (real parts) of the columns `units` over the samples fitted.
    fn gram(&self, units: &[Vec<Complex64>]) -> (Vec<f64>, Vec<f64>) {
        let k = units.len();
        let mut gram = vec![0.0; k * k];
        let mut rhs = vec![0.0; k];
        for (i, (n, w)) in self.range.clone().zip(&self.weights).enumerate() {
            let w2 = w * w;
            for a in 0..k {
                let ua = units[a][i].conj() * w2;
                rhs[a] += (ua * self.band.samples[n]).re;
                for b in a..k {
                    gram[a * k + b] += (ua * units[b][i]).re;
                }
            }
        }
        for a in 0..k {
            for b in 0..a {
                gram[a * k + b] = gram[b * k + a];
            }
        }
        (gram, rhs)
    }

    /// Weighted squared error of the columns `units` with gains `gains`.
    fn error_of(&self, units: &[&Vec<Complex64>], gains: &[f64]) -> f64 {
        self.range
            .clone()
            .zip(&self.weights)
            .enumerate()
            .map(|(i, (n, w))| {
                let model: Complex64 = units.iter().zip(gains).map(|(u, g)| u[i] * g).sum();
                w * w * (self.band.samples[n] - model).norm_sqr()
            })
            .sum()
    }

    /// Refines every parameter of `fit` together; returns the final weighted error.
    pub fn refine(&self, fit: &mut Modes) -> f64 {
        self.refine_for(fit, MAX_ITERATIONS)
    }

    /// Refines every parameter of `fit` together, over at most `iterations`; returns the final
    /// weighted error.
    fn refine_for(&self, fit: &mut Modes, iterations: usize) -> f64 {
        let mut error = self.error(fit);
        let mut lambda = START_LAMBDA;
        for _ in 0..iterations {
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
        let dim = PARAMS * fit.modes.len() + 1;
        let mut buffers = self.jacobian.borrow_mut();
        let (jacobian, residual) = &mut *buffers;
        self.weighted_jacobian(fit, jacobian, residual);
        let products = products(jacobian, residual, dim);
        let columns = dim + 1;
        let mut normal = vec![0.0; dim * dim];
        let mut gradient = vec![0.0; dim];
        for a in 0..dim {
            gradient[a] = products[a * columns + dim];
            for b in 0..dim {
                normal[a * dim + b] = products[a.min(b) * columns + a.max(b)];
            }
        }
        (normal, gradient)
    }

    /// Writes the weighted Jacobian of `fit` by columns, and its weighted residual, each as
    /// real parts then imaginary parts: `J^T W J` is then the real part of `J^H W J`.
    fn weighted_jacobian(&self, fit: &Modes, jacobian: &mut Vec<f64>, residual: &mut Vec<f64>) {
        let modes = &fit.modes;
        let dim = PARAMS * modes.len() + 1;
        let (cols, d_tau) = self.columns(fit);
        let m = self.range.len();
        // Every entry is written below.
        jacobian.resize(dim * 2 * m, 0.0);
        residual.resize(2 * m, 0.0);
        let (re, im) = residual.split_at_mut(m);
        for ((n, &w), (re, im)) in self
            .range
            .clone()
            .zip(&self.weights)
            .zip(re.iter_mut().zip(im))
        {
            (*re, *im) = (self.band.samples[n].re * w, self.band.samples[n].im * w);
        }
        // Column by column, each written from start to end: `values` times `scale` and the
        // weights.
        let weights = &self.weights;
        let mut put = |column: usize, values: &[Complex64], scale: f64| {
            let (re, im) = jacobian[column * 2 * m..(column + 1) * 2 * m].split_at_mut(m);
            for (((re, im), v), w) in re.iter_mut().zip(im).zip(values).zip(weights) {
                let v = v * (scale * w);
                (*re, *im) = (v.re, v.im);
            }
        };
        for (k, (c, mode)) in cols.iter().zip(modes).enumerate() {
            put(PARAMS * k, &c.d_log_magnitude, mode.gain);
            put(PARAMS * k + 1, &c.d_angle, mode.gain);
            put(PARAMS * k + 2, &c.unit, 1.0);
            let (re, im) = residual.split_at_mut(m);
            for (((re, im), u), w) in re.iter_mut().zip(im).zip(&c.unit).zip(weights) {
                let v = u * (mode.gain * w);
                *re -= v.re;
                *im -= v.im;
            }
        }
        put(dim - 1, &d_tau, 1.0);
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
            .map(|(k, m)| Exp {
                s: Complex64::new(
                    (m.s.re + b[PARAMS * k].re)
                        .min(MAX_LOG_MAGNITUDE)
                        .max(self.min_log_magnitude()),
                    (m.s.im + b[PARAMS * k + 1].re).clamp(0.0, self.max_angle()),
                ),
                gain: m.gain + b[PARAMS * k + 2].re,
            })
            .collect();
        let max_tau = self.max_tau();
        Modes {
            modes,
            tau: (fit.tau + b[dim - 1].re).clamp(-max_tau, max_tau),
        }
    }

    /// Drops modes, the weakest first, while that shortens the description of the signal, then
    /// refines what is left. Returns the fit kept and its weighted error.
    ///
    /// All the modes are refined briefly, and only those whose loss would lengthen the
    /// description by less than [`CLEAR_DROP`] are dropped; the rest are refined further and
    /// dropped by the description length itself; the modes kept are refined in full. Modes are
    /// dropped with the poles held and the gains of those left solved again.
    pub fn select(&self, mut fit: Modes) -> (Modes, f64) {
        let mut error = self.refine_for(&mut fit, FIRST_ITERATIONS);
        while let Some(k) = self.unresolved(&fit) {
            fit.modes.remove(k);
            self.gains(&mut fit);
            error = self.refine_for(&mut fit, SELECTION_ITERATIONS);
        }
        self.eliminate(&mut fit, error, CLEAR_DROP);
        error = self.refine_for(&mut fit, SECOND_ITERATIONS);
        self.eliminate(&mut fit, error, 0.0);
        let error = self.refine(&mut fit);
        (fit, error)
    }

    /// Drops from `fit` (whose weighted error is `error`), the weakest first, the modes whose
    /// loss shortens the description by more than `margin`, and solves the gains of the others.
    fn eliminate(&self, fit: &mut Modes, error: f64, margin: f64) {
        let units = self.units(fit);
        let (gram, rhs) = self.gram(&units);
        let mut kept: Vec<usize> = (0..fit.modes.len()).collect();
        let mut gains: Vec<f64> = fit.modes.iter().map(|m| m.gain).collect();
        let mut length = self.description_length(kept.len(), error);
        let n = units.len();
        while !kept.is_empty() {
            // A mode's weighted energy: its gain squared times its Gram diagonal.
            let energy = |i: usize| gains[i] * gains[i] * gram[kept[i] * n + kept[i]];
            let weakest = (0..kept.len())
                .min_by(|&a, &b| energy(a).total_cmp(&energy(b)))
                .expect("not empty");
            let mut fewer = kept.clone();
            fewer.remove(weakest);
            let fewer_gains = subset_gains(&gram, &rhs, &fewer);
            let columns: Vec<&Vec<Complex64>> = fewer.iter().map(|&i| &units[i]).collect();
            let e = self.error_of(&columns, &fewer_gains);
            let fewer_length = self.description_length(fewer.len(), e);
            if fewer_length >= length - margin {
                break;
            }
            (kept, gains, length) = (fewer, fewer_gains, fewer_length);
        }
        if kept.len() < fit.modes.len() {
            fit.modes = kept
                .iter()
                .zip(&gains)
                .map(|(&i, &gain)| Exp {
                    gain,
                    ..fit.modes[i]
                })
                .collect();
        }
    }

    /// A mode the data cannot tell from another, if any: the weaker of two poles closer than
    /// half the resolution of the samples fitted in both frequency and decay, or a mode louder
    /// than the band's loudest sample (it cancels another).
    fn unresolved(&self, fit: &Modes) -> Option<usize> {
        let modes = &fit.modes;
        let resolution = RESOLUTION_SHARE / self.range.len().max(1) as f64;
        let peak = self
            .range
            .clone()
            .map(|n| self.band.samples[n].norm())
            .fold(0.0, f64::max);
        let peaks = self.peaks(fit);
        if let Some(k) = (0..modes.len()).find(|&k| peaks[k] > MAX_OVER_PEAK * peak) {
            return Some(k);
        }
        let energies = self.energies(fit);
        for a in 0..modes.len() {
            for b in a + 1..modes.len() {
                let (sa, sb) = (modes[a].s, modes[b].s);
                let d_angle = (sa.im - sb.im).abs() / TAU;
                if d_angle < resolution && (sa.re - sb.re).abs() < resolution {
                    return Some(if energies[a] < energies[b] { a } else { b });
                }
            }
        }
        None
    }

    /// Each mode's loudest sample in the band over the samples fitted.
    pub fn peaks(&self, fit: &Modes) -> Vec<f64> {
        self.units(fit)
            .iter()
            .zip(&fit.modes)
            .map(|(u, m)| u.iter().map(|v| v.norm()).fold(0.0, f64::max) * m.gain.abs())
            .collect()
    }

    /// Weighted energy of each mode over the samples fitted.
    fn energies(&self, fit: &Modes) -> Vec<f64> {
        self.units(fit)
            .iter()
            .zip(&fit.modes)
            .map(|(u, m)| {
                u.iter()
                    .zip(&self.weights)
                    .map(|(v, w)| w * w * v.norm_sqr())
                    .sum::<f64>()
                    * m.gain
                    * m.gain
            })
            .collect()
    }
}

/// The upper triangle (row-major, `dim + 1` square) of the products of the `dim` columns of
/// `jacobian` (one after another, each as long as `residual`) and `residual` (the last column:
/// its products are the gradient).
///
/// By stretches of rows short enough that every column's stretch stays in the cache while it
/// meets the others, and by blocks of columns, each loaded once for several products.
fn products(jacobian: &[f64], residual: &[f64], dim: usize) -> Vec<f64> {
    let rows_total = residual.len();
    let columns = dim + 1;
    let mut products = vec![0.0; columns * columns];
    for start in (0..rows_total).step_by(ROWS_AT_ONCE) {
        let rows = start..(start + ROWS_AT_ONCE).min(rows_total);
        let column = |a: usize| {
            let a = a.min(columns - 1);
            if a == dim {
                &residual[rows.clone()]
            } else {
                &jacobian[a * rows_total..(a + 1) * rows_total][rows.clone()]
            }
        };
        for a in (0..columns).step_by(BLOCK.0) {
            for b in (a - a % BLOCK.1..columns).step_by(BLOCK.1) {
                let block = dots(
                    std::array::from_fn(|i| column(a + i)),
                    std::array::from_fn(|j| column(b + j)),
                );
                for (i, row) in block.iter().enumerate() {
                    for (j, v) in row.iter().enumerate() {
                        let (p, q) = (a + i, b + j);
                        if p <= q && q < columns {
                            products[p * columns + q] += v;
                        }
                    }
                }
            }
        }
    }
    products
}

/// The least-squares gains of the columns `subset` of the system `gram` (`rhs` its right-hand
/// side, both over every column).
fn subset_gains(gram: &[f64], rhs: &[f64], subset: &[usize]) -> Vec<f64> {
    let (k, n) = (subset.len(), rhs.len());
    if k == 0 {
        return Vec::new();
    }
    let mut a: Vec<Complex64> = subset
        .iter()
        .flat_map(|&i| {
            subset
                .iter()
                .map(move |&j| Complex64::new(gram[i * n + j], 0.0))
        })
        .collect();
    let mut b: Vec<Complex64> = subset
        .iter()
        .map(|&i| Complex64::new(rhs[i], 0.0))
        .collect();
    solve(&mut a, &mut b, k, 1);
    b.iter().map(|g| g.re).collect()
}

#[cfg(test)]
mod tests {
    use super::super::subband::{layout, split, Splitter};
    use super::*;
    use crate::rng::Rng;

    /// Frequency in Hz, decay in 1/s and gain of each of three modes.
    const TRUTH: [(f64, f64, f64); 3] = [
        (1000.0, 300.0, 0.5),
        (1040.0, 3.0, -0.1),
        (1085.0, 40.0, 0.2),
    ];

    /// `len` samples at `rate` of [`TRUTH`] struck `delay_s` after the first, plus `noise`.
    fn strike(rate: f64, len: usize, delay_s: f64, mut noise: impl FnMut() -> f64) -> Vec<f64> {
        (0..len)
            .map(|n| {
                let t = n as f64 / rate - delay_s;
                TRUTH
                    .iter()
                    .map(|&(f, d, g)| g * (-d * t).exp() * (TAU * f * t).sin())
                    .sum::<f64>()
                    + noise()
            })
            .collect()
    }

    /// The mode of `band` at `freq_hz` decaying at `decay_per_s`, with `gain`.
    fn mode(band: &Band, freq_hz: f64, decay_per_s: f64, gain: f64) -> Exp {
        Exp {
            s: Complex64::new(
                -decay_per_s * band.dt_s,
                TAU * (freq_hz - band.base_hz) * band.dt_s,
            ),
            gain,
        }
    }

    /// The model is the band of the modes exactly, from the onset to past the end of a sound
    /// cut while it rings, in a band taken from a shortened transform too.
    #[test]
    fn the_model_is_the_band_of_its_modes() {
        let rate = 44_100.0;
        let delay = 0.3 / rate;
        let x = strike(rate, 30_000, delay, || 0.0);
        let mut splitter = Splitter::new(&x, rate);
        for samples in [usize::MAX, 300] {
            let band = splitter.band((1008.0, 1129.0), samples);
            let target = Target::new(&band, 0..band.samples.len(), 1e-12, 8);
            let fit = Modes {
                modes: TRUTH
                    .iter()
                    .map(|&(f, d, g)| mode(&band, f, d, g))
                    .collect(),
                tau: delay / band.dt_s,
            };
            let peak = band.samples.iter().map(|v| v.norm()).fold(0.0, f64::max);
            for (n, (m, y)) in target.model(&fit).iter().zip(&band.samples).enumerate() {
                assert!((m - y).norm() < 1e-9 * peak, "sample {n}: {m} for {y}");
            }
        }
    }

    /// The Jacobian's columns are the model's derivatives, by central differences.
    #[test]
    fn the_jacobian_is_the_derivative_of_the_model() {
        let rate = 44_100.0;
        let x = strike(rate, 20_000, 0.0, || 0.0);
        let mut splitter = Splitter::new(&x, rate);
        let band = splitter.band((1008.0, 1129.0), usize::MAX);
        let target = Target::new(&band, 0..band.samples.len() / 2, 1e-12, 8);
        let fit = Modes {
            modes: TRUTH
                .iter()
                .map(|&(f, d, g)| mode(&band, f + 0.3, d * 1.2, g))
                .collect(),
            tau: 0.3,
        };
        let (columns, d_tau) = target.columns(&fit);
        let nudged = |k: usize, which: usize, h: f64| {
            let mut f = fit.clone();
            match which {
                0 => f.modes[k].s.re += h,
                1 => f.modes[k].s.im += h,
                _ => f.tau += h,
            }
            target.model(&f)
        };
        let check = |got: Vec<Complex64>, k: usize, which: usize, h: f64, name: &str| {
            let (up, down) = (nudged(k, which, h), nudged(k, which, -h));
            let peak = got.iter().map(|v| v.norm()).fold(0.0, f64::max);
            assert!(peak > 0.0, "{name}");
            for (n, g) in got.iter().enumerate() {
                let want = (up[n] - down[n]) / (2.0 * h);
                assert!(
                    (g - want).norm() < 1e-5 * peak,
                    "{name} sample {n}: {g} vs {want}"
                );
            }
        };
        for (k, (c, m)) in columns.iter().zip(&fit.modes).enumerate() {
            let scaled = |v: &Vec<Complex64>| v.iter().map(|x| x * m.gain).collect();
            check(scaled(&c.d_log_magnitude), k, 0, 1e-7, "log-magnitude");
            check(scaled(&c.d_angle), k, 1, 1e-7, "angle");
        }
        check(d_tau, 0, 2, 1e-4, "strike time");
    }

    /// Strikes of known modes, one above its band's centre, with the strike a little after the
    /// onset, are recovered from the band's first sample.
    #[test]
    fn refinement_recovers_exact_modes_and_selection_drops_a_spurious_one() {
        let rate = 48_000.0;
        let delay = 0.4 / rate;
        let mut rng = Rng::new(11);
        let x = strike(rate, 24_000, delay, || 1e-5 * rng.bipolar() as f64);
        let bands = split(&x, rate, &layout(900.0, 1200.0));
        let band = bands
            .iter()
            .find(|b| (b.core_hz.0..b.core_hz.1).contains(&1040.0))
            .unwrap();
        let target = Target::new(band, 0..band.samples.len(), 1e-10, 8);
        let guess = |f: f64, d: f64| mode(band, f, d, 0.0);
        let mut start = Modes {
            modes: TRUTH
                .iter()
                .map(|&(f, d, _)| guess(f + 0.1, d * 1.1))
                .collect(),
            tau: 0.0,
        };
        // A spurious mode where there is only noise.
        start.modes.push(guess(1060.0, 20.0));
        target.gains(&mut start);
        let (kept, _) = target.select(start);
        assert_eq!(kept.modes.len(), 3, "{kept:?}");
        for &(f, d, g) in &TRUTH {
            let got = kept
                .modes
                .iter()
                .map(|m| (band.mode_of_log_pole(m.s), m.gain))
                .min_by(|a, b| (a.0 .0 - f).abs().total_cmp(&(b.0 .0 - f).abs()))
                .unwrap();
            let ((f2, d2), g2) = got;
            assert!((f2 - f).abs() < 0.01, "{f2} Hz for {f}");
            assert!((d2 - d).abs() < 0.01 * d, "{d2}/s for {d}");
            assert!((g2 - g).abs() < 1e-3 * g.abs(), "gain {g2} for {g}");
        }
        let delay_s = kept.tau * band.dt_s;
        assert!((delay_s - delay).abs() < 0.05 / rate, "{delay_s} s");
    }
}
