//! Offline rendering over the engine: notes in seconds in, stereo samples out.
//!
//! [`render`] drives one [`Engine`] exactly as a plugin host would: fixed blocks, note events at
//! their exact sample inside a block, nothing else. The same notes and settings give the same
//! samples bit for bit, whatever the block size. A MIDI file's messages are read by the engine's
//! own MIDI reading ([`MidiInput`]), the plugins': a MIDI file rendered here and the same MIDI
//! played to a plugin at the same samples give the same samples.

mod midi_file;
mod normalize;
mod notes;
mod wav;

use std::fmt;
use std::path::PathBuf;
use std::sync::Arc;

pub use midi_file::{read_midi_file, TimedMidi};
pub use normalize::normalizing_scale;
pub use notes::{parse_notes, Note};
pub use wav::{to_int_sample, wav_bytes, write_wav, BitDepth, WavEncoder, WavFile};

use crate::bank::Bank;
use crate::engine::{
    Controls, Engine, ExciterKind, MidiInput, MidiMessage, NoteEvent, NoteExpression, PositionMap,
    PreparedBank,
};
use crate::units::{db_to_gain, gain_to_db};

/// Silence kept after the last sound (or the last event, if later), in seconds: enough that a
/// player does not cut the very end of the tail.
pub const TAIL_MARGIN_S: f64 = 0.1;

/// Length of the fade applied when the maximum length cuts a sound short, in seconds: long
/// enough not to click.
pub const CUT_FADE_S: f64 = 0.01;

/// How to render.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderSettings {
    /// Sample rate in Hz, at least 8000.
    pub sample_rate_hz: u32,
    /// Sample format of the file the render is meant for.
    pub bit_depth: BitDepth,
    /// The engine's controls for the whole render.
    pub controls: Controls,
    /// Longest render in seconds: rendering stops here even if the sound goes on.
    pub max_seconds: f64,
    /// Samples per call to [`Engine::process`], as a host's buffer size.
    pub block: usize,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            sample_rate_hz: 48_000,
            bit_depth: BitDepth::Int24,
            controls: Controls::default(),
            max_seconds: 30.0,
            block: 512,
        }
    }
}

impl RenderSettings {
    /// The defaults with the bank's own default controls.
    pub fn for_bank(bank: &Bank) -> Self {
        Self {
            controls: Controls::for_bank(bank),
            ..Self::default()
        }
    }
}

/// A finished render.
#[derive(Debug, Clone, PartialEq)]
pub struct Rendered {
    /// Left channel.
    pub left: Vec<f32>,
    /// Right channel, as long as the left.
    pub right: Vec<f32>,
    /// Sample rate in Hz.
    pub sample_rate_hz: u32,
    /// Most voices sounding at the end of any block.
    pub max_voices: usize,
    /// Whether `max_seconds` cut the render while it still sounded or had notes to play.
    pub cut_short: bool,
}

impl Rendered {
    /// Length in samples per channel.
    pub fn len(&self) -> usize {
        self.left.len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.left.is_empty()
    }

    /// Length in seconds.
    pub fn duration_s(&self) -> f64 {
        self.len() as f64 / self.sample_rate_hz as f64
    }

    /// Largest absolute sample of either channel.
    pub fn peak(&self) -> f32 {
        self.left
            .iter()
            .chain(&self.right)
            .fold(0.0, |a, x| a.max(x.abs()))
    }

    /// Samples of either channel beyond full scale: clipped in an integer file.
    pub fn clipped_samples(&self) -> usize {
        self.left
            .iter()
            .chain(&self.right)
            .filter(|x| x.abs() > 1.0)
            .count()
    }

    /// Scales both channels so that the peak lands at `peak_dbfs`. A silent render stays
    /// silent.
    pub fn normalize(&mut self, peak_dbfs: f32) {
        let peak = self.peak();
        if peak > 0.0 {
            let scale = 10f32.powf(peak_dbfs / 20.0) / peak;
            for x in self.left.iter_mut().chain(self.right.iter_mut()) {
                *x *= scale;
            }
        }
    }

    /// Peak level in dBFS (negative infinity for silence).
    pub fn peak_dbfs(&self) -> f32 {
        match self.peak() {
            0.0 => f32::NEG_INFINITY,
            peak => gain_to_db(peak),
        }
    }
}

/// Why reading notes or writing audio failed. Every error names the file.
#[derive(Debug)]
pub enum RenderError {
    /// A file could not be read or written.
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
    /// A MIDI file could not be parsed.
    Midi {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        message: String,
    },
    /// A WAV file could not be written.
    Wav {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
}

impl fmt::Display for RenderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RenderError::Io { path, source } => write!(f, "{}: {source}", path.display()),
            RenderError::Midi { path, message } => write!(f, "{}: {message}", path.display()),
            RenderError::Wav { path, source } => {
                write!(f, "{}: cannot write WAV: {source}", path.display())
            }
        }
    }
}

impl std::error::Error for RenderError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            RenderError::Io { source, .. } => Some(source),
            RenderError::Midi { .. } => None,
            RenderError::Wav { source, .. } => Some(source),
        }
    }
}

/// A note event at an absolute sample time.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TimedEvent {
    /// Sample from the start of the render.
    pub(crate) sample: u64,
    /// Order among events on the same sample: releases of earlier notes, then strikes, then
    /// releases of notes struck on that very sample.
    rank: u8,
    /// The event, with its time set when its block is known.
    pub(crate) event: NoteEvent,
}

/// What a render plays: notes (from `--notes`, with their contact curves), or a MIDI file's
/// messages.
#[derive(Debug, Clone, Copy)]
pub enum Score<'a> {
    /// Notes, in any order.
    Notes(&'a [Note]),
    /// MIDI messages, in time order.
    Midi(&'a [TimedMidi]),
}

impl<'a> From<&'a [Note]> for Score<'a> {
    fn from(notes: &'a [Note]) -> Self {
        Score::Notes(notes)
    }
}

impl<'a> From<&'a Vec<Note>> for Score<'a> {
    fn from(notes: &'a Vec<Note>) -> Self {
        Score::Notes(notes)
    }
}

impl<'a, const N: usize> From<&'a [Note; N]> for Score<'a> {
    fn from(notes: &'a [Note; N]) -> Self {
        Score::Notes(notes)
    }
}

impl<'a> From<&'a Vec<TimedMidi>> for Score<'a> {
    fn from(midi: &'a Vec<TimedMidi>) -> Self {
        Score::Midi(midi)
    }
}

impl<'a> From<&'a [TimedMidi]> for Score<'a> {
    fn from(midi: &'a [TimedMidi]) -> Self {
        Score::Midi(midi)
    }
}

impl Score<'_> {
    /// The time of the first note struck at or after `seconds`, and its number from 1, if any.
    pub fn first_note_from(&self, seconds: f64) -> Option<(usize, f64)> {
        match self {
            Score::Notes(notes) => notes
                .iter()
                .enumerate()
                .find(|(_, n)| n.time_s >= seconds)
                .map(|(i, n)| (i + 1, n.time_s)),
            Score::Midi(midi) => midi
                .iter()
                .filter(
                    |m| matches!(m.message, MidiMessage::NoteOn { velocity, .. } if velocity > 0.0),
                )
                .enumerate()
                .find(|(_, m)| m.time_s >= seconds)
                .map(|(i, m)| (i + 1, m.time_s)),
        }
    }

    /// The engine events at `rate` up to `until_s`, in the order the engine must see them.
    fn schedule(&self, rate: f64, until_s: f64, controls: &Controls) -> Vec<TimedEvent> {
        match self {
            Score::Notes(notes) => schedule(notes, rate, until_s),
            Score::Midi(midi) => schedule_midi(midi, rate, controls),
        }
    }
}

/// The engine events of MIDI `messages` at `rate`, as a plugin reads them with `controls`.
fn schedule_midi(messages: &[TimedMidi], rate: f64, controls: &Controls) -> Vec<TimedEvent> {
    let mut input = MidiInput::default();
    let mut events = Vec::with_capacity(messages.len());
    for m in messages {
        let sample = (m.time_s * rate).round().max(0.0) as u64;
        input.read(0, m.message, controls, |event| {
            events.push(TimedEvent {
                sample,
                rank: 1,
                event,
            })
        });
    }
    // Stable: messages on one sample keep their order.
    events.sort_by_key(|e| e.sample);
    events
}

/// The events of `notes` at `rate`, in the order the engine must see them.
pub(crate) fn schedule(notes: &[Note], rate: f64, until_s: f64) -> Vec<TimedEvent> {
    let to_sample = |t: f64| (t * rate).round().max(0.0) as u64;
    let mut events = Vec::with_capacity(2 * notes.len());
    for note in notes {
        let on = to_sample(note.time_s);
        events.push(TimedEvent {
            sample: on,
            rank: 1,
            event: NoteEvent::on(0, note.key, note.velocity),
        });
        contact_curves(note, rate, until_s, &mut events);
        if let Some(release_s) = note.release_s() {
            let off = to_sample(release_s).max(on);
            events.push(TimedEvent {
                sample: off,
                rank: if off == on { 2 } else { 0 },
                event: NoteEvent::off(0, note.key),
            });
        }
    }
    // Stable, so simultaneous strikes keep the order they were given in.
    events.sort_by_key(|e| (e.sample, e.rank));
    events
}

/// Seconds between the points of a note's contact curves: finer than the engine's 5 ms
/// smoothing, so a ramp is followed without steps.
const CURVE_STEP_S: f64 = 0.002;

/// A note's contact curves (speed, force) as the note's speed and pressure, from its strike to
/// its release (or the strike alone, for a note held until it dies away), up to `until_s`.
fn contact_curves(note: &Note, rate: f64, until_s: f64, events: &mut Vec<TimedEvent>) {
    if note.speed_m_per_s.is_none() && note.force.is_none() || note.time_s > until_s {
        return;
    }
    let duration = note.duration_s.unwrap_or(0.0);
    // Points up to the end of the render only.
    let heard = duration.min(until_s - note.time_s).max(0.0);
    let steps = (heard / CURVE_STEP_S).ceil() as usize;
    let who = crate::engine::Note {
        key: note.key,
        channel: 0,
        id: None,
    };
    for i in 0..=steps {
        let t = if steps == 0 {
            0.0
        } else {
            heard * i as f64 / steps as f64
        };
        let u = if duration > 0.0 { t / duration } else { 0.0 };
        let sample = ((note.time_s + t) * rate).round() as u64;
        let at = |(a, b): (f64, f64)| (a + (b - a) * u) as f32;
        let mut push = |expression| {
            events.push(TimedEvent {
                sample,
                rank: 1,
                event: NoteEvent::Expression {
                    time: 0,
                    note: who,
                    expression,
                },
            })
        };
        if let Some(speed) = note.speed_m_per_s {
            push(NoteExpression::ContactSpeed(at(speed)));
        }
        if let Some(force) = note.force {
            push(NoteExpression::Pressure(at(force)));
        }
    }
}

/// Seconds until the longest-ringing mode of `bank` falls below the truncation threshold after a
/// full strike at the root pitch: an estimate of a note's tail, for progress reports only.
fn estimated_tail_s(bank: &PreparedBank, controls: &Controls) -> f64 {
    let log_damping = bank.log_damping(controls.material_q);
    let threshold = db_to_gain(controls.truncation_db) as f64;
    (0..bank.num_modes())
        .map(|m| {
            let row = &bank.gains[m * bank.num_positions..(m + 1) * bank.num_positions];
            let gain = row.iter().fold(0.0f64, |a, g| a.max(g.abs() as f64));
            let decay = bank.damped_decay(m, log_damping, controls.damping_tilt as f64);
            (gain / threshold).ln() / decay
        })
        .fold(0.0, f64::max)
}

/// What a render produced, besides its samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderSummary {
    /// Length in samples per channel.
    pub len: u64,
    /// Sample rate in Hz.
    pub sample_rate_hz: u32,
    /// Largest absolute sample of either channel.
    pub peak: f32,
    /// Samples of either channel beyond full scale: clipped in an integer file.
    pub clipped_samples: u64,
    /// Most voices sounding at the end of any block.
    pub max_voices: usize,
    /// Whether `max_seconds` cut the render while it still sounded or had notes to play.
    pub cut_short: bool,
}

impl RenderSummary {
    /// Length in seconds.
    pub fn duration_s(&self) -> f64 {
        self.len as f64 / self.sample_rate_hz as f64
    }

    /// Peak level in dBFS (negative infinity for silence).
    pub fn peak_dbfs(&self) -> f32 {
        match self.peak {
            0.0 => f32::NEG_INFINITY,
            peak => gain_to_db(peak),
        }
    }
}

/// Quietest level [`resynthesize`] renders, in dBFS: far below any recording's noise.
const RESYNTHESIS_TRUNCATION_DB: f32 = -140.0;

/// Key [`resynthesize`] strikes; with key tracking off any key plays the bank as authored.
const RESYNTHESIS_KEY: u8 = 60;

/// `bank` struck at position `position` with a unit impulse and rendered mono through the
/// engine for `len` samples at `sample_rate_hz`, in the bank's own units: the engine's loudness
/// normalisation is undone, so a mode of gain `a` starts at amplitude `a`. What the fit's score
/// (`authoring::fit::synthesize_strike`) stands for.
pub fn resynthesize(bank: &Bank, position: usize, sample_rate_hz: u32, len: usize) -> Vec<f32> {
    let prepared = Arc::new(PreparedBank::new(bank));
    let mut controls = Controls::for_bank(bank);
    controls.exciter = ExciterKind::Impulse;
    controls.width = 0.0;
    controls.key_tracking = 0.0;
    controls.position_variation = 0.0;
    controls.truncation_db = RESYNTHESIS_TRUNCATION_DB;
    let coords: Vec<Vec<f64>> = bank.positions.iter().map(|p| p.coords.clone()).collect();
    if let Some(at) = PositionMap::new(&coords).coords().get(position) {
        controls.strike_x = at[0] as f32;
        controls.strike_y = at[1] as f32;
    }
    let settings = RenderSettings {
        sample_rate_hz,
        controls,
        max_seconds: len as f64 / sample_rate_hz as f64,
        ..RenderSettings::default()
    };
    let note = Note::new(RESYNTHESIS_KEY, 1.0, 0.0, None);
    let rendered = render(&prepared, &[note], &settings, |_| {});
    // With width 0 both channels carry the sum of the modes.
    let scale = 1.0 / prepared.normalization;
    let mut out: Vec<f32> = rendered.left.iter().map(|v| v * scale).collect();
    out.resize(len, 0.0);
    out
}

/// Renders `score` through `bank` with `settings` into memory, as [`render_to`] renders it.
pub fn render<'a>(
    bank: &Arc<PreparedBank>,
    score: impl Into<Score<'a>>,
    settings: &RenderSettings,
    progress: impl FnMut(f64),
) -> Rendered {
    let mut left = Vec::new();
    let mut right = Vec::new();
    let sink = |l: &[f32], r: &[f32]| {
        left.extend_from_slice(l);
        right.extend_from_slice(r);
        Ok::<(), std::convert::Infallible>(())
    };
    let Ok(summary) = render_to(bank, score, settings, 1.0, progress, sink);
    Rendered {
        left,
        right,
        sample_rate_hz: summary.sample_rate_hz,
        max_voices: summary.max_voices,
        cut_short: summary.cut_short,
    }
}

/// Renders `score` through `bank` with `settings`, every sample multiplied by
/// `scale`, handing the stereo samples to `sink` in order as they are made (in pieces of any
/// length, left and right of equal length) and calling `progress` with the fraction done (0 to
/// 1, an estimate until the end) after each block. Memory does not grow with the length: only
/// a run of silence, counted, and the last [`CUT_FADE_S`] before `max_seconds` wait before
/// going to the sink. Stops at the first error of `sink`, and returns it.
///
/// Stops at `settings.max_seconds` (fading the last [`CUT_FADE_S`] out if it still sounds), or
/// once every note has been played and released and the engine is silent; a silent render is
/// then trimmed to [`TAIL_MARGIN_S`] after its last sound or last event, so its length does not
/// depend on the block size either.
///
/// # Panics
/// If the sample rate is below 8000 Hz.
pub fn render_to<'a, E>(
    bank: &Arc<PreparedBank>,
    score: impl Into<Score<'a>>,
    settings: &RenderSettings,
    scale: f32,
    mut progress: impl FnMut(f64),
    sink: impl FnMut(&[f32], &[f32]) -> Result<(), E>,
) -> Result<RenderSummary, E> {
    let rate = settings.sample_rate_hz as f64;
    let block = settings.block.max(1);
    let max_samples = (settings.max_seconds.max(0.0) * rate).round() as u64;
    let mut engine = Engine::new(Arc::clone(bank));
    engine.set_controls(&settings.controls);
    engine.reserve_voices(settings.controls.polyphony);
    engine.prepare(settings.sample_rate_hz as f32, block);

    let mut events = score
        .into()
        .schedule(rate, settings.max_seconds, &settings.controls);
    // A release past the end changes nothing that is not still sounding at the cut; a strike
    // past it is a note not played.
    let dropped = events
        .iter()
        .any(|e| e.sample >= max_samples && matches!(e.event, NoteEvent::On { .. }));
    events.retain(|e| e.sample < max_samples);
    let last_event_end = events.last().map_or(0, |e| e.sample + 1);
    let estimated_len = (last_event_end as f64 + estimated_tail_s(bank, engine.controls()) * rate)
        .min(max_samples as f64)
        .max(1.0);

    let fade_len = ((CUT_FADE_S * rate) as u64).min(max_samples);
    let mut out = Stream::new(sink, max_samples - fade_len, scale);
    let mut left = vec![0.0f32; block];
    let mut right = vec![0.0f32; block];
    let mut block_events = Vec::with_capacity(events.len().min(4096));
    let mut next = 0;
    let mut pos = 0u64;
    let mut max_voices = 0;
    let mut done = 0.0f64;
    let finished = |next: usize, engine: &Engine| next == events.len() && engine.is_silent();
    while pos < max_samples && !finished(next, &engine) {
        let len = (block as u64).min(max_samples - pos);
        block_events.clear();
        while next < events.len() && events[next].sample < pos + len {
            block_events.push(events[next].event.at((events[next].sample - pos) as u32));
            next += 1;
        }
        let (l, r) = (&mut left[..len as usize], &mut right[..len as usize]);
        l.fill(0.0);
        r.fill(0.0);
        engine.process(&block_events, None, l, r);
        out.push(l, r)?;
        max_voices = max_voices.max(engine.take_peak_voices());
        pos += len;
        done = done.max((pos as f64 / estimated_len).min(0.99));
        progress(done);
    }

    let sounding = !finished(next, &engine);
    let end = if sounding {
        pos
    } else {
        let margin = (TAIL_MARGIN_S * rate).round() as u64;
        (out.sound_end().max(last_event_end) + margin).min(max_samples)
    };
    out.finish(end, sounding.then_some(fade_len))?;
    progress(1.0);
    Ok(RenderSummary {
        len: end,
        sample_rate_hz: settings.sample_rate_hz,
        peak: out.peak,
        clipped_samples: out.clipped,
        max_voices,
        cut_short: sounding || dropped,
    })
}

/// The samples of a render on their way to a sink: each is passed on as soon as it is known to
/// be kept as it is, that is once a sound follows it, or (before `fade_start`) at once when it
/// is not silent.
struct Stream<F> {
    sink: F,
    /// Scale applied to every sample.
    scale: f32,
    /// Samples passed to the sink.
    sent: u64,
    /// Silent samples (both channels exactly 0) after the sent ones, not sent yet.
    silent: u64,
    /// First sample that waits for the end: the fade of a render cut while it sounds.
    fade_start: u64,
    /// Samples from `fade_start` on, waiting for the end.
    held: (Vec<f32>, Vec<f32>),
    /// One past the last sample that is not silent.
    sound_end: u64,
    /// Largest absolute sample sent.
    peak: f32,
    /// Samples sent beyond full scale.
    clipped: u64,
    /// Runs of silence, sent a piece at a time.
    zeros: Vec<f32>,
}

impl<E, F: FnMut(&[f32], &[f32]) -> Result<(), E>> Stream<F> {
    fn new(sink: F, fade_start: u64, scale: f32) -> Self {
        Self {
            sink,
            scale,
            sent: 0,
            silent: 0,
            fade_start,
            held: (Vec::new(), Vec::new()),
            sound_end: 0,
            peak: 0.0,
            clipped: 0,
            zeros: vec![0.0; 4096],
        }
    }

    /// One past the last sample that is not silent.
    fn sound_end(&self) -> u64 {
        self.sound_end
    }

    /// Takes the next samples (both slices of one length), scaling them in place.
    fn push(&mut self, left: &mut [f32], right: &mut [f32]) -> Result<(), E> {
        let start = self.sent + self.silent + self.held.0.len() as u64;
        // Before scaling, so that a scaled render has the length of the unscaled one.
        if let Some(last) = left
            .iter()
            .zip(&*right)
            .rposition(|(l, r)| *l != 0.0 || *r != 0.0)
        {
            self.sound_end = start + last as u64 + 1;
        }
        if self.scale != 1.0 {
            for x in left.iter_mut().chain(right.iter_mut()) {
                *x *= self.scale;
            }
        }
        let before_fade = (self.fade_start.saturating_sub(start) as usize).min(left.len());
        let (left, fade_left) = left.split_at(before_fade);
        let (right, fade_right) = right.split_at(before_fade);
        self.held.0.extend_from_slice(fade_left);
        self.held.1.extend_from_slice(fade_right);
        // Everything up to the last sound goes out now; the silence after it waits.
        match left
            .iter()
            .zip(right)
            .rposition(|(l, r)| *l != 0.0 || *r != 0.0)
        {
            Some(last) => {
                self.send_silence(self.silent)?;
                self.send(&left[..=last], &right[..=last])?;
                self.silent = (left.len() - last - 1) as u64;
            }
            None => self.silent += left.len() as u64,
        }
        Ok(())
    }

    /// Ends the render at sample `end`, fading the last `fade` samples out when asked.
    fn finish(&mut self, end: u64, fade: Option<u64>) -> Result<(), E> {
        let silent = self.silent.min(end.saturating_sub(self.sent));
        self.send_silence(silent)?;
        let mut held = std::mem::take(&mut self.held);
        let keep = (end.saturating_sub(self.sent) as usize).min(held.0.len());
        held.0.truncate(keep);
        held.1.truncate(keep);
        if let Some(fade) = fade {
            let len = (fade as usize).min(keep);
            let start = keep - len;
            for (i, (l, r)) in held.0[start..]
                .iter_mut()
                .zip(&mut held.1[start..])
                .enumerate()
            {
                let gain = 1.0 - (i + 1) as f32 / len as f32;
                *l *= gain;
                *r *= gain;
            }
        }
        self.send(&held.0, &held.1)?;
        let rest = end.saturating_sub(self.sent);
        self.send_silence(rest)
    }

    fn send(&mut self, left: &[f32], right: &[f32]) -> Result<(), E> {
        for &x in left.iter().chain(right) {
            self.peak = self.peak.max(x.abs());
            self.clipped += u64::from(x.abs() > 1.0);
        }
        self.sent += left.len() as u64;
        (self.sink)(left, right)
    }

    fn send_silence(&mut self, mut count: u64) -> Result<(), E> {
        while count > 0 {
            let n = (count as usize).min(self.zeros.len());
            self.sent += n as u64;
            count -= n as u64;
            (self.sink)(&self.zeros[..n], &self.zeros[..n])?;
        }
        Ok(())
    }
}
