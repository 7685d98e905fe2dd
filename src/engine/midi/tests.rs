//! MIDI reading: the sustain pedal, MPE member channels, controllers and slide.

use super::*;

fn read_all(controls: &Controls, messages: &[MidiMessage]) -> Vec<NoteEvent> {
    let mut midi = MidiInput::default();
    let mut out = Vec::new();
    for (t, m) in messages.iter().enumerate() {
        midi.read(t as u32, *m, controls, |e| out.push(e));
    }
    out
}

fn note(channel: u8, key: u8) -> Note {
    Note {
        key,
        channel,
        id: None,
    }
}

fn on(channel: u8, key: u8) -> MidiMessage {
    MidiMessage::NoteOn {
        note: note(channel, key),
        velocity: 0.8,
    }
}

fn off(channel: u8, key: u8) -> MidiMessage {
    MidiMessage::NoteOff {
        note: note(channel, key),
    }
}

fn pedal(channel: u8, down: bool) -> MidiMessage {
    MidiMessage::Control {
        channel,
        cc: SUSTAIN_CC,
        value: if down { 1.0 } else { 0.0 },
    }
}

fn offs(events: &[NoteEvent]) -> Vec<(u32, u8)> {
    events
        .iter()
        .filter_map(|e| match *e {
            NoteEvent::Off { time, note } => Some((time, note.key)),
            _ => None,
        })
        .collect()
}

#[test]
fn the_pedal_holds_released_notes_until_it_comes_up() {
    let c = Controls::default();
    // 60 let go under the pedal, 62 pressed and let go under it, 64 let go after it is up.
    let events = read_all(
        &c,
        &[
            on(0, 60),
            pedal(0, true),
            off(0, 60),
            on(0, 62),
            off(0, 62),
            pedal(0, false),
            on(0, 64),
            off(0, 64),
        ],
    );
    assert_eq!(offs(&events), vec![(5, 60), (5, 62), (7, 64)]);
    // A sustained key struck again is held by its key: the pedal's release leaves it.
    let events = read_all(
        &c,
        &[
            pedal(0, true),
            on(0, 60),
            off(0, 60),
            on(0, 60),
            pedal(0, false),
            off(0, 60),
        ],
    );
    assert_eq!(offs(&events), vec![(5, 60)]);
    // A pedal holds its own channel's notes only, without MPE.
    let events = read_all(&c, &[on(1, 60), pedal(0, true), off(1, 60)]);
    assert_eq!(offs(&events), vec![(2, 60)]);
    // With MPE the manager channel's pedal holds every channel's.
    let mpe = Controls {
        mpe: true,
        ..Controls::default()
    };
    let events = read_all(
        &mpe,
        &[on(3, 60), pedal(0, true), off(3, 60), pedal(0, false)],
    );
    assert_eq!(offs(&events), vec![(3, 60)]);
}

#[test]
fn bend_wheel_and_pressure_are_channel_wide_unless_on_an_mpe_member_channel() {
    let bend = |channel| MidiMessage::PitchBend {
        channel,
        value: 1.0,
    };
    let pressure = |channel| MidiMessage::ChannelPressure {
        channel,
        pressure: 0.5,
    };
    let wheel = MidiMessage::Control {
        channel: 4,
        cc: 1,
        value: 0.25,
    };
    let c = Controls::default();
    let events = read_all(&c, &[bend(2), pressure(2), wheel]);
    assert!(
        matches!(events[0], NoteEvent::Controller { change: ControlChange::Bend(b), .. } if b == 1.0)
    );
    assert!(
        matches!(events[1], NoteEvent::Controller { change: ControlChange::Pressure(p), .. } if p == 0.5)
    );
    assert!(
        matches!(events[2], NoteEvent::Controller { change: ControlChange::ModWheel(w), .. } if w == 0.25)
    );
    // MPE: a member channel's bend and pressure are its notes', and a note starting there
    // after them takes them with it; the manager channel's bend is everyone's.
    let mpe = Controls {
        mpe: true,
        ..Controls::default()
    };
    let events = read_all(&mpe, &[bend(2), pressure(2), on(2, 60), bend(0)]);
    let range = mpe.mpe_bend_range_semitones;
    assert!(
        matches!(events[0], NoteEvent::ChannelExpression { channel: 2, expression: NoteExpression::Tuning(t), .. } if t == range)
    );
    assert!(
        matches!(events[1], NoteEvent::ChannelExpression { channel: 2, expression: NoteExpression::Pressure(p), .. } if p == 0.5)
    );
    assert!(matches!(events[2], NoteEvent::On { .. }));
    assert!(
        matches!(events[3], NoteEvent::Expression { expression: NoteExpression::Tuning(t), .. } if t == range)
    );
    assert!(
        matches!(events[4], NoteEvent::Expression { expression: NoteExpression::Pressure(p), .. } if p == 0.5)
    );
    assert!(matches!(
        events[5],
        NoteEvent::Controller {
            change: ControlChange::Bend(_),
            ..
        }
    ));
    assert_eq!(events.len(), 6);
}

#[test]
fn slide_and_poly_pressure_reach_the_notes() {
    let slide = MidiMessage::Control {
        channel: 5,
        cc: SLIDE_CC,
        value: 0.5,
    };
    let poly = MidiMessage::PolyPressure {
        note: note(5, 60),
        pressure: 0.75,
    };
    // Pressure routed elsewhere leaves a struck note alone; a contact takes it as its force.
    let c = Controls {
        pressure_target: ExpressionTarget::Position,
        ..Controls::default()
    };
    let events = read_all(&c, &[slide, on(5, 60), poly]);
    assert!(
        matches!(events[0], NoteEvent::ChannelExpression { channel: 5, expression: NoteExpression::Slide(s), .. } if s == 0.5)
    );
    assert!(matches!(events[1], NoteEvent::On { .. }));
    assert!(
        matches!(events[2], NoteEvent::Expression { expression: NoteExpression::Slide(s), .. } if s == 0.5)
    );
    assert_eq!(events.len(), 3, "{events:?}");
    let contact = Controls {
        exciter: crate::dsp::ExciterKind::Scrape,
        ..c
    };
    let events = read_all(&contact, &[on(5, 60), poly]);
    assert!(
        matches!(events[1], NoteEvent::Expression { expression: NoteExpression::Pressure(p), .. } if p == 0.75)
    );
    // Channel pressure routed to damping, which a contact does not take, is its channel's
    // notes' force; routed elsewhere it goes there.
    let aftertouch = MidiMessage::ChannelPressure {
        channel: 5,
        pressure: 0.5,
    };
    let damping = Controls {
        pressure_target: ExpressionTarget::Damping,
        ..contact.clone()
    };
    let events = read_all(&damping, &[aftertouch, on(5, 62)]);
    assert!(
        matches!(events[0], NoteEvent::ChannelExpression { channel: 5, expression: NoteExpression::Pressure(p), .. } if p == 0.5)
    );
    // A note struck while the key is pressed down takes the pressure with it.
    assert!(
        matches!(events[2], NoteEvent::Expression { expression: NoteExpression::Pressure(p), .. } if p == 0.5)
    );
    // Damping does not damp a contact (its pressure is the notes' force).
    let pressed = crate::engine::Controllers {
        pressure: 1.0,
        ..Default::default()
    };
    assert_eq!(damping.expressed(&pressed).extra_damping, 0.0);
    assert_eq!(Controls::default().expressed(&pressed).extra_damping, 1.0);
    // With MPE the manager channel's pressure stays channel-wide.
    let mpe = Controls {
        mpe: true,
        ..damping.clone()
    };
    let manager = MidiMessage::ChannelPressure {
        channel: 0,
        pressure: 0.5,
    };
    let events = read_all(&mpe, &[manager]);
    assert!(
        matches!(events[0], NoteEvent::Controller { change: ControlChange::Pressure(p), .. } if p == 0.5)
    );
    let events = read_all(&contact, &[aftertouch]);
    assert!(
        matches!(events[0], NoteEvent::Controller { change: ControlChange::Pressure(p), .. } if p == 0.5)
    );
    // All notes off forgets what the pedal held.
    let all_off = MidiMessage::Control {
        channel: 0,
        cc: ALL_NOTES_OFF_CC,
        value: 0.0,
    };
    let events = read_all(
        &Controls::default(),
        &[
            on(0, 60),
            pedal(0, true),
            off(0, 60),
            all_off,
            pedal(0, false),
        ],
    );
    assert!(offs(&events).is_empty());
    assert!(matches!(events.last(), Some(NoteEvent::AllNotesOff { .. })));
}
