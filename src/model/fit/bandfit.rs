//! The modes of one band: ESPRIT's poles as the start, then the weighted joint refinement and
//! the choice of how many to keep ([`refine`](super::refine)).

use realfft::num_complex::Complex64;

use super::esprit::{esprit, MIN_SAMPLES};
use super::refine::{Exp, Target};
use super::subband::Band;

/// Most modes a band may hold (its core spans about two semitones).
const MAX_ORDER: usize = 14;

/// Most samples of a band ESPRIT's covariance is taken over: the first of them, where the modes
/// are loudest.
const MAX_ESPRIT_SAMPLES: usize = 4096;

/// Most samples of a band refined over.
const MAX_FIT_SAMPLES: usize = 6000;

/// Span of the running mean of the band's power that weights the refinement, in seconds.
const SMOOTH_S: f64 = 0.01;

/// The fit ends where the band's running power stays below this many times its noise's.
const END_ABOVE_NOISE: f64 = 2.0;

/// A mode measured in a band.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BandMode {
    /// Frequency in Hz.
    pub freq_hz: f64,
    /// Decay rate in 1/s.
    pub decay_per_s: f64,
    /// Complex amplitude at the onset, as the least squares gives it: `x = Re(c exp(s t))`.
    pub amplitude: Complex64,
    /// Samples of the band the mode was fitted over.
    pub samples: usize,
    /// Amplitude of the mode where the fit starts over the band's noise, in dB.
    pub snr_db: f64,
}

/// The modes whose frequencies lie in the core of `band`.
pub fn fit_band(band: &Band) -> Vec<BandMode> {
    let y = &band.samples;
    if y.len() < band.first + MIN_SAMPLES {
        return Vec::new();
    }
    let data = &y[band.first..];
    let Some(estimate) = esprit(&data[..data.len().min(MAX_ESPRIT_SAMPLES)], MAX_ORDER) else {
        return Vec::new();
    };
    if estimate.poles.is_empty() {
        return Vec::new();
    }
    let smooth = ((SMOOTH_S / band.dt_s) as usize).max(4);
    let end = sound_end(y, band.first, smooth, estimate.noise_var)
        .min(band.first + MAX_FIT_SAMPLES)
        .max(band.first + MIN_SAMPLES);
    let target = Target::new(y, band.first..end, estimate.noise_var, smooth);
    let max_magnitude = (-1e-6f64).exp();
    let mut modes: Vec<Exp> = estimate
        .poles
        .iter()
        .map(|&z| Exp {
            z: if z.norm() > max_magnitude {
                z / z.norm() * max_magnitude
            } else {
                z
            },
            c: Complex64::new(0.0, 0.0),
        })
        .collect();
    target.amplitudes(&mut modes);
    let (kept, _) = target.select(modes);
    let noise = estimate.noise_var.sqrt().max(1e-300);
    kept.iter()
        .filter_map(|m| {
            let (freq_hz, decay_per_s) = band.mode_of_pole(m.z);
            let inside = freq_hz >= band.core_hz.0 && freq_hz < band.core_hz.1;
            let level = (m.c * m.z.powu(band.first as u32)).norm();
            (inside && level > 0.0).then(|| BandMode {
                freq_hz,
                decay_per_s,
                // The band holds half the real mode (its positive frequency).
                amplitude: 2.0 * m.c,
                samples: end - band.first,
                snr_db: 20.0 * (level / noise).log10(),
            })
        })
        .collect()
}

/// One past the last sample from `first` whose running power over `smooth` samples stands above
/// the noise.
fn sound_end(y: &[Complex64], first: usize, smooth: usize, noise_var: f64) -> usize {
    let mut sum = 0.0;
    let mut end = first;
    for n in first..y.len() {
        sum += y[n].norm_sqr();
        if n >= first + smooth {
            sum -= y[n - smooth].norm_sqr();
        }
        let count = (n + 1 - first).min(smooth) as f64;
        if sum / count > END_ABOVE_NOISE * noise_var {
            end = n + 1;
        }
    }
    end
}
