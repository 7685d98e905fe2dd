//! What is wrong with a recording that still allows a fit (some clipping, noise), and clipping so
//! heavy that it does not.

use super::onset::Strike;
use super::{FitError, Recording};

/// A sample at or above this magnitude counts as full scale...
const CLIP_LEVEL: f32 = 0.999;

/// ... and this many in a row as clipping: a single full-scale peak is a normalised recording,
/// a flat run is a converter or a gain stage that ran out of range.
const CLIP_RUN: usize = 3;

/// A recording with more than this fraction of its sound clipped is refused: its strongest modes
/// are flattened through much of their ring, so their decays cannot be measured.
pub const MAX_CLIPPED_FRACTION: f64 = 0.1;

/// A strike less than this many dB above the noise gets a warning.
pub const NOISY_SNR_DB: f64 = 30.0;

/// The warnings for `recording`, whose strike is `strike`: the notes made while reading it,
/// then clipping and noise.
pub fn input_warnings(recording: &Recording, strike: &Strike) -> Vec<String> {
    let mut warnings = recording.notes.clone();
    let clipped = clipped_samples(&recording.samples);
    if clipped > 0 {
        warnings.push(format!(
            "clipped: {clipped} samples at full scale in runs of {CLIP_RUN} or more; the strongest \
             modes' gains and decays are unreliable: record with more headroom"
        ));
    }
    if strike.snr_db < NOISY_SNR_DB {
        warnings.push(format!(
            "very noisy: the strike stands only {:.1} dB above the noise ({NOISY_SNR_DB} dB or \
             more is advised); weak modes are lost and decays are less certain",
            strike.snr_db
        ));
    }
    warnings
}

/// An error when more than [`MAX_CLIPPED_FRACTION`] of the sound of `recording` (from the
/// strike's onset to its end) is clipped; `origin` names the recording in the message.
pub fn check_clipping(
    recording: &Recording,
    strike: &Strike,
    origin: &str,
) -> Result<(), FitError> {
    let end = strike.end.min(recording.samples.len());
    let sound = &recording.samples[strike.onset.min(end)..end];
    let fraction = clipped_samples(sound) as f64 / sound.len().max(1) as f64;
    if fraction > MAX_CLIPPED_FRACTION {
        return Err(FitError::Clipped {
            name: origin.to_string(),
            fraction,
        });
    }
    Ok(())
}

/// Samples in runs of at least [`CLIP_RUN`] at full scale.
fn clipped_samples(samples: &[f32]) -> usize {
    let mut total = 0;
    let mut run = 0;
    for &v in samples.iter().chain(std::iter::once(&0.0)) {
        if v.abs() >= CLIP_LEVEL {
            run += 1;
        } else {
            if run >= CLIP_RUN {
                total += run;
            }
            run = 0;
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_runs_at_full_scale_count_as_clipping() {
        assert_eq!(clipped_samples(&[0.5, 1.0, 0.2, -1.0, 0.0]), 0);
        assert_eq!(clipped_samples(&[0.5, 1.0, 1.0, 0.9995, 0.2]), 3);
        assert_eq!(clipped_samples(&[-1.0, -1.0, -1.0, -1.0]), 4);
    }
}
