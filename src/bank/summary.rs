//! A bank described for people: what `modal-resonator info` prints and the editor shows.

use std::fmt;

use super::Bank;
use crate::units::{decay_to_t60_s, hz_to_midi_key};

/// Name of the equal-tempered note nearest `freq_hz` and its offset in cents, e.g. "C4" or
/// "C4 +12 c".
pub fn note_name(freq_hz: f64) -> String {
    const NAMES: [&str; 12] = [
        "C", "C#", "D", "D#", "E", "F", "F#", "G", "G#", "A", "A#", "B",
    ];
    let key = hz_to_midi_key(freq_hz);
    let nearest = key.round();
    let cents = ((key - nearest) * 100.0).round();
    let index = nearest as i64;
    let name = format!(
        "{}{}",
        NAMES[index.rem_euclid(12) as usize],
        index.div_euclid(12) - 1
    );
    if cents == 0.0 {
        name
    } else {
        format!("{name} {cents:+} c")
    }
}

/// The MIDI key (60 = C4, 69 = A4) of a note name such as "C4", "F#2", "Bb5" or "C-1", or of a
/// key number such as "60"; `None` when `text` is neither.
pub fn note_to_midi_key(text: &str) -> Option<u8> {
    let text = text.trim();
    if let Ok(key) = text.parse::<u8>() {
        return (key <= 127).then_some(key);
    }
    let mut chars = text.chars();
    let letter = chars.next()?.to_ascii_uppercase();
    let pitch_class: i32 = match letter {
        'C' => 0,
        'D' => 2,
        'E' => 4,
        'F' => 5,
        'G' => 7,
        'A' => 9,
        'B' => 11,
        _ => return None,
    };
    let rest = chars.as_str();
    let (accidental, octave) = match rest.chars().next()? {
        '#' => (1, &rest[1..]),
        'b' => (-1, &rest[1..]),
        _ => (0, rest),
    };
    let octave: i32 = octave.parse().ok()?;
    let key = 12 * (octave + 1) + pitch_class + accidental;
    u8::try_from(key).ok().filter(|&k| k <= 127)
}

/// The facts about a bank worth showing.
#[derive(Debug, Clone, PartialEq)]
pub struct BankSummary {
    /// Display name.
    pub name: String,
    /// Description.
    pub description: String,
    /// Author.
    pub author: String,
    /// Licence.
    pub license: String,
    /// `source.kind`, if given.
    pub source_kind: Option<String>,
    /// Pitch at size 1, in Hz.
    pub root_hz: f64,
    /// Number of modes.
    pub num_modes: usize,
    /// Lowest and highest mode frequency in Hz.
    pub freq_range_hz: (f64, f64),
    /// Shortest, median and longest T60 in seconds (infinite for undamped modes).
    pub t60_s: (f64, f64, f64),
    /// The bank's own quality factor (median of pi f / d), if any mode decays.
    pub reference_q: Option<f64>,
    /// Position names with their coordinates.
    pub positions: Vec<(String, Vec<f64>)>,
    /// The strongest modes (largest gain over the positions): frequency in Hz, T60 in s, gain.
    pub strongest: Vec<(f64, f64, f64)>,
}

/// How many of the strongest modes a summary lists.
const STRONGEST_LISTED: usize = 8;

impl BankSummary {
    /// Summarises `bank` (which should be valid; an empty bank gives zeros).
    pub fn of(bank: &Bank) -> Self {
        let freqs = bank.modes.iter().map(|m| m.freq_hz);
        let lo = freqs.clone().fold(f64::INFINITY, f64::min);
        let hi = freqs.fold(0.0, f64::max);
        let t60 = |d: f64| {
            if d > 0.0 {
                decay_to_t60_s(d)
            } else {
                f64::INFINITY
            }
        };
        let mut t60s: Vec<f64> = bank.modes.iter().map(|m| t60(m.decay_per_s)).collect();
        t60s.sort_by(f64::total_cmp);
        let t60_s = match t60s.len() {
            0 => (0.0, 0.0, 0.0),
            n => (t60s[0], t60s[n / 2], t60s[n - 1]),
        };
        let strength = |m: &super::Mode| m.gains.iter().fold(0.0f64, |a, g| a.max(g.abs()));
        let mut by_strength: Vec<&super::Mode> = bank.modes.iter().collect();
        by_strength.sort_by(|a, b| strength(b).total_cmp(&strength(a)));
        Self {
            name: bank.name.clone(),
            description: bank.description.clone(),
            author: bank.author.clone(),
            license: bank.license.clone(),
            source_kind: bank.source_text("kind").map(str::to_string),
            root_hz: bank.effective_root_hz(),
            num_modes: bank.modes.len(),
            freq_range_hz: if bank.modes.is_empty() {
                (0.0, 0.0)
            } else {
                (lo, hi)
            },
            t60_s,
            reference_q: bank.reference_q(),
            positions: bank
                .positions
                .iter()
                .map(|p| (p.name.clone(), p.coords.clone()))
                .collect(),
            strongest: by_strength
                .iter()
                .take(STRONGEST_LISTED)
                .map(|m| (m.freq_hz, t60(m.decay_per_s), strength(m)))
                .collect(),
        }
    }
}

impl fmt::Display for BankSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{}", self.name)?;
        if !self.description.is_empty() {
            writeln!(f, "  {}", self.description)?;
        }
        let or_dash = |s: &str| {
            if s.is_empty() {
                "-".to_string()
            } else {
                s.to_string()
            }
        };
        writeln!(
            f,
            "  author: {}   licence: {}   source: {}",
            or_dash(&self.author),
            or_dash(&self.license),
            self.source_kind.as_deref().unwrap_or("-")
        )?;
        writeln!(
            f,
            "  root: {:.2} Hz ({})",
            self.root_hz,
            note_name(self.root_hz)
        )?;
        writeln!(
            f,
            "  modes: {}, {:.2} Hz to {:.2} Hz",
            self.num_modes, self.freq_range_hz.0, self.freq_range_hz.1
        )?;
        let (short, median, long) = self.t60_s;
        writeln!(
            f,
            "  T60: {short:.3} s shortest, {median:.3} s median, {long:.3} s longest"
        )?;
        match self.reference_q {
            Some(q) => writeln!(f, "  quality factor Q (median of pi f / d): {q:.0}")?,
            None => writeln!(f, "  quality factor Q: undamped")?,
        }
        writeln!(f, "  positions: {}", self.positions.len())?;
        for (name, coords) in &self.positions {
            let coords: Vec<String> = coords.iter().map(|c| format!("{c}")).collect();
            writeln!(f, "    {name} ({})", coords.join(", "))?;
        }
        writeln!(f, "  strongest modes:")?;
        for (freq, t60, gain) in &self.strongest {
            writeln!(
                f,
                "    {freq:>10.2} Hz  {:<12} T60 {t60:>7.3} s  gain {gain:.4}",
                note_name(*freq)
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn note_names_parse_to_keys() {
        assert_eq!(note_to_midi_key("C4"), Some(60));
        assert_eq!(note_to_midi_key("a4"), Some(69));
        assert_eq!(note_to_midi_key("F#2"), Some(42));
        assert_eq!(note_to_midi_key("Bb5"), Some(82));
        assert_eq!(note_to_midi_key("C-1"), Some(0));
        assert_eq!(note_to_midi_key("G9"), Some(127));
        assert_eq!(note_to_midi_key(" 61 "), Some(61));
        for bad in ["", "H2", "C", "C#", "G#9", "128", "Cb-1", "C4x"] {
            assert_eq!(note_to_midi_key(bad), None, "{bad}");
        }
        // note_name reads back.
        for key in 0..=127u8 {
            let hz = crate::units::midi_key_to_hz(f64::from(key));
            assert_eq!(note_to_midi_key(&note_name(hz)), Some(key));
        }
    }

    #[test]
    fn note_names_and_cents() {
        assert_eq!(note_name(440.0), "A4");
        assert_eq!(note_name(261.6255653005986), "C4");
        assert_eq!(note_name(440.0 * 2f64.powf(0.12 / 12.0)), "A4 +12 c");
        assert_eq!(note_name(27.5), "A0");
    }
}
