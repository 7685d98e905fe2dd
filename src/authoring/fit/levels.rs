//! Each mode's level over time matched to the recording's, in dB, as the ear weighs it.
//!
//! The band fits minimise the squared difference of the waveforms, which the loud start of the
//! sound dominates: where the sound is not quite a sum of exponentially decaying sinusoids (a
//! pitch that glides, a decay fast then slow, noise between the partials), the fitted decay
//! follows the first few milliseconds and the tail rings tens of dB too loud or too quiet; and a
//! partial the band fits did not keep is missing altogether. The ear hears levels, not
//! waveforms. So, in short frames (40 ms, a quarter of that apart):
//!
//! - each peak of the recording's spectrum that stands well over the noise and over the
//!   resynthesis, with no mode near it, is given a mode, its level and decay measured from the
//!   frames (seed 000 section 6.2.2's measurement);
//! - modes too close to tell apart in a frame form a group, and each group is given the part of
//!   the spectrum nearer it than any other group (at most half an ERB, Glasberg and Moore 1990,
//!   beyond its outer modes). Over the frames where the recording's power there, less the other
//!   modes', stands clear of the noise and the group rules the resynthesis, the difference
//!   between that power and the group's own, in dB, is fitted by a line: its value at the onset
//!   corrects the group's gains, its slope their decays. Modes leak into their neighbours'
//!   parts, so the resynthesis is made again and the correction repeated a few times.

use realfft::num_complex::Complex64;

use super::analysis::{Analysis, Found};
use super::lsq::add_modes;
use super::stft::{hann, Spectrogram};
use super::track::Track;
use crate::bank::format::MIN_DECAY_PER_S;

/// Length of the frames compared, in seconds: short enough to follow a 20 ms decay, long enough
/// to resolve partials 50 Hz apart.
const FRAME_S: f64 = 0.04;

/// Frames per frame length.
const FRAMES_PER_WINDOW: usize = 4;

/// Zero-padding of the frames.
const PAD: usize = 2;

/// Rounds of correction.
const ROUNDS: usize = 3;

/// A frame counts where the recording's power in a mode's part of the spectrum, less the other
/// modes', is at least this many times the noise's there (6 dB): a sum of a few noise bins
/// often reaches twice its mean.
const ABOVE_NOISE: f64 = 4.0;

/// Fewest frames above the noise to correct a decay; with fewer, only the gain is corrected.
const MIN_FRAMES_FOR_SLOPE: usize = 3;

/// A frame tells a mode's level where the mode holds at least this share of the resynthesis's
/// power in its part of the spectrum.
const MIN_SHARE: f64 = 0.5;

/// A peak of the recording's spectrum with no mode near it is given one when it stands this
/// many times over the noise (10 dB)...
const MISSING_ABOVE_NOISE: f64 = 10.0;

/// ... and over the resynthesis (10 dB)...
const MISSING_ABOVE_MODEL: f64 = 10.0;

/// ... within this share of the loudest peak (60 dB).
const MISSING_RANGE: f64 = 1e-6;

/// A missing peak whose level falls by less than this many nepers (8.7 dB) over the sound is
/// left out: the frames do not measure so slow a decay (a fitted decay of nearly nothing would
/// ring for minutes), and a partial that slow is the band fits' to find, where hum is judged.
const MIN_MISSING_NEPERS: f64 = 1.0;

/// A group whose slowest mode falls by more than this many nepers from one frame to the next
/// is left as the band fit measured it.
const MAX_NEPERS_PER_HOP: f64 = 1.0;

/// The correction of a group goes to its modes decaying at most this many times as fast as its
/// slowest.
const TAIL_SPREAD: f64 = 2.0;

/// Largest gain correction, in dB.
const MAX_GAIN_DB: f64 = 40.0;

/// Largest factor by which one round slows a decay: a slope measured over a few frames cannot
/// make a quick mode ring on. (A decay may grow by any amount.)
const MAX_DECAY_STEP: f64 = 2.0;

/// Modes closer than this many unpadded bins are corrected together: the Hann window's main lobe
/// is four bins wide.
const RESOLUTION_BINS: f64 = 2.0;

/// Equivalent rectangular bandwidth of the auditory filter at `freq_hz` (Glasberg and Moore
/// 1990), in Hz.
fn erb_hz(freq_hz: f64) -> f64 {
    24.7 * (4.37 * freq_hz / 1000.0 + 1.0)
}

/// The frames the recording and the resynthesis are compared in.
struct Frames {
    /// The recording's spectrogram.
    recording: Spectrogram,
    /// The window of a frame.
    window: Vec<f64>,
    /// Sum of the window's squares: a noise's power in a bin of a frame over its density.
    sum_sq: f64,
    /// Samples from one frame to the next.
    hop: usize,
    /// Time of each frame's centre after the first sample, in seconds.
    time_s: Vec<f64>,
}

impl Frames {
    /// The frames of `a`'s recording, or `None` when it is shorter than one.
    fn new(a: &Analysis) -> Option<Self> {
        let rate = a.sample_rate_hz;
        let window_len = ((FRAME_S * rate).log2().round().exp2() as usize).max(64);
        if a.signal.len() < window_len {
            return None;
        }
        let hop = window_len / FRAMES_PER_WINDOW;
        let recording = Spectrogram::new(&a.signal, rate, window_len, hop, PAD);
        let window = hann(window_len);
        let sum_sq = window.iter().map(|w| w * w).sum();
        let time_s = (0..recording.power.len())
            .map(|j| (j * hop) as f64 / rate + 0.5 * (window_len - 1) as f64 / rate)
            .collect();
        Some(Self {
            recording,
            window,
            sum_sq,
            hop,
            time_s,
        })
    }
}

/// Corrects the gains and decays of `a`'s modes so each one's level over time follows the
/// recording's near its frequency.
pub fn match_levels(a: &mut Analysis, min_hz: f64, max_hz: f64) {
    let Some(frames) = Frames::new(a) else {
        return;
    };
    let synthesis = synthesize(a, &frames);
    add_missing(a, &frames, &synthesis, min_hz..max_hz);
    if a.modes.is_empty() {
        return;
    }
    let groups = groups(a, &frames.recording);
    // Each group's recording power per frame, and the noise's.
    let measured: Vec<(Vec<f64>, f64)> = groups
        .iter()
        .map(|g| {
            let noise = a.noise_density(a.modes[g.modes.start].freq_hz)
                * frames.sum_sq
                * g.bins.len() as f64;
            let power = frames
                .recording
                .power
                .iter()
                .map(|frame| frame[g.bins.clone()].iter().sum())
                .collect();
            (power, noise)
        })
        .collect();
    let mut total_db = vec![0.0; groups.len()];
    for _ in 0..ROUNDS {
        let synthesis = synthesize(a, &frames);
        for ((g, measured), total_db) in groups.iter().zip(&measured).zip(&mut total_db) {
            correct_group(a, g, &frames, &synthesis, measured, total_db);
        }
    }
}

/// One round's correction of the gains and decays of group `g`'s modes, from the recording's
/// power in its bins per frame and the noise's there (`measured`) against the resynthesis
/// `synthesis`; `total_db` is the gain correction of the rounds so far, kept within
/// [`MAX_GAIN_DB`].
fn correct_group(
    a: &mut Analysis,
    g: &Group,
    frames: &Frames,
    synthesis: &Spectrogram,
    measured: &(Vec<f64>, f64),
    total_db: &mut f64,
) {
    let rate = a.sample_rate_hz;
    // A group gone within a frame step is a click the frames cannot see: the band fit
    // measured it.
    let slowest = a.modes[g.modes.clone()]
        .iter()
        .map(|m| m.decay_per_s)
        .fold(f64::INFINITY, f64::min);
    if slowest * frames.hop as f64 / rate > MAX_NEPERS_PER_HOP {
        return;
    }
    let points = group_points(
        &a.modes[g.modes.clone()],
        rate,
        g,
        frames,
        synthesis,
        measured,
    );
    let Some((at_onset_db, slope_db_per_s)) = line(&points) else {
        return;
    };
    let step_db = (*total_db + at_onset_db).clamp(-MAX_GAIN_DB, MAX_GAIN_DB) - *total_db;
    *total_db += step_db;
    let step = 10f64.powf(step_db / 20.0);
    for m in &mut a.modes[g.modes.clone()] {
        // The frames are mostly the tail, which the group's slow modes make: a quick
        // mode beside them (the first stage of a decay fast then slow) keeps its level.
        if m.decay_per_s > TAIL_SPREAD * slowest {
            continue;
        }
        m.amplitude *= step;
        m.gain *= step;
        // Power falling by s dB per second more is an amplitude decay s ln(10) / 20
        // faster.
        let wanted = m.decay_per_s - slope_db_per_s * std::f64::consts::LN_10 / 20.0;
        m.decay_per_s = wanted
            .max(m.decay_per_s / MAX_DECAY_STEP)
            .max(MIN_DECAY_PER_S);
        m.track.decay_per_s = m.decay_per_s;
        m.track.amplitude = m.amplitude.norm();
    }
}

/// The frames that tell the level of group `g` (its modes `modes`): their times, and the
/// recording's power in the group's bins beyond the other modes' over the group's own, in dB.
/// A frame tells where that power stands clear of the noise and the group rules the
/// resynthesis.
///
/// The group's own spectrum in its bins, frame by frame: each mode's in the first frame, turned
/// and shrunk by its pole from frame to frame (each frame starts at or after the onset). Summed
/// as complex values, so modes that cancel or beat count as they sound.
fn group_points(
    modes: &[Found],
    rate: f64,
    g: &Group,
    frames: &Frames,
    synthesis: &Spectrogram,
    (rec_power, noise): &(Vec<f64>, f64),
) -> Vec<(f64, f64)> {
    let fft_len = frames.recording.fft_len;
    let spectra: Vec<(Vec<Complex64>, Vec<Complex64>)> = modes
        .iter()
        .map(|m| own_spectrum(m, rate, &frames.window, g.bins.clone(), fft_len))
        .collect();
    let steps: Vec<Complex64> = modes
        .iter()
        .map(|m| pole(m, rate).powi(frames.hop as i32))
        .collect();
    let mut turns = vec![Complex64::new(1.0, 0.0); modes.len()];
    let mut bins = vec![Complex64::new(0.0, 0.0); g.bins.len()];
    let mut points: Vec<(f64, f64)> = Vec::new();
    for ((frame, rec_power), time_s) in synthesis.power.iter().zip(rec_power).zip(&frames.time_s) {
        bins.fill(Complex64::new(0.0, 0.0));
        for ((positive, negative), u) in spectra.iter().zip(&turns) {
            for ((b, p), n) in bins.iter_mut().zip(positive).zip(negative) {
                *b += u * p + u.conj() * n;
            }
        }
        for (u, step) in turns.iter_mut().zip(&steps) {
            *u *= step;
        }
        let own: f64 = bins.iter().map(|b| b.norm_sqr()).sum();
        let total: f64 = frame[g.bins.clone()].iter().sum();
        let wanted = rec_power - (total - own);
        if wanted >= ABOVE_NOISE * noise && own >= MIN_SHARE * total && own > 0.0 {
            points.push((*time_s, 10.0 * (wanted / own).log10()));
        }
    }
    points
}

/// The spectrogram of `a`'s modes resynthesised, in `frames`.
fn synthesize(a: &Analysis, frames: &Frames) -> Spectrogram {
    let shapes = a.shapes();
    let amplitudes: Vec<Complex64> = a.modes.iter().map(|m| m.amplitude).collect();
    let mut model = vec![0.0; a.signal.len()];
    add_modes(&mut model, a.sample_rate_hz, &shapes, &amplitudes);
    Spectrogram::new(
        &model,
        a.sample_rate_hz,
        frames.window.len(),
        frames.hop,
        PAD,
    )
}

/// Gives a mode to each peak of the recording's spectrum (summed over the frames) that stands
/// [`MISSING_ABOVE_NOISE`] over the noise and [`MISSING_ABOVE_MODEL`] over the resynthesis, with
/// no mode within the frames' resolution: a partial the band fits left out (see
/// [`missing_mode`]).
fn add_missing(
    a: &mut Analysis,
    frames: &Frames,
    synthesis: &Spectrogram,
    range_hz: std::ops::Range<f64>,
) {
    let recording = &frames.recording;
    let count = recording.power.len();
    let bins = recording.num_bins();
    let total = |spec: &Spectrogram, k: usize| spec.power.iter().map(|f| f[k]).sum::<f64>();
    let rec: Vec<f64> = (0..bins).map(|k| total(recording, k)).collect();
    let model: Vec<f64> = (0..bins).map(|k| total(synthesis, k)).collect();
    let loudest = rec.iter().copied().fold(0.0, f64::max);
    let reach = (RESOLUTION_BINS * recording.pad as f64).round() as usize;
    let resolution_hz = RESOLUTION_BINS * recording.bin_hz * recording.pad as f64;
    let mut added = Vec::new();
    for k in reach.max(1)..bins.saturating_sub(reach) {
        let f = k as f64 * recording.bin_hz;
        let noise = a.noise_density(f) * frames.sum_sq * count as f64;
        let peak = (k - reach..=k + reach).all(|i| rec[i] <= rec[k]);
        if !peak
            || !range_hz.contains(&f)
            || rec[k] < MISSING_ABOVE_NOISE * noise
            || rec[k] < MISSING_ABOVE_MODEL * model[k]
            || rec[k] < MISSING_RANGE * loudest
            || a.modes
                .iter()
                .any(|m| (m.freq_hz - f).abs() < resolution_hz)
        {
            continue;
        }
        added.extend(missing_mode(a, frames, synthesis, &rec, k, reach, noise));
    }
    if added.is_empty() {
        return;
    }
    a.modes.extend(added);
    a.modes.sort_by(|x, y| x.freq_hz.total_cmp(&y.freq_hz));
}

/// The mode of the recording's peak at bin `k` (`rec`: its power in each bin summed over the
/// frames, `noise` the noise's there): its frequency the peak's, its level and decay the line
/// through its power beyond the resynthesis in the bins within `reach` over the frames (seed 000
/// section 6.2.2's measurement). `None` when no frame stands clear of the noise or its decay is
/// too slow to measure (see [`MIN_MISSING_NEPERS`]).
fn missing_mode(
    a: &Analysis,
    frames: &Frames,
    synthesis: &Spectrogram,
    rec: &[f64],
    k: usize,
    reach: usize,
    noise: f64,
) -> Option<Found> {
    let recording = &frames.recording;
    let count = recording.power.len();
    // The peak between bins, from a parabola through the log powers.
    let (l, c, r) = (rec[k - 1].ln(), rec[k].ln(), rec[k + 1].ln());
    let denom = l - 2.0 * c + r;
    let offset = if denom < 0.0 && denom.is_finite() {
        (0.5 * (l - r) / denom).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    let freq_hz = (k as f64 + offset) * recording.bin_hz;
    let part = k - reach..k + reach + 1;
    let frame_noise = noise / count as f64 * (part.len() as f64);
    // The recording's power there beyond the other modes', where it stands clear of the
    // noise.
    let points: Vec<(f64, f64)> = (0..count)
        .filter_map(|j| {
            let p = recording.power[j][part.clone()].iter().sum::<f64>()
                - synthesis.power[j][part.clone()].iter().sum::<f64>();
            (p >= ABOVE_NOISE * frame_noise).then(|| (frames.time_s[j], 10.0 * p.log10()))
        })
        .collect();
    let (at_onset_db, slope_db_per_s) = line(&points)?;
    let decay_per_s = (-slope_db_per_s * std::f64::consts::LN_10 / 20.0).max(MIN_DECAY_PER_S);
    let sound_s = a.signal.len() as f64 / a.sample_rate_hz;
    if decay_per_s * sound_s < MIN_MISSING_NEPERS {
        return None;
    }
    // A unit mode's power in the part sets the amplitude.
    let unit = Found {
        freq_hz,
        decay_per_s,
        amplitude: Complex64::new(0.0, -1.0),
        gain: 1.0,
        track: Track::default(),
    };
    let unit_power = own_power(
        &unit,
        a.sample_rate_hz,
        &frames.window,
        part,
        recording.fft_len,
    );
    if unit_power.is_nan() || unit_power <= 0.0 {
        return None;
    }
    // Both at the first frame: the unit mode's power there is that of the frame, not of
    // its onset.
    let first_frame_db = at_onset_db + slope_db_per_s * frames.time_s[0];
    let amplitude = (10f64.powf(first_frame_db / 10.0) / unit_power).sqrt();
    Some(Found {
        amplitude: Complex64::new(0.0, -amplitude),
        gain: amplitude,
        track: Track {
            freq_hz,
            decay_per_s,
            amplitude,
            frames: points.len(),
            rms_error_db: 0.0,
            snr_db: 10.0 * (rec[k] / noise).log10(),
        },
        ..unit
    })
}

/// Modes too close to tell apart in the frames compared, and the bins they are compared in.
struct Group {
    /// Indices of the modes (consecutive by frequency).
    modes: std::ops::Range<usize>,
    /// Bins of the spectrogram nearer the group than any other, at most half an ERB beyond its
    /// outer modes.
    bins: std::ops::Range<usize>,
}

/// Chains modes closer than [`RESOLUTION_BINS`] unpadded bins into groups, and gives each group
/// the bins nearer it than any other.
fn groups(a: &Analysis, spec: &Spectrogram) -> Vec<Group> {
    let f: Vec<f64> = a.modes.iter().map(|m| m.freq_hz).collect();
    let resolution_hz = RESOLUTION_BINS * spec.bin_hz * spec.pad as f64;
    let mut spans: Vec<std::ops::Range<usize>> = Vec::new();
    for i in 0..f.len() {
        match spans.last_mut() {
            Some(span) if f[i] - f[i - 1] < resolution_hz => span.end = i + 1,
            _ => spans.push(i..i + 1),
        }
    }
    let bins = spec.num_bins();
    (0..spans.len())
        .map(|k| {
            let (first, last) = (f[spans[k].start], f[spans[k].end - 1]);
            let below = if k > 0 {
                0.5 * (f[spans[k - 1].end - 1] + first)
            } else {
                f64::MIN
            };
            let above = if k + 1 < spans.len() {
                0.5 * (last + f[spans[k + 1].start])
            } else {
                f64::MAX
            };
            let lo_hz = below.max(first - 0.5 * erb_hz(first));
            let hi_hz = above.min(last + 0.5 * erb_hz(last));
            let lo = ((lo_hz / spec.bin_hz).ceil().max(0.0) as usize).min(bins - 1);
            let hi = ((hi_hz / spec.bin_hz).floor() as usize + 1).clamp(lo + 1, bins);
            Group {
                modes: spans[k].clone(),
                bins: lo..hi,
            }
        })
        .collect()
}

/// Least-squares line `y = c + s t` through `points`: `(c, s)`; the slope is 0 with fewer than
/// [`MIN_FRAMES_FOR_SLOPE`] points, and there is no line through none.
fn line(points: &[(f64, f64)]) -> Option<(f64, f64)> {
    let n = points.len() as f64;
    if points.is_empty() {
        return None;
    }
    let mean_t = points.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_y = points.iter().map(|p| p.1).sum::<f64>() / n;
    if points.len() < MIN_FRAMES_FOR_SLOPE {
        return Some((mean_y, 0.0));
    }
    let stt: f64 = points.iter().map(|p| (p.0 - mean_t).powi(2)).sum();
    let sty: f64 = points.iter().map(|p| (p.0 - mean_t) * (p.1 - mean_y)).sum();
    let slope = if stt > 0.0 { sty / stt } else { 0.0 };
    Some((mean_y - slope * mean_t, slope))
}

/// The pole of mode `m` at `rate`.
fn pole(m: &Found, rate: f64) -> Complex64 {
    Complex64::from_polar(
        (-m.decay_per_s / rate).exp(),
        std::f64::consts::TAU * m.freq_hz / rate,
    )
}

/// Bins `bins` of the `fft_len`-point transform of the first frame (windowed by `window`) of
/// the mode `m`, `Re(c z^n) = (c z^n + c* z*^n) / 2`: of its two halves apart, so a later
/// frame's, `n` shifted by `s`, is `z^s` times the first and `z*^s` times the second.
fn own_spectrum(
    m: &Found,
    rate: f64,
    window: &[f64],
    bins: std::ops::Range<usize>,
    fft_len: usize,
) -> (Vec<Complex64>, Vec<Complex64>) {
    let z = pole(m, rate);
    let zero = Complex64::new(0.0, 0.0);
    let (mut positive, mut negative) = (vec![zero; bins.len()], vec![zero; bins.len()]);
    let steps: Vec<Complex64> = bins
        .clone()
        .map(|k| Complex64::from_polar(1.0, -std::f64::consts::TAU * k as f64 / fft_len as f64))
        .collect();
    let mut turn = vec![Complex64::new(1.0, 0.0); bins.len()];
    let mut p = 0.5 * m.amplitude;
    for &w in window {
        let (x, y) = (w * p, w * p.conj());
        for (((pos, neg), t), step) in positive
            .iter_mut()
            .zip(negative.iter_mut())
            .zip(turn.iter_mut())
            .zip(&steps)
        {
            *pos += *t * x;
            *neg += *t * y;
            *t *= step;
        }
        p *= z;
    }
    (positive, negative)
}

/// Power in bins `bins` of the `fft_len`-point transform of the first frame (windowed by
/// `window`) of the mode `m`.
fn own_power(
    m: &Found,
    rate: f64,
    window: &[f64],
    bins: std::ops::Range<usize>,
    fft_len: usize,
) -> f64 {
    let (positive, negative) = own_spectrum(m, rate, window, bins, fft_len);
    positive
        .iter()
        .zip(&negative)
        .map(|(p, n)| (p + n).norm_sqr())
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::authoring::fit::analyse::prepare;
    use crate::authoring::fit::analysis::Found;
    use crate::authoring::fit::{FitOptions, Recording};

    const RATE: u32 = 48_000;

    /// Half a second of faint noise, then `modes` (frequency, decay, gain) struck, for 1.5 s.
    fn recording(modes: &[(f64, f64, f64)]) -> Recording {
        let rate = f64::from(RATE);
        let lead = RATE as usize / 2;
        let mut seed = 12_345u64;
        let samples = (0..2 * RATE as usize)
            .map(|n| {
                seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
                let noise = 1e-5 * ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
                let t = n.saturating_sub(lead) as f64 / rate;
                let ring: f64 = if n < lead {
                    0.0
                } else {
                    modes
                        .iter()
                        .map(|&(f, d, g)| {
                            g * (-d * t).exp() * (std::f64::consts::TAU * f * t).sin()
                        })
                        .sum()
                };
                (ring + noise) as f32
            })
            .collect();
        Recording::new("strike", samples, RATE)
    }

    /// The mode `(frequency, decay, gain)` as an analysis holds it, in sine phase at the onset.
    fn found(freq_hz: f64, decay_per_s: f64, gain: f64) -> Found {
        Found {
            freq_hz,
            decay_per_s,
            amplitude: Complex64::new(0.0, -gain),
            gain,
            track: Track::default(),
        }
    }

    /// The analysis of `truth` with `modes` for its modes, levels matched.
    fn matched(truth: &[(f64, f64, f64)], modes: &[(f64, f64, f64)]) -> Vec<Found> {
        let mut a = prepare(&recording(truth), &FitOptions::default()).unwrap();
        a.modes = modes.iter().map(|&(f, d, g)| found(f, d, g)).collect();
        match_levels(&mut a, 20.0, 20_000.0);
        a.modes
    }

    fn db(ratio: f64) -> f64 {
        20.0 * ratio.abs().log10()
    }

    #[test]
    fn exact_modes_are_left_as_they_are() {
        let truth = [(440.0, 3.0, 0.3), (1234.0, 12.0, 0.1), (5100.0, 40.0, 0.05)];
        let modes = matched(&truth, &truth);
        assert_eq!(modes.len(), truth.len(), "{modes:?}");
        for (m, &(f, d, g)) in modes.iter().zip(&truth) {
            assert_eq!(m.freq_hz, f);
            assert!((m.decay_per_s / d - 1.0).abs() < 0.02, "{m:?}");
            assert!(db(m.gain / g).abs() < 0.2, "{m:?}");
        }
    }

    #[test]
    fn a_wrong_level_and_decay_follow_the_recording() {
        let truth = [(440.0, 3.0, 0.3), (1234.0, 30.0, 0.1)];
        // The second mode 8 dB too quiet and ringing four times too long.
        let modes = matched(&truth, &[(440.0, 3.0, 0.3), (1234.0, 7.5, 0.04)]);
        assert_eq!(modes.len(), 2, "{modes:?}");
        assert!((modes[1].decay_per_s / 30.0 - 1.0).abs() < 0.1, "{modes:?}");
        assert!(db(modes[1].gain / 0.1).abs() < 1.5, "{modes:?}");
        assert!((modes[0].decay_per_s / 3.0 - 1.0).abs() < 0.02, "{modes:?}");
    }

    #[test]
    fn a_partial_the_fit_left_out_is_given_a_mode() {
        let truth = [(440.0, 3.0, 0.3), (2345.0, 8.0, 0.05)];
        let modes = matched(&truth, &truth[..1]);
        assert_eq!(modes.len(), 2, "{modes:?}");
        let m = &modes[1];
        assert!((m.freq_hz - 2345.0).abs() < 3.0, "{m:?}");
        assert!((m.decay_per_s / 8.0 - 1.0).abs() < 0.1, "{m:?}");
        assert!(db(m.gain / 0.05).abs() < 1.5, "{m:?}");
    }

    #[test]
    fn a_steady_tone_is_not_given_a_mode() {
        let truth = [(440.0, 3.0, 0.3), (1000.0, 0.0, 0.01)];
        let modes = matched(&truth, &truth[..1]);
        assert_eq!(modes.len(), 1, "{modes:?}");
    }
}
