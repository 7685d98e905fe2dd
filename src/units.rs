//! Conversions between units that every layer may use: levels, decay rates, pitches.

/// T60 in seconds of a mode decaying at `decay_per_s`: the time its amplitude falls by 60 dB.
pub fn decay_to_t60_s(decay_per_s: f64) -> f64 {
    3.0 * std::f64::consts::LN_10 / decay_per_s
}

/// Decay rate in 1/s of a mode whose amplitude falls by 60 dB in `t60_s` seconds.
pub fn t60_to_decay(t60_s: f64) -> f64 {
    3.0 * std::f64::consts::LN_10 / t60_s
}

/// Linear amplitude of a level in dB.
#[inline]
pub fn db_to_gain(gain_db: f32) -> f32 {
    10f32.powf(gain_db / 20.0)
}

/// Level in dB of a linear amplitude.
#[inline]
pub fn gain_to_db(gain: f32) -> f32 {
    20.0 * gain.abs().max(1e-30).log10()
}

/// Frequency in Hz of a (possibly fractional) MIDI key, A4 = key 69 = 440 Hz.
#[inline]
pub fn midi_key_to_hz(key: f64) -> f64 {
    440.0 * ((key - 69.0) / 12.0).exp2()
}

/// The (fractional) MIDI key of a frequency in Hz.
#[inline]
pub fn hz_to_midi_key(freq_hz: f64) -> f64 {
    69.0 + 12.0 * (freq_hz / 440.0).log2()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_conversions_round_trip() {
        assert!((midi_key_to_hz(69.0) - 440.0).abs() < 1e-12);
        assert!((hz_to_midi_key(261.6255653005986) - 60.0).abs() < 1e-9);
        assert!((decay_to_t60_s(t60_to_decay(2.5)) - 2.5).abs() < 1e-12);
        assert!((gain_to_db(db_to_gain(-6.0)) + 6.0).abs() < 1e-5);
    }
}
