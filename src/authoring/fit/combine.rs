//! One set of modes for all recordings: modes matched across recordings by frequency (findings in
//! different recordings closer than the difference limen, seed 000 section 5.4.1, are one mode),
//! and each recording's column of gains measured for every mode, near zero where the strike did
//! not excite it.
//!
//! Frequencies and decays belong to the object, gains to the strike position (DESIGN.md, the
//! model): a mode found in any recording is measured in all of them, by the joint least squares
//! with the common frequencies and decays held fixed.

use realfft::num_complex::Complex64;

use super::analyse::{energy_over, INAUDIBLE_DB};
use super::analysis::Analysis;
use super::lsq::Shape;
use super::track::Track;
use crate::authoring::limen::difference_limen_hz;
use crate::bank::format::MIN_DECAY_PER_S;

/// A mode of the fitted bank.
#[derive(Debug, Clone, PartialEq)]
pub struct Combined {
    /// Frequency in Hz.
    pub freq_hz: f64,
    /// Decay rate in 1/s.
    pub decay_per_s: f64,
    /// Signed gain at each recording's position; 0 where the mode is below that recording's
    /// noise floor.
    pub gains: Vec<f64>,
    /// Index of the recording in which the mode stands highest above the noise.
    pub source: usize,
    /// The mode's track in that recording.
    pub track: Track,
    /// Findings of the mode in the recordings combined into it: one per recording it was found
    /// in, more when modes closer than the difference limen were merged.
    pub findings: usize,
}

/// A found mode, with the recording it was found in and its weight in a merge.
#[derive(Debug, Clone, Copy)]
struct Member {
    /// Recording index.
    recording: usize,
    /// Frequency in Hz.
    freq_hz: f64,
    /// Decay in 1/s.
    decay_per_s: f64,
    /// Squared amplitude over the squared noise floor: the inverse of the variance of the
    /// mode's estimates, so the best-measured finding counts most.
    weight: f64,
    /// The finding's track.
    track: Track,
    /// Its signed gain at the strike in its recording.
    gain: f64,
}

/// The bank's modes from the modes of every recording: at most `max_modes`, the strongest by
/// energy (seed 000 eq. 5.15), by frequency.
pub fn combine(analyses: &[Analysis], max_modes: usize) -> Vec<Combined> {
    let clusters = clusters(members(analyses));
    let mut modes = merged(&clusters);
    if analyses.len() == 1 {
        // One recording: the gains its analysis measured, each mode with the strike's phase,
        // less those under a noise floor the user gave.
        let a = &analyses[0];
        for (m, c) in modes.iter_mut().zip(&clusters) {
            let heard = !a.floor_given() || c[0].gain.abs() >= a.floor_amplitude(m.freq_hz);
            m.gains = vec![if heard { c[0].gain } else { 0.0 }];
        }
    } else {
        measure_gains(analyses, &mut modes);
    }
    modes.retain(|m| m.gains.iter().any(|&g| g != 0.0));
    drop_inaudible(analyses, &mut modes);
    if modes.len() > max_modes {
        modes.sort_by(|a, b| energy(b).total_cmp(&energy(a)));
        modes.truncate(max_modes);
        modes.sort_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
        // Without the dropped modes the kept ones take back the energy they shared.
        if analyses.len() > 1 {
            measure_gains(analyses, &mut modes);
        }
    }
    modes
}

/// Every recording's modes, by frequency.
fn members(analyses: &[Analysis]) -> Vec<Member> {
    let mut members: Vec<Member> = analyses
        .iter()
        .enumerate()
        .flat_map(|(k, a)| {
            a.modes.iter().map(move |m| Member {
                recording: k,
                freq_hz: m.freq_hz,
                decay_per_s: m.decay_per_s,
                weight: (m.amplitude.norm() / a.floor_amplitude(m.freq_hz)).powi(2),
                gain: m.gain,
                track: m.track,
            })
        })
        .collect();
    members.sort_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
    members
}

/// Clusters along the frequency axis of `members` (by frequency): a finding joins the nearest
/// cluster closer than the limen to it that has no finding of its recording yet. Two modes found
/// in one recording stay two, however close: the analysis resolved them, and a beating pair or a
/// fast-then-slow decay is heard as such.
fn clusters(members: Vec<Member>) -> Vec<Vec<Member>> {
    let mut clusters: Vec<Vec<Member>> = Vec::new();
    for m in members {
        let limen = difference_limen_hz(m.freq_hz);
        let nearest = clusters
            .iter()
            .enumerate()
            .rev()
            .take_while(|(_, c)| m.freq_hz - c[0].freq_hz < 2.0 * limen)
            .filter(|(_, c)| c.iter().all(|x| x.recording != m.recording))
            .map(|(i, c)| (i, (m.freq_hz - weighted(c, |x| x.freq_hz)).abs()))
            .filter(|&(_, distance)| distance < limen)
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match nearest {
            Some((i, _)) => clusters[i].push(m),
            None => clusters.push(vec![m]),
        }
    }
    clusters
}

/// One mode of each cluster, its gains still to be measured.
fn merged(clusters: &[Vec<Member>]) -> Vec<Combined> {
    clusters
        .iter()
        .map(|c| {
            let best = c
                .iter()
                .max_by(|a, b| a.weight.total_cmp(&b.weight))
                .expect("clusters are never empty");
            Combined {
                freq_hz: weighted(c, |x| x.freq_hz),
                // Merged modes average their decays (seed 000 section 5.4.1), weighted by how
                // well each was measured.
                decay_per_s: weighted(c, |x| x.decay_per_s),
                gains: Vec::new(),
                source: best.recording,
                track: best.track,
                findings: c.len(),
            }
        })
        .collect()
}

/// Drops the modes the analysis' rule for inaudible modes drops (energy over the sound, the
/// longest recording's here): gains measured again over several recordings can leave one far
/// below the others (a click dying within a millisecond, its gain taken from the start of each
/// recording).
fn drop_inaudible(analyses: &[Analysis], modes: &mut Vec<Combined>) {
    let sound_s = analyses
        .iter()
        .map(|a| a.signal.len() as f64 / a.sample_rate_hz)
        .fold(0.0, f64::max);
    let heard = |m: &Combined| {
        let a = m.gains.iter().fold(0.0f64, |acc, g| acc.max(g.abs()));
        energy_over(a, m.decay_per_s, sound_s)
    };
    let loudest = modes.iter().map(heard).fold(0.0, f64::max);
    let floor = loudest * 10f64.powf(-INAUDIBLE_DB / 10.0);
    modes.retain(|m| heard(m) >= floor);
}

/// Mean of `value` over a cluster, weighted by the members' weights.
fn weighted(cluster: &[Member], value: impl Fn(&Member) -> f64) -> f64 {
    let total: f64 = cluster.iter().map(|m| m.weight).sum();
    cluster.iter().map(|m| m.weight * value(m)).sum::<f64>() / total
}

/// Fills every mode's gains: the joint least squares in each recording with all modes' shapes.
fn measure_gains(analyses: &[Analysis], modes: &mut [Combined]) {
    let shapes: Vec<Shape> = modes
        .iter()
        .map(|m| Shape {
            freq_hz: m.freq_hz,
            decay_per_s: m.decay_per_s,
        })
        .collect();
    for m in modes.iter_mut() {
        m.gains.clear();
    }
    for a in analyses {
        // A recording at a lower rate cannot hold modes above its Nyquist frequency.
        let nyquist_hz = 0.5 * a.sample_rate_hz;
        let (inside, outside): (Vec<usize>, Vec<usize>) =
            (0..modes.len()).partition(|&i| modes[i].freq_hz < nyquist_hz);
        let inside_shapes: Vec<Shape> = inside.iter().map(|&i| shapes[i]).collect();
        let amplitudes = a.amplitudes(&inside_shapes);
        let delay_s = strike_delay_s(&inside_shapes, &amplitudes, a.sample_rate_hz);
        for ((&i, c), shape) in inside.iter().zip(amplitudes).zip(&inside_shapes) {
            let m = &mut modes[i];
            // The amplitude as if time 0 were the strike itself.
            let at_strike =
                c * Complex64::from_polar(1.0, std::f64::consts::TAU * shape.freq_hz * delay_s);
            m.gains.push(if c.norm() < a.floor_amplitude(m.freq_hz) {
                0.0
            } else {
                signed_gain(at_strike)
            });
        }
        for i in outside {
            modes[i].gains.push(0.0);
        }
    }
}

/// Widest error of the detected onset corrected, in seconds: a few samples of detection
/// threshold plus a mallet's contact time.
const MAX_STRIKE_DELAY_S: f64 = 0.002;

/// Steps per sample of the search for the strike's time.
const DELAY_STEPS_PER_SAMPLE: f64 = 8.0;

/// The time of the strike after the detected onset, to a fraction of a sample.
///
/// An impulse at time `t_s` starts every mode in sine phase there: `a sin(w (t - t_s))`, whose
/// complex amplitude at the onset is `c = -i a exp(-i w t_s)`. So `c exp(i w t_s)` is imaginary
/// for every mode, whatever the sign of `a`: the search maximises the energy in the imaginary
/// parts, `sum |Im(c_m exp(i w_m t))|^2`, over `t` within [`MAX_STRIKE_DELAY_S`] of the onset.
/// The phases of the modes then give the signs of the gains with the onset's error removed.
fn strike_delay_s(shapes: &[Shape], amplitudes: &[Complex64], sample_rate_hz: f64) -> f64 {
    let step = 1.0 / (sample_rate_hz * DELAY_STEPS_PER_SAMPLE);
    let steps = (MAX_STRIKE_DELAY_S / step).round() as i64;
    let score = |t: f64| -> f64 {
        shapes
            .iter()
            .zip(amplitudes)
            .map(|(s, c)| {
                (c * Complex64::from_polar(1.0, std::f64::consts::TAU * s.freq_hz * t))
                    .im
                    .powi(2)
            })
            .sum()
    };
    (-steps..=steps)
        .map(|i| i as f64 * step)
        .map(|t| (t, score(t)))
        .fold((0.0, f64::NEG_INFINITY), |best, c| {
            if c.1 > best.1 {
                c
            } else {
                best
            }
        })
        .0
}

/// The bank's signed gain for a complex amplitude: its magnitude, signed by whether the mode
/// starts in sine phase (positive) or opposite (negative). `Re(c e^(i w t))` with `c = -i a` is
/// `a sin(w t)`.
pub fn signed_gain(c: Complex64) -> f64 {
    let sine_part = -c.im;
    if sine_part < 0.0 {
        -c.norm()
    } else {
        c.norm()
    }
}

/// Energy of a mode struck at its loudest position (seed 000 eq. 5.15, Bonneel et al.):
/// `E = (1/4) w^2 a^2 / (d (d^2 + w^2))`.
fn energy(m: &Combined) -> f64 {
    let a = m.gains.iter().fold(0.0f64, |acc, g| acc.max(g.abs()));
    let w = std::f64::consts::TAU * m.freq_hz;
    let d = m.decay_per_s.max(MIN_DECAY_PER_S);
    0.25 * w * w * a * a / (d * (d * d + w * w))
}
