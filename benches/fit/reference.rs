//! Seed 000's method for modes from a recorded strike (sections 3.3 and 6.2.2, after van den
//! Doel), as the reference the project's fitter is scored against.
//!
//! A Hann STFT from the onset; in every frame each spectral peak votes for its bin with its
//! squared magnitude (the seed's change to van den Doel's unweighted votes, step 5); the most
//! voted bins are the modes (step 6). Each mode's frequency is refined between bins by parabolic
//! interpolation on the log magnitude (the seed tunes a constant `t` by hand, eq. 6.1), and its
//! decay and initial amplitude come from a linear regression of its bin's log magnitude over time
//! (step 7, eqs. 6.2 and 6.3), over the frames from its loudest until it meets the noise.
//!
//! Readings where the seed leaves a choice: the window is about 80 ms; only bins that are local
//! maxima of the votes are taken, so a mode voting into two bins counts once; the amplitude is
//! the intercept at the onset divided by the window's gain for a sinusoid, rather than eq. 6.3's
//! sum over a window, so that it is the amplitude of `a sin`.

use modal_resonator::authoring::fit::Recording;
use realfft::RealFftPlanner;

use crate::fit_score::{onset_index, FittedMode};

/// Analysis window in seconds, rounded to the nearest power of two of samples (4096 at 44.1 kHz).
const WINDOW_S: f64 = 0.08;
/// Shortest window in samples, for very short recordings.
const MIN_WINDOW: usize = 256;
/// Modes kept: the most voted bins.
const NUM_MODES: usize = 40;
/// Lowest mode frequency in Hz.
const MIN_HZ: f64 = 20.0;
/// Highest mode frequency as a share of the sample rate (the engine plays nothing higher).
const MAX_FREQ_RATIO: f64 = 0.45;
/// A bin is above the noise while it is this many dB over the noise floor.
const NOISE_MARGIN_DB: f64 = 6.0;
/// Fewest frames a decay is regressed over; a mode with fewer is dropped.
const MIN_FRAMES: usize = 2;

/// The modes of `recording` by seed 000's binning method, time 0 at the onset of
/// [`crate::fit_score::onset_index`].
pub fn fit(recording: &Recording) -> Vec<FittedMode> {
    let rate = f64::from(recording.sample_rate_hz);
    let onset = onset_index(&recording.samples, recording.sample_rate_hz);
    let x: Vec<f64> = recording.samples[onset..]
        .iter()
        .map(|&v| f64::from(v))
        .collect();
    let n = window_len(x.len(), rate);
    let hop = n / 4;
    let mags = stft_magnitudes(&x, n, hop);
    let (lo, hi) = (
        ((MIN_HZ * n as f64 / rate).ceil() as usize).max(1),
        ((MAX_FREQ_RATIO * n as f64) as usize).min(n / 2 - 1),
    );
    let votes = vote(&mags, lo, hi);
    let noise_db = noise_floor_db(&mags, lo, hi) + NOISE_MARGIN_DB;
    // The window's gain for a sinusoid of amplitude 1 at a bin centre: half its sum.
    let window_gain = n as f64 / 4.0;
    let frame_time_s = |k: usize| (k * hop) as f64 / rate + n as f64 / (2.0 * rate);
    most_voted_bins(&votes, lo, hi)
        .into_iter()
        .filter_map(|bin| {
            let (delta, peak_correction) = interpolate(&mags, bin);
            let (intercept_db, slope_db_per_s) = regress(&mags, bin, noise_db, &frame_time_s)?;
            Some(FittedMode {
                freq_hz: (bin as f64 + delta) * rate / n as f64,
                decay_per_s: (-slope_db_per_s * std::f64::consts::LN_10 / 20.0).max(0.0),
                gain: 10f64.powf(intercept_db / 20.0) * peak_correction / window_gain,
            })
        })
        .collect()
}

/// The window length: the power of two nearest [`WINDOW_S`], but short enough that a recording
/// of `len` samples holds at least two windows.
fn window_len(len: usize, rate: f64) -> usize {
    let nominal = 2f64.powf((WINDOW_S * rate).log2().round()).round() as usize;
    let fits = ((len / 2).max(1) + 1).next_power_of_two() / 2;
    nominal.min(fits).max(MIN_WINDOW)
}

/// Magnitudes of the Hann-windowed frames of `x` (frame-major); only whole frames, or one
/// zero-padded frame when `x` is shorter than a window.
fn stft_magnitudes(x: &[f64], n: usize, hop: usize) -> Vec<Vec<f64>> {
    let frames = if x.len() <= n {
        1
    } else {
        1 + (x.len() - n) / hop
    };
    let window: Vec<f64> = (0..n)
        .map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / n as f64).cos())
        .collect();
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let (mut input, mut spectrum) = (fft.make_input_vec(), fft.make_output_vec());
    (0..frames)
        .map(|f| {
            for (i, v) in input.iter_mut().enumerate() {
                *v = x.get(f * hop + i).copied().unwrap_or(0.0) * window[i];
            }
            fft.process(&mut input, &mut spectrum)
                .expect("FFT sizes match");
            spectrum.iter().map(|c| c.norm()).collect()
        })
        .collect()
}

/// Seed 000 section 6.2.2 steps 3 to 5: every spectral peak of every frame adds its squared
/// magnitude to its bin.
fn vote(mags: &[Vec<f64>], lo: usize, hi: usize) -> Vec<f64> {
    let mut votes = vec![0.0; mags[0].len()];
    for frame in mags {
        for k in lo..=hi {
            if frame[k] > frame[k - 1] && frame[k] >= frame[k + 1] {
                votes[k] += frame[k] * frame[k];
            }
        }
    }
    votes
}

/// Step 6: the [`NUM_MODES`] bins with the most votes, among the local maxima of the votes.
fn most_voted_bins(votes: &[f64], lo: usize, hi: usize) -> Vec<usize> {
    let mut bins: Vec<usize> = (lo..=hi)
        .filter(|&k| votes[k] > 0.0 && votes[k] > votes[k - 1] && votes[k] >= votes[k + 1])
        .collect();
    bins.sort_by(|&a, &b| votes[b].total_cmp(&votes[a]));
    bins.truncate(NUM_MODES);
    bins
}

/// The noise floor in dB of magnitude: over the bins searched, the median of each bin's quietest
/// frame.
fn noise_floor_db(mags: &[Vec<f64>], lo: usize, hi: usize) -> f64 {
    let mut quietest: Vec<f64> = (lo..=hi)
        .map(|k| mags.iter().map(|f| f[k]).fold(f64::INFINITY, f64::min))
        .collect();
    quietest.sort_by(f64::total_cmp);
    20.0 * quietest[quietest.len() / 2].max(1e-12).log10()
}

/// The offset of the peak from `bin` in bins, and the ratio of the peak's magnitude to the
/// bin's, by a parabola through the log magnitudes of the bin and its neighbours, summed in
/// power over the frames.
fn interpolate(mags: &[Vec<f64>], bin: usize) -> (f64, f64) {
    let log_mag = |k: usize| {
        0.5 * mags
            .iter()
            .map(|f| f[k] * f[k])
            .sum::<f64>()
            .max(1e-300)
            .ln()
    };
    let (a, b, c) = (log_mag(bin - 1), log_mag(bin), log_mag(bin + 1));
    let denom = a - 2.0 * b + c;
    if denom >= 0.0 {
        return (0.0, 1.0);
    }
    let delta = (0.5 * (a - c) / denom).clamp(-0.5, 0.5);
    (delta, (-0.25 * (a - c) * delta).exp())
}

/// Step 7: least-squares line through the bin's log magnitude (dB) against time, over the frames
/// from its loudest while it stays over `noise_db`: the intercept at the onset in dB and the
/// slope in dB/s; `None` for fewer than [`MIN_FRAMES`].
fn regress(
    mags: &[Vec<f64>],
    bin: usize,
    noise_db: f64,
    frame_time_s: &dyn Fn(usize) -> f64,
) -> Option<(f64, f64)> {
    let db: Vec<f64> = mags
        .iter()
        .map(|f| 20.0 * f[bin].max(1e-12).log10())
        .collect();
    let start = (0..db.len()).max_by(|&a, &b| db[a].total_cmp(&db[b]))?;
    let points: Vec<(f64, f64)> = (start..db.len())
        .take_while(|&k| db[k] > noise_db)
        .map(|k| (frame_time_s(k), db[k]))
        .collect();
    if points.len() < MIN_FRAMES {
        return None;
    }
    let count = points.len() as f64;
    let mean_t = points.iter().map(|p| p.0).sum::<f64>() / count;
    let mean_db = points.iter().map(|p| p.1).sum::<f64>() / count;
    let sxx: f64 = points.iter().map(|p| (p.0 - mean_t).powi(2)).sum();
    let sxy: f64 = points
        .iter()
        .map(|p| (p.0 - mean_t) * (p.1 - mean_db))
        .sum();
    let slope = sxy / sxx;
    Some((mean_db - slope * mean_t, slope))
}
