//! Notes in seconds, as written on the command line or read from a MIDI file.

use std::fmt;

/// Highest MIDI key.
const MAX_KEY: u8 = 127;

/// What one item of a note list looks like, for error messages.
const NOTE_SYNTAX: &str = "key:velocity@time_s or key:velocity@time_s+duration_s";

/// One struck note.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Note {
    /// MIDI key, 0 to 127.
    pub key: u8,
    /// Strike velocity, above 0 up to 1.
    pub velocity: f32,
    /// When the note is struck, in seconds from the start.
    pub time_s: f64,
    /// How long the key is held, in seconds; `None` holds it until the note dies away.
    pub duration_s: Option<f64>,
}

impl Note {
    /// When the key is released, in seconds, if it is.
    pub fn release_s(&self) -> Option<f64> {
        self.duration_s.map(|d| self.time_s + d)
    }
}

impl fmt::Display for Note {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}@{}", self.key, self.velocity, self.time_s)?;
        if let Some(d) = self.duration_s {
            write!(f, "+{d}")?;
        }
        Ok(())
    }
}

/// Parses a comma-separated note list such as `"60:0.8@0.0, 64:0.5@0.25+0.5"`: each item is
/// `key:velocity@time_s`, optionally followed by `+duration_s` for a note-off. Whitespace around
/// items and fields is ignored. Errors name the item (1-based) and what was expected.
pub fn parse_notes(text: &str) -> Result<Vec<Note>, String> {
    if text.trim().is_empty() {
        return Err(format!(
            "no notes given: expected {NOTE_SYNTAX}, separated by commas"
        ));
    }
    text.split(',')
        .enumerate()
        .map(|(i, item)| {
            parse_note(item.trim()).map_err(|e| format!("note {} \"{}\": {e}", i + 1, item.trim()))
        })
        .collect()
}

/// Parses one `key:velocity@time_s[+duration_s]` item.
fn parse_note(item: &str) -> Result<Note, String> {
    if item.is_empty() {
        return Err(format!("empty item: expected {NOTE_SYNTAX}"));
    }
    let (key, rest) = item
        .split_once(':')
        .ok_or_else(|| format!("missing ':' after the key: expected {NOTE_SYNTAX}"))?;
    let (velocity, timing) = rest
        .split_once('@')
        .ok_or_else(|| format!("missing '@' before the time: expected {NOTE_SYNTAX}"))?;
    let (time, duration) = match timing.split_once('+') {
        Some((t, d)) => (t, Some(d)),
        None => (timing, None),
    };

    let key = key.trim();
    let key = key
        .parse::<u8>()
        .ok()
        .filter(|k| *k <= MAX_KEY)
        .ok_or_else(|| {
            format!("key: expected a whole number from 0 to {MAX_KEY}, found \"{key}\"")
        })?;
    let velocity = parse_number(velocity)
        .filter(|v| *v > 0.0 && *v <= 1.0)
        .ok_or_else(|| {
            format!(
                "velocity: expected a number above 0 up to 1, found \"{}\"",
                velocity.trim()
            )
        })? as f32;
    let time_s = parse_number(time).filter(|t| *t >= 0.0).ok_or_else(|| {
        format!(
            "time: expected a number of seconds >= 0, found \"{}\"",
            time.trim()
        )
    })?;
    let duration_s = duration
        .map(|d| {
            parse_number(d).filter(|d| *d >= 0.0).ok_or_else(|| {
                format!(
                    "duration: expected a number of seconds >= 0 after '+', found \"{}\"",
                    d.trim()
                )
            })
        })
        .transpose()?;
    Ok(Note {
        key,
        velocity,
        time_s,
        duration_s,
    })
}

/// A finite number, or `None`.
fn parse_number(text: &str) -> Option<f64> {
    text.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_parses_back() {
        let notes = parse_notes("60:0.5@1.25+0.5, 61:1@0").unwrap();
        let text: Vec<String> = notes.iter().map(Note::to_string).collect();
        assert_eq!(parse_notes(&text.join(",")).unwrap(), notes);
    }
}
