//! MIDI into engine events, the one way the plugins and the renderer both play it: notes with the
//! sustain pedal, pitch bend, mod wheel, channel and polyphonic pressure, CC 74 (slide), and MPE
//! member channels, whose bend, pressure and slide are their note's own.
//!
//! - Pitch bend, the mod wheel (CC 1) and channel pressure are channel-wide controllers
//!   ([`NoteEvent::Controller`]): the engine moves its controls from their sample on, through
//!   the bend range and the wheel's and pressure's targets ([`Controls::expressed`]).
//! - With MPE on, a member channel's (2 to 16) bend, pressure and slide are its note's, and are
//!   sent with a note that starts there after them; the manager channel's (1) bend, pressure and
//!   wheel act on every note (its slide, as any channel's, on its own notes).
//! - Polyphonic pressure, and channel pressure on a member channel, is a note's pressure: it damps
//!   a struck note when pressure is routed to damping, and is a contact's force whatever the
//!   routing; otherwise it is left alone. Without MPE, with a contact exciter and pressure routed
//!   to damping, channel pressure is its channel's notes' force too (and sent with a note that
//!   starts there after it): pressing harder on a plain keyboard presses the contact harder.
//! - CC 74 is the slide of the notes of its channel (a contact's speed), and of notes that start
//!   there after it.
//! - The sustain pedal (CC 64, down from 64) holds the notes released while it is down until it
//!   comes up; with MPE on, the manager channel's pedal holds every channel's notes.
//! - CC 120 (all sound off) and CC 123 (all notes off) end or release every note.

use super::{ControlChange, Controls, ExpressionTarget, Note, NoteEvent, NoteExpression};

/// MIDI channels.
pub const CHANNELS: usize = 16;

/// The MPE manager channel (MIDI channel 1, lower zone): its controllers act on every note.
pub const MPE_MANAGER_CHANNEL: u8 = 0;

/// Mod wheel (CC 1, coarse).
const MOD_WHEEL_CC: u8 = 1;

/// Sustain pedal (CC 64).
const SUSTAIN_CC: u8 = 64;

/// Sound controller 5, "brightness" (CC 74): MPE's slide, the third dimension of a note.
pub const SLIDE_CC: u8 = 74;

/// All sound off (CC 120).
const ALL_SOUND_OFF_CC: u8 = 120;

/// All notes off (CC 123).
const ALL_NOTES_OFF_CC: u8 = 123;

/// Most notes the sustain pedal holds after their keys are let go; a further release acts at
/// once.
const MAX_SUSTAINED: usize = 128;

/// A MIDI message, values as the wire gives them scaled to 0..1 (7-bit values over 127, the
/// 14-bit pitch bend over 16383).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MidiMessage {
    /// A key pressed (velocity 0 lets it go).
    NoteOn {
        /// The note, with its channel (and id, from a host that gives one).
        note: Note,
        /// Velocity, 0 to 1.
        velocity: f32,
    },
    /// A key let go.
    NoteOff {
        /// The note.
        note: Note,
    },
    /// Polyphonic key pressure.
    PolyPressure {
        /// The note.
        note: Note,
        /// Pressure, 0 to 1.
        pressure: f32,
    },
    /// Pitch bend, 0 to 1 with the centre at 8192 / 16383.
    PitchBend {
        /// MIDI channel, 0 to 15.
        channel: u8,
        /// The wheel, 0 to 1.
        value: f32,
    },
    /// Channel pressure.
    ChannelPressure {
        /// MIDI channel, 0 to 15.
        channel: u8,
        /// Pressure, 0 to 1.
        pressure: f32,
    },
    /// A control change.
    Control {
        /// MIDI channel, 0 to 15.
        channel: u8,
        /// Controller number.
        cc: u8,
        /// Value, 0 to 1.
        value: f32,
    },
}

/// The state of the MIDI being played: each channel's own bend, pressure and slide, the sustain
/// pedals and the notes they hold. Fixed size: reading never allocates.
#[derive(Debug, Clone)]
pub struct MidiInput {
    /// Pitch bend of each channel, -1 to 1 (used for MPE member channels).
    channel_bend: [f32; CHANNELS],
    /// Pressure of each channel, 0 to 1 (used for MPE member channels).
    channel_pressure: [f32; CHANNELS],
    /// Slide (CC 74) of each channel, 0 to 1, once sent.
    channel_slide: [Option<f32>; CHANNELS],
    /// Whether each channel's sustain pedal is down.
    pedal: [bool; CHANNELS],
    /// Notes let go while a pedal held them; the first `num_sustained` are in use.
    sustained: [Note; MAX_SUSTAINED],
    /// See `sustained`.
    num_sustained: usize,
}

impl Default for MidiInput {
    fn default() -> Self {
        Self {
            channel_bend: [0.0; CHANNELS],
            channel_pressure: [0.0; CHANNELS],
            channel_slide: [None; CHANNELS],
            pedal: [false; CHANNELS],
            sustained: [Note::key(0); MAX_SUSTAINED],
            num_sustained: 0,
        }
    }
}

/// A pitch-bend wheel's value on the wire (0 to 1) as a bend of -1 to 1.
pub fn bend_of(value: f32) -> f32 {
    (value * 2.0 - 1.0).clamp(-1.0, 1.0)
}

/// How a block's MIDI reaches the notes, as its controls say.
#[derive(Debug, Clone, Copy)]
struct Routing {
    /// MPE (lower zone): member channels' bend, pressure and slide are their notes' own.
    mpe: bool,
    /// Semitones of a member channel's full bend.
    mpe_bend_range_semitones: f32,
    /// Whether a note's pressure is its own: it damps the note when routed so, and is a
    /// contact's force whatever the routing.
    pressure_is_the_notes: bool,
    /// Whether the notes hold a contact while pressure is routed to damping (which would damp
    /// the contact instead of pressing it).
    contact_routed_to_damping: bool,
}

impl Routing {
    /// The routing `controls` set.
    fn of(controls: &Controls) -> Self {
        let contact = controls.exciter.is_contact();
        let damping = controls.pressure_target == ExpressionTarget::Damping;
        Self {
            mpe: controls.mpe,
            mpe_bend_range_semitones: controls.mpe_bend_range_semitones,
            pressure_is_the_notes: contact || damping,
            contact_routed_to_damping: contact && damping,
        }
    }

    /// Whether `channel` is an MPE member channel.
    fn is_member(self, channel: u8) -> bool {
        self.mpe && channel != MPE_MANAGER_CHANNEL
    }

    /// Whether channel pressure on `channel` is its notes' own: on MPE member channels, and,
    /// without MPE, on a contact when routed to damping.
    fn channel_pressure_is_the_notes(self, channel: u8) -> bool {
        self.is_member(channel) || (!self.mpe && self.contact_routed_to_damping)
    }
}

/// The index of `channel`'s state.
fn index(channel: u8) -> usize {
    channel as usize % CHANNELS
}

impl MidiInput {
    /// Reads `message` at sample `time`, handing the engine events it makes to `emit`, as
    /// `controls` (their MPE setting, bend range and pressure routing, and exciter) say.
    pub fn read(
        &mut self,
        time: u32,
        message: MidiMessage,
        controls: &Controls,
        mut emit: impl FnMut(NoteEvent),
    ) {
        let routing = Routing::of(controls);
        let emit = &mut emit;
        match message {
            MidiMessage::NoteOn { note, velocity } if velocity > 0.0 => {
                self.note_on(time, note, velocity, routing, emit)
            }
            MidiMessage::NoteOn { note, .. } | MidiMessage::NoteOff { note } => {
                let held = self.pedal[index(note.channel)]
                    || (routing.mpe && self.pedal[MPE_MANAGER_CHANNEL as usize]);
                if held && self.num_sustained < MAX_SUSTAINED {
                    self.sustained[self.num_sustained] = note;
                    self.num_sustained += 1;
                } else {
                    emit(NoteEvent::Off { time, note });
                }
            }
            MidiMessage::PolyPressure { note, pressure } => {
                if routing.pressure_is_the_notes {
                    emit(NoteEvent::Expression {
                        time,
                        note,
                        expression: NoteExpression::Pressure(pressure.clamp(0.0, 1.0)),
                    });
                }
            }
            MidiMessage::PitchBend { channel, value } => {
                self.pitch_bend(time, channel, value, routing, emit)
            }
            MidiMessage::ChannelPressure { channel, pressure } => {
                self.channel_pressure(time, channel, pressure, routing, emit)
            }
            MidiMessage::Control { channel, cc, value } => {
                self.control(time, channel, cc, value, routing, emit)
            }
        }
    }

    /// A note struck: it starts with its channel's bend (a member channel's), pressure (when
    /// its own) and slide, sent before it, so they shape it from its first sample.
    fn note_on(
        &mut self,
        time: u32,
        note: Note,
        velocity: f32,
        routing: Routing,
        emit: &mut impl FnMut(NoteEvent),
    ) {
        // Pressed again, it is held by its key, not by the pedal.
        self.unsustain(|n| n.channel == note.channel && n.key == note.key);
        emit(NoteEvent::On {
            time,
            note,
            velocity,
        });
        let c = index(note.channel);
        let mut express = |expression| {
            emit(NoteEvent::Expression {
                time,
                note,
                expression,
            })
        };
        if routing.is_member(note.channel) {
            let bend = self.channel_bend[c] * routing.mpe_bend_range_semitones;
            express(NoteExpression::Tuning(bend));
        }
        if routing.channel_pressure_is_the_notes(note.channel) && routing.pressure_is_the_notes {
            express(NoteExpression::Pressure(self.channel_pressure[c]));
        }
        if let Some(slide) = self.channel_slide[c] {
            express(NoteExpression::Slide(slide));
        }
    }

    /// Pitch bend on `channel` (`value` on the wire, 0 to 1): a member channel's notes' own, or
    /// the engine's.
    fn pitch_bend(
        &mut self,
        time: u32,
        channel: u8,
        value: f32,
        routing: Routing,
        emit: &mut impl FnMut(NoteEvent),
    ) {
        let bend = bend_of(value);
        if routing.is_member(channel) {
            self.channel_bend[index(channel)] = bend;
            emit(NoteEvent::ChannelExpression {
                time,
                channel,
                expression: NoteExpression::Tuning(bend * routing.mpe_bend_range_semitones),
            });
        } else {
            emit(NoteEvent::Controller {
                time,
                change: ControlChange::Bend(bend),
            });
        }
    }

    /// Channel pressure on `channel`: its notes' own, or the engine's.
    fn channel_pressure(
        &mut self,
        time: u32,
        channel: u8,
        pressure: f32,
        routing: Routing,
        emit: &mut impl FnMut(NoteEvent),
    ) {
        let pressure = pressure.clamp(0.0, 1.0);
        if routing.channel_pressure_is_the_notes(channel) {
            self.channel_pressure[index(channel)] = pressure;
            if routing.pressure_is_the_notes {
                emit(NoteEvent::ChannelExpression {
                    time,
                    channel,
                    expression: NoteExpression::Pressure(pressure),
                });
            }
        } else {
            emit(NoteEvent::Controller {
                time,
                change: ControlChange::Pressure(pressure),
            });
        }
    }

    /// Controller `cc` on `channel` moves to `value` (0 to 1): slide, mod wheel, sustain pedal,
    /// all sound off, all notes off; others are ignored.
    fn control(
        &mut self,
        time: u32,
        channel: u8,
        cc: u8,
        value: f32,
        routing: Routing,
        emit: &mut impl FnMut(NoteEvent),
    ) {
        let value = value.clamp(0.0, 1.0);
        match cc {
            SLIDE_CC => {
                self.channel_slide[index(channel)] = Some(value);
                emit(NoteEvent::ChannelExpression {
                    time,
                    channel,
                    expression: NoteExpression::Slide(value),
                });
            }
            MOD_WHEEL_CC => emit(NoteEvent::Controller {
                time,
                change: ControlChange::ModWheel(value),
            }),
            SUSTAIN_CC => {
                self.pedal[index(channel)] = value >= 0.5;
                // Notes whose pedal has come up are let go.
                let manager = routing.mpe && self.pedal[MPE_MANAGER_CHANNEL as usize];
                let pedal = self.pedal;
                self.unsustain_with(
                    |n| !manager && !pedal[index(n.channel)],
                    |note| emit(NoteEvent::Off { time, note }),
                );
            }
            ALL_SOUND_OFF_CC => {
                self.num_sustained = 0;
                emit(NoteEvent::AllSoundOff { time });
            }
            ALL_NOTES_OFF_CC => {
                self.num_sustained = 0;
                emit(NoteEvent::AllNotesOff { time });
            }
            _ => {}
        }
    }

    /// Forgets the sustained notes (after every note has ended: a host's reset). The channels'
    /// controllers and pedals stay where the player left them.
    pub fn forget_notes(&mut self) {
        self.num_sustained = 0;
    }

    /// Drops the sustained notes matching `matches`, without letting them go.
    fn unsustain(&mut self, matches: impl Fn(&Note) -> bool) {
        self.unsustain_with(matches, |_| {});
    }

    /// Drops the sustained notes matching `matches`, handing each to `release`.
    fn unsustain_with(&mut self, matches: impl Fn(&Note) -> bool, mut release: impl FnMut(Note)) {
        let mut kept = 0;
        for i in 0..self.num_sustained {
            let note = self.sustained[i];
            if matches(&note) {
                release(note);
            } else {
                self.sustained[kept] = note;
                kept += 1;
            }
        }
        self.num_sustained = kept;
    }
}

#[cfg(test)]
mod tests;
