//! Host note events into engine events: notes with their channel and id, note expressions,
//! polyphonic modulation, MPE member channels, and the channel-wide controllers that change the
//! engine's controls part-way through a block.

use nice_plug::midi::{Channel, Key, VoiceID};
use nice_plug::prelude::*;

use super::{Kind, ModalPlugin, MAX_EVENTS};
use crate::editor::Audition;
use crate::engine::{MidiMessage, Note, NoteEvent as EngineEvent, NoteExpression};

/// A key number that names no voice: events with a note id but no key find their voice by id.
const NO_KEY: u8 = u8::MAX;

/// VST3's number for channel pressure among MIDI controllers (`kAfterTouch`, VST3 SDK
/// `ivstmidicontrollers.h`).
const VST3_CHANNEL_PRESSURE: u8 = 128;

/// VST3's number for pitch bend among MIDI controllers (`kPitchBend`, the same header).
const VST3_PITCH_BEND: u8 = 129;

/// The MIDI controllers the engine reads ([`crate::engine::MidiInput`]), numbered as VST3 numbers
/// them: the mod wheel (CC 1), the sustain pedal (CC 64), slide (CC 74), all sound off (CC 120),
/// all notes off (CC 123), channel pressure and pitch bend. VST3 has no MIDI controller events: a
/// host turns each into a change of a hidden parameter standing for it on its channel, and the
/// plugin lists those parameters for these controllers alone.
pub const VST3_MIDI_CONTROLLERS: [u8; 7] =
    [1, 64, 74, 120, 123, VST3_CHANNEL_PRESSURE, VST3_PITCH_BEND];

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
    /// Reads the block's host events into `self.events`, in time order: MIDI (and notes) through
    /// the engine's MIDI reading, as the renderer plays a MIDI file; CLAP's note expressions and
    /// polyphonic modulation directly.
    pub(super) fn read_events(&mut self, context: &mut impl ProcessContext<Self>) {
        self.events.clear();
        // The block's controls; MIDI is read with their MPE setting, bend ranges, pressure
        // routing and exciter.
        self.block_controls = self.params.controls();
        self.read_auditions();
        while let Some(event) = context.next_event() {
            if let Some((time, message)) = self.midi_of(event) {
                let events = &mut self.events;
                self.midi
                    .read(time, message, &self.block_controls, |event| {
                        if events.len() < MAX_EVENTS {
                            events.push(event);
                        }
                    });
            }
        }
    }

    /// A host event as a MIDI message at its time, for the engine's MIDI reading; `None` for
    /// the events read directly ([`ModalPlugin::read_direct`]) and for a note-off of every note.
    fn midi_of(&mut self, event: PluginNoteEvent<Self>) -> Option<(u32, MidiMessage)> {
        match event {
            NoteEvent::NoteOn {
                timing,
                voice_id,
                channel,
                key,
                velocity,
            } => {
                let note = note_of(voice_id, channel, key).filter(|n| n.key != NO_KEY)?;
                if velocity > 0.0 {
                    self.last_key = Some(note.key);
                }
                Some((timing, MidiMessage::NoteOn { note, velocity }))
            }
            // A wildcard key (and no id) means every note.
            NoteEvent::NoteOff {
                timing,
                voice_id,
                channel,
                key,
                ..
            } => match note_of(voice_id, channel, key) {
                Some(note) => Some((timing, MidiMessage::NoteOff { note })),
                None => {
                    self.push(EngineEvent::AllNotesOff { time: timing });
                    None
                }
            },
            NoteEvent::PolyPressure {
                timing,
                voice_id,
                channel,
                key,
                pressure,
            } => note_of(voice_id, channel, key)
                .map(|note| (timing, MidiMessage::PolyPressure { note, pressure })),
            NoteEvent::MidiPitchBend {
                timing,
                channel,
                value,
            } => Some((timing, MidiMessage::PitchBend { channel, value })),
            NoteEvent::MidiChannelPressure {
                timing,
                channel,
                pressure,
            } => Some((timing, MidiMessage::ChannelPressure { channel, pressure })),
            NoteEvent::MidiCC {
                timing,
                cc,
                channel,
                value,
            } => Some((timing, MidiMessage::Control { channel, cc, value })),
            event => {
                self.read_direct(event);
                None
            }
        }
    }

    /// Reads a host event that is no MIDI into `self.events`: a choke, a note expression, or
    /// polyphonic modulation and the automation under it. Others are ignored.
    fn read_direct(&mut self, event: PluginNoteEvent<Self>) {
        match event {
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
            } => self.express(
                timing,
                note_of(voice_id, channel, key),
                NoteExpression::Tuning(tuning),
            ),
            // Brightness (CLAP's note expression) is a note's slide: a contact's speed.
            NoteEvent::PolyBrightness {
                timing,
                voice_id,
                channel,
                key,
                brightness,
            } => self.express(
                timing,
                note_of(voice_id, channel, key),
                NoteExpression::Slide(brightness),
            ),
            NoteEvent::PolyModulation {
                timing,
                voice_id,
                poly_modulation_id,
                normalized_offset,
            } => self.modulate(timing, voice_id, poly_modulation_id, normalized_offset),
            NoteEvent::MonoAutomation {
                timing,
                poly_modulation_id,
                normalized_value,
            } => self.automate_modulated(timing, poly_modulation_id, normalized_value),
            _ => {}
        }
    }

    /// Queues `expression` of `note` (if any) at `time`.
    fn express(&mut self, time: u32, note: Option<Note>, expression: NoteExpression) {
        if let Some(note) = note {
            self.push(EngineEvent::Expression {
                time,
                note,
                expression,
            });
        }
    }

    /// The host's polyphonic modulation of parameter `poly_id` on the note it knows as `id`, by
    /// `normalized_offset` from the parameter's value: kept, and queued for the note.
    fn modulate(&mut self, time: u32, id: i32, poly_id: u32, normalized_offset: f32) {
        self.poly.set(id, poly_id, normalized_offset);
        let base = self.params.poly_base(poly_id).unwrap_or(0.0);
        if let Some(modulation) = self
            .params
            .voice_modulation(poly_id, base + normalized_offset)
        {
            self.push(EngineEvent::Modulate {
                time,
                id,
                modulation,
            });
        }
    }

    /// Parameter `poly_id` moves to `normalized_value` (monophonic automation): every note it
    /// modulates moves with it, keeping its offset.
    fn automate_modulated(&mut self, time: u32, poly_id: u32, normalized_value: f32) {
        for (id, offset) in self.poly.offsets(poly_id) {
            if let Some(modulation) = self
                .params
                .voice_modulation(poly_id, normalized_value + offset)
            {
                if self.events.len() < MAX_EVENTS {
                    self.events.push(EngineEvent::Modulate {
                        time,
                        id,
                        modulation,
                    });
                }
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::{Controls, MidiInput};

    /// What the engine makes of a note held and let go, with the message `controller` makes
    /// sent at full while the note is held and at zero once it is let go.
    fn played_with(controller: &dyn Fn(f32) -> Option<MidiMessage>) -> Vec<EngineEvent> {
        let note = Note::key(60);
        let script = [
            (
                0,
                Some(MidiMessage::NoteOn {
                    note,
                    velocity: 1.0,
                }),
            ),
            (1, controller(1.0)),
            (2, Some(MidiMessage::NoteOff { note })),
            (3, controller(0.0)),
        ];
        let mut input = MidiInput::default();
        let mut events = Vec::new();
        for (time, message) in script {
            if let Some(message) = message {
                input.read(time, message, &Controls::default(), |e| events.push(e));
            }
        }
        events
    }

    /// The controllers listed for VST3 are exactly those that change what the engine plays.
    #[test]
    fn the_vst3_controllers_are_the_ones_the_engine_reads() {
        let plain = played_with(&|_| None);
        let channel = 0;
        let read: Vec<u8> = (0..=VST3_PITCH_BEND)
            .filter(|&number| {
                let events = played_with(&|value| {
                    Some(match number {
                        VST3_CHANNEL_PRESSURE => MidiMessage::ChannelPressure {
                            channel,
                            pressure: value,
                        },
                        VST3_PITCH_BEND => MidiMessage::PitchBend { channel, value },
                        cc => MidiMessage::Control { channel, cc, value },
                    })
                });
                events != plain
            })
            .collect();
        assert_eq!(read, VST3_MIDI_CONTROLLERS);
    }
}
