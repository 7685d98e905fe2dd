//! The modes of one recording: onset, noise floor, candidates by voting, then rounds of
//! tracking each mode in what the others leave and solving for all amplitudes together.
//!
//! Each round subtracts every other mode's fitted contribution before tracking a mode (the
//! space-alternating scheme of Fessler and Hero's SAGE), so a weak mode beside a strong one is
//! measured on its own, and the joint least squares ([`lsq`](super::lsq)) shares the energy of
//! overlapping modes correctly. After the first round the residual is searched again for modes
//! the strong ones hid.

use realfft::num_complex::Complex64;

use super::lsq::{add_modes, fit_amplitudes, Shape};
use super::noise::NoiseSpectrum;
use super::onset::{find_strike, Strike};
use super::peaks::vote;
use super::stft::{hann, Spectrogram};
use super::track::{track, Track};
use super::warnings::{check_clipping, input_warnings};
use super::{FitError, FitOptions, Recording};

/// Lowest sample rate analysed, in Hz.
pub const MIN_SAMPLE_RATE_HZ: u32 = 8_000;

/// Least sound after the onset, in seconds, to measure anything.
pub const MIN_SOUND_S: f64 = 0.05;

/// Smallest analysis window, in samples.
const MIN_WINDOW: usize = 256;

/// Fewest frames of the analysis window the sound must span.
const MIN_WINDOWS_IN_SOUND: usize = 4;

/// Time after the onset left out of the fits, in seconds: the mallet is still in contact.
const START_SKIP_S: f64 = 0.002;

/// Rounds of tracking and joint amplitude fitting.
const ROUNDS: usize = 3;

/// Zero-padding of the voting spectrogram.
const PAD: usize = 2;

/// A mode whose amplitude falls by less than this many nepers (10%) over the recording is a
/// steady tone, not part of the ring.
const STEADY_NEPERS: f64 = 0.1;

/// One mode found in a recording.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Found {
    /// Frequency in Hz.
    pub freq_hz: f64,
    /// Decay rate in 1/s.
    pub decay_per_s: f64,
    /// Complex amplitude at the onset from the joint fit (`-i a` for `a sin(w t)`).
    pub amplitude: Complex64,
    /// The last tracking of the mode: frames used and how well they fit.
    pub track: Track,
}

/// What one recording holds.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// Position name of the recording.
    pub name: String,
    /// Sample rate in Hz.
    pub sample_rate_hz: f64,
    /// The sound from the onset to where it meets the noise, as f64.
    pub signal: Vec<f64>,
    /// First sample of `signal` used by the fits.
    pub start: usize,
    /// Where the strike is in the recording.
    pub strike: Strike,
    /// Analysis window in samples.
    pub window_len: usize,
    /// Modes found, by frequency.
    pub modes: Vec<Found>,
    /// Warnings for the report.
    pub warnings: Vec<String>,
    /// Noise power per bin of the voting spectrogram.
    noise: NoiseSpectrum,
    /// Bin width of the voting spectrogram in Hz.
    bin_hz: f64,
    /// `sum(w)` and `sum(w^2)` of the analysis window.
    window_sums: (f64, f64),
    /// Noise floor given by the user, as a linear amplitude.
    floor_override: Option<f64>,
}

impl Analysis {
    /// Noise `|Z|^2` per unit `sum(w^2)` near `freq_hz` (see [`track`]).
    pub fn noise_density(&self, freq_hz: f64) -> f64 {
        let (sum, sum_sq) = self.window_sums;
        match self.floor_override {
            // A sinusoid of amplitude a gives |Z| = a sum(w) / 2.
            Some(a) => (0.5 * a * sum).powi(2) / sum_sq,
            None => {
                let bin =
                    ((freq_hz / self.bin_hz).round() as usize).min(self.noise.power.len() - 1);
                self.noise.power[bin] / sum_sq
            }
        }
    }

    /// Amplitude of a mode as strong as the noise in one analysis frame near `freq_hz`: the
    /// noise floor in the units of the bank's gains.
    pub fn floor_amplitude(&self, freq_hz: f64) -> f64 {
        let (sum, sum_sq) = self.window_sums;
        2.0 * (self.noise_density(freq_hz) * sum_sq).sqrt() / sum
    }

    /// Joint amplitudes of `shapes` in this recording.
    pub fn amplitudes(&self, shapes: &[Shape]) -> Vec<Complex64> {
        fit_amplitudes(&self.signal, self.sample_rate_hz, self.start, shapes)
    }

    /// The signal less `shapes` with `amplitudes`.
    pub fn residual(&self, shapes: &[Shape], amplitudes: &[Complex64]) -> Vec<f64> {
        let mut model = vec![0.0; self.signal.len()];
        add_modes(&mut model, self.sample_rate_hz, shapes, amplitudes);
        self.signal.iter().zip(&model).map(|(x, m)| x - m).collect()
    }
}

/// Finds the modes of `recording` within the options' frequency range.
pub fn analyse(recording: &Recording, options: &FitOptions) -> Result<Analysis, FitError> {
    let mut analysis = prepare(recording, options)?;
    let max_hz = options.max_hz(recording.sample_rate_hz);
    let max_candidates = 3 * options.max_modes + 16;
    find_modes(&mut analysis, options.min_hz, max_hz, max_candidates);
    drop_steady_tones(&mut analysis);
    Ok(analysis)
}

/// Checks `recording`, finds its strike and noise floor, and warns of clipping and noise; finds
/// no modes yet.
pub fn prepare(recording: &Recording, options: &FitOptions) -> Result<Analysis, FitError> {
    // Errors name the file as well as the position.
    let name = recording.origin.clone();
    let rate_hz = recording.sample_rate_hz;
    if rate_hz < MIN_SAMPLE_RATE_HZ {
        return Err(FitError::SampleRate {
            name,
            sample_rate_hz: rate_hz,
        });
    }
    let rate = rate_hz as f64;
    if let Some(bad) = recording.samples.iter().position(|v| !v.is_finite()) {
        return Err(FitError::Silent {
            name,
            detail: format!("sample {bad} is not a finite number"),
        });
    }
    let x: Vec<f64> = recording.samples.iter().map(|&v| v as f64).collect();
    let strike = find_strike(&x, rate).map_err(|detail| FitError::Silent {
        name: name.clone(),
        detail,
    })?;
    check_clipping(recording, &strike, &name)?;
    let max_len = (options.max_seconds * rate) as usize;
    let end = strike.end.min(strike.onset + max_len);
    let sound_len = end - strike.onset;
    let needed = ((MIN_SOUND_S * rate) as usize).max(MIN_WINDOW * MIN_WINDOWS_IN_SOUND);
    if sound_len < needed {
        return Err(FitError::TooShort {
            name,
            found_s: sound_len as f64 / rate,
            needed_s: needed as f64 / rate,
        });
    }
    let mut window_len = ((options.window_s * rate).log2().round().exp2() as usize).max(MIN_WINDOW);
    while window_len > MIN_WINDOW && window_len * MIN_WINDOWS_IN_SOUND > sound_len {
        window_len /= 2;
    }
    let window = hann(window_len);
    let window_sums = (window.iter().sum(), window.iter().map(|w| w * w).sum());
    let hop = window_len / 4;

    let warnings = input_warnings(recording, &strike);

    let whole = Spectrogram::new(&x, rate, window_len, hop, PAD);
    let noise = NoiseSpectrum::estimate(&whole, window_sums.0);
    Ok(Analysis {
        name: recording.name.clone(),
        sample_rate_hz: rate,
        signal: x[strike.onset..end].to_vec(),
        start: (START_SKIP_S * rate).round() as usize,
        strike,
        window_len,
        modes: Vec::new(),
        warnings,
        bin_hz: whole.bin_hz,
        noise,
        window_sums,
        floor_override: options.noise_floor_db.map(|db| 10f64.powf(db / 20.0)),
    })
}

/// The rounds of voting, tracking and joint fitting.
fn find_modes(a: &mut Analysis, min_hz: f64, max_hz: f64, max_candidates: usize) {
    let rate = a.sample_rate_hz;
    let bin_hz = rate / a.window_len as f64;
    let first = candidates(a, &a.signal, min_hz, max_hz, max_candidates, &[]);
    let mut modes: Vec<Found> = first
        .into_iter()
        .filter_map(|f| track_in(a, &a.signal, f, a.window_len))
        .collect();
    dedupe(&mut modes, bin_hz);
    for round in 0..ROUNDS {
        let shapes = shapes_of(&modes);
        let amplitudes = a.amplitudes(&shapes);
        for (m, c) in modes.iter_mut().zip(&amplitudes) {
            m.amplitude = *c;
        }
        let residual = a.residual(&shapes, &amplitudes);
        // Modes the strong ones hid: found in the residual, they join the joint fit next round.
        let hidden: Vec<Found> = if round == 0 {
            let known: Vec<f64> = modes.iter().map(|m| m.freq_hz).collect();
            candidates(a, &residual, min_hz, max_hz, max_candidates, &known)
                .into_iter()
                .filter_map(|f| track_in(a, &residual, f, a.window_len))
                .collect()
        } else {
            Vec::new()
        };
        let mut own = vec![0.0; residual.len()];
        let tracked: Vec<Found> = modes
            .iter()
            .filter_map(|m| {
                own.copy_from_slice(&residual);
                add_modes(
                    &mut own,
                    rate,
                    &shapes_of(std::slice::from_ref(m)),
                    &[m.amplitude],
                );
                // A window about one time constant long: shorter for fast decays, so they span
                // more frames before meeting the noise.
                let span = (rate / m.decay_per_s.max(1e-3)).log2().floor().exp2() as usize;
                let len = span.clamp(MIN_WINDOW, a.window_len);
                let found = track_in(a, &own, m.freq_hz, len)
                    .or_else(|| track_in(a, &own, m.freq_hz, a.window_len))?;
                Some(Found {
                    amplitude: m.amplitude,
                    ..found
                })
            })
            .filter(|m| m.freq_hz >= min_hz && m.freq_hz <= max_hz)
            .collect();
        modes = tracked;
        modes.extend(hidden);
        dedupe(&mut modes, bin_hz);
    }
    let shapes = shapes_of(&modes);
    let amplitudes = a.amplitudes(&shapes);
    for (m, c) in modes.iter_mut().zip(&amplitudes) {
        m.amplitude = *c;
    }
    let before = modes.len();
    modes.retain(|m| m.amplitude.norm() >= a.floor_amplitude(m.freq_hz));
    if modes.len() < before {
        let shapes = shapes_of(&modes);
        let amplitudes = a.amplitudes(&shapes);
        for (m, c) in modes.iter_mut().zip(&amplitudes) {
            m.amplitude = *c;
        }
    }
    a.modes = modes;
}

/// Leaves out the modes that hardly decay over the whole recording, with a warning for each:
/// mains hum, a fan or a whistle, not the object. A struck object's slowest modes still lose more
/// than 10% of their amplitude over a recording of their ring.
fn drop_steady_tones(a: &mut Analysis) {
    let sound_s = a.signal.len() as f64 / a.sample_rate_hz;
    let (steady, modes): (Vec<Found>, Vec<Found>) = a
        .modes
        .iter()
        .partition(|m| m.decay_per_s * sound_s < STEADY_NEPERS);
    if steady.is_empty() {
        return;
    }
    for m in &steady {
        a.warnings.push(format!(
            "steady tone at {:.1} Hz left out: it decays by less than 10% over the {sound_s:.2} s \
             of sound (hum or background noise?)",
            m.freq_hz
        ));
    }
    let shapes = shapes_of(&modes);
    let amplitudes = a.amplitudes(&shapes);
    a.modes = modes
        .into_iter()
        .zip(amplitudes)
        .map(|(m, amplitude)| Found { amplitude, ..m })
        .collect();
}

/// Frequencies voted for in `signal` between `min_hz` and `max_hz`, leaving out those within
/// one bin of a `known` frequency.
fn candidates(
    a: &Analysis,
    signal: &[f64],
    min_hz: f64,
    max_hz: f64,
    max_candidates: usize,
    known: &[f64],
) -> Vec<f64> {
    let hop = a.window_len / 4;
    let from = a.start.min(signal.len());
    let spec = Spectrogram::new(&signal[from..], a.sample_rate_hz, a.window_len, hop, PAD);
    let bins = spec.bin_of(min_hz)..spec.bin_of(max_hz) + 1;
    let unpadded_bin_hz = spec.bin_hz * PAD as f64;
    vote(&spec, &a.noise, 0..spec.power.len(), bins, max_candidates)
        .into_iter()
        .map(|c| c.freq_hz)
        .filter(|f| known.iter().all(|k| (k - f).abs() > unpadded_bin_hz))
        .collect()
}

/// Tracks the mode near `freq_hz` in `signal` with a window of `len` samples.
fn track_in(a: &Analysis, signal: &[f64], freq_hz: f64, len: usize) -> Option<Found> {
    let t = track(
        signal,
        a.sample_rate_hz,
        a.start,
        freq_hz,
        len,
        a.noise_density(freq_hz),
    )?;
    // A track that wandered off to another mode's frequency is not this candidate's.
    let bin_hz = a.sample_rate_hz / a.window_len as f64;
    if (t.freq_hz - freq_hz).abs() > 2.0 * bin_hz.max(a.sample_rate_hz / len as f64) {
        return None;
    }
    Some(Found {
        freq_hz: t.freq_hz,
        decay_per_s: t.decay_per_s,
        amplitude: Complex64::new(0.0, -t.amplitude),
        track: t,
    })
}

/// Sorts `modes` by frequency and keeps the stronger of any two closer than one analysis bin:
/// the same mode found twice (the window cannot tell such a pair apart, so the track of the
/// stronger already holds both). Pairs the window resolves stay apart here, even within the
/// difference limen: they are merged when the recordings are combined, which averages their
/// frequencies and decays and sums their amplitudes (seed 000 section 5.4.1).
fn dedupe(modes: &mut Vec<Found>, bin_hz: f64) {
    modes.sort_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
    let mut kept: Vec<Found> = Vec::with_capacity(modes.len());
    for m in modes.drain(..) {
        match kept.last_mut() {
            Some(last) if m.freq_hz - last.freq_hz < bin_hz => {
                if m.amplitude.norm() > last.amplitude.norm() {
                    *last = m;
                }
            }
            _ => kept.push(m),
        }
    }
    *modes = kept;
}

/// The shapes of `modes`, for the least squares.
pub fn shapes_of(modes: &[Found]) -> Vec<Shape> {
    modes
        .iter()
        .map(|m| Shape {
            freq_hz: m.freq_hz,
            decay_per_s: m.decay_per_s,
        })
        .collect()
}
