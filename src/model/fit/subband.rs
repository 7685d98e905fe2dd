//! Frequency sub-bands of a recording, each a short complex signal at a low sample rate in which
//! a mode is still a decaying complex exponential (Sirdey, Derrien, Kronland-Martinet and
//! Aramaki, "Modal analysis of impact sounds with ESPRIT in Gabor transforms", DAFx 2011).
//!
//! The whole sound after the onset is transformed once; each band takes the bins of its range,
//! tapered at both ends, and transforms them back with an FFT as long as the band is wide. The
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
    /// The band's signal, sample 0 at the onset, up to the end of the sound (less the stretch
    /// the band filter smears there).
    pub samples: Vec<Complex64>,
}

impl Band {
    /// Frequency in Hz and decay in 1/s of a pole `z` per sample of this band.
    pub fn mode_of_pole(&self, z: Complex64) -> (f64, f64) {
        let span_hz = 1.0 / self.dt_s;
        let mut rel_hz = z.arg() / (TAU * self.dt_s);
        if rel_hz < 0.0 {
            rel_hz += span_hz;
        }
        (
            self.base_hz + rel_hz,
            -z.norm().max(1e-300).ln() / self.dt_s,
        )
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

/// The bands of `x` (time 0 at `x[0]`) over `cores`, each holding the sound up to `x.len()`.
pub fn split(x: &[f64], sample_rate_hz: f64, cores: &[(f64, f64)]) -> Vec<Band> {
    let fft_len = (2 * x.len()).next_power_of_two().max(64);
    let mut real = RealFftPlanner::<f64>::new();
    let forward = real.plan_fft_forward(fft_len);
    let mut input = forward.make_input_vec();
    input[..x.len()].copy_from_slice(x);
    let mut spectrum = forward.make_output_vec();
    forward
        .process(&mut input, &mut spectrum)
        .expect("buffers come from the plan");
    let bin_hz = sample_rate_hz / fft_len as f64;
    let mut planner = FftPlanner::<f64>::new();
    cores
        .iter()
        .map(|&core| band(&spectrum, bin_hz, fft_len, x.len(), core, &mut planner))
        .collect()
}

/// One band from the spectrum of the whole sound.
fn band(
    spectrum: &[Complex64],
    bin_hz: f64,
    fft_len: usize,
    len: usize,
    core_hz: (f64, f64),
    planner: &mut FftPlanner<f64>,
) -> Band {
    let width = core_hz.1 - core_hz.0;
    let taper_hz = ((1.0 - FLAT_MARGIN) * MARGIN_CORES * width).max(MIN_TAPER_HZ);
    let flat = (
        core_hz.0 - FLAT_MARGIN * MARGIN_CORES * width,
        core_hz.1 + FLAT_MARGIN * MARGIN_CORES * width,
    );
    let last_bin = spectrum.len() - 1;
    let k0 = (((flat.0 - taper_hz) / bin_hz).floor().max(0.0) as usize).min(last_bin);
    let k1 = (((flat.1 + taper_hz) / bin_hz).ceil() as usize).clamp(k0 + 1, last_bin + 1);
    let bins = k1 - k0;
    let mut buffer: Vec<Complex64> = (k0..k1)
        .map(|k| {
            let f = k as f64 * bin_hz;
            let outside = (flat.0 - f).max(f - flat.1).max(0.0) / taper_hz;
            let gain = if outside >= 1.0 {
                0.0
            } else {
                0.5 + 0.5 * (std::f64::consts::PI * outside).cos()
            };
            spectrum[k] * (gain / fft_len as f64)
        })
        .collect();
    let inverse: Arc<dyn Fft<f64>> = planner.plan_fft_inverse(bins);
    inverse.process(&mut buffer);
    let dt_s = 1.0 / (bins as f64 * bin_hz);
    // The band filter smears the end of the recording too, where a sound cut short stops
    // abruptly: that stretch is left out as the start is.
    let first = (SETTLE_TAPERS / (taper_hz * dt_s)).ceil() as usize;
    let end = ((len as f64 * bins as f64 / fft_len as f64) as usize).min(bins);
    buffer.truncate(end.saturating_sub(first));
    Band {
        core_hz,
        base_hz: k0 as f64 * bin_hz,
        dt_s,
        first,
        samples: buffer,
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
        for n in [b.first, mid] {
            let want = c * z.powu(n as u32);
            let got = b.samples[n];
            assert!(
                (got - want).norm() < 1e-3 * want.norm(),
                "sample {n}: {got} vs {want}"
            );
        }
        let (f2, d2) = b.mode_of_pole(z);
        assert!((f2 - f).abs() < 1e-9 && (d2 - d).abs() < 1e-9);
    }
}
