//! Standard MIDI files read into timed MIDI messages, in seconds.
//!
//! Every track and channel is merged into one list, in time order (messages at one tick keep their
//! track order). Metrical files follow the tempo map (set-tempo meta events from any track, 120 bpm
//! until the first); SMPTE timecode files count fixed ticks per second. Notes, polyphonic and
//! channel pressure, control changes and pitch bend are read, with values scaled as a plugin host
//! scales them (7-bit values over 127, the 14-bit bend over 16383), so the renderer plays them
//! exactly as the plugins do ([`crate::engine::MidiInput`]); program changes and system messages
//! are left out.

use std::path::Path;

use midly::{MetaMessage, MidiMessage as Wire, Smf, Timing, TrackEventKind};

use super::RenderError;
use crate::engine::{MidiMessage, Note};

/// A MIDI message at a time in seconds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimedMidi {
    /// Seconds from the start.
    pub time_s: f64,
    /// The message.
    pub message: MidiMessage,
}

/// Tempo until the first set-tempo event: 120 bpm, as the MIDI file specification says.
const DEFAULT_MICROS_PER_QUARTER: u32 = 500_000;

/// Largest 7-bit MIDI value, which maps to 1.
const MAX_7_BIT: f32 = 127.0;

/// Largest 14-bit MIDI value (pitch bend), which maps to 1.
const MAX_14_BIT: f32 = 16_383.0;

/// Reads the messages of the MIDI file at `path`, sorted by time.
pub fn read_midi_file(path: impl AsRef<Path>) -> Result<Vec<TimedMidi>, RenderError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let smf = Smf::parse(&bytes).map_err(|e| RenderError::Midi {
        path: path.to_path_buf(),
        message: format!("not a readable MIDI file: {e}"),
    })?;
    check_complete(&bytes).map_err(|message| RenderError::Midi {
        path: path.to_path_buf(),
        message,
    })?;
    Ok(messages_of(&smf))
}

/// An error unless every track a standard MIDI file declares is there whole: the parser reads
/// what it can of a file cut short, which would play only part of it. A RIFF-wrapped file
/// (RMID) is checked inside its `data` chunk; bytes after the last track declared are left to
/// the parser, as junk at the end of a whole file is.
fn check_complete(bytes: &[u8]) -> Result<(), String> {
    let bytes = riff_data(bytes)?;
    let length_at = |at: usize| {
        bytes
            .get(at..at.checked_add(4)?)
            .map(|b| u32::from_be_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    // The header chunk: "MThd", its length, format, number of tracks, timing.
    let cut_in_header = || "the file is cut short in its header".to_string();
    let header_len = length_at(4).ok_or_else(cut_in_header)?;
    let declared_tracks = bytes
        .get(10..12)
        .map(|b| u16::from_be_bytes([b[0], b[1]]) as usize)
        .ok_or_else(cut_in_header)?;
    let mut at = header_len.checked_add(8).ok_or_else(cut_in_header)?;
    let mut tracks = 0;
    while tracks < declared_tracks {
        if at >= bytes.len() {
            return Err(format!(
                "the file is cut short: its header declares {declared_tracks} tracks, {tracks} are there"
            ));
        }
        let Some(len) = length_at(at + 4) else {
            return Err(format!(
                "the file is cut short: {} bytes at byte {at} where a chunk header of 8 is due",
                bytes.len() - at
            ));
        };
        let there = bytes.len() - at - 8;
        if len > there {
            return Err(format!(
                "the file is cut short: the chunk at byte {at} declares {len} bytes, {there} are there"
            ));
        }
        if &bytes[at..at + 4] == b"MTrk" {
            tracks += 1;
        }
        at += 8 + len;
    }
    Ok(())
}

/// The standard MIDI file inside a RIFF-wrapped one (its `data` chunk), or `bytes` themselves.
fn riff_data(bytes: &[u8]) -> Result<&[u8], String> {
    if !bytes.starts_with(b"RIFF") {
        return Ok(bytes);
    }
    let mut at = 12;
    while let Some(header) = bytes.get(at..at + 8) {
        let len = u32::from_le_bytes([header[4], header[5], header[6], header[7]]) as usize;
        let body = &bytes[at + 8..];
        if &header[..4] == b"data" {
            return Ok(&body[..len.min(body.len())]);
        }
        match (at + 8).checked_add(len + (len & 1)) {
            Some(next) => at = next,
            None => break,
        }
    }
    Err("the file is cut short: a RIFF file without its data chunk".to_string())
}

/// A message or tempo change at an absolute tick.
#[derive(Debug, Clone, Copy)]
enum Event {
    /// Set-tempo meta event.
    Tempo { micros_per_quarter: u32 },
    /// A channel message.
    Midi(MidiMessage),
}

/// The engine's message for a channel message of the file; `None` for those it does not play.
fn message_of(channel: u8, message: Wire) -> Option<MidiMessage> {
    let note = |key: midly::num::u7| Note {
        key: key.as_int(),
        channel,
        id: None,
    };
    let scaled = |v: midly::num::u7| v.as_int() as f32 / MAX_7_BIT;
    Some(match message {
        Wire::NoteOn { key, vel } if vel > 0 => MidiMessage::NoteOn {
            note: note(key),
            velocity: scaled(vel),
        },
        Wire::NoteOn { key, .. } | Wire::NoteOff { key, .. } => {
            MidiMessage::NoteOff { note: note(key) }
        }
        Wire::Aftertouch { key, vel } => MidiMessage::PolyPressure {
            note: note(key),
            pressure: scaled(vel),
        },
        Wire::ChannelAftertouch { vel } => MidiMessage::ChannelPressure {
            channel,
            pressure: scaled(vel),
        },
        Wire::Controller { controller, value } => MidiMessage::Control {
            channel,
            cc: controller.as_int(),
            value: scaled(value),
        },
        Wire::PitchBend { bend } => MidiMessage::PitchBend {
            channel,
            value: bend.0.as_int() as f32 / MAX_14_BIT,
        },
        Wire::ProgramChange { .. } => return None,
    })
}

/// The messages of a parsed file, sorted by time.
fn messages_of(smf: &Smf) -> Vec<TimedMidi> {
    let mut events = Vec::new();
    for track in &smf.tracks {
        let mut tick = 0u64;
        for event in track {
            tick += event.delta.as_int() as u64;
            let e = match event.kind {
                TrackEventKind::Meta(MetaMessage::Tempo(t)) => Event::Tempo {
                    micros_per_quarter: t.as_int(),
                },
                TrackEventKind::Midi { channel, message } => {
                    match message_of(channel.as_int(), message) {
                        Some(m) => Event::Midi(m),
                        None => continue,
                    }
                }
                _ => continue,
            };
            events.push((tick, e));
        }
    }
    // Stable: events at one tick keep their track order; tempo changes act before notes there.
    events.sort_by_key(|&(tick, e)| (tick, !matches!(e, Event::Tempo { .. })));

    let mut clock = Clock::new(smf.header.timing);
    let mut messages = Vec::new();
    for (tick, e) in events {
        match e {
            Event::Tempo { micros_per_quarter } => clock.set_tempo(tick, micros_per_quarter),
            Event::Midi(message) => messages.push(TimedMidi {
                time_s: clock.seconds_at(tick),
                message,
            }),
        }
    }
    messages
}

/// Converts absolute ticks to seconds, following tempo changes in tick order.
struct Clock {
    /// Seconds per tick for SMPTE timecode files, which ignore tempo.
    fixed_s_per_tick: Option<f64>,
    /// Ticks per quarter note, for metrical files.
    ticks_per_quarter: f64,
    /// Tick of the last tempo change.
    anchor_tick: u64,
    /// Time of the last tempo change, in seconds.
    anchor_s: f64,
    /// Seconds per tick since the last tempo change.
    s_per_tick: f64,
}

impl Clock {
    fn new(timing: Timing) -> Self {
        let (fixed, ticks_per_quarter) = match timing {
            Timing::Metrical(tpq) => (None, tpq.as_int().max(1) as f64),
            Timing::Timecode(fps, ticks_per_frame) => (
                Some(1.0 / (fps.as_f32() as f64 * ticks_per_frame.max(1) as f64)),
                1.0,
            ),
        };
        let mut clock = Self {
            fixed_s_per_tick: fixed,
            ticks_per_quarter,
            anchor_tick: 0,
            anchor_s: 0.0,
            s_per_tick: 0.0,
        };
        clock.set_tempo(0, DEFAULT_MICROS_PER_QUARTER);
        clock
    }

    /// Seconds at `tick`, which must not precede the last tempo change.
    fn seconds_at(&self, tick: u64) -> f64 {
        self.anchor_s + (tick - self.anchor_tick) as f64 * self.s_per_tick
    }

    /// A new tempo from `tick` on.
    fn set_tempo(&mut self, tick: u64, micros_per_quarter: u32) {
        self.anchor_s = self.seconds_at(tick);
        self.anchor_tick = tick;
        self.s_per_tick = self
            .fixed_s_per_tick
            .unwrap_or(micros_per_quarter as f64 * 1e-6 / self.ticks_per_quarter);
    }
}
