//! Frequency sub-bands of a recording, each a short complex signal at a low sample rate in which
//! a mode is still a decaying complex exponential (Sirdey, Derrien, Kronland-Martinet and
//! Aramaki, "Modal analysis of impact sounds with ESPRIT in Gabor transforms", DAFx 2011).
//!
//! The sound after the onset is transformed once (or a few times, cut shorter for the wide bands,
//! whose fits span less time); each band takes the bins of its range, tapered at both ends, and
//! transforms them back with an FFT as long as the band is wide. The
//! result is the band's part of the signal, shifted down by the band's lowest frequency and
//! sampled `fs * len / fft_len` times a second: a mode `Re(c exp((-d + i w) t))` inside the band
//! becomes `(c / 2) exp((-d + i (w - w_base)) t)`. Narrow bands at low frequencies resolve close
//! modes over long spans; wide ones at high frequencies follow fast decays.

use std::f64::consts::TAU;
use std::sync::Arc;

use realfft::num_complex::Complex64;
use realfft::RealFftPlanner;
use rustfft::{Fft, FftPlanner};

/// Narrowest band core, in Hz: below `MIN_CORE_HZ / RELATIVE_CORE` the cores have this width.
const MIN_CORE_HZ: f64 = 60.0;

/// Width of a band's core relative to its lowest frequency (about two semitones).
const RELATIVE_CORE: f64 = 0.12;

/// Each band reaches this many core widths beyond its core on either side: modes near a core's
/// edge are measured whole, and only the outer half of the margin is tapered.
const MARGIN_CORES: f64 = 1.0;

/// Share of the margin left untapered, next to the core.
const FLAT_MARGIN: f64 = 0.4;

/// Narrowest taper in Hz: the band filter smears the onset over about its inverse, so a narrow
/// band at low frequencies still sees a quick decay after a short skip.
const MIN_TAPER_HZ: f64 = 150.0;

/// Samples left out at the start of a band, in units of the inverse taper width: the band filter
/// smears the abrupt start of the sound over about that long.
const SETTLE_TAPERS: f64 = 2.0;

/// Silence after the sound in its transform, in seconds: twice the stretch the narrowest taper
/// smears (see [`SETTLE_TAPERS`]).
const WRAP_S: f64 = 2.0 * SETTLE_TAPERS / MIN_TAPER_HZ;

/// Most samples of sound a band holds: a longer sound is cut there (a band's fit spans at most
/// some 6,000 of its samples, see [`bandfit`](super::bandfit)).
const MAX_BAND_SAMPLES: usize = 8192;

/// One band of a recording.
#[derive(Debug, Clone)]
pub struct Band {
    /// Frequencies whose modes this band measures, in Hz: cores tile the range searched.
    pub core_hz: (f64, f64),
    /// Frequency shifted to 0 in `samples`, in Hz.
    pub base_hz: f64,
    /// Time between two samples, in seconds.
    pub dt_s: f64,
    /// First sample clear of the band filter's smear of the onset.
    pub first: usize,
    /// The band's signal, sample 0 at the onset, up to the end of the sound and the stretch the
    /// band filter smears beyond it.
    pub samples: Vec<Complex64>,
    /// Lowest bin of the sound's spectrum the band takes.
    pub first_bin: usize,
    /// Length of the transform of the sound.
    pub fft_len: usize,
    /// Samples of sound transformed: the sound stops abruptly there.
    pub sound_len: usize,
    /// Gain of each bin taken, the taper over the transform's length.
    pub taper: Vec<f64>,
}

impl Band {
    /// Frequency in Hz and decay in 1/s of a pole `z` per sample of this band.
    #[cfg(test)]
    pub fn mode_of_pole(&self, z: Complex64) -> (f64, f64) {
        self.mode_of_log_pole(log_pole(z))
    }

    /// Frequency in Hz and decay in 1/s of the pole `exp(s)` per sample of this band, its angle
    /// `s.im` counted from the band's base frequency.
    pub fn mode_of_log_pole(&self, s: Complex64) -> (f64, f64) {
        (self.base_hz + s.im / (TAU * self.dt_s), -s.re / self.dt_s)
    }

    /// Samples of the sound per sample of this band.
    pub fn decimation(&self) -> f64 {
        self.fft_len as f64 / self.taper.len() as f64
    }

    /// The pole per sample of this band of a mode at `freq_hz` decaying at `decay_per_s`.
    #[cfg(test)]
    pub fn pole_of_mode(&self, freq_hz: f64, decay_per_s: f64) -> Complex64 {
        Complex64::from_polar(
            (-decay_per_s * self.dt_s).exp(),
            TAU * (freq_hz - self.base_hz) * self.dt_s,
        )
    }
}

/// The logarithm of a pole per sample of a band, its angle in `0..2 pi`: every frequency of a
/// band lies above its base.
pub fn log_pole(z: Complex64) -> Complex64 {
    let angle = z.arg();
    Complex64::new(
        z.norm().max(1e-300).ln(),
        if angle < 0.0 { angle + TAU } else { angle },
    )
}

/// The cores of the bands that tile `min_hz..max_hz`.
pub fn layout(min_hz: f64, max_hz: f64) -> Vec<(f64, f64)> {
    let mut cores = Vec::new();
    let mut lo = min_hz;
    while lo < max_hz {
        let hi = (lo + MIN_CORE_HZ.max(RELATIVE_CORE * lo)).min(max_hz);
        cores.push((lo, hi));
        lo = hi;
    }
    cores
}

/// Makes the bands of a sound, sharing the transforms of its start among them.
pub struct Splitter<'a> {
    /// The sound, time 0 at `x[0]`.
    x: &'a [f64],
    /// Its sample rate in Hz.
    sample_rate_hz: f64,
    /// Spectra of the start of the sound (half the transform long), by transform length.
    spectra: Vec<(usize, Vec<Complex64>)>,
}

impl<'a> Splitter<'a> {
    /// Bands of `x` at `sample_rate_hz`.
    pub fn new(x: &'a [f64], sample_rate_hz: f64) -> Self {
        Self {
            x,
            sample_rate_hz,
            spectra: Vec::new(),
        }
    }

    /// The band of `core`, holding at least `samples` of its own samples of sound (at most
    /// [`MAX_BAND_SAMPLES`]), or all of it when it is shorter.
    pub fn band(&mut self, core: (f64, f64), samples: usize) -> Band {
        let (_, taper_hz, _) = shape(core);
        let span_hz = (1.0 + 2.0 * FLAT_MARGIN * MARGIN_CORES) * (core.1 - core.0) + 2.0 * taper_hz;
        let samples = samples.min(MAX_BAND_SAMPLES) as f64;
        let wanted = (samples * self.sample_rate_hz / span_hz).ceil() as usize;
        // Room after the sound for the band filter's smear of its end, which would otherwise
        // wrap round onto its start.
        let room = (WRAP_S * self.sample_rate_hz).ceil() as usize;
        let fft_len = fast_len(self.x.len().min(wanted) + room).max(32);
        let len = self.x.len().min(fft_len - room);
        let index = match self.spectra.iter().position(|(n, _)| *n == fft_len) {
            Some(i) => i,
            None => {
                // A planner of its own, as for the bands' (see `band`).
                let forward = RealFftPlanner::new().plan_fft_forward(fft_len);
                let mut input = forward.make_input_vec();
                input[..len].copy_from_slice(&self.x[..len]);
                let mut spectrum = forward.make_output_vec();
                forward
                    .process(&mut input, &mut spectrum)
                    .expect("buffers come from the plan");
                self.spectra.push((fft_len, spectrum));
                self.spectra.len() - 1
            }
        };
        let bin_hz = self.sample_rate_hz / fft_len as f64;
        band(&self.spectra[index].1, bin_hz, fft_len, len, core)
    }
}

/// The bands of `x` (time 0 at `x[0]`) over `cores`, each holding as much of the sound as it
/// can (see [`Splitter::band`]).
#[cfg(test)]
pub fn split(x: &[f64], sample_rate_hz: f64, cores: &[(f64, f64)]) -> Vec<Band> {
    let mut splitter = Splitter::new(x, sample_rate_hz);
    cores
        .iter()
        .map(|&core| splitter.band(core, usize::MAX))
        .collect()
}

/// The least `2^a 3^b` at or above `n`.
fn fast_len(n: usize) -> usize {
    let mut best = n.next_power_of_two();
    let mut three = 1;
    while three < best {
        let candidate = three * (n.div_ceil(three)).next_power_of_two();
        best = best.min(candidate);
        three *= 3;
    }
    best
}

/// The untapered range of the band of `core`, the width of its tapers, and its core's width,
/// in Hz.
fn shape(core_hz: (f64, f64)) -> ((f64, f64), f64, f64) {
    let width = core_hz.1 - core_hz.0;
    let taper_hz = ((1.0 - FLAT_MARGIN) * MARGIN_CORES * width).max(MIN_TAPER_HZ);
    let flat = (
        core_hz.0 - FLAT_MARGIN * MARGIN_CORES * width,
        core_hz.1 + FLAT_MARGIN * MARGIN_CORES * width,
    );
    (flat, taper_hz, width)
}

/// One band from the spectrum of the sound.
fn band(
    spectrum: &[Complex64],
    bin_hz: f64,
    fft_len: usize,
    len: usize,
    core_hz: (f64, f64),
) -> Band {
    let (flat, taper_hz, _) = shape(core_hz);
    let last_bin = spectrum.len() - 1;
    let k0 = (((flat.0 - taper_hz) / bin_hz).floor().max(0.0) as usize).min(last_bin);
    let k1 = (((flat.1 + taper_hz) / bin_hz).ceil() as usize).clamp(k0 + 1, last_bin + 1);
    // As many bins as a quick transform takes, those past the band's end at zero gain.
    let bins = fast_len(k1 - k0);
    let k1 = k0 + bins;
    let taper: Vec<f64> = (k0..k1)
        .map(|k| {
            let f = k as f64 * bin_hz;
            let outside = (flat.0 - f).max(f - flat.1).max(0.0) / taper_hz;
            let gain = if outside >= 1.0 || k > last_bin {
                0.0
            } else {
                0.5 + 0.5 * (std::f64::consts::PI * outside).cos()
            };
            gain / fft_len as f64
        })
        .collect();
    let mut buffer: Vec<Complex64> = (k0..k1)
        .zip(&taper)
        .map(|(k, g)| spectrum.get(k).map_or(Complex64::new(0.0, 0.0), |v| v * g))
        .collect();
    // A planner of its own: one that has planned other lengths may build this one from
    // other parts, which changes the last bits, and the bank would depend on the order the
    // bands are made in (and so on the number of threads making them).
    let inverse: Arc<dyn Fft<f64>> = FftPlanner::new().plan_fft_inverse(bins);
    inverse.process(&mut buffer);
    let dt_s = 1.0 / (bins as f64 * bin_hz);
    let first = (SETTLE_TAPERS / (taper_hz * dt_s)).ceil() as usize;
    // The band filter smears the end of the sound as it does its start.
    let end = ((len as f64 * bins as f64 / fft_len as f64).ceil() as usize + first).min(bins);
    buffer.truncate(end);
    Band {
        core_hz,
        base_hz: k0 as f64 * bin_hz,
        dt_s,
        first,
        samples: buffer,
        first_bin: k0,
        fft_len,
        sound_len: len,
        taper,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mode_in_a_band_is_a_decaying_exponential_of_half_its_amplitude() {
        let rate = 48_000.0;
        let (f, d, a) = (1234.5, 6.0, 0.8);
        let x: Vec<f64> = (0..48_000)
            .map(|n| {
                let t = n as f64 / rate;
                a * (-d * t).exp() * (TAU * f * t).sin()
            })
            .collect();
        let cores = layout(20.0, 20_000.0);
        assert!(cores.windows(2).all(|w| w[0].1 == w[1].0));
        let bands = split(&x, rate, &cores);
        let b = bands
            .iter()
            .find(|b| (b.core_hz.0..b.core_hz.1).contains(&f))
            .unwrap();
        let z = b.pole_of_mode(f, d);
        // sin = Re(-i e^{iwt}): c = -i a, so the band holds (-i a / 2) z^n.
        let c = Complex64::new(0.0, -a / 2.0);
        let mid = b.samples.len() / 3;
        // The band filter's smear of the onset is of the order of 1e-3 at the first sample
        // clear of it, and gone well before the middle.
        for (n, tolerance) in [(b.first, 2e-3), (mid, 1e-4)] {
            let want = c * z.powu(n as u32);
            let got = b.samples[n];
            assert!(
                (got - want).norm() < tolerance * want.norm(),
                "sample {n}: {got} vs {want}"
            );
        }
        let (f2, d2) = b.mode_of_pole(z);
        assert!((f2 - f).abs() < 1e-9 && (d2 - d).abs() < 1e-9);
    }
}
