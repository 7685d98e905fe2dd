//! Notes in seconds, as written on the command line or read from a MIDI file.

use std::fmt;

/// Highest MIDI key.
const MAX_KEY: u8 = 127;

/// What one item of a note list looks like, for error messages.
const NOTE_SYNTAX: &str =
    "key:velocity@time_s or key:velocity@time_s+duration_s, then speed=... force=... if held";

/// Fastest contact speed a note may ask for, in m/s (the engine's).
const MAX_SPEED_M_PER_S: f64 = crate::engine::CONTACT_SPEED_MAX_M_PER_S as f64;

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
    /// A contact's speed in m/s, from the strike to the release (a ramp), if given.
    pub speed_m_per_s: Option<(f64, f64)>,
    /// A contact's force, 0 to 1, from the strike to the release (a ramp), if given.
    pub force: Option<(f64, f64)>,
}

impl Note {
    /// A note struck at `time_s` with `velocity`, held for `duration_s` (or until it dies away),
    /// without contact curves.
    pub fn new(key: u8, velocity: f32, time_s: f64, duration_s: Option<f64>) -> Self {
        Self {
            key,
            velocity,
            time_s,
            duration_s,
            speed_m_per_s: None,
            force: None,
        }
    }

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
        for (name, curve) in [("speed", self.speed_m_per_s), ("force", self.force)] {
            if let Some((a, b)) = curve {
                write!(f, " {name}={a}..{b}")?;
            }
        }
        Ok(())
    }
}

/// Parses a comma-separated note list such as `"60:0.8@0.0, 64:0.5@0.25+0.5"`: each item is
/// `key:velocity@time_s`, optionally followed by `+duration_s` for a note-off, then for a held
/// contact (scrape, roll, rub) `speed=A..B` (m/s) and `force=A..B` (0 to 1), ramps from the strike to
/// the release (`speed=A` holds one value). Whitespace around items and fields is ignored. Errors
/// name the item (1-based) and what was expected.
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

/// Parses one `key:velocity@time_s[+duration_s] [speed=A..B] [force=A..B]` item.
fn parse_note(item: &str) -> Result<Note, String> {
    if item.is_empty() {
        return Err(format!("empty item: expected {NOTE_SYNTAX}"));
    }
    // The strike runs up to the first word naming a curve (whitespace around its fields is
    // allowed); the curves follow, one word each.
    let curves_at = item
        .split_whitespace()
        .find(|w| w.contains('='))
        .map_or(item.len(), |w| w.as_ptr() as usize - item.as_ptr() as usize);
    let mut note = parse_strike(&item[..curves_at])?;
    for word in item[curves_at..].split_whitespace() {
        let (name, value) = word
            .split_once('=')
            .ok_or_else(|| format!("\"{word}\": expected speed=A..B or force=A..B"))?;
        let (slot, range) = match name {
            "speed" => (&mut note.speed_m_per_s, (0.0, MAX_SPEED_M_PER_S)),
            "force" => (&mut note.force, (0.0, 1.0)),
            _ => return Err(format!("\"{name}\": expected speed or force")),
        };
        *slot = Some(parse_curve(name, value, range)?);
        if note.duration_s.is_none() && slot.is_some_and(|(a, b)| a != b) {
            return Err(format!(
                "{name}: a ramp A..B runs from the strike to the release, so the note needs a \
                 duration (+duration_s)"
            ));
        }
    }
    Ok(note)
}

/// Parses `A..B` or `A`, each within `range`.
fn parse_curve(name: &str, text: &str, (lo, hi): (f64, f64)) -> Result<(f64, f64), String> {
    let (a, b) = text.split_once("..").unwrap_or((text, text));
    let value = |t: &str| {
        parse_number(t)
            .filter(|v| (lo..=hi).contains(v))
            .ok_or_else(|| format!("{name}: expected a number from {lo} to {hi}, found \"{t}\""))
    };
    Ok((value(a)?, value(b)?))
}

/// Parses the `key:velocity@time_s[+duration_s]` part of an item.
fn parse_strike(item: &str) -> Result<Note, String> {
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
    Ok(Note::new(key, velocity, time_s, duration_s))
}

/// A finite number, or `None`.
fn parse_number(text: &str) -> Option<f64> {
    text.trim().parse::<f64>().ok().filter(|v| v.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn contact_curves_parse_and_bad_ones_say_why() {
        let notes = parse_notes("60:0.8@0+2 speed=0.2..1.5 force=0.6, 62:1@1 speed=0.4").unwrap();
        assert_eq!(notes[0].speed_m_per_s, Some((0.2, 1.5)));
        assert_eq!(notes[0].force, Some((0.6, 0.6)));
        assert_eq!(notes[1].speed_m_per_s, Some((0.4, 0.4)));
        for (text, expected) in [
            ("60:1@0 speed=0.1..1", "needs a duration"),
            ("60:1@0+1 speed=9", "speed: expected a number from 0 to 3"),
            (
                "60:1@0+1 force=0.5..2",
                "force: expected a number from 0 to 1",
            ),
            ("60:1@0+1 pitch=3", "\"pitch\": expected speed or force"),
            ("60:1@0+1 speed", "duration: expected a number"),
            ("60:1@0+1 speed=1 x", "\"x\": expected speed=A..B"),
        ] {
            let err = parse_notes(text).unwrap_err();
            assert!(
                err.contains(expected) && err.contains("note 1"),
                "{text}: {err}"
            );
        }
    }

    #[test]
    fn display_parses_back() {
        let notes = parse_notes("60:0.5@1.25+0.5 speed=0.1..2 force=0.3, 61:1@0").unwrap();
        let text: Vec<String> = notes.iter().map(Note::to_string).collect();
        assert_eq!(parse_notes(&text.join(",")).unwrap(), notes);
    }
}
