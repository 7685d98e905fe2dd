//! Where the strike starts in a recording, where its sound ends, and how far it stands above
//! the noise.
//!
//! Energy in 1 ms blocks: the noise level is a low percentile of the blocks (the quiet before
//! the strike or after the ring, or the end of a recording cut short), the onset the first block
//! clearly above both that level and the loudest block's level less a fixed range, refined to the
//! first sample standing out of the noise. Where the recording has a lead-in before the onset,
//! the noise is then the median of the lead-in's blocks. A recording with no strike is told
//! apart as steady noise or a held tone.

/// Length of an energy block in seconds.
const BLOCK_S: f64 = 1e-3;

/// Percentile of block energies taken as the noise level.
const NOISE_PERCENTILE: f64 = 0.1;

/// The loudest block must stand this far above the noise, in dB, to count as a strike.
pub const MIN_STRIKE_DB: f64 = 20.0;

/// The onset block is within this many dB of the loudest block...
const ONSET_BELOW_PEAK_DB: f64 = 30.0;

/// ... and at least this many dB above the noise.
const ONSET_ABOVE_NOISE_DB: f64 = 12.0;

/// Blocks before the strike that make a lead-in to take the noise from (20 ms).
const MIN_LEAD_IN_BLOCKS: usize = 20;

/// A sample stands out of the noise when it exceeds this many noise RMS.
const SAMPLE_ABOVE_NOISE: f64 = 5.0;

/// Where the strike is in a recording.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Strike {
    /// First sample of the strike.
    pub onset: usize,
    /// One past the last sample of the recording that is not digital silence.
    pub end: usize,
    /// RMS level of the noise, linear full scale.
    pub noise_rms: f64,
    /// Level of the loudest 1 ms block over the noise, in dB: the recording's signal-to-noise
    /// ratio.
    pub snr_db: f64,
}

/// Length of the blocks the decay after the strike is judged on, in seconds: long enough that
/// steady noise varies by well under a decibel from block to block.
const DECAY_BLOCK_S: f64 = 0.01;

/// A recording with no quiet stretch counts as a strike when its loudest 10 ms stand this many
/// dB above the level of its last quarter: its sound decays, as a struck object's does, where
/// steady noise or a held tone stays level.
pub const MIN_DECAY_DB: f64 = 3.0;

/// Finds the strike in `x` (at `sample_rate_hz`), or says in words why there is none.
///
/// A strike either rises out of a quiet stretch (the loudest millisecond [`MIN_STRIKE_DB`] above
/// the quietest), or, in a recording cut before its ring dies away, decays: its loudest 10 ms
/// [`MIN_DECAY_DB`] above its last quarter. The sound runs to the end of the recording (less
/// digital silence): the noise is judged band by band later, never assumed from the file's end.
pub fn find_strike(x: &[f64], sample_rate_hz: f64) -> Result<Strike, String> {
    let block = ((BLOCK_S * sample_rate_hz).round() as usize).max(1);
    let energies = block_energies(x, block);
    let peak = energies.iter().copied().fold(0.0, f64::max);
    if peak <= 0.0 {
        return Err("no strike: every sample is zero".to_string());
    }
    let mut sorted = energies.clone();
    let rank = ((sorted.len() - 1) as f64 * NOISE_PERCENTILE).round() as usize;
    let (_, noise, _) = sorted.select_nth_unstable_by(rank, f64::total_cmp);
    // Digital silence before the strike: the noise is at most the quantisation of 24-bit audio.
    let noise = noise.max(peak * 1e-15).max(1e-18);
    let snr_db = 10.0 * (peak / noise).log10();
    if snr_db < MIN_STRIKE_DB {
        let decay_db = decay_db(x, sample_rate_hz);
        if decay_db < MIN_DECAY_DB {
            return Err(format!(
                "no strike: the sound neither rises out of quiet (the loudest part is only \
                 {snr_db:.1} dB above the quietest, {MIN_STRIKE_DB} dB is needed) nor decays \
                 (its loudest 10 ms are {decay_db:.1} dB above its last quarter, \
                 {MIN_DECAY_DB} dB is needed): {}",
                steady_sound(x, sample_rate_hz)
            ));
        }
    }
    let db = |ratio_db: f64| 10f64.powf(ratio_db / 10.0);
    // In a recording with no quiet stretch, the onset is where it first comes near its peak.
    let threshold = (peak / db(ONSET_BELOW_PEAK_DB))
        .max(noise * db(ONSET_ABOVE_NOISE_DB))
        .min(0.25 * peak);
    let first = energies
        .iter()
        .position(|&e| e > threshold)
        .expect("the loudest block exceeds the threshold");
    // A lead-in tells the noise better than a percentile over the whole file, which lands in
    // the ring when the lead-in is under a tenth of it: the median of its blocks, clear of the
    // strike.
    let noise = if first > MIN_LEAD_IN_BLOCKS {
        let mut lead_in = energies[..first - 1].to_vec();
        let mid = lead_in.len() / 2;
        let (_, median, _) = lead_in.select_nth_unstable_by(mid, f64::total_cmp);
        median.max(peak * 1e-15).max(1e-18)
    } else {
        noise
    };
    let snr_db = 10.0 * (peak / noise).log10();
    let noise_rms = noise.sqrt();
    let search = first.saturating_sub(1) * block..((first + 1) * block).min(x.len());
    let onset = search
        .clone()
        .find(|&n| x[n].abs() > SAMPLE_ABOVE_NOISE * noise_rms)
        .unwrap_or(search.start);
    let end = x.iter().rposition(|&v| v != 0.0).map_or(x.len(), |n| n + 1);
    Ok(Strike {
        onset,
        end: end.max(onset + 1),
        noise_rms,
        snr_db,
    })
}

/// Length of the frames a steady sound's spectrum is averaged over, in seconds: bins of about
/// 3 Hz, so mains hum lies well clear of the lowest bins.
const STEADY_FRAME_S: f64 = 0.34;

/// A bin is part of a tone when it is the top of a peak standing this many dB above the median
/// of the bins on each side of it.
const TONE_ABOVE_LOCAL_DB: f64 = 15.0;

/// Bins on each side of a bin that make up its surroundings.
const LOCAL_BINS: usize = 16;

/// Bins either side of a peak's top that belong to it (the window's main lobe).
const PEAK_HALF_WIDTH: usize = 2;

/// A steady sound is a held tone when this share of its power is in tones.
const TONAL_SHARE: f64 = 0.5;

/// What a sound with no strike is, in words: a held tone (named by its strongest frequency)
/// when most of its power stands in narrow peaks, each well above the spectrum on both sides of
/// it, steady noise otherwise. The spectrum, of the signal less its mean, is averaged over
/// overlapping frames, so noise varies little from bin to bin; asking for both sides keeps a
/// steep slope of coloured noise from passing for a peak.
fn steady_sound(x: &[f64], sample_rate_hz: f64) -> String {
    let frame = ((STEADY_FRAME_S * sample_rate_hz) as usize)
        .next_power_of_two()
        .min(x.len().next_power_of_two() / 2);
    if frame < 4 * LOCAL_BINS {
        return "steady noise or a held tone, too short to tell which".to_string();
    }
    let mean = x.iter().sum::<f64>() / x.len() as f64;
    let centred: Vec<f64> = x.iter().map(|v| v - mean).collect();
    let frames = super::stft::Spectrogram::new(&centred, sample_rate_hz, frame, frame / 2, 1);
    let mut power = vec![0.0; frames.num_bins()];
    for p in &frames.power {
        for (m, v) in power.iter_mut().zip(p) {
            *m += v;
        }
    }
    let total: f64 = power.iter().sum();
    if total <= 0.0 {
        return "steady noise or a held tone".to_string();
    }
    let above = 10f64.powf(TONE_ABOVE_LOCAL_DB / 10.0);
    let median = |bins: &[f64]| {
        let mut v = bins.to_vec();
        let mid = v.len() / 2;
        *v.select_nth_unstable_by(mid, f64::total_cmp).1
    };
    let n = power.len();
    let mut tonal = vec![false; n];
    for k in LOCAL_BINS..n.saturating_sub(LOCAL_BINS) {
        let lobe = k - PEAK_HALF_WIDTH..=k + PEAK_HALF_WIDTH;
        if lobe.clone().any(|j| power[j] > power[k]) {
            continue;
        }
        let left = median(&power[k - LOCAL_BINS..k - PEAK_HALF_WIDTH]);
        let right = median(&power[k + PEAK_HALF_WIDTH + 1..=k + LOCAL_BINS]);
        if power[k] > above * left.max(right) {
            for t in &mut tonal[lobe] {
                *t = true;
            }
        }
    }
    let in_tones: f64 = power
        .iter()
        .zip(&tonal)
        .filter(|(_, t)| **t)
        .map(|(p, _)| p)
        .sum();
    if in_tones / total < TONAL_SHARE {
        return "it is steady noise".to_string();
    }
    let strongest = (0..n)
        .max_by(|&a, &b| power[a].total_cmp(&power[b]))
        .expect("a spectrum has bins");
    format!(
        "it is a held tone (strongest near {:.0} Hz)",
        strongest as f64 * frames.bin_hz
    )
}

/// Mean square of `x` in blocks of `block` samples.
fn block_energies(x: &[f64], block: usize) -> Vec<f64> {
    x.chunks(block)
        .map(|c| c.iter().map(|v| v * v).sum::<f64>() / c.len() as f64)
        .collect()
}

/// How far, in dB, the loudest 10 ms of `x`, or of its first difference, stand above the median
/// 10 ms of its last quarter. The difference stresses high frequencies, whose decay shows a
/// strike even where the lowest partial swells or beats (a vibraphone): the upper partials of a
/// struck object die first, while a held tone keeps its brightness.
fn decay_db(x: &[f64], sample_rate_hz: f64) -> f64 {
    let difference: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    level_fall_db(x, sample_rate_hz).max(level_fall_db(&difference, sample_rate_hz))
}

/// How far, in dB, the loudest 10 ms of `x` stand above the median 10 ms of its last quarter.
fn level_fall_db(x: &[f64], sample_rate_hz: f64) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    let block = ((DECAY_BLOCK_S * sample_rate_hz).round() as usize).max(1);
    let energies = block_energies(x, block);
    let peak = energies.iter().copied().fold(0.0, f64::max);
    let mut last: Vec<f64> = energies[energies.len() - energies.len().div_ceil(4)..].to_vec();
    let mid = last.len() / 2;
    let (_, median, _) = last.select_nth_unstable_by(mid, f64::total_cmp);
    10.0 * (peak / median.max(1e-300)).log10()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    fn strike_at(onset: usize, noise: f64) -> Vec<f64> {
        let rate = 48_000.0;
        let mut rng = Rng::new(3);
        (0..48_000)
            .map(|n| {
                let ring = if n >= onset {
                    let t = (n - onset) as f64 / rate;
                    (-8.0 * t).exp() * (std::f64::consts::TAU * 3_000.0 * t + 1.0).sin()
                } else {
                    0.0
                };
                ring + noise * rng.bipolar() as f64
            })
            .collect()
    }

    #[test]
    fn finds_the_first_sample_of_the_strike() {
        for onset in [0, 100, 4_801, 20_000] {
            let x = strike_at(onset, 1e-3);
            let s = find_strike(&x, 48_000.0).unwrap();
            assert!(
                s.onset >= onset.saturating_sub(1) && s.onset <= onset + 2,
                "onset at {}, expected {onset}",
                s.onset
            );
            assert!(s.snr_db > 40.0, "snr {}", s.snr_db);
            // The sound runs to the end of the recording: the noise is judged later.
            assert_eq!(s.end, x.len());
        }
    }

    #[test]
    fn a_strike_cut_before_its_ring_dies_is_found() {
        // 0.4 s of a ring losing 1.4 dB a tenth of a second, cut off 5.5 dB down: no quiet
        // stretch at all.
        let rate = 44_100.0;
        let x: Vec<f64> = (0..17_640)
            .map(|n| {
                let t = n as f64 / rate;
                (-1.6 * t).exp() * (std::f64::consts::TAU * 880.0 * t).sin()
            })
            .collect();
        let s = find_strike(&x, rate).unwrap();
        assert!(s.onset < 10, "onset {}", s.onset);
        assert_eq!(s.end, x.len());
    }

    #[test]
    fn a_strike_whose_low_partial_swells_is_found_by_its_fading_brightness() {
        // A partial rising 4 dB over the first 0.2 s (beating with its neighbour) under one at
        // 4.4 kHz that dies within 0.1 s: the level hardly falls, the brightness does.
        let rate = 44_100.0;
        let tau = std::f64::consts::TAU;
        let x: Vec<f64> = (0..17_640)
            .map(|n| {
                let t = n as f64 / rate;
                (1.0 - 0.37 * (-10.0 * t).exp()) * (tau * 440.0 * t).sin()
                    + 0.3 * (-40.0 * t).exp() * (tau * 4_400.0 * t).sin()
            })
            .collect();
        assert!(level_fall_db(&x, rate) < MIN_DECAY_DB);
        assert!(find_strike(&x, rate).is_ok());
    }

    #[test]
    fn silence_and_steady_noise_are_not_strikes() {
        assert!(find_strike(&[0.0; 1000], 48_000.0).is_err());
        let mut rng = Rng::new(9);
        let noise: Vec<f64> = (0..48_000).map(|_| 0.1 * rng.bipolar() as f64).collect();
        let message = find_strike(&noise, 48_000.0).unwrap_err();
        assert!(message.contains("it is steady noise"), "{message}");
        // Coloured noise is noise too: white noise through a one-pole low-pass, brown noise
        // (falling 6 dB an octave from the lowest bins up, a steep slope on either side of no
        // peak), and noise on a DC offset.
        let low_passed = |pole: f64| -> Vec<f64> {
            let mut state = 0.0;
            noise
                .iter()
                .map(|v| {
                    state = pole * state + v;
                    state
                })
                .collect()
        };
        for (name, x) in [
            ("low-passed", low_passed(0.7)),
            ("brown", low_passed(0.9995)),
            ("offset", noise.iter().map(|v| v + 0.3).collect()),
        ] {
            // (Whether a strike is found in it is the decay test's matter.)
            assert_eq!(steady_sound(&x, 48_000.0), "it is steady noise", "{name}");
        }
        let near_hz = |message: &str| -> f64 {
            let at = message.find("strongest near ").expect(message) + "strongest near ".len();
            message[at..].split(' ').next().unwrap().parse().unwrap()
        };
        // A held tone with harmonics over a little noise: named, with its strongest frequency.
        let tone: Vec<f64> = (0..48_000)
            .map(|n| {
                let phase = std::f64::consts::TAU * 440.0 * n as f64 / 48_000.0;
                phase.sin()
                    + 0.5 * (2.0 * phase).sin()
                    + 0.25 * (3.0 * phase).sin()
                    + 0.01 * rng.bipolar() as f64
            })
            .collect();
        let message = find_strike(&tone, 48_000.0).unwrap_err();
        assert!(message.contains("nor decays"), "{message}");
        assert!(message.contains("it is a held tone"), "{message}");
        assert!((near_hz(&message) - 440.0).abs() < 3.0, "{message}");
        // Hum: a mains tone under hiss.
        let hum: Vec<f64> = (0..48_000)
            .map(|n| {
                0.1 * (std::f64::consts::TAU * 60.0 * n as f64 / 48_000.0).sin()
                    + 0.02 * rng.bipolar() as f64
            })
            .collect();
        let message = find_strike(&hum, 48_000.0).unwrap_err();
        assert!(message.contains("held tone"), "{message}");
        assert!((near_hz(&message) - 60.0).abs() < 3.0, "{message}");
    }
}
