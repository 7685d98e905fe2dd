//! Candidate modes by voting (seed 000 section 6.2.2): every spectral peak of every frame votes
//! for its bin with its squared magnitude, so the peaks of a ringing mode outvote the chance peaks
//! of noise; the most-voted bins are the candidates.

use std::ops::Range;

use super::noise::NoiseSpectrum;
use super::stft::Spectrogram;

/// A peak must stand this many dB above the noise in its bin to vote.
const PEAK_ABOVE_NOISE_DB: f64 = 10.0;

/// A peak is the largest value within this many bins of the unpadded window on either side.
/// Two bins reach past the Hann window's main lobe (+-2 bins), so the side lobes of a strong
/// mode, each lower than its neighbour towards the main lobe, never count as peaks.
const PEAK_HALF_WIDTH_BINS: usize = 2;

/// A candidate mode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// Frequency, interpolated between bins, in Hz.
    pub freq_hz: f64,
    /// Sum of the squared magnitudes of the peaks that voted for its bin.
    pub votes: f64,
}

/// The `max_candidates` most-voted bins of `frames` of `spec` within `bins`, strongest first.
/// A bin is a candidate when its votes are a local maximum within one unpadded bin.
pub fn vote(
    spec: &Spectrogram,
    noise: &NoiseSpectrum,
    frames: Range<usize>,
    bins: Range<usize>,
    max_candidates: usize,
) -> Vec<Candidate> {
    let n = spec.num_bins();
    let bins = bins.start.max(1)..bins.end.min(n - 1);
    let half = PEAK_HALF_WIDTH_BINS * spec.pad;
    let above = 10f64.powf(PEAK_ABOVE_NOISE_DB / 10.0);
    let mut votes = vec![0.0; n];
    let mut summed = vec![0.0; n];
    for frame in &spec.power[frames] {
        for (s, p) in summed.iter_mut().zip(frame) {
            *s += p;
        }
        for i in bins.clone() {
            let p = frame[i];
            if p <= noise.power[i] * above {
                continue;
            }
            let lo = i.saturating_sub(half);
            let hi = (i + half + 1).min(n);
            // Strictly above the bins before, at least the bins after: one vote per plateau.
            let is_peak =
                frame[lo..i].iter().all(|&q| q < p) && frame[i + 1..hi].iter().all(|&q| q <= p);
            if is_peak {
                votes[i] += p;
            }
        }
    }
    let mut found: Vec<Candidate> = bins
        .filter(|&i| {
            votes[i] > 0.0 && {
                let lo = i.saturating_sub(spec.pad);
                let hi = (i + spec.pad + 1).min(n);
                votes[lo..i].iter().all(|&v| v < votes[i])
                    && votes[i + 1..hi].iter().all(|&v| v <= votes[i])
            }
        })
        .map(|i| Candidate {
            freq_hz: (i as f64 + parabolic_offset(&summed, i)) * spec.bin_hz,
            votes: votes[i],
        })
        .collect();
    found.sort_by(|a, b| b.votes.total_cmp(&a.votes));
    found.truncate(max_candidates);
    found
}

/// Offset in bins (-0.5 to 0.5) of the vertex of the parabola through the logarithms of
/// `power[i - 1..=i + 1]`: the peak's position between bins.
pub fn parabolic_offset(power: &[f64], i: usize) -> f64 {
    if i == 0 || i + 1 >= power.len() {
        return 0.0;
    }
    let ln = |p: f64| p.max(1e-300).ln();
    let (a, b, c) = (ln(power[i - 1]), ln(power[i]), ln(power[i + 1]));
    let curvature = a - 2.0 * b + c;
    if curvature >= 0.0 {
        return 0.0;
    }
    (0.5 * (a - c) / curvature).clamp(-0.5, 0.5)
}

#[cfg(test)]
mod tests {
    use super::super::stft::hann;
    use super::*;

    #[test]
    fn strong_modes_win_and_side_lobes_do_not_vote() {
        let rate = 48_000.0;
        // A strong mode, a weak one 30 dB down, and nothing else: no noise at all.
        let x: Vec<f64> = (0..48_000)
            .map(|n| {
                let t = n as f64 / rate;
                let tau = std::f64::consts::TAU;
                (-3.0 * t).exp() * (tau * 440.7 * t).sin()
                    + 0.03 * (-5.0 * t).exp() * (tau * 1234.5 * t).sin()
            })
            .collect();
        let spec = Spectrogram::new(&x, rate, 2048, 512, 2);
        let sum: f64 = hann(2048).iter().sum();
        let noise = NoiseSpectrum {
            power: vec![1e-12 * sum * sum; spec.num_bins()],
        };
        let found = vote(&spec, &noise, 0..spec.power.len(), 0..spec.num_bins(), 10);
        assert_eq!(found.len(), 2, "{found:?}");
        assert!(
            (found[0].freq_hz - 440.7).abs() < 0.1 * spec.bin_hz * 2.0,
            "{found:?}"
        );
        assert!(
            (found[1].freq_hz - 1234.5).abs() < 0.1 * spec.bin_hz * 2.0,
            "{found:?}"
        );
    }

    #[test]
    fn votes_weigh_each_peak_by_its_power() {
        // A loud mode that dies within a third of a second against a quiet one that rings all
        // along: counting frames, or weighing by magnitude, elects the quiet one; weighing by
        // power (the squared magnitude) elects the loud one.
        let rate = 48_000.0;
        let tau = std::f64::consts::TAU;
        let x: Vec<f64> = (0..48_000)
            .map(|n| {
                let t = n as f64 / rate;
                (-40.0 * t).exp() * (tau * 440.7 * t).sin()
                    + 0.05 * (-0.5 * t).exp() * (tau * 1234.5 * t).sin()
            })
            .collect();
        let spec = Spectrogram::new(&x, rate, 2048, 512, 2);
        let sum: f64 = hann(2048).iter().sum();
        let noise = NoiseSpectrum {
            power: vec![1e-12 * sum * sum; spec.num_bins()],
        };
        let frames = 0..spec.power.len();
        let all = vote(&spec, &noise, frames.clone(), 0..spec.num_bins(), 10);
        assert_eq!(all.len(), 2, "{all:?}");
        let bin_of = |c: &Candidate| (c.freq_hz / spec.bin_hz).round() as usize;
        let (loud, quiet) = (bin_of(&all[0]), bin_of(&all[1]));
        assert!((all[0].freq_hz - 440.7).abs() < spec.bin_hz, "{all:?}");
        // The other weightings would rank them the other way round.
        let count = |b: usize| spec.power.iter().filter(|f| f[b] > noise.power[b]).count();
        let magnitude = |b: usize| spec.power.iter().map(|f| f[b].sqrt()).sum::<f64>();
        assert!(
            count(quiet) > count(loud),
            "frames {} vs {}",
            count(quiet),
            count(loud)
        );
        assert!(magnitude(quiet) > magnitude(loud));
        // Each vote is the power of its bin summed over the frames where it peaks: here every
        // frame in which the mode stands above the noise.
        for c in &all {
            let b = bin_of(c);
            let power: f64 = spec
                .power
                .iter()
                .map(|f| f[b])
                .filter(|&p| p > noise.power[b] * 10f64.powf(PEAK_ABOVE_NOISE_DB / 10.0))
                .sum();
            assert!(
                (c.votes / power - 1.0).abs() < 1e-3,
                "{} Hz: votes {} against summed power {power}",
                c.freq_hz,
                c.votes
            );
        }
        let one = vote(&spec, &noise, frames, 0..spec.num_bins(), 1);
        assert_eq!(one.len(), 1);
        assert!((one[0].freq_hz - 440.7).abs() < spec.bin_hz, "{one:?}");
    }
}
