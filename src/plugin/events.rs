//! Host note events into engine events: notes with their channel and id, note expressions,
//! polyphonic modulation, MPE member channels, and the channel-wide controllers that change the
//! engine's controls part-way through a block.

use nice_plug::midi::{Channel, Key, VoiceID};
use nice_plug::prelude::*;

use super::{Kind, ModalPlugin, MAX_EVENTS};
use crate::editor::Audition;
use crate::engine::{Note, NoteEvent as EngineEvent, NoteExpression};
use crate::params::ExpressionTarget;

/// MIDI CC 74 (sound controller 5, "brightness"): MPE's slide, the third dimension of a note.
const SLIDE_CC: u8 = 74;

/// MIDI channels.
pub const CHANNELS: usize = 16;

/// The MPE manager channel (MIDI channel 1, lower zone): its controllers act on every note.
const MPE_MANAGER_CHANNEL: u8 = 0;

/// A key number that names no voice: events with a note id but no key find their voice by id.
const NO_KEY: u8 = u8::MAX;

/// A channel-wide controller that changes the engine's controls from its sample on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ControlChange {
    /// Pitch bend, -1 to 1.
    Bend(f32),
    /// Mod wheel, 0 to 1.
    ModWheel(f32),
    /// Channel pressure, 0 to 1.
    Pressure(f32),
}

/// Where the player's controllers are.
#[derive(Debug, Clone, Copy, Default)]
pub struct Expression {
    /// Pitch bend, -1 to 1.
    pub bend: f32,
    /// Mod wheel, 0 to 1.
    pub mod_wheel: f32,
    /// Channel pressure, 0 to 1.
    pub pressure: f32,
    /// Pitch bend of each MPE member channel, -1 to 1.
    pub channel_bend: [f32; CHANNELS],
    /// Pressure of each MPE member channel, 0 to 1.
    pub channel_pressure: [f32; CHANNELS],
    /// Slide (CC 74) of each MPE member channel, 0 to 1, if it has been sent.
    pub channel_slide: [Option<f32>; CHANNELS],
}

impl Expression {
    /// Applies a channel-wide controller.
    pub fn apply(&mut self, change: ControlChange) {
        match change {
            ControlChange::Bend(v) => self.bend = v,
            ControlChange::ModWheel(v) => self.mod_wheel = v,
            ControlChange::Pressure(v) => self.pressure = v,
        }
    }
}

/// The engine's note for a host note; `None` for a wildcard key without an id.
fn note_of(voice_id: VoiceID, channel: Channel, key: Key) -> Option<Note> {
    let id = voice_id.id();
    let key = match (key.number(), id) {
        (Some(key), _) => key,
        (None, Some(_)) => NO_KEY,
        (None, None) => return None,
    };
    Some(Note {
        key,
        channel: channel.number().unwrap_or(0),
        id,
    })
}

impl<K: Kind> ModalPlugin<K> {
    /// Reads the block's host events: note events into `self.events` (in time order) and
    /// channel-wide controllers into `self.changes`.
    pub(super) fn read_events(&mut self, context: &mut impl ProcessContext<Self>) {
        self.events.clear();
        self.changes.clear();
        let mpe = self.params.voices.mpe.value();
        let mpe_range = self.params.voices.mpe_bend_range.value();
        // Per-note pressure damps a struck note when routed to damping, and is the force of a
        // contact note (scrape, roll, rub) whatever the routing.
        let contact = self.params.strike.exciter.value().kind().is_contact();
        let pressure_damps =
            contact || self.params.voices.pressure_target.value() == ExpressionTarget::Damping;
        let is_member = |channel: u8| mpe && channel != MPE_MANAGER_CHANNEL;
        self.read_auditions();
        while let Some(event) = context.next_event() {
            match event {
                NoteEvent::NoteOn {
                    timing,
                    voice_id,
                    channel,
                    key,
                    velocity,
                } => {
                    let Some(note) = note_of(voice_id, channel, key).filter(|n| n.key != NO_KEY)
                    else {
                        continue;
                    };
                    if velocity > 0.0 {
                        self.last_key = Some(note.key);
                    }
                    self.push(EngineEvent::On {
                        time: timing,
                        note,
                        velocity,
                    });
                    // A member channel's bend and pressure, sent before the note, shape it from
                    // its first sample.
                    if is_member(note.channel) && velocity > 0.0 {
                        let c = note.channel as usize % CHANNELS;
                        let bend = self.expression.channel_bend[c] * mpe_range;
                        self.push(EngineEvent::Expression {
                            time: timing,
                            note,
                            expression: NoteExpression::Tuning(bend),
                        });
                        if pressure_damps {
                            let pressure = self.expression.channel_pressure[c];
                            self.push(EngineEvent::Expression {
                                time: timing,
                                note,
                                expression: NoteExpression::Pressure(pressure),
                            });
                        }
                        if let Some(slide) = self.expression.channel_slide[c] {
                            self.push(EngineEvent::Expression {
                                time: timing,
                                note,
                                expression: NoteExpression::Slide(slide),
                            });
                        }
                    }
                }
                // A wildcard key (and no id) means every note.
                NoteEvent::NoteOff {
                    timing,
                    voice_id,
                    channel,
                    key,
                    ..
                } => self.push(match note_of(voice_id, channel, key) {
                    Some(note) => EngineEvent::Off { time: timing, note },
                    None => EngineEvent::AllNotesOff { time: timing },
                }),
                NoteEvent::Choke {
                    timing,
                    voice_id,
                    channel,
                    key,
                } => self.push(match note_of(voice_id, channel, key) {
                    Some(note) => EngineEvent::Choke { time: timing, note },
                    None => EngineEvent::AllSoundOff { time: timing },
                }),
                NoteEvent::PolyTuning {
                    timing,
                    voice_id,
                    channel,
                    key,
                    tuning,
                } => {
                    if let Some(note) = note_of(voice_id, channel, key) {
                        self.push(EngineEvent::Expression {
                            time: timing,
                            note,
                            expression: NoteExpression::Tuning(tuning),
                        });
                    }
                }
                // Per-note pressure follows the pressure routing: it can damp one note; a strike
                // position only matters when the note is struck, so it is not moved per note.
                NoteEvent::PolyPressure {
                    timing,
                    voice_id,
                    channel,
                    key,
                    pressure,
                } if pressure_damps => {
                    if let Some(note) = note_of(voice_id, channel, key) {
                        self.push(EngineEvent::Expression {
                            time: timing,
                            note,
                            expression: NoteExpression::Pressure(pressure),
                        });
                    }
                }
                // Brightness (CLAP's note expression) is a note's slide: a contact's speed.
                NoteEvent::PolyBrightness {
                    timing,
                    voice_id,
                    channel,
                    key,
                    brightness,
                } => {
                    if let Some(note) = note_of(voice_id, channel, key) {
                        self.push(EngineEvent::Expression {
                            time: timing,
                            note,
                            expression: NoteExpression::Slide(brightness),
                        });
                    }
                }
                NoteEvent::PolyModulation {
                    timing,
                    voice_id,
                    poly_modulation_id,
                    normalized_offset,
                } => {
                    self.poly
                        .set(voice_id, poly_modulation_id, normalized_offset);
                    let base = self.params.poly_base(poly_modulation_id).unwrap_or(0.0);
                    if let Some(modulation) = self
                        .params
                        .voice_modulation(poly_modulation_id, base + normalized_offset)
                    {
                        self.push(EngineEvent::Modulate {
                            time: timing,
                            id: voice_id,
                            modulation,
                        });
                    }
                }
                NoteEvent::MonoAutomation {
                    timing,
                    poly_modulation_id,
                    normalized_value,
                } => {
                    // Every modulated note moves with the parameter's new value.
                    for (id, offset) in self.poly.offsets(poly_modulation_id) {
                        if let Some(modulation) = self
                            .params
                            .voice_modulation(poly_modulation_id, normalized_value + offset)
                        {
                            if self.events.len() < MAX_EVENTS {
                                self.events.push(EngineEvent::Modulate {
                                    time: timing,
                                    id,
                                    modulation,
                                });
                            }
                        }
                    }
                }
                NoteEvent::MidiPitchBend {
                    timing,
                    channel,
                    value,
                } => {
                    let bend = (value * 2.0 - 1.0).clamp(-1.0, 1.0);
                    if is_member(channel) {
                        self.expression.channel_bend[channel as usize % CHANNELS] = bend;
                        self.push(EngineEvent::ChannelExpression {
                            time: timing,
                            channel,
                            expression: NoteExpression::Tuning(bend * mpe_range),
                        });
                    } else {
                        self.change(timing, ControlChange::Bend(bend));
                    }
                }
                NoteEvent::MidiChannelPressure {
                    timing,
                    channel,
                    pressure,
                } => {
                    let pressure = pressure.clamp(0.0, 1.0);
                    if is_member(channel) {
                        self.expression.channel_pressure[channel as usize % CHANNELS] = pressure;
                        if pressure_damps {
                            self.push(EngineEvent::ChannelExpression {
                                time: timing,
                                channel,
                                expression: NoteExpression::Pressure(pressure),
                            });
                        }
                    } else {
                        self.change(timing, ControlChange::Pressure(pressure));
                    }
                }
                // An MPE member channel's slide is its note's.
                NoteEvent::MidiCC {
                    timing,
                    cc: SLIDE_CC,
                    channel,
                    value,
                } if is_member(channel) => {
                    let slide = value.clamp(0.0, 1.0);
                    self.expression.channel_slide[channel as usize % CHANNELS] = Some(slide);
                    self.push(EngineEvent::ChannelExpression {
                        time: timing,
                        channel,
                        expression: NoteExpression::Slide(slide),
                    })
                }
                NoteEvent::MidiCC {
                    timing, cc, value, ..
                } => match cc {
                    control_change::MODULATION_MSB => {
                        self.change(timing, ControlChange::ModWheel(value.clamp(0.0, 1.0)))
                    }
                    control_change::ALL_SOUND_OFF => {
                        self.push(EngineEvent::AllSoundOff { time: timing })
                    }
                    control_change::ALL_NOTES_OFF => {
                        self.push(EngineEvent::AllNotesOff { time: timing })
                    }
                    _ => {}
                },
                _ => {}
            }
        }
    }

    /// Turns the editor's strike-pad requests into notes at the block's start: a strike on the
    /// last key played (else the bank's root) at the pad's position, and its release.
    fn read_auditions(&mut self) {
        while let Some(audition) = self.editor_shared.next_audition() {
            let key = match audition {
                Audition::Strike { .. } => {
                    let key = self.strike_key();
                    self.audition_key = Some(key);
                    key
                }
                Audition::Release => match self.audition_key.take() {
                    Some(key) => key,
                    None => continue,
                },
            };
            for event in audition.events(key) {
                self.push(event);
            }
        }
    }

    /// Queues a note event, unless the block already has [`MAX_EVENTS`].
    fn push(&mut self, event: EngineEvent) {
        if self.events.len() < MAX_EVENTS {
            self.events.push(event);
        }
    }

    /// Queues a channel-wide controller change, unless the block already has [`MAX_EVENTS`].
    fn change(&mut self, time: u32, change: ControlChange) {
        if self.changes.len() < MAX_EVENTS {
            self.changes.push((time, change));
        }
    }
}
