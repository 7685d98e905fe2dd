//! The modes of one band: ESPRIT's poles as the start, then the weighted joint refinement and
//! the choice of how many to keep ([`refine`](super::refine)).

use realfft::num_complex::Complex64;

use super::esprit::{esprit, MIN_SAMPLES};
use super::refine::{Exp, Modes, Target};
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

/// Share of its core's width beyond either edge of the core within which a band keeps the modes
/// it finds: a mode on the boundary of two cores is kept by both, and [`dedupe`] keeps one. It
/// stays inside the untapered part of the band (see [`subband`](super::subband)), where the
/// band filter's smear of the onset does not reach.
const CORE_REACH: f64 = 0.25;

/// Two findings in neighbouring bands are the same mode when their frequencies differ by less
/// than this many Hz...
const SAME_MODE_HZ: f64 = 0.1;

/// ... or less than this share of the modes' bandwidth, `d / pi`.
const SAME_MODE_BANDWIDTHS: f64 = 0.05;

/// ... or less than this share of the frequency resolution of the longer of their fits.
const SAME_MODE_RESOLUTIONS: f64 = 0.5;

/// Share of the band's settling stretch the refinement still fits: ESPRIT starts after all of
/// it, where the band holds pure exponentials, but fitting the second half too keeps modes from
/// summing, before the first sample fitted, to an onset louder than the recording's.
const FIT_FROM_SETTLE: f64 = 0.5;

/// A mode must start, at the band's first clean sample, at least this many times the noise's
/// RMS: a weaker one is never heard above it and fits the noise or the band filter's smear.
const MIN_LEVEL_OVER_NOISE: f64 = 2.0;

/// A pole whose log-magnitude is within 1% of the lowest allowed is held at that bound.
const AT_BOUND: f64 = 0.99;

/// A mode measured in a band.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BandMode {
    /// Frequency in Hz.
    pub freq_hz: f64,
    /// Decay rate in 1/s.
    pub decay_per_s: f64,
    /// Complex amplitude at the onset: `x = Re(c exp(s t))`.
    pub amplitude: Complex64,
    /// Signed gain at the strike, which the band's fit places a little after or before the
    /// onset: `a exp(-d (t - t_s)) sin(w (t - t_s))`.
    pub gain: f64,
    /// Samples of the band the mode was fitted over.
    pub samples: usize,
    /// Amplitude of the mode where the fit starts over the band's noise, in dB.
    pub snr_db: f64,
    /// Frequency resolution of the fit, the inverse of its span, in Hz.
    pub resolution_hz: f64,
    /// Index of the band it was found in.
    pub band: usize,
    /// Distance of the mode from the centre of its band's core, in core widths.
    pub off_centre: f64,
}

/// Sorts `modes` by frequency and keeps one of each mode found in two neighbouring bands: the
/// one nearer its band's centre.
pub fn dedupe(modes: &mut Vec<BandMode>) {
    modes.sort_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
    let mut kept: Vec<BandMode> = Vec::with_capacity(modes.len());
    for m in modes.drain(..) {
        let bandwidth_hz = (m.decay_per_s + kept.last().map_or(0.0, |l| l.decay_per_s))
            / (2.0 * std::f64::consts::PI);
        let resolution_hz = m
            .resolution_hz
            .max(kept.last().map_or(0.0, |l| l.resolution_hz));
        let tolerance = SAME_MODE_HZ
            .max(SAME_MODE_BANDWIDTHS * bandwidth_hz)
            .max(SAME_MODE_RESOLUTIONS * resolution_hz);
        match kept.last_mut() {
            Some(last) if m.freq_hz - last.freq_hz < tolerance && m.band != last.band => {
                if m.off_centre < last.off_centre {
                    *last = m;
                }
            }
            _ => kept.push(m),
        }
    }
    *modes = kept;
}

/// The modes whose frequencies lie in the core of `band` (or near it, see [`CORE_REACH`]);
/// `index` tells the band apart from others.
pub fn fit_band(band: &Band, index: usize) -> Vec<BandMode> {
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
    let beta = std::f64::consts::TAU * band.base_hz * band.dt_s;
    let from = (band.first as f64 * FIT_FROM_SETTLE) as usize;
    let target = Target::new(y, from..end, estimate.noise_var, smooth, beta);
    let magnitudes = target.min_log_magnitude().exp()..=(-1e-6f64).exp();
    let mut start = Modes {
        modes: estimate
            .poles
            .iter()
            .map(|&z| Exp {
                z: z / z.norm() * z.norm().clamp(*magnitudes.start(), *magnitudes.end()),
                gain: 0.0,
            })
            .collect(),
        tau: 0.0,
    };
    target.gains(&mut start);
    let (kept, _) = target.select(start);
    let noise = estimate.noise_var.sqrt().max(1e-300);
    let delay_s = kept.tau * band.dt_s;
    kept.modes
        .iter()
        .filter_map(|m| {
            let (freq_hz, decay_per_s) = band.mode_of_pole(m.z);
            let reach = CORE_REACH * (band.core_hz.1 - band.core_hz.0);
            let inside = freq_hz >= band.core_hz.0 - reach && freq_hz < band.core_hz.1 + reach;
            // a exp(-d (t - t_s)) sin(w (t - t_s)) is Re(c exp((-d + i w) t)) with this c.
            let pole_s = Complex64::new(-decay_per_s, std::f64::consts::TAU * freq_hz);
            let amplitude = Complex64::new(0.0, -m.gain) * (-pole_s * delay_s).exp();
            let level = 0.5
                * m.gain.abs()
                * (-decay_per_s * (band.first as f64 * band.dt_s - delay_s)).exp();
            // A pole held at the fastest decay allowed was not measured: the fit pushed it
            // there to match the band filter's smear of the onset.
            let measured = m.z.norm().ln() > AT_BOUND * target.min_log_magnitude();
            (inside && measured && level > MIN_LEVEL_OVER_NOISE * noise).then(|| BandMode {
                freq_hz,
                decay_per_s,
                amplitude,
                gain: m.gain,
                samples: end - band.first,
                snr_db: 20.0 * (level / noise).log10(),
                band: index,
                resolution_hz: 1.0 / ((end - band.first) as f64 * band.dt_s),
                off_centre: (freq_hz - 0.5 * (band.core_hz.0 + band.core_hz.1)).abs()
                    / (band.core_hz.1 - band.core_hz.0),
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
