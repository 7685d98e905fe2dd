//! The editor drawn headlessly: egui runs without a window, frames are fed pointer and key events,
//! and the tests check what the player's actions did to the parameters, the bank and the strike
//! pad's queue. A panic while drawing, or widgets laid out off screen, fails here.

#[path = "common/editor.rs"]
mod harness;

use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

use egui::{pos2, vec2, Event, Key, Modifiers, Pos2, Rect};
use harness::{at, Harness};
use modal_resonator::bank::factory::{factory_bank, factory_banks};
use modal_resonator::bank::io::bank_to_json;
use modal_resonator::bank::{load_bank_file, Bank};
use modal_resonator::editor::{control_rect, fixed_strike_axes};
use modal_resonator::editor::{
    Audition, EditorShared, EDITOR_MIN_SIZE, EDITOR_SIZE, METER_INTERVAL_S, MODE_VIEW_DB_SPAN,
};
use modal_resonator::engine::{Controls, Engine, NoteEvent, PreparedBank};
use nice_plug::prelude::{Param, Params};

/// Most space between two widgets stacked in a panel, in points.
const ROW_GAP: f32 = 12.0;

#[test]
fn every_factory_bank_draws_at_every_size_and_scale() {
    let sizes = [
        vec2(EDITOR_MIN_SIZE.0, EDITOR_MIN_SIZE.1),
        vec2(EDITOR_SIZE.0 as f32, EDITOR_SIZE.1 as f32),
        vec2(1920.0, 1080.0),
    ];
    for bank in factory_banks() {
        let mut h = Harness::new(Some(&bank));
        for size in sizes {
            for pixels_per_point in [1.0, 1.25, 2.0] {
                h.size = size;
                h.pixels_per_point = pixels_per_point;
                h.settle();
                let output = h.frame(Vec::new());
                let context = format!("{} at {size:?}, {pixels_per_point}x", bank.name);
                assert_eq!(output.pixels_per_point, pixels_per_point, "{context}");
                assert_eq!(
                    h.app.stems_drawn(),
                    bank.modes.len(),
                    "{context}: one stem per mode"
                );
                let screen = Rect::from_min_size(Pos2::ZERO, size);
                let layout = h.app.layout();
                for (name, rect) in [
                    ("mode view", layout.mode_view),
                    ("strike pad", layout.strike_area),
                ] {
                    assert!(
                        rect.width() > 100.0 && rect.height() > 20.0,
                        "{context}: {name} is {rect:?}"
                    );
                    assert!(
                        screen.contains_rect(rect),
                        "{context}: {name} {rect:?} leaves the window"
                    );
                }
                assert!(
                    !layout.mode_view.intersects(layout.strike_area),
                    "{context}: the mode view and the strike pad overlap"
                );
                let again = h.frame(Vec::new());
                assert_eq!(
                    h.app.layout(),
                    layout,
                    "{context}: the layout moves by itself"
                );
                assert_eq!(again.shapes.len(), output.shapes.len(), "{context}");
                let shapes = output.shapes.len();
                assert!(shapes > 200, "{context}: only {shapes} shapes drawn");
            }
        }
    }
}

/// Window sizes from the smallest to a large screen, in points: the strike pad and the bank
/// list change with both width and height.
const SIZES: [(f32, f32); 7] = [
    EDITOR_MIN_SIZE,
    (1000.0, 600.0),
    (900.0, 800.0),
    (EDITOR_SIZE.0 as f32, EDITOR_SIZE.1 as f32),
    (1400.0, 900.0),
    (1920.0, 1080.0),
    (2560.0, 1600.0),
];

/// The strike pad writes the name of every position of every factory bank at every window size,
/// inside the pad, clear of the positions' marks, and never over another name (on the marimba
/// bar, "quarter" and "near centre" once printed as "quartemear centre").
#[test]
fn the_strike_pads_names_never_overlap() {
    for bank in factory_banks() {
        let mut h = Harness::new(Some(&bank));
        for (width, height) in SIZES {
            h.size = vec2(width, height);
            h.settle();
            let context = format!("{} at {width} x {height}", bank.name);
            let labels = h.app.strike_pad_labels().to_vec();
            let mut drawn: Vec<&str> = labels.iter().map(|(name, _)| name.as_str()).collect();
            let mut names: Vec<&str> = bank.positions.iter().map(|p| p.name.as_str()).collect();
            drawn.sort_unstable();
            names.sort_unstable();
            assert_eq!(drawn, names, "{context}: the names written");
            let area = h.app.layout().strike_area;
            let positions = h.app.session().positions();
            let marks: Vec<Pos2> = positions
                .coords()
                .iter()
                .map(|c| match positions.dims() {
                    2 => at(area, c[0] as f32, c[1] as f32),
                    _ => pos2(at(area, c[0] as f32, 0.0).x, area.center().y),
                })
                .collect();
            let pad = h.app.layout().strike_pad;
            for (i, (name, rect)) in labels.iter().enumerate() {
                assert!(
                    pad.contains_rect(*rect),
                    "{context}: {name:?} at {rect:?} leaves the pad {pad:?}"
                );
                for mark in &marks {
                    assert!(!rect.contains(*mark), "{context}: {name:?} covers a mark");
                }
                for (other, other_rect) in &labels[i + 1..] {
                    assert!(
                        !rect.intersects(*other_rect),
                        "{context}: {name:?} at {rect:?} runs into {other:?} at {other_rect:?}"
                    );
                }
            }
        }
    }
}

/// The list of factory banks takes the height the bank panel leaves it, down to the user banks
/// below it: a taller window shows more banks, and a tall one shows them all.
#[test]
fn the_factory_bank_list_fills_its_panel() {
    let banks = factory_banks().len();
    let mut h = Harness::new(None);
    let mut shown_before = 0;
    let mut sizes = SIZES;
    sizes.sort_by(|a, b| a.1.total_cmp(&b.1));
    for (width, height) in sizes {
        h.size = vec2(width, height);
        h.settle();
        let context = format!("at {width} x {height}");
        let layout = h.app.layout();
        let shown = h.app.factory_banks_shown();
        let gap = layout.bank_files.top() - layout.bank_list.bottom();
        assert!(
            (0.0..=ROW_GAP).contains(&gap) || shown == banks,
            "{context}: the list {:?} ends {gap} points above the user banks {:?}",
            layout.bank_list,
            layout.bank_files
        );
        assert!(shown >= shown_before, "{context}: {shown} banks shown");
        shown_before = shown;
    }
    h.size = vec2(EDITOR_SIZE.0 as f32, EDITOR_SIZE.1 as f32);
    h.settle();
    let shown = h.app.factory_banks_shown();
    assert!(
        shown >= 12,
        "the window as it opens shows {shown} factory banks"
    );
    h.size = vec2(1920.0, 2400.0);
    h.settle();
    let shown = h.app.factory_banks_shown();
    assert_eq!(shown, banks, "a tall window shows every factory bank");
}

#[test]
fn the_effect_editor_draws_at_every_size() {
    let mut h = Harness::with_kind(None, true);
    for size in [
        vec2(EDITOR_MIN_SIZE.0, EDITOR_MIN_SIZE.1),
        vec2(EDITOR_SIZE.0 as f32, EDITOR_SIZE.1 as f32),
    ] {
        h.size = size;
        h.settle();
        let screen = Rect::from_min_size(Pos2::ZERO, size);
        let layout = h.app.layout();
        assert!(screen.contains_rect(layout.mode_view) && screen.contains_rect(layout.strike_area));
        let dry_wet =
            control_rect(&h.ctx, h.params.output.dry_wet.name()).expect("dry/wet is drawn");
        assert!(dry_wet.width() > 50.0, "dry/wet at {dry_wet:?}");
    }
}

#[test]
fn every_parameter_has_a_labelled_control() {
    for is_effect in [false, true] {
        let h = Harness::with_kind(None, is_effect);
        let shown = h.app.shown_parameter_names();
        for (_, ptr, _) in h.params.param_map() {
            // SAFETY: the parameters live as long as `h`.
            let name = unsafe { ptr.name() }.to_string();
            assert!(shown.contains(&name), "parameter {name:?} has no control");
        }
    }
}

#[test]
fn a_strike_axis_the_bank_does_not_vary_along_is_marked() {
    for (slug, want) in [
        ("rosewood-marimba-bar", [false, true]),
        ("glass-plate", [false, false]),
    ] {
        let bank = factory_bank(slug).expect(slug);
        let mut h = Harness::new(Some(&bank));
        h.settle();
        assert_eq!(fixed_strike_axes(&h.ctx), Some(want), "{slug}");
    }
}

#[test]
fn sliders_end_every_gesture_they_begin() {
    let mut h = Harness::new(None);
    let name = h.params.object.size.name().to_string();
    let rect = control_rect(&h.ctx, &name).expect("the size slider is drawn");
    let default = h.params.object.size.default_plain_value();

    // A drag moves the value by the distance dragged, not to the pointer.
    let from = at(rect, 0.5, 0.5);
    let before = h.params.object.size.unmodulated_normalized_value();
    h.drag(
        from,
        from + vec2(rect.width() * 0.2, 0.0),
        4,
        Modifiers::NONE,
    );
    let after = h.params.object.size.unmodulated_normalized_value();
    assert!(
        (after - before - 0.2).abs() < 0.02,
        "dragged a fifth of the width: {before} -> {after}"
    );
    assert!(h.gestures_balanced());

    // Shift moves it a tenth as far.
    let before = after;
    h.drag(
        from,
        from + vec2(rect.width() * 0.2, 0.0),
        4,
        Modifiers::SHIFT,
    );
    let after = h.params.object.size.unmodulated_normalized_value();
    assert!(
        (after - before - 0.02).abs() < 0.005,
        "fine drag of a fifth of the width: {before} -> {after}"
    );
    assert!(h.gestures_balanced());

    // A plain click changes nothing and leaves no gesture open.
    h.click(at(rect, 0.9, 0.5));
    assert_eq!(h.params.object.size.unmodulated_normalized_value(), after);
    assert!(h.gestures_balanced());

    // A double-click resets, in balanced gestures.
    let p = at(rect, 0.9, 0.5);
    h.move_to(p);
    for _ in 0..2 {
        h.button(p, true, Modifiers::NONE);
        h.button(p, false, Modifiers::NONE);
    }
    h.settle();
    assert_eq!(h.params.object.size.value(), default);
    assert!(h.gestures_balanced());

    // So does a Ctrl-click.
    h.drag(
        from,
        from + vec2(rect.width() * 0.3, 0.0),
        3,
        Modifiers::NONE,
    );
    assert_ne!(h.params.object.size.value(), default);
    h.frame(vec![Event::ModifiersChanged(Modifiers::COMMAND)]);
    h.button(p, true, Modifiers::COMMAND);
    h.button(p, false, Modifiers::COMMAND);
    h.frame(vec![Event::ModifiersChanged(Modifiers::NONE)]);
    h.settle();
    assert_eq!(h.params.object.size.value(), default);
    assert!(h.gestures_balanced());
}

#[test]
fn hovering_a_stem_finds_its_mode() {
    let bank = factory_bank("steel-free-free-bar").unwrap();
    let mut h = Harness::new(Some(&bank));
    for i in 0..bank.modes.len() {
        let head = h.app.stem_head(i).unwrap();
        h.move_to(head + vec2(0.0, 3.0));
        h.move_to(head + vec2(0.0, 3.0));
        assert_eq!(
            h.app.hovered_mode(),
            Some(i),
            "stem of mode {i} at {head:?}"
        );
    }
    h.move_to(pos2(1.0, 1.0));
    assert_eq!(h.app.hovered_mode(), None);
}

#[test]
fn pressing_the_strike_pad_auditions_there_and_dragging_moves_the_strike() {
    let mut h = Harness::new(None);
    let area = h.app.layout().strike_area;
    let y = h.params.strike.strike_y.value();
    h.move_to(at(area, 0.3, 0.5));
    h.button(at(area, 0.3, 0.5), true, Modifiers::NONE);
    let queued = h.auditions();
    assert_eq!(queued.len(), 1, "{queued:?}");
    let Audition::Strike {
        x,
        y: strike_y,
        velocity,
    } = queued[0]
    else {
        panic!("expected a strike, got {queued:?}");
    };
    assert!((x - 0.3).abs() < 0.01, "struck at {x}");
    assert_eq!(strike_y, y, "a 1-D bank keeps strike Y");
    assert!(velocity > 0.0 && velocity <= 1.0);
    assert!((h.params.strike.strike_x.value() - 0.3).abs() < 0.01);

    // Dragging moves the strike position without striking again; releasing ends the note.
    for x in [0.4, 0.5, 0.6] {
        h.move_to(at(area, x, 0.5));
    }
    assert!(h.auditions().is_empty());
    assert!((h.params.strike.strike_x.value() - 0.6).abs() < 0.01);
    h.button(at(area, 0.6, 0.5), false, Modifiers::NONE);
    assert_eq!(h.auditions(), vec![Audition::Release]);
    assert!(h.gestures_balanced());
}

#[test]
fn the_strike_pad_of_a_surface_sets_both_coordinates() {
    let bank = factory_bank("steel-plate").unwrap();
    let mut h = Harness::new(Some(&bank));
    let area = h.app.layout().strike_area;
    assert!(
        (area.width() - area.height()).abs() < 1.0,
        "a 2-D pad is square: {area:?}"
    );
    h.click(at(area, 0.25, 0.75));
    let queued = h.auditions();
    let Audition::Strike { x, y, .. } = queued[0] else {
        panic!("expected a strike, got {queued:?}");
    };
    assert!(
        (x - 0.25).abs() < 0.01 && (y - 0.75).abs() < 0.01,
        "({x}, {y})"
    );
    assert_eq!(queued[1], Audition::Release);
    assert!((h.params.strike.strike_y.value() - 0.75).abs() < 0.01);
    assert!(h.gestures_balanced());
}

#[test]
fn an_audition_strikes_like_a_note_at_the_pad_position() {
    let bank = factory_bank("steel-plate").unwrap();
    let prepared = Arc::new(PreparedBank::new(&bank));
    let render = |controls: &Controls, events: &[NoteEvent]| {
        let mut e = Engine::new(prepared.clone());
        e.prepare(48_000.0, 512);
        e.set_controls(controls);
        let (mut l, mut r) = (vec![0.0; 4800], vec![0.0; 4800]);
        e.process(events, None, &mut l, &mut r);
        l
    };
    let defaults = Controls::for_bank(&bank);
    let audition = Audition::Strike {
        x: 0.8,
        y: 0.3,
        velocity: 0.7,
    };
    let events: Vec<NoteEvent> = audition.events(60).collect();
    let heard = render(&defaults, &events);
    let at_point = Controls {
        strike_x: 0.8,
        strike_y: 0.3,
        ..defaults.clone()
    };
    let reference = render(&at_point, &[NoteEvent::on(0, 60, 0.7)]);
    assert!(heard.iter().any(|&s| s != 0.0));
    assert!(
        heard == reference,
        "the audition differs from a strike there"
    );
    let elsewhere = render(&defaults, &[NoteEvent::on(0, 60, 0.7)]);
    assert!(heard != elsewhere, "the pad position made no difference");
    let release: Vec<NoteEvent> = Audition::Release.events(60).collect();
    assert!(matches!(release[..], [NoteEvent::Off { note, .. }] if note.key == 60));
}

#[test]
fn dragging_a_stem_edits_the_mode_and_undo_restores_the_bank() {
    let bank = factory_bank("rosewood-marimba-bar").unwrap();
    let mut h = Harness::new(Some(&bank));
    let before = h.played();
    let generation = h.generation();
    let i = 2;
    let head = h.app.stem_head(i).unwrap();
    h.click(head);
    assert_eq!(h.app.selected_mode(), Some(i));

    // Up by 20 points: louder; Ctrl holds the frequency.
    let gain_before = h.app.session().bank().modes[i].gains.clone();
    h.drag(head, head - vec2(0.0, 20.0), 5, Modifiers::CTRL);
    let played = h.played();
    assert!(h.generation() > generation, "the edit reached the plugin");
    assert_eq!(played.modes[i].freq_hz, before.modes[i].freq_hz);
    // The gain axis spans MODE_VIEW_DB_SPAN over the plot's height.
    let db = 20.0 * (played.modes[i].gains[0] / gain_before[0]).log10();
    let expected_db = 20.0 * MODE_VIEW_DB_SPAN / h.app.layout().mode_view.height() as f64;
    assert!(
        (db - expected_db).abs() < 0.05 * expected_db,
        "dragging up 20 points: {db} dB, expected {expected_db} dB"
    );
    for m in (0..bank.modes.len()).filter(|&m| m != i) {
        assert_eq!(played.modes[m], before.modes[m], "mode {m} changed");
    }

    // Sideways with Ctrl: nothing moves; without: higher in frequency.
    let head = h.app.stem_head(i).unwrap();
    h.drag(head, head + vec2(40.0, 0.0), 4, Modifiers::CTRL);
    assert_eq!(h.played().modes[i].freq_hz, before.modes[i].freq_hz);
    h.drag(head, head + vec2(40.0, 0.0), 4, Modifiers::NONE);
    let moved = h.played().modes[i].freq_hz;
    assert!(moved > before.modes[i].freq_hz * 1.05, "frequency {moved}");

    // Two undo steps from the keyboard restore the bank; the plugin gets it back too.
    assert!(h.app.session().can_undo());
    for _ in 0..3 {
        h.frame(vec![Event::Key {
            key: Key::Z,
            physical_key: None,
            pressed: true,
            repeat: false,
            modifiers: Modifiers::COMMAND,
        }]);
    }
    h.settle();
    assert!(!h.app.session().can_undo());
    assert_eq!(h.app.session().bank(), &bank);
    assert_eq!(h.played(), before);
}

#[test]
fn a_bad_bank_file_shows_where_it_is_wrong_and_keeps_the_bank() {
    let mut h = Harness::new(None);
    let json_before = h.params.bank.json.read().unwrap().clone();
    let generation = h.generation();
    let path = h.dir.path().join("broken.json");
    let mut bank = factory_bank("bronze-bell").unwrap();
    bank.modes[3].decay_per_s = -1.0;
    std::fs::write(&path, bank_to_json(&bank)).unwrap();
    assert!(!h.load(&path));
    h.settle();
    let (message, is_error) = h.app.browser_message().unwrap();
    assert!(is_error);
    assert!(message.contains("broken.json"), "{message}");
    assert!(message.contains("modes[3].decay_per_s"), "{message}");
    assert_eq!(h.generation(), generation);
    assert_eq!(*h.params.bank.json.read().unwrap(), json_before);

    assert!(!h.load(Path::new("/no/such/bank.json")));
    let (message, _) = h.app.browser_message().unwrap();
    assert!(message.contains("/no/such/bank.json"), "{message}");
}

#[test]
fn loading_a_bank_file_plays_it_with_its_defaults() {
    let mut h = Harness::new(None);
    let bank = factory_bank("glass-plate").unwrap();
    let path = h.dir.path().join("glass.json");
    std::fs::write(&path, bank_to_json(&bank)).unwrap();
    assert!(h.load(&path));
    h.settle();
    assert_eq!(h.played(), bank);
    assert_eq!(h.app.stems_drawn(), bank.modes.len());
    let c = Controls::for_bank(&bank);
    assert!((h.params.strike.strike_x.value() - c.strike_x).abs() < 1e-3);
    assert!((h.params.strike.strike_y.value() - c.strike_y).abs() < 1e-3);
    assert!((h.params.strike.hardness.value() - c.hardness_ms).abs() < 0.01);
    assert!(h.gestures_balanced());
}

#[test]
fn mute_and_solo_shape_the_played_bank() {
    let bank = factory_bank("aluminium-vibraphone-bar").unwrap();
    let mut h = Harness::new(Some(&bank));
    let silent = |b: &Bank, m: usize| b.modes[m].gains.iter().all(|&g| g == 0.0);
    h.app.session_mut().toggle_mute(1);
    h.settle();
    let played = h.played();
    assert_eq!(played.modes.len(), bank.modes.len());
    assert!(silent(&played, 1));
    assert!(!silent(&played, 0));
    h.app.session_mut().toggle_solo(4);
    h.settle();
    let played = h.played();
    for m in 0..bank.modes.len() {
        assert_eq!(silent(&played, m), m != 4, "mode {m}");
    }
    h.app.session_mut().undo();
    h.app.session_mut().undo();
    h.settle();
    assert_eq!(h.played(), bank);
}

#[test]
fn save_as_writes_the_bank_heard() {
    let bank = factory_bank("bronze-bell").unwrap();
    let mut h = Harness::new(Some(&bank));
    h.app.session_mut().toggle_mute(0);
    h.settle();
    let path = h.app.save_as("My Bell").expect("saved");
    assert!(path.starts_with(h.app.user_dir().unwrap()));
    let saved = load_bank_file(&path).unwrap();
    assert_eq!(saved.name, "My Bell");
    assert_eq!(saved.modes.len(), bank.modes.len() - 1);
    assert_eq!(saved.modes[..], bank.modes[1..]);
    assert!(h.app.save_as("  ").is_none());
    assert!(
        h.app.browser_message().unwrap().1,
        "an empty name is refused"
    );
}

#[test]
fn a_bank_restored_by_the_host_replaces_the_one_shown() {
    let mut h = Harness::new(None);
    let bank = factory_bank("ideal-string").unwrap();
    h.params.bank.replace(bank_to_json(&bank));
    h.settle();
    assert_eq!(h.app.session().bank(), &bank);
    assert_eq!(h.app.stems_drawn(), bank.modes.len());
    // A broken saved bank leaves the one shown.
    h.params
        .bank
        .replace("{\"format\": \"modal-bank\"".to_string());
    h.settle();
    assert_eq!(h.app.session().bank(), &bank);
}

#[test]
fn the_mode_view_shows_live_and_truncated_modes_the_audio_thread_published() {
    let bank = factory_bank("steel-plate").unwrap();
    let mut h = Harness::new(Some(&bank));
    let mut engine = Engine::new(Arc::new(PreparedBank::new(&bank)));
    engine.prepare(48_000.0, 512);
    let mut c = Controls::for_bank(&bank);
    c.truncation_db = -60.0;
    engine.set_controls(&c);
    let (mut l, mut r) = (vec![0.0; 24_000], vec![0.0; 24_000]);
    engine.process(&[NoteEvent::on(0, 60, 1.0)], None, &mut l, &mut r);
    let stats = engine.stats();
    assert!(stats.voices == 1 && stats.live_modes > 0 && stats.live_modes < bank.modes.len());

    h.shared.publish(&engine, h.generation());
    h.settle();
    let reading = h.app.meter_reading();
    assert_eq!(reading.voices, 1);
    assert_eq!(reading.live_modes as usize, stats.live_modes);
    assert_eq!(reading.bank_modes as usize, bank.modes.len());
    let (live, truncated) = h.app.marks_drawn();
    assert_eq!(live, stats.live_modes, "one live level per sounding mode");
    assert_eq!(live + truncated, bank.modes.len(), "the others are marked");

    // Energies of another bank are not drawn over this one.
    h.shared.publish(&engine, h.generation() + 1);
    h.settle();
    assert_eq!(h.app.marks_drawn(), (0, 0));
}

#[test]
fn the_mode_view_draws_pruned_modes_hollow() {
    // A long note on a dense plate with pruning on: some modes are masked and switched off.
    let bank = factory_bank("steel-plate").unwrap();
    let mut h = Harness::new(Some(&bank));
    let mut engine = Engine::new(Arc::new(PreparedBank::new(&bank)));
    engine.prepare(48_000.0, 512);
    let mut c = Controls::for_bank(&bank);
    c.pruning = true;
    engine.set_controls(&c);
    let (mut l, mut r) = (vec![0.0; 24_000], vec![0.0; 24_000]);
    engine.process(&[NoteEvent::on(0, 60, 1.0)], None, &mut l, &mut r);
    let stats = engine.stats();
    assert!(stats.voices == 1 && stats.dormant_modes > 0, "{stats:?}");
    let mut switched_off = Vec::new();
    engine.visit_switched_off_modes(|m| switched_off.push(m));

    h.shared.publish(&engine, h.generation());
    h.settle();
    assert_eq!(
        h.app.meter_reading().pruned_modes as usize,
        stats.dormant_modes
    );
    let (live, _) = h.app.marks_drawn();
    assert_eq!(
        live, stats.live_modes,
        "pruned modes still show their level"
    );
    assert_eq!(
        h.app.pruned_drawn(),
        switched_off.len(),
        "one hollow level per mode switched off"
    );

    // Pruning off: every live level is computed again.
    c.pruning = false;
    engine.set_controls(&c);
    engine.process(&[], None, &mut l[..4_800], &mut r[..4_800]);
    assert_eq!(engine.stats().dormant_modes, 0);
    h.shared.publish(&engine, h.generation());
    h.settle();
    assert_eq!(h.app.pruned_drawn(), 0);
}

#[test]
fn meters_are_published_at_the_meter_interval() {
    let shared = EditorShared::new();
    let bank = factory_bank("rosewood-marimba-bar").unwrap();
    let mut engine = Engine::new(Arc::new(PreparedBank::new(&bank)));
    engine.prepare(48_000.0, 512);
    let rate = 48_000.0;
    let block = 256;
    let (mut l, mut r) = (vec![0.0; block], vec![0.0; block]);
    let seconds = 1.0;
    let blocks = (seconds * rate / block as f32) as usize;
    for b in 0..blocks {
        let events = if b == 0 {
            vec![NoteEvent::on(0, 60, 1.0)]
        } else {
            vec![]
        };
        engine.process(&events, None, &mut l, &mut r);
        let channels: [&mut [f32]; 2] = [&mut l, &mut r];
        shared.measure_block(
            Some(&engine),
            7,
            &channels,
            Duration::from_micros(500),
            rate,
        );
    }
    let expected = seconds / METER_INTERVAL_S;
    let published = shared.serial() as f32;
    assert!(
        (published - expected).abs() <= 2.0,
        "{published} publications in {seconds} s, expected about {expected}"
    );
    let reading = shared.take_reading();
    assert!(reading.peak > 0.05 && reading.peak < 1.0, "{reading:?}");
    let load = 500e-6 * rate / block as f32;
    assert!((reading.dsp_load - load).abs() < 1e-4, "{reading:?}");
    assert_eq!(
        shared.take_reading().peak,
        0.0,
        "the peak is taken by the reading"
    );
    let (mut energies, mut pruned) = (Vec::new(), Vec::new());
    assert!(shared.read_energies(7, &mut energies, &mut pruned));
    assert_eq!(energies.len(), bank.modes.len());
    assert!(!shared.read_energies(8, &mut energies, &mut pruned));
}

#[test]
fn the_window_opens_at_the_size_it_was_left_at() {
    // A fresh project: nothing to restore; the size the window has is recorded.
    let resizes = |h: &Harness| -> Vec<egui::ViewportCommand> {
        h.commands
            .iter()
            .filter(|c| matches!(c, egui::ViewportCommand::InnerSize(_)))
            .cloned()
            .collect()
    };
    let mut h = Harness::new(None);
    assert!(resizes(&h).is_empty(), "{:?}", h.commands);
    let default = (EDITOR_SIZE.0 as f32, EDITOR_SIZE.1 as f32);
    assert_eq!(*h.params.editor_size.read().unwrap(), Some(default));
    h.size = vec2(1000.0, 700.0);
    h.settle();
    assert_eq!(*h.params.editor_size.read().unwrap(), Some((1000.0, 700.0)));

    // A project saved with the window at 1000 x 700: the editor asks for that size on opening,
    // and records nothing until the host has applied it.
    let saved = h.params.editor_size.read().unwrap().unwrap();
    let mut h = Harness::with_size(None, saved);
    assert_eq!(
        resizes(&h),
        [egui::ViewportCommand::InnerSize(vec2(1000.0, 700.0))]
    );
    assert_eq!(*h.params.editor_size.read().unwrap(), Some(saved));
    h.size = vec2(1000.0, 700.0);
    h.settle();
    h.size = vec2(1300.0, 800.0);
    h.settle();
    assert_eq!(*h.params.editor_size.read().unwrap(), Some((1300.0, 800.0)));
}
