//! A score for a fitted list of modes against the recording it came from, independent of the
//! library's fitter and of its own fidelity measure, so fitters can be compared on it.
//!
//! The modes are re-synthesised exactly in f64, `sum_m g_m exp(-d_m t) sin(2 pi f_m t)`, from the
//! recording's onset for as long as the recording lasts. Both signals go through the same STFT
//! (4-term Blackman-Harris window of 46.4 ms, hop a quarter window); power is summed into bands
//! from 50 Hz, each a sixth of an octave but at least 25 Hz wide, up to 16 kHz or 0.45 times the
//! sample rate; each (band, frame) cell is taken in dB, floored 60 dB under the recording's
//! loudest cell. The score is the mean absolute dB difference over the cells where either signal
//! is above the floor, after the one gain offset that makes it least (the engine normalises a
//! bank's loudness, so the overall level is not the fitter's to get right). It is given over all
//! frames, over the attack (frames centred in the first 200 ms) and over the tail (the rest).
//!
//! Beside it: the median error in cents, over the five strongest spectral peaks of the first
//! second, of the fitted mode nearest each peak.

use std::f64::consts::TAU;

use modal_resonator::authoring::fit::Recording;
use modal_resonator::bank::Bank;
use realfft::RealFftPlanner;

/// Onset threshold, relative to the recording's peak.
pub const ONSET_FRACTION: f64 = 0.1;
/// How far before the first sample over the threshold the onset is put, in seconds: the strike
/// starts a little before it crosses a tenth of the peak.
pub const ONSET_LEAD_S: f64 = 0.002;
/// STFT window length in seconds (2048 samples at 44.1 kHz).
pub const WINDOW_S: f64 = 0.0464;
/// Lowest band edge in Hz.
pub const LOWEST_HZ: f64 = 50.0;
/// Highest band edge in Hz, also capped at [`MAX_FREQ_RATIO`] times the sample rate.
pub const HIGHEST_HZ: f64 = 16_000.0;
/// Highest band edge as a share of the sample rate (the engine plays nothing higher).
pub const MAX_FREQ_RATIO: f64 = 0.45;
/// Narrowest band in Hz: under about 200 Hz a sixth of an octave would hold a single bin.
pub const MIN_BAND_HZ: f64 = 25.0;
/// Range of the cells scored, in dB under the recording's loudest cell.
pub const RANGE_DB: f64 = 60.0;
/// Frames centred before this time after the onset are the attack, in seconds.
pub const ATTACK_S: f64 = 0.2;
/// Widest gain offset searched either side of the median difference, in dB.
pub const OFFSET_SEARCH_DB: f64 = 20.0;
/// Step of the offset grid, in dB, refined by golden-section search within one step.
pub const OFFSET_STEP_DB: f64 = 0.05;
/// Spectral peaks whose nearest mode sets the cents error.
pub const NUM_PEAKS: usize = 5;
/// Length of the recording searched for spectral peaks, in seconds from the onset.
pub const PEAK_SPAN_S: f64 = 1.0;

/// One mode: `gain * exp(-decay_per_s * t) * sin(2 pi freq_hz t)` from the onset.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FittedMode {
    /// Frequency in Hz.
    pub freq_hz: f64,
    /// Amplitude decay rate in 1/s.
    pub decay_per_s: f64,
    /// Amplitude at the onset, in the recording's full scale.
    pub gain: f64,
}

/// The modes of `bank` with their gains at `position`.
pub fn fitted_modes(bank: &Bank, position: usize) -> Vec<FittedMode> {
    bank.modes
        .iter()
        .map(|m| FittedMode {
            freq_hz: m.freq_hz,
            decay_per_s: m.decay_per_s,
            gain: m.gains[position],
        })
        .collect()
}

/// How close a list of modes comes to a recording.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Score {
    /// Mean absolute dB difference over every frame.
    pub all_db: f64,
    /// The same over the frames centred in the first [`ATTACK_S`]; NaN if none.
    pub attack_db: f64,
    /// The same over the later frames; NaN if the recording is too short to have any.
    pub tail_db: f64,
    /// Gain offset added to the re-synthesis, in dB.
    pub offset_db: f64,
    /// Median error in cents of the mode nearest each of the strongest spectral peaks; NaN for
    /// no modes.
    pub peak_cents: f64,
}

/// Index of the onset: the first sample over [`ONSET_FRACTION`] of the peak, less
/// [`ONSET_LEAD_S`], not before the start.
pub fn onset_index(samples: &[f32], sample_rate_hz: u32) -> usize {
    let peak = samples.iter().fold(0.0f32, |a, v| a.max(v.abs()));
    let threshold = ONSET_FRACTION as f32 * peak;
    let first = samples
        .iter()
        .position(|v| v.abs() > threshold)
        .unwrap_or(0);
    first.saturating_sub((ONSET_LEAD_S * f64::from(sample_rate_hz)).round() as usize)
}

/// `len` samples of `modes` at `sample_rate_hz`, from t = 0.
pub fn synthesize(modes: &[FittedMode], sample_rate_hz: u32, len: usize) -> Vec<f64> {
    // Each block restarts every oscillator from its closed form, so the complex recursion
    // within a block adds no error that grows with the length.
    const BLOCK: usize = 1024;
    let rate = f64::from(sample_rate_hz);
    let mut out = vec![0.0; len];
    for m in modes {
        let w = TAU * m.freq_hz / rate;
        let step_mag = (-m.decay_per_s / rate).exp();
        let (step_im, step_re) = w.sin_cos();
        let (step_re, step_im) = (step_mag * step_re, step_mag * step_im);
        for (b, block) in out.chunks_mut(BLOCK).enumerate() {
            let n0 = (b * BLOCK) as f64;
            let a = m.gain * (-m.decay_per_s * n0 / rate).exp();
            let (s, c) = (w * n0).sin_cos();
            let (mut re, mut im) = (a * c, a * s);
            for y in block {
                *y += im;
                (re, im) = (re * step_re - im * step_im, re * step_im + im * step_re);
            }
        }
    }
    out
}

/// The band edges in Hz for a recording at `sample_rate_hz`.
pub fn band_edges_hz(sample_rate_hz: u32) -> Vec<f64> {
    let top = HIGHEST_HZ.min(MAX_FREQ_RATIO * f64::from(sample_rate_hz));
    let sixth_octave = 2f64.powf(1.0 / 6.0) - 1.0;
    let mut edges = vec![LOWEST_HZ];
    loop {
        let e = *edges.last().unwrap();
        let next = e + (e * sixth_octave).max(MIN_BAND_HZ);
        if next > top {
            return edges;
        }
        edges.push(next);
    }
}

/// Power per band (columns) and frame (rows) of `x` in dB, and each frame's centre in seconds.
fn band_spectrogram(x: &[f64], sample_rate_hz: u32) -> (Vec<Vec<f64>>, Vec<f64>) {
    let rate = f64::from(sample_rate_hz);
    let n = (WINDOW_S * rate).round() as usize;
    let hop = (n as f64 / 4.0).round() as usize;
    // 4-term Blackman-Harris (Harris 1978, table 1), periodic.
    let window: Vec<f64> = (0..n)
        .map(|i| {
            let p = TAU * i as f64 / n as f64;
            0.35875 - 0.48829 * p.cos() + 0.14128 * (2.0 * p).cos() - 0.01168 * (3.0 * p).cos()
        })
        .collect();
    let edges = band_edges_hz(sample_rate_hz);
    let band_of_bin: Vec<Option<usize>> = (0..=n / 2)
        .map(|k| {
            let f = k as f64 * rate / n as f64;
            edges.windows(2).position(|e| e[0] <= f && f < e[1])
        })
        .collect();
    let frames = if x.len() <= n {
        1
    } else {
        1 + (x.len() - n).div_ceil(hop)
    };
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let (mut input, mut spectrum) = (fft.make_input_vec(), fft.make_output_vec());
    let mut rows = Vec::with_capacity(frames);
    let mut centres_s = Vec::with_capacity(frames);
    for f in 0..frames {
        let start = f * hop;
        for (i, v) in input.iter_mut().enumerate() {
            *v = x.get(start + i).copied().unwrap_or(0.0) * window[i];
        }
        fft.process(&mut input, &mut spectrum)
            .expect("FFT sizes match");
        let mut power = vec![0.0; edges.len() - 1];
        for (c, band) in spectrum.iter().zip(&band_of_bin) {
            if let Some(b) = band {
                power[*b] += c.norm_sqr();
            }
        }
        rows.push(power.iter().map(|&p| 10.0 * p.log10()).collect());
        centres_s.push((start as f64 + n as f64 / 2.0) / rate);
    }
    (rows, centres_s)
}

/// Scores `modes` against `recording`.
pub fn score(modes: &[FittedMode], recording: &Recording) -> Score {
    let rate = recording.sample_rate_hz;
    let onset = onset_index(&recording.samples, rate);
    let x: Vec<f64> = recording.samples[onset..]
        .iter()
        .map(|&v| f64::from(v))
        .collect();
    let y = synthesize(modes, rate, x.len());
    let (rec, centres_s) = band_spectrogram(&x, rate);
    let (syn, _) = band_spectrogram(&y, rate);
    let loudest = rec.iter().flatten().fold(f64::MIN, |a, &v| a.max(v));
    let floor = loudest - RANGE_DB;
    let cells: Vec<Cell> = rec
        .iter()
        .zip(&syn)
        .zip(&centres_s)
        .flat_map(|((r, s), &t)| {
            r.iter().zip(s).map(move |(&rec_db, &syn_db)| Cell {
                rec_db: rec_db.max(floor),
                syn_db,
                attack: t < ATTACK_S,
            })
        })
        .collect();
    let offset_db = best_offset_db(&cells, floor);
    if std::env::var("FIT_SCORE_BANDS").is_ok() {
        let edges = band_edges_hz(rate);
        let nb = rec[0].len();
        for b in 0..nb {
            let mut acc = [(0.0, 0usize); 2];
            for (f, (r, s)) in rec.iter().zip(&syn).enumerate() {
                let (rr, ss) = (r[b].max(floor), (s[b] + offset_db).max(floor));
                if rr > floor || ss > floor {
                    let i = usize::from(centres_s[f] >= ATTACK_S);
                    acc[i].0 += ss - rr;
                    acc[i].1 += 1;
                }
            }
            eprintln!(
                "  band {:6.0} Hz attack {:+6.1} ({:3}) tail {:+6.1} ({:4})",
                edges[b],
                acc[0].0 / acc[0].1.max(1) as f64,
                acc[0].1,
                acc[1].0 / acc[1].1.max(1) as f64,
                acc[1].1
            );
        }
    }
    let mean = |keep: &dyn Fn(&Cell) -> bool| {
        let chosen: Vec<&Cell> = cells.iter().filter(|c| keep(c)).collect();
        mean_difference_db(chosen.into_iter(), floor, offset_db)
    };
    Score {
        all_db: mean(&|_| true),
        attack_db: mean(&|c| c.attack),
        tail_db: mean(&|c| !c.attack),
        offset_db,
        peak_cents: peak_cents_error(modes, &x, rate),
    }
}

/// One (band, frame) cell of both spectrograms.
struct Cell {
    /// The recording's level in dB, floored.
    rec_db: f64,
    /// The re-synthesis's level in dB before the offset and the floor (-inf for silence).
    syn_db: f64,
    /// Whether the frame is centred in the attack.
    attack: bool,
}

/// Mean absolute difference over `cells` where either level is above `floor`, the re-synthesis
/// shifted by `offset_db` before flooring; NaN if no cell is above the floor.
fn mean_difference_db<'a>(
    cells: impl Iterator<Item = &'a Cell>,
    floor: f64,
    offset_db: f64,
) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for c in cells {
        let syn = (c.syn_db + offset_db).max(floor);
        if c.rec_db > floor || syn > floor {
            sum += (c.rec_db - syn).abs();
            count += 1;
        }
    }
    if count == 0 {
        f64::NAN
    } else {
        sum / count as f64
    }
}

/// The offset minimising the mean difference: a grid of [`OFFSET_STEP_DB`] over
/// ±[`OFFSET_SEARCH_DB`] around two guesses, then a golden-section search within a step of the
/// best grid point. The guesses: the offset that matches the loudest cells, and the median
/// difference over the cells where both signals lie within [`RANGE_DB`] of their loudest (cells
/// the modes leave empty would pull a median over all cells far too high).
fn best_offset_db(cells: &[Cell], floor: f64) -> f64 {
    let syn_loudest = cells
        .iter()
        .map(|c| c.syn_db)
        .filter(|v| v.is_finite())
        .fold(f64::MIN, f64::max);
    if syn_loudest == f64::MIN {
        return 0.0;
    }
    let mut diffs: Vec<f64> = cells
        .iter()
        .filter(|c| c.rec_db > floor && c.syn_db > syn_loudest - RANGE_DB)
        .map(|c| c.rec_db - c.syn_db)
        .collect();
    diffs.sort_by(f64::total_cmp);
    let mut guesses = vec![floor + RANGE_DB - syn_loudest];
    guesses.extend(diffs.get(diffs.len() / 2));
    let cost = |o: f64| mean_difference_db(cells.iter(), floor, o);
    let steps = (OFFSET_SEARCH_DB / OFFSET_STEP_DB).round() as i32;
    let (best, best_cost) = guesses
        .iter()
        .flat_map(|&g| (-steps..=steps).map(move |k| g + f64::from(k) * OFFSET_STEP_DB))
        .map(|o| (o, cost(o)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("the grid is not empty");
    let (mut lo, mut hi) = (best - OFFSET_STEP_DB, best + OFFSET_STEP_DB);
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..30 {
        let (a, b) = (hi - ratio * (hi - lo), lo + ratio * (hi - lo));
        if cost(a) < cost(b) {
            hi = b;
        } else {
            lo = a;
        }
    }
    let refined = (lo + hi) / 2.0;
    if cost(refined) < best_cost {
        refined
    } else {
        best
    }
}

/// Median |cents| between each of the [`NUM_PEAKS`] strongest spectral peaks of `x` (starting at
/// the onset) and the nearest of `modes`.
fn peak_cents_error(modes: &[FittedMode], x: &[f64], sample_rate_hz: u32) -> f64 {
    if modes.is_empty() {
        return f64::NAN;
    }
    let mut errors: Vec<f64> = strongest_peaks_hz(x, sample_rate_hz, NUM_PEAKS)
        .iter()
        .map(|&peak| {
            modes
                .iter()
                .map(|m| (1200.0 * (m.freq_hz / peak).log2()).abs())
                .fold(f64::INFINITY, f64::min)
        })
        .collect();
    if errors.is_empty() {
        return f64::NAN;
    }
    errors.sort_by(f64::total_cmp);
    errors[errors.len() / 2]
}

/// Frequencies of the `count` strongest peaks of the spectrum of the first [`PEAK_SPAN_S`] of
/// `x`: Hann window, zero-padded eight times and more, peaks that are the largest within three
/// unpadded bins (so a peak's side lobes are not taken for peaks), parabolic interpolation on the
/// log magnitude; between [`LOWEST_HZ`] and the top band edge.
pub fn strongest_peaks_hz(x: &[f64], sample_rate_hz: u32, count: usize) -> Vec<f64> {
    const PADDING: usize = 8;
    const DOMINATES_BINS: usize = 3;
    let rate = f64::from(sample_rate_hz);
    let len = x.len().min((PEAK_SPAN_S * rate) as usize).max(2);
    let n = (PADDING * len).next_power_of_two();
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let (mut input, mut spectrum) = (fft.make_input_vec(), fft.make_output_vec());
    for (i, v) in x.iter().take(len).enumerate() {
        input[i] = v * (0.5 - 0.5 * (TAU * i as f64 / len as f64).cos());
    }
    fft.process(&mut input, &mut spectrum)
        .expect("FFT sizes match");
    let mag: Vec<f64> = spectrum.iter().map(|c| c.norm()).collect();
    let bin_hz = rate / n as f64;
    let top_hz = *band_edges_hz(sample_rate_hz).last().unwrap();
    let reach = DOMINATES_BINS * n / len;
    let lo = ((LOWEST_HZ / bin_hz).ceil() as usize).max(1);
    let hi = ((top_hz / bin_hz) as usize).min(mag.len() - 2);
    let mut peaks: Vec<(f64, f64)> = (lo..=hi)
        .filter(|&k| {
            let around = &mag[k.saturating_sub(reach)..(k + reach + 1).min(mag.len())];
            mag[k] > 0.0 && around.iter().all(|&m| m <= mag[k])
        })
        .map(|k| {
            let (a, b, c) = (mag[k - 1].ln(), mag[k].ln(), mag[k + 1].ln());
            let denom = a - 2.0 * b + c;
            let delta = if denom < 0.0 {
                0.5 * (a - c) / denom
            } else {
                0.0
            };
            (mag[k], (k as f64 + delta) * bin_hz)
        })
        .collect();
    peaks.sort_by(|p, q| q.0.total_cmp(&p.0));
    peaks.into_iter().take(count).map(|p| p.1).collect()
}
