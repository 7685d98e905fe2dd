//! The modes of one band: ESPRIT's poles as the start, then the weighted joint refinement and
//! the choice of how many to keep ([`refine`](super::refine)).

use realfft::num_complex::Complex64;

use super::esprit::{esprit, Estimate, MIN_SAMPLES};
use super::refine::{Exp, Modes, Target};
use super::subband::{log_pole, Band, Splitter};

/// Most modes a band may hold when its core spans about two semitones...
const MAX_ORDER: usize = 14;

/// ... and at most when it spans more (the cores of one width at low frequencies, where a drum
/// or a timpani packs its partials closest).
const MAX_ORDER_WIDE: usize = 24;

/// Most modes the band of `core` may hold: [`MAX_ORDER`] per two semitones.
fn max_order(core: (f64, f64)) -> usize {
    let semitones = 12.0 * (core.1 / core.0).log2();
    ((MAX_ORDER as f64 * semitones / 2.0).round() as usize).clamp(MAX_ORDER, MAX_ORDER_WIDE)
}

/// Most samples of a band ESPRIT's covariance is taken over: the first of them clear of the
/// band filter's smear of the onset, where the modes are loudest.
const MAX_ESPRIT_SAMPLES: usize = 4096;

/// Most samples of a band refined over.
const MAX_FIT_SAMPLES: usize = 6000;

/// A band is made at least this many times as long as the samples it fits (and the stretch
/// the band filter smears): the sound goes on past them, so the band filter's smear of the
/// place it is cut off stays clear of them.
const SPARE_LENGTH: f64 = 1.5;

/// Span of the running mean of the band's power that weights the refinement, in seconds.
const SMOOTH_S: f64 = 0.01;

/// The fit ends where the band's running power stays below this many times its noise's.
const END_ABOVE_NOISE: f64 = 2.0;

/// Share of its core's width beyond either edge of the core within which a band keeps the modes
/// it finds: a mode on the boundary of two cores is kept by both, and [`dedupe`] keeps one. It
/// stays inside the untapered part of the band (see [`subband`](super::subband)).
const CORE_REACH: f64 = 0.25;

/// A mode outside its band's core is the neighbouring band's when that band found one within
/// this many frequency resolutions of it (or within their bandwidths).
const OWNED_RESOLUTIONS: f64 = 3.0;

/// A mode within that distance of one this many times louder (20 dB) both at the strike and at
/// the end of the sound is left out.
const MASKED_RATIO: f64 = 10.0;

/// Two findings in neighbouring bands are the same mode when their frequencies differ by less
/// than this many Hz...
const SAME_MODE_HZ: f64 = 0.1;

/// ... or less than this share of the modes' bandwidth, `d / pi`.
const SAME_MODE_BANDWIDTHS: f64 = 0.05;

/// ... or less than this share of the frequency resolution of the longer of their fits.
const SAME_MODE_RESOLUTIONS: f64 = 0.5;

/// A mode's loudest sample in the band must stand at least this many times above the noise's
/// RMS: a weaker one is never heard above it and fits the noise.
const MIN_LEVEL_OVER_NOISE: f64 = 2.0;

/// Least quality factor `pi f / d` of a mode kept: its amplitude falls by `e^-pi` over a cycle.
const MIN_Q: f64 = 1.0;

/// Decay of the click a band's fit starts with, as a share of the fastest allowed.
const CLICK_DECAY_SHARE: f64 = 0.5;

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
/// one found in the band whose core holds it, else the one nearer its band's centre. Leaves out
/// a mode [`MASKED_RATIO`] under an overlapping neighbour from the strike to the end of the
/// sound (`sound_s` long).
pub fn dedupe(modes: &mut Vec<BandMode>, sound_s: f64) {
    modes.sort_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
    // A mode found outside its band's core is the neighbour's to measure: it stays only when
    // the neighbour found nothing there.
    let owned: Vec<bool> = modes
        .iter()
        .map(|m| {
            m.off_centre > 0.5
                && modes.iter().any(|n| {
                    n.band != m.band && n.off_centre <= 0.5 && {
                        let tolerance = (OWNED_RESOLUTIONS * m.resolution_hz.max(n.resolution_hz))
                            .max((m.decay_per_s + n.decay_per_s) / std::f64::consts::TAU);
                        (m.freq_hz - n.freq_hz).abs() < tolerance
                    }
                })
        })
        .collect();
    let mut flags = owned.into_iter();
    modes.retain(|_| !flags.next().expect("one flag a mode"));
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
    // A mode far weaker than a neighbour it overlaps, from the strike to the end of the sound,
    // is the fit's rounding of that neighbour.
    let level = |m: &BandMode, t: f64| m.gain.abs() * (-m.decay_per_s * t).exp();
    let masked: Vec<bool> = kept
        .iter()
        .map(|m| {
            kept.iter().any(|n| {
                let tolerance = (OWNED_RESOLUTIONS * m.resolution_hz.max(n.resolution_hz))
                    .max((m.decay_per_s + n.decay_per_s) / std::f64::consts::TAU);
                (m.freq_hz - n.freq_hz).abs() < tolerance
                    && [0.0, sound_s]
                        .iter()
                        .all(|&t| level(m, t) * MASKED_RATIO < level(n, t))
            })
        })
        .collect();
    let mut flags = masked.into_iter();
    kept.retain(|_| !flags.next().expect("one flag a mode"));
    *modes = kept;
}

/// The modes whose frequencies lie in the core of `band` (or near it, see [`CORE_REACH`]);
/// `index` tells the band apart from others.
pub fn fit_band(splitter: &mut Splitter, core: (f64, f64), index: usize) -> Vec<BandMode> {
    let mut band = splitter.band(core, usize::MAX);
    let mut measured = measure(&band);
    // A band longer than its sound is made again, cut shorter: the fit's cost grows with the
    // band's length.
    if let Some((_, end)) = measured {
        let wanted = (SPARE_LENGTH * (end + band.first) as f64) as usize;
        if wanted + wanted / 4 < band.samples.len() {
            band = splitter.band(core, wanted);
            measured = measure(&band);
        }
    }
    let Some((estimate, end)) = measured else {
        return Vec::new();
    };
    let smooth = smoothing(&band);
    let target = Target::new(&band, 0..end, estimate.noise_var, smooth);
    let min_log_magnitude = target.min_log_magnitude();
    let mut start = Modes {
        modes: estimate
            .poles
            .iter()
            .map(|&z| {
                let s = log_pole(z);
                Exp {
                    s: Complex64::new(s.re.clamp(min_log_magnitude, -1e-6), s.im),
                    gain: 0.0,
                }
            })
            .collect(),
        tau: 0.0,
    };
    // A quick mode at the core's centre for the strike's click, which dies before ESPRIT's
    // first sample; the selection keeps it only if the band's start needs it.
    let centre_hz = 0.5 * (band.core_hz.0 + band.core_hz.1);
    start.modes.push(Exp {
        s: Complex64::new(
            CLICK_DECAY_SHARE * min_log_magnitude,
            std::f64::consts::TAU * (centre_hz - band.base_hz) * band.dt_s,
        ),
        gain: 0.0,
    });
    target.gains(&mut start);
    let (kept, _) = target.select(start);
    let noise = estimate.noise_var.sqrt().max(1e-300);
    let delay_s = kept.tau * band.dt_s;
    let peaks = target.peaks(&kept);
    kept.modes
        .iter()
        .zip(peaks)
        .filter_map(|(m, level)| {
            let (freq_hz, decay_per_s) = band.mode_of_log_pole(m.s);
            let reach = CORE_REACH * (band.core_hz.1 - band.core_hz.0);
            let inside = freq_hz >= band.core_hz.0 - reach && freq_hz < band.core_hz.1 + reach;
            // a exp(-d (t - t_s)) sin(w (t - t_s)) is Re(c exp((-d + i w) t)) with this c.
            let pole_s = Complex64::new(-decay_per_s, std::f64::consts::TAU * freq_hz);
            let amplitude = Complex64::new(0.0, -m.gain) * (-pole_s * delay_s).exp();
            // A mode that dies within a cycle is no resonance: it stands in for the band
            // filter's view of the start of louder modes outside the band.
            let rings = std::f64::consts::PI * freq_hz >= MIN_Q * decay_per_s;
            (inside && rings && level > MIN_LEVEL_OVER_NOISE * noise).then(|| BandMode {
                freq_hz,
                decay_per_s,
                amplitude,
                gain: m.gain,
                samples: end,
                snr_db: 20.0 * (level / noise).log10(),
                band: index,
                resolution_hz: 1.0 / (end as f64 * band.dt_s),
                off_centre: (freq_hz - centre_hz).abs() / (band.core_hz.1 - band.core_hz.0),
            })
        })
        .collect()
}

/// Running-mean span of the band's power, in its samples.
fn smoothing(band: &Band) -> usize {
    ((SMOOTH_S / band.dt_s) as usize).max(4)
}

/// ESPRIT's estimate of the band's poles and noise, and the end of the samples fitted; `None`
/// when the band is too short to measure.
fn measure(band: &Band) -> Option<(Estimate, usize)> {
    let y = &band.samples;
    if y.len() < band.first + MIN_SAMPLES {
        return None;
    }
    let data = &y[band.first..];
    let estimate = esprit(
        &data[..data.len().min(MAX_ESPRIT_SAMPLES)],
        max_order(band.core_hz),
    )?;
    let end = sound_end(y, 0, smoothing(band), estimate.noise_var)
        .min(MAX_FIT_SAMPLES)
        .max(band.first + MIN_SAMPLES);
    Some((estimate, end))
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
