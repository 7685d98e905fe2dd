//! Psychoacoustics for perceptual mode pruning (seed 001, van den Doel, Knott and Pai, section 4):
//! the Bark scale, the threshold of hearing in quiet, the two-slope masking curve, and the energy
//! measures modes are ranked by.
//!
//! Levels are in dB SPL, frequencies in Hz, critical-band rates in Bark. Everything here is a pure
//! function or a table built once; [`PsychoTable`] answers the audio thread's questions without
//! transcendental functions.

use std::f32::consts::LOG10_E;

/// Lower slope of the masking curve, in dB per Bark (seed 001 eq. 4, `s_l`).
pub const LOWER_SLOPE_DB_PER_BARK: f32 = 25.0;

/// Upper slope of the masking curve at a masker level of 0 dB SPL, in dB per Bark (seed 001,
/// `s_u = 22 - L_m / 5`).
pub const UPPER_SLOPE_AT_0_DB: f32 = 22.0;

/// How much the upper slope flattens per dB of masker level (seed 001, the `1/5` of
/// `s_u = 22 - L_m / 5`): louder sounds mask more of what lies above them.
pub const UPPER_SLOPE_PER_DB: f32 = 0.2;

/// dB per neper of amplitude: `20 / ln 10`. A mode decaying at `delta` per sample loses
/// `DB_PER_NEPER * delta` dB per sample.
pub const DB_PER_NEPER: f32 = 20.0 * LOG10_E;

/// Critical-band rate in Bark of a frequency in Hz (Zwicker and Terhardt 1980):
/// `13 atan(0.00076 f) + 3.5 atan((f / 7500)^2)`. One Bark is one critical band (seed 001).
pub fn hz_to_bark(freq_hz: f64) -> f64 {
    13.0 * (0.00076 * freq_hz).atan() + 3.5 * (freq_hz / 7500.0).powi(2).atan()
}

/// Threshold of hearing in quiet in dB SPL at `freq_hz` (Terhardt 1979, as seed 001 gives it):
/// `3.64 (f/1000)^-0.8 - 6.5 exp(-0.6 (f/1000 - 3.3)^2) + 1e-3 (f/1000)^4`.
pub fn threshold_in_quiet_db(freq_hz: f64) -> f64 {
    let khz = freq_hz / 1000.0;
    3.64 * khz.powf(-0.8) - 6.5 * (-0.6 * (khz - 3.3).powi(2)).exp() + 1e-3 * khz.powi(4)
}

/// Upper slope in dB per Bark of the masking curve of a masker at `masker_db` dB SPL:
/// `s_u = 22 - L_m / 5` (seed 001 eq. 4), never negative (a masker above 110 dB SPL masks
/// everything above it at its own level less the offset).
#[inline]
pub fn upper_slope_db_per_bark(masker_db: f32) -> f32 {
    (UPPER_SLOPE_AT_0_DB - UPPER_SLOPE_PER_DB * masker_db).max(0.0)
}

/// Level in dB SPL below which a tone at `probe_bark` is masked by a masker at `masker_bark` and
/// `masker_db` dB SPL, with masking offset `offset_db` (seed 001 eq. 4, `p_m(b)`): two straight
/// lines on the Bark scale, falling at [`LOWER_SLOPE_DB_PER_BARK`] below the masker and at
/// [`upper_slope_db_per_bark`] above it, from `L_m - a_v` at the masker.
#[inline]
pub fn masking_curve_db(masker_bark: f32, masker_db: f32, offset_db: f32, probe_bark: f32) -> f32 {
    let below = LOWER_SLOPE_DB_PER_BARK * (masker_bark - probe_bark);
    let above = upper_slope_db_per_bark(masker_db) * (probe_bark - masker_bark);
    // One of the two is negative (or both zero): the larger is the distance term of this side.
    masker_db - offset_db - below.max(above)
}

/// The masking threshold `mu(b) = max(Th(b), p_m(b))` (seed 001 eq. 4) for one masker, with the
/// threshold in quiet `threshold_db` of the probe.
#[inline]
pub fn masking_threshold_db(
    masker_bark: f32,
    masker_db: f32,
    offset_db: f32,
    probe_bark: f32,
    threshold_db: f32,
) -> f32 {
    threshold_db.max(masking_curve_db(
        masker_bark,
        masker_db,
        offset_db,
        probe_bark,
    ))
}

/// Samples until a masked tone at `probe_bark` stops being masked by a masker at `masker_bark`,
/// when both decay exponentially: levels fall linearly in dB, the masker's by
/// `masker_fall_db_per_sample`, the probe's by `probe_fall_db_per_sample`. As the masker fades its
/// curve also narrows upwards (its upper slope grows by [`UPPER_SLOPE_PER_DB`] per dB), so its
/// level at the probe falls faster above it. Infinite when the probe fades at least as fast as
/// the masking does; zero when it is not masked now.
pub fn unmask_delay_samples(
    masker_bark: f32,
    masker_db: f32,
    masker_fall_db_per_sample: f32,
    offset_db: f32,
    probe_bark: f32,
    probe_db: f32,
    probe_fall_db_per_sample: f32,
) -> f32 {
    let margin_db = masking_curve_db(masker_bark, masker_db, offset_db, probe_bark) - probe_db;
    if margin_db <= 0.0 {
        return 0.0;
    }
    let spread = curve_spread(masker_bark, masker_db, probe_bark);
    let closing_db_per_sample = masker_fall_db_per_sample * spread - probe_fall_db_per_sample;
    if closing_db_per_sample > 0.0 {
        margin_db / closing_db_per_sample
    } else {
        f32::INFINITY
    }
}

/// How many dB a masking curve falls at `probe_bark` per dB its masker at `masker_bark` and
/// `masker_db` falls: 1 below the masker; above it also the upper slope steepening as the masker
/// fades (`s_u = 22 - L_m / 5`, seed 001 eq. 4).
#[inline]
pub fn curve_spread(masker_bark: f32, masker_db: f32, probe_bark: f32) -> f32 {
    if probe_bark > masker_bark && upper_slope_db_per_bark(masker_db) > 0.0 {
        1.0 + UPPER_SLOPE_PER_DB * (probe_bark - masker_bark)
    } else {
        1.0
    }
}

/// Instantaneous energy of a mode from its last two output samples (seed 001 eq. 3): the sum of
/// potential and kinetic energy, `(y^2 + fs^2 (y[t] - y[t-1])^2 / (2 pi f)^2) / 2`. For a sine of
/// amplitude `A` it is about `A^2 / 2`; the engine reads the same quantity exactly as
/// `|z|^2 / 2` from each phasor, whose modulus is the mode's amplitude.
pub fn instantaneous_energy(y: f64, y_prev: f64, sample_rate_hz: f64, freq_hz: f64) -> f64 {
    let velocity = sample_rate_hz * (y - y_prev) / (std::f64::consts::TAU * freq_hz);
    (y * y + velocity * velocity) / 2.0
}

/// Energy of a mode's whole remaining response (seed 000 eq. 5.15, Bonneel et al.):
/// `E = (1/4) w^2 a^2 / (alpha (alpha^2 + w^2))` for amplitude `a`, angular frequency `w` and decay
/// rate `alpha`, in any consistent time unit (per second, or per sample with `w` in radians per
/// sample). Ranks modes for a computation budget: loud modes, and long-ringing ones, first.
#[inline]
pub fn remaining_energy(amplitude: f32, omega: f32, alpha: f32) -> f32 {
    let alpha = alpha.max(f32::MIN_POSITIVE);
    0.25 * omega * omega * amplitude * amplitude / (alpha * (alpha * alpha + omega * omega))
}

/// Level in dB of a power `|z|^2` relative to a unit amplitude: `10 log10(power)` to within
/// 0.001 dB, without a libm call.
#[inline]
pub fn power_to_db(power: f32) -> f32 {
    // 10 log10(x) = 10 log10(2) log2(x)
    3.010_3 * fast_log2(power.max(1e-30))
}

/// `log2(x)` for positive normal `x` to within 3e-4: the float's exponent plus a quartic in its
/// mantissa (a least-squares fit of `log2(1 + m)` on `[0, 1)`).
#[inline]
fn fast_log2(x: f32) -> f32 {
    let bits = x.to_bits();
    let exponent = ((bits >> 23) & 0xff) as f32 - 127.0;
    let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000) - 1.0;
    exponent + m * (1.437_745_9 + m * (-0.674_439_2 + m * (0.318_979_2 - m * 0.082_557_7)))
}

/// Bark and threshold in quiet for any frequency, from a table on a logarithmic frequency grid,
/// linearly interpolated: a handful of operations per query instead of four transcendental
/// functions. Built once (allocates); queries never allocate.
#[derive(Debug, Clone)]
pub struct PsychoTable {
    /// `(bark, threshold_db)` at `TABLE_LOW_HZ * 2^(i / STEPS_PER_OCTAVE)`.
    entries: Vec<(f32, f32)>,
}

/// Lowest frequency of the table, in Hz: 2^4. Queries below take its value.
const TABLE_LOW_HZ: f32 = 16.0;

/// Octaves above [`TABLE_LOW_HZ`] covered: up to 32 kHz. Queries above take the last value.
const TABLE_OCTAVES: usize = 11;

/// Grid steps per octave; the Bark scale and the threshold are smooth on this grid (interpolation
/// error below 0.005 Bark and 0.05 dB from 20 Hz to 20 kHz).
const STEPS_PER_OCTAVE: usize = 64;

impl Default for PsychoTable {
    fn default() -> Self {
        Self::new()
    }
}

impl PsychoTable {
    /// Builds the table. Allocates.
    pub fn new() -> Self {
        let n = TABLE_OCTAVES * STEPS_PER_OCTAVE + 1;
        let entries = (0..n)
            .map(|i| {
                let f = TABLE_LOW_HZ as f64 * (i as f64 / STEPS_PER_OCTAVE as f64).exp2();
                (hz_to_bark(f) as f32, threshold_in_quiet_db(f) as f32)
            })
            .collect();
        Self { entries }
    }

    /// `(bark, threshold_db)` at `freq_hz`.
    #[inline]
    pub fn lookup(&self, freq_hz: f32) -> (f32, f32) {
        // The grid is uniform in log2 f.
        let pos = fast_log2((freq_hz / TABLE_LOW_HZ).max(1.0)) * STEPS_PER_OCTAVE as f32;
        let last = self.entries.len() - 1;
        if pos >= last as f32 {
            return self.entries[last];
        }
        let i = pos as usize;
        let t = pos - i as f32;
        let (b0, h0) = self.entries[i];
        let (b1, h1) = self.entries[i + 1];
        (b0 + t * (b1 - b0), h0 + t * (h1 - h0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bark_scale_matches_the_formula_at_chosen_points() {
        // 13 atan(0.76) + 3.5 atan((1/7.5)^2), worked by hand.
        let at_1k = 13.0 * 0.76f64.atan() + 3.5 * (1.0f64 / 56.25).atan();
        assert!((hz_to_bark(1000.0) - at_1k).abs() < 1e-12);
        assert!(
            (hz_to_bark(1000.0) - 8.5105).abs() < 1e-3,
            "{}",
            hz_to_bark(1000.0)
        );
        assert_eq!(hz_to_bark(0.0), 0.0);
        // The band edges of Zwicker's critical-band table, within 0.2 Bark.
        for (f, z) in [(100.0, 1.0), (510.0, 5.0), (2000.0, 13.0), (9500.0, 22.0)] {
            assert!(
                (hz_to_bark(f) - z).abs() < 0.2,
                "{f} Hz: {} Bark, expected about {z}",
                hz_to_bark(f)
            );
        }
    }

    #[test]
    fn threshold_in_quiet_matches_terhardts_formula_at_chosen_points() {
        // 1 kHz: 3.64 - 6.5 exp(-0.6 * 2.3^2) + 0.001.
        let at_1k = 3.64 - 6.5 * (-0.6f64 * 5.29).exp() + 0.001;
        assert!((threshold_in_quiet_db(1000.0) - at_1k).abs() < 1e-12);
        assert!((threshold_in_quiet_db(1000.0) - 3.369).abs() < 1e-3);
        // The dip of greatest sensitivity at 3.3 kHz: 3.64 * 3.3^-0.8 - 6.5 + 0.001 * 3.3^4.
        let at_dip = 3.64 * 3.3f64.powf(-0.8) - 6.5 + 1e-3 * 3.3f64.powi(4);
        assert!((threshold_in_quiet_db(3300.0) - at_dip).abs() < 1e-12);
        assert!(threshold_in_quiet_db(3300.0) < -4.9);
        // Steep at both ends of hearing.
        assert!(threshold_in_quiet_db(20.0) > 70.0);
        assert!(threshold_in_quiet_db(16_000.0) > 60.0);
    }

    #[test]
    fn masking_curve_has_two_slopes_and_the_offset() {
        let (b, l, av) = (10.0, 60.0, 5.0);
        // At the masker: L - a_v.
        assert_eq!(masking_curve_db(b, l, av, b), 55.0);
        // One Bark below: 25 dB lower.
        assert_eq!(masking_curve_db(b, l, av, b - 1.0), 30.0);
        // Two Bark above: s_u = 22 - 60/5 = 10 dB per Bark.
        assert_eq!(upper_slope_db_per_bark(l), 10.0);
        assert_eq!(masking_curve_db(b, l, av, b + 2.0), 35.0);
        // Louder maskers spread further up: at 90 dB, s_u = 4.
        assert_eq!(masking_curve_db(b, 90.0, av, b + 2.0), 77.0);
        // The lower slope does not depend on level.
        assert_eq!(masking_curve_db(b, 90.0, av, b - 1.0), 60.0);
        // The threshold in quiet bounds it from below (eq. 4).
        assert_eq!(masking_threshold_db(b, l, av, b + 10.0, 3.0), 3.0);
        assert_eq!(masking_threshold_db(b, l, av, b, 3.0), 55.0);
        assert_eq!(upper_slope_db_per_bark(200.0), 0.0);
    }

    #[test]
    fn unmasking_time_follows_the_two_decays() {
        // Masker at 10 Bark, 60 dB, falling 1 dB per unit time; probe one Bark below at 25 dB
        // (curve there: 60 - 5 - 25 = 30 dB, margin 5 dB), falling 0.5 dB per unit time.
        let t = unmask_delay_samples(10.0, 60.0, 1.0, 5.0, 9.0, 25.0, 0.5);
        assert!((t - 10.0).abs() < 1e-4, "{t}");
        // Check against the curve itself at that time.
        let curve = masking_curve_db(10.0, 60.0 - t, 5.0, 9.0);
        assert!((curve - (25.0 - 0.5 * t)).abs() < 1e-4);
        // Above the masker the curve also narrows as the masker fades.
        let t = unmask_delay_samples(10.0, 60.0, 1.0, 5.0, 12.0, 30.0, 0.0);
        let curve = masking_curve_db(10.0, 60.0 - t, 5.0, 12.0);
        assert!((curve - 30.0).abs() < 1e-3, "{t}: curve {curve}");
        // A probe fading faster than its masker stays masked; an unmasked one is due now.
        assert_eq!(
            unmask_delay_samples(10.0, 60.0, 0.1, 5.0, 9.0, 25.0, 0.5),
            f32::INFINITY
        );
        assert_eq!(
            unmask_delay_samples(10.0, 60.0, 1.0, 5.0, 9.0, 45.0, 0.5),
            0.0
        );
    }

    #[test]
    fn eq_3_energy_is_half_the_squared_amplitude_of_a_sine() {
        let (fs, f, a) = (48_000.0, 440.0, 0.3);
        let w = std::f64::consts::TAU * f / fs;
        for n in [10, 123, 4567] {
            let y = a * (w * n as f64).sin();
            let y_prev = a * (w * (n - 1) as f64).sin();
            let e = instantaneous_energy(y, y_prev, fs, f);
            // The backward difference lags by half a sample: off by at most theta / 2.
            assert!(
                (e / (a * a / 2.0) - 1.0).abs() < w / 2.0,
                "sample {n}: eq. 3 gives {e}, A^2/2 = {}",
                a * a / 2.0
            );
        }
    }

    #[test]
    fn remaining_energy_is_the_integral_of_the_squared_response() {
        // a exp(-alpha t) sin(w t), squared and integrated numerically.
        let (a, w, alpha) = (0.7f64, 40.0f64, 3.0f64);
        let dt = 1e-5;
        let integral: f64 = (0..(6.0 / dt) as usize)
            .map(|i| {
                let t = i as f64 * dt;
                let y = a * (-alpha * t).exp() * (w * t).sin();
                y * y * dt
            })
            .sum();
        let e = remaining_energy(a as f32, w as f32, alpha as f32) as f64;
        assert!((e / integral - 1.0).abs() < 1e-3, "{e} vs {integral}");
    }

    #[test]
    fn fast_decibels_match_log10() {
        for i in 0..2000 {
            let p = 10f32.powf(-14.0 + i as f32 * 0.0071);
            let want = 10.0 * p.log10();
            let got = power_to_db(p);
            assert!((got - want).abs() < 0.001, "{p}: {got} dB, expected {want}");
        }
    }

    #[test]
    fn table_matches_the_formulas() {
        let table = PsychoTable::new();
        for i in 0..=1000 {
            let f = 20.0 * 1000f64.powf(i as f64 / 1000.0);
            let (bark, th) = table.lookup(f as f32);
            assert!(
                (bark as f64 - hz_to_bark(f)).abs() < 0.005,
                "{f} Hz: {bark} Bark, expected {}",
                hz_to_bark(f)
            );
            let want = threshold_in_quiet_db(f);
            assert!(
                (th as f64 - want).abs() < 0.05 + 1e-3 * want.abs(),
                "{f} Hz: threshold {th} dB, expected {want}"
            );
        }
        // Beyond the ends: clamped, finite.
        assert!(table.lookup(1.0).0.is_finite());
        assert!(table.lookup(1e6).1 > 100.0);
    }
}
