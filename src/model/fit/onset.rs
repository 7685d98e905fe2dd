//! Where the strike starts in a recording, where its sound ends, and how far it stands above
//! the noise.
//!
//! Energy in 1 ms blocks: the noise level is a low percentile of the blocks (the quiet before
//! the strike or after the ring), the onset the first block clearly above both the noise and the
//! loudest block's level less a fixed range, refined to the first sample standing out of the
//! noise.

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

/// A sample stands out of the noise when it exceeds this many noise RMS.
const SAMPLE_ABOVE_NOISE: f64 = 5.0;

/// The sound has ended once no later block is this many dB above the noise.
const END_ABOVE_NOISE_DB: f64 = 6.0;

/// Where the strike is in a recording.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Strike {
    /// First sample of the strike.
    pub onset: usize,
    /// One past the last sample with sound above the noise.
    pub end: usize,
    /// RMS level of the noise, linear full scale.
    pub noise_rms: f64,
    /// Level of the loudest 1 ms block over the noise, in dB: the recording's signal-to-noise
    /// ratio.
    pub snr_db: f64,
}

/// Finds the strike in `x` (at `sample_rate_hz`), or says in words why there is none.
pub fn find_strike(x: &[f64], sample_rate_hz: f64) -> Result<Strike, String> {
    let block = ((BLOCK_S * sample_rate_hz).round() as usize).max(1);
    let energies: Vec<f64> = x
        .chunks(block)
        .map(|c| c.iter().map(|v| v * v).sum::<f64>() / c.len() as f64)
        .collect();
    let peak = energies.iter().copied().fold(0.0, f64::max);
    if peak <= 0.0 {
        return Err("every sample is zero".to_string());
    }
    let mut sorted = energies.clone();
    let rank = ((sorted.len() - 1) as f64 * NOISE_PERCENTILE).round() as usize;
    let (_, noise, _) = sorted.select_nth_unstable_by(rank, f64::total_cmp);
    // Digital silence before the strike: the noise is at most the quantisation of 24-bit audio.
    let noise = noise.max(peak * 1e-15).max(1e-18);
    let snr_db = 10.0 * (peak / noise).log10();
    if snr_db < MIN_STRIKE_DB {
        return Err(format!(
            "the loudest part is only {snr_db:.1} dB above the quietest, {MIN_STRIKE_DB} dB is \
             needed (is it silence or steady noise?)"
        ));
    }
    let db = |ratio_db: f64| 10f64.powf(ratio_db / 10.0);
    let threshold = (peak / db(ONSET_BELOW_PEAK_DB)).max(noise * db(ONSET_ABOVE_NOISE_DB));
    let first = energies
        .iter()
        .position(|&e| e > threshold)
        .expect("the loudest block exceeds the threshold");
    let noise_rms = noise.sqrt();
    let search = first.saturating_sub(1) * block..((first + 1) * block).min(x.len());
    let onset = search
        .clone()
        .find(|&n| x[n].abs() > SAMPLE_ABOVE_NOISE * noise_rms)
        .unwrap_or(search.start);
    let last = energies
        .iter()
        .rposition(|&e| e > noise * db(END_ABOVE_NOISE_DB))
        .unwrap_or(first);
    let end = ((last + 1) * block).min(x.len()).max(onset + 1);
    Ok(Strike {
        onset,
        end,
        noise_rms,
        snr_db,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dsp::rng::Rng;

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
            // The ring falls to 6 dB above the noise (1e-3 / sqrt(3) RMS) after about 0.8 s.
            let expected_end = (onset + 38_400).min(x.len());
            assert!(
                s.end.abs_diff(expected_end) < 2_400,
                "end {}, expected about {expected_end}",
                s.end
            );
        }
    }

    #[test]
    fn silence_and_steady_noise_are_not_strikes() {
        assert!(find_strike(&[0.0; 1000], 48_000.0).is_err());
        let mut rng = Rng::new(9);
        let noise: Vec<f64> = (0..48_000).map(|_| 0.1 * rng.bipolar() as f64).collect();
        let message = find_strike(&noise, 48_000.0).unwrap_err();
        assert!(message.contains("dB above the quietest"), "{message}");
    }
}
