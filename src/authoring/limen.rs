//! The frequency difference limen: how far apart two frequencies must be to be heard as two.
//!
//! Mode compression (Raghuvanshi and Lin, seed 000 section 5.4.1) replaces modes closer than this
//! by one. The seed quotes Sek and Moore (1995): just under 5 Hz at 2 kHz and over 80 Hz at 8 kHz.
//! Below 2 kHz the limen is close to a constant fraction of the frequency (Weber's law); above it
//! grows much faster, and the two quoted points fix a square law there.

/// Frequency at which the two regimes meet, in Hz.
const KNEE_HZ: f64 = 2_000.0;

/// The limen at the knee, in Hz (seed 000 section 5.4.1: "just under 5 Hz at 2 kHz").
const LIMEN_AT_KNEE_HZ: f64 = 5.0;

/// Smallest limen, in Hz: low tones are not told apart much better than this, whatever their
/// frequency.
const MIN_LIMEN_HZ: f64 = 1.0;

/// The smallest difference in Hz between two tones near `freq_hz` that a listener hears: a fixed
/// fraction (0.25%) of the frequency up to 2 kHz, at least 1 Hz, then growing as the square of the
/// frequency, through 5 Hz at 2 kHz and 80 Hz at 8 kHz (seed 000 section 5.4.1).
pub fn difference_limen_hz(freq_hz: f64) -> f64 {
    let f = freq_hz.abs();
    if f <= KNEE_HZ {
        (LIMEN_AT_KNEE_HZ * f / KNEE_HZ).max(MIN_LIMEN_HZ)
    } else {
        LIMEN_AT_KNEE_HZ * (f / KNEE_HZ).powi(2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meets_the_seed_figures() {
        // seed 000 section 5.4.1: just under 5 Hz at 2 kHz, over 80 Hz at 8 kHz.
        assert!((difference_limen_hz(2_000.0) - 5.0).abs() < 1e-9);
        assert!((difference_limen_hz(8_000.0) - 80.0).abs() < 1e-9);
    }

    #[test]
    fn grows_with_frequency_without_jumps() {
        let mut last = difference_limen_hz(10.0);
        for i in 1..2_000 {
            let f = i as f64 * 10.0;
            let dl = difference_limen_hz(f);
            assert!(dl >= last, "limen falls at {f} Hz: {dl} after {last}");
            assert!(dl - last < 1.0, "limen jumps at {f} Hz: {last} to {dl}");
            last = dl;
        }
        assert_eq!(difference_limen_hz(100.0), MIN_LIMEN_HZ);
    }
}
