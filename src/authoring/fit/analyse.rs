//! The modes of one recording: onset and noise floor, then the sound split into frequency bands
//! ([`subband`](super::subband)), each band's modes estimated by ESPRIT and refined against the
//! band's signal, keeping as many as measurably improve its resynthesis
//! ([`bandfit`](super::bandfit)).

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;

use realfft::num_complex::Complex64;

use super::analysis::{Analysis, Found};
use super::bandfit::{dedupe, fit_band, BandMode};
use super::levels::match_levels;
use super::lsq::{add_modes, Shape};
use super::noise::NoiseSpectrum;
use super::onset::find_strike;
use super::stft::{hann, Spectrogram};
use super::subband::{layout, Splitter};
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

/// Zero-padding of the noise spectrogram.
const PAD: usize = 2;

/// A mode whose amplitude falls by less than this many nepers (5%) over the whole recording
/// after the strike does not decay at all: a steady tone, not part of the ring.
const STEADY_NEPERS: f64 = 0.05;

/// Shortest sound, in seconds, over which a mode that does not decay is taken for hum without
/// hearing it before the strike: over 2 s it would take more than four minutes to fall by
/// 60 dB, which no struck object in air rings for; over less, a slow mode of the object may
/// seem as steady (a glockenspiel sampled for 1.3 s has one).
const MIN_STEADY_S: f64 = 2.0;

/// A mode falling by less than this many nepers over the recording is hum when it is already
/// there before the strike...
const SLOW_NEPERS: f64 = 1.0;

/// ... at least this share of its amplitude at the strike.
const BEFORE_SHARE: f64 = 0.5;

/// A mode with this many dB less energy than the strongest is left out.
pub(super) const INAUDIBLE_DB: f64 = 70.0;

/// Longest stretch before the onset kept to look for hum, in seconds.
const BEFORE_S: f64 = 1.0;

/// Shortest stretch before the onset that can show hum, in seconds.
const MIN_BEFORE_S: f64 = 0.05;

/// Finds the modes of `recording` within the options' frequency range.
/// `progress` hears the share of the work done.
pub fn analyse(
    recording: &Recording,
    options: &FitOptions,
    progress: &mut dyn FnMut(f64),
) -> Result<Analysis, FitError> {
    let mut analysis = prepare(recording, options)?;
    let max_hz = options.max_hz(recording.sample_rate_hz);
    find_modes(&mut analysis, options, max_hz, progress);
    drop_steady_tones(&mut analysis);
    match_levels(&mut analysis, options.min_hz, max_hz);
    decay_as_the_recording_shows(&mut analysis);
    // Matching levels can leave a mode far under the others.
    let sound_s = analysis.signal.len() as f64 / analysis.sample_rate_hz;
    drop_inaudible(&mut analysis.modes, sound_s, |m| {
        (m.amplitude, m.decay_per_s)
    });
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
    let needed = ((MIN_SOUND_S * rate) as usize).max(MIN_WINDOW * MIN_WINDOWS_IN_SOUND);
    // A whole recording shorter than the sound a fit needs is too short, whatever it holds:
    // too short as well to tell a strike from steady noise.
    if x.len() < needed {
        return Err(FitError::TooShort {
            name,
            found_s: x.len() as f64 / rate,
            needed_s: needed as f64 / rate,
        });
    }
    let strike = find_strike(&x, rate).map_err(|detail| FitError::Silent {
        name: name.clone(),
        detail,
    })?;
    check_clipping(recording, &strike, &name)?;
    let max_len = (options.max_seconds * rate) as usize;
    let end = strike.end.min(strike.onset + max_len);
    let sound_len = end - strike.onset;
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
        before: x[strike.onset.saturating_sub((BEFORE_S * rate) as usize)..strike.onset].to_vec(),
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

/// The modes of every band, measured jointly in each and kept by what they add to the
/// resynthesis; a mode two bands find is kept once. The bands are fitted on
/// [`FitOptions::threads`] threads, each taking the next band not yet taken, and their modes
/// gathered in band order, so the result is the same on any number of threads.
fn find_modes(a: &mut Analysis, options: &FitOptions, max_hz: f64, progress: &mut dyn FnMut(f64)) {
    let min_hz = options.min_hz;
    let cores = layout(min_hz, max_hz);
    let threads = match options.threads {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    }
    .clamp(1, cores.len().max(1));
    let next = AtomicUsize::new(0);
    let (sender, receiver) = mpsc::channel();
    let mut by_band: Vec<Vec<BandMode>> = vec![Vec::new(); cores.len()];
    let (signal, rate) = (&a.signal, a.sample_rate_hz);
    std::thread::scope(|scope| {
        for _ in 0..threads {
            let (sender, next, cores) = (sender.clone(), &next, &cores);
            scope.spawn(move || {
                let mut splitter = Splitter::new(signal, rate);
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&core) = cores.get(k) else { break };
                    if sender.send((k, fit_band(&mut splitter, core, k))).is_err() {
                        break;
                    }
                }
            });
        }
        drop(sender);
        for (done, (k, modes)) in receiver.iter().enumerate() {
            by_band[k] = modes;
            progress((done + 1) as f64 / cores.len() as f64);
        }
    });
    let mut found: Vec<BandMode> = by_band.into_iter().flatten().collect();
    dedupe(&mut found, a.signal.len() as f64 / a.sample_rate_hz);
    // A band's reach beyond its core stops at the range searched.
    found.retain(|m| (min_hz..=max_hz).contains(&m.freq_hz));
    drop_inaudible(&mut found, a.signal.len() as f64 / a.sample_rate_hz, |m| {
        (m.amplitude, m.decay_per_s)
    });
    let shapes: Vec<Shape> = found
        .iter()
        .map(|m| Shape {
            freq_hz: m.freq_hz,
            decay_per_s: m.decay_per_s,
        })
        .collect();
    let tracks = report_tracks(a, &shapes, &found);
    a.modes = found
        .iter()
        .zip(tracks)
        .map(|(m, track)| Found {
            freq_hz: m.freq_hz,
            decay_per_s: m.decay_per_s,
            amplitude: m.amplitude,
            gain: m.gain,
            track,
        })
        .collect();
}

/// Leaves out modes whose energy over the sound is more than [`INAUDIBLE_DB`] below the
/// strongest mode's: a rounding error of the fit, never heard beside it. `shape` gives a mode's
/// complex amplitude and decay.
fn drop_inaudible<T>(modes: &mut Vec<T>, sound_s: f64, shape: impl Fn(&T) -> (Complex64, f64)) {
    let energy = |m: &T| {
        let (amplitude, decay) = shape(m);
        energy_over(amplitude.norm(), decay, sound_s)
    };
    let loudest = modes.iter().map(&energy).fold(0.0, f64::max);
    let floor = loudest * 10f64.powf(-INAUDIBLE_DB / 10.0);
    modes.retain(|m| energy(m) >= floor);
}

/// The energy of an `amplitude exp(-decay t)` envelope over `sound_s` seconds:
/// `a^2 (1 - exp(-2 d T)) / (2 d)`.
pub(super) fn energy_over(amplitude: f64, decay_per_s: f64, sound_s: f64) -> f64 {
    let d = decay_per_s.max(1e-9);
    amplitude * amplitude * -(-2.0 * d * sound_s).exp_m1() / (2.0 * d)
}

/// For the report, each mode followed alone in the recording less every other mode: the frames
/// its level was measured in and how close they lie to its exponential. A mode too quick or
/// too weak to follow that way gets the band fit's figures.
fn report_tracks(a: &Analysis, shapes: &[Shape], found: &[BandMode]) -> Vec<Track> {
    let amplitudes: Vec<Complex64> = found.iter().map(|m| m.amplitude).collect();
    let residual = a.residual(shapes, &amplitudes);
    let mut own = vec![0.0; residual.len()];
    found
        .iter()
        .zip(shapes)
        .map(|(m, shape)| {
            own.copy_from_slice(&residual);
            add_modes(
                &mut own,
                a.sample_rate_hz,
                std::slice::from_ref(shape),
                &[m.amplitude],
            );
            // A window about one time constant long, so a fast decay spans several frames.
            let span = (a.sample_rate_hz / m.decay_per_s.max(1e-3))
                .log2()
                .floor()
                .exp2() as usize;
            let len = span.clamp(MIN_WINDOW, a.window_len);
            let density = a.noise_density(m.freq_hz);
            track(&own, a.sample_rate_hz, a.start, m.freq_hz, len, density)
                .map(|t| Track {
                    freq_hz: m.freq_hz,
                    decay_per_s: m.decay_per_s,
                    amplitude: m.amplitude.norm(),
                    ..t
                })
                .unwrap_or(Track {
                    freq_hz: m.freq_hz,
                    decay_per_s: m.decay_per_s,
                    amplitude: m.amplitude.norm(),
                    frames: m.samples,
                    rms_error_db: 0.0,
                    snr_db: m.snr_db,
                })
        })
        .collect()
}

/// Leaves out hum, with a warning for each tone: a mode that does not decay at all over the
/// recording, or one that decays slowly and is already there before the strike. A mode that
/// starts with the strike stays, however slowly it decays: a bell's hum note, a recording cut
/// short.
fn drop_steady_tones(a: &mut Analysis) {
    let sound_s = a.signal.len() as f64 / a.sample_rate_hz;
    let heard_before = (a.before.len() as f64) >= MIN_BEFORE_S * a.sample_rate_hz;
    let (steady, modes): (Vec<Found>, Vec<Found>) = a.modes.iter().partition(|m| {
        let nepers = m.decay_per_s * sound_s;
        let before =
            heard_before && amplitude_before(a, m.freq_hz) >= BEFORE_SHARE * m.amplitude.norm();
        let long_enough = sound_s >= MIN_STEADY_S;
        (before && nepers < SLOW_NEPERS) || (!heard_before && long_enough && nepers < STEADY_NEPERS)
    });
    if steady.is_empty() {
        return;
    }
    for m in &steady {
        a.warnings.push(format!(
            "steady tone at {:.1} Hz left out as hum: it decays by {:.0}% over the {sound_s:.2} s \
             of sound{}",
            m.freq_hz,
            100.0 * (1.0 - (-m.decay_per_s * sound_s).exp()),
            if heard_before {
                " and is there before the strike"
            } else {
                ""
            }
        ));
    }
    a.modes = modes;
}

/// Amplitude of a sinusoid at `freq_hz` in the recording before the onset (Hann-windowed).
fn amplitude_before(a: &Analysis, freq_hz: f64) -> f64 {
    amplitude_in(&a.before, &hann(a.before.len()), a.sample_rate_hz, freq_hz)
}

/// Amplitude of a sinusoid at `freq_hz` in `x` under the window `w` (of `x`'s length).
fn amplitude_in(x: &[f64], w: &[f64], sample_rate_hz: f64, freq_hz: f64) -> f64 {
    let step = Complex64::from_polar(1.0, -std::f64::consts::TAU * freq_hz / sample_rate_hz);
    let mut turn = Complex64::new(1.0, 0.0);
    let mut sum = Complex64::new(0.0, 0.0);
    for (x, w) in x.iter().zip(w) {
        sum += turn * (x * w);
        turn *= step;
    }
    2.0 * sum.norm() / w.iter().sum::<f64>().max(1e-300)
}

/// The stretch at the end of the sound over which a slow mode's level is checked against the
/// recording's, as a share of the sound: heard as one window, so its frequency resolution
/// parts a weak mode from a strong neighbour a few hertz away.
const TAIL_SHARE: f64 = 0.25;

/// How far a mode may stand above what the recording shows at its frequency in the tail, as an
/// amplitude ratio (6 dB).
const TAIL_MARGIN: f64 = 2.0;

/// A mode falling by less than this many nepers over the sound has a decay the fits could
/// hardly measure: the recording's tail must bear it out.
const SLOW_FIT_NEPERS: f64 = 1.0;

/// Makes every slow mode decay at least as fast as the recording shows it does. A mode falling
/// by less than [`SLOW_FIT_NEPERS`] over the sound is checked: over the last quarter of the
/// sound, seen through one window, the resynthesis of all the modes may hold at its frequency
/// at most [`TAIL_MARGIN`] over what the recording holds there (or the noise there, if more);
/// where it holds more, the mode, which rules the resynthesis there, decays faster until it
/// does not. A weak mode the fits could not follow into the noise (its decay unmeasured, at the
/// floor) would otherwise ring for minutes in every voice where the recording shows it gone
/// within seconds. A mode still ringing at the end of a recording cut short keeps its decay, a
/// beating pair is judged by its sum, and modes whose decay the fits measured are left as
/// measured.
fn decay_as_the_recording_shows(a: &mut Analysis) {
    let rate = a.sample_rate_hz;
    let tail_start = ((1.0 - TAIL_SHARE) * a.signal.len() as f64) as usize;
    let tail_len = a.signal.len() - tail_start;
    let sound_s = a.signal.len() as f64 / rate;
    let slow = |m: &Found| m.decay_per_s * sound_s < SLOW_FIT_NEPERS;
    if tail_len < a.window_len || !a.modes.iter().any(slow) {
        return;
    }
    let t = tail_start as f64 / rate;
    // The resynthesis of the tail alone: each mode's complex amplitude carried to its start.
    let shapes = a.shapes();
    let carried: Vec<Complex64> = a
        .modes
        .iter()
        .map(|m| {
            m.amplitude
                * Complex64::from_polar(
                    (-m.decay_per_s * t).exp(),
                    std::f64::consts::TAU * m.freq_hz * t,
                )
        })
        .collect();
    let mut model = vec![0.0; tail_len];
    add_modes(&mut model, rate, &shapes, &carried);
    let window = hann(tail_len);
    let tail = &a.signal[tail_start..];
    // Noise in one bin falls as the window grows: the floor of a frame, scaled to the tail's.
    let noise_scale = (a.window_len as f64 / tail_len as f64).sqrt();
    // The window weighs the middle of the tail most.
    let t_mid = t + 0.5 * tail_len as f64 / rate;
    for k in 0..a.modes.len() {
        if !slow(&a.modes[k]) {
            continue;
        }
        let f = a.modes[k].freq_hz;
        let shown = amplitude_in(tail, &window, rate, f).max(noise_scale * a.floor_amplitude(f));
        let ratio = amplitude_in(&model, &window, rate, f) / (TAIL_MARGIN * shown);
        if ratio > 1.0 {
            let m = &mut a.modes[k];
            m.decay_per_s += ratio.ln() / t_mid;
            m.track.decay_per_s = m.decay_per_s;
        }
    }
}
