//! The engine's process call never allocates: a counting global allocator watches it through note
//! storms, control sweeps, audio input, re-strikes, stealing and resets.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use common::*;
use modal_resonator::dsp::ExciterKind;
use modal_resonator::engine::{
    ControlChange, Controls, Note, NoteEvent, NoteExpression, VoiceModulation, NUMERIC_CONTROLS,
};

struct Counting;

thread_local! {
    /// Allocations made on this thread while `WATCHING` is set.
    static COUNT: Cell<usize> = const { Cell::new(0) };
    static WATCHING: Cell<bool> = const { Cell::new(false) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if WATCHING.with(|w| w.get()) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if WATCHING.with(|w| w.get()) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if WATCHING.with(|w| w.get()) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Runs `f` and returns how many allocations and frees it made on this thread.
fn allocations_in(f: impl FnOnce()) -> usize {
    COUNT.with(|c| c.set(0));
    WATCHING.with(|w| w.set(true));
    f();
    WATCHING.with(|w| w.set(false));
    COUNT.with(|c| c.get())
}

/// A block of `len` samples of a rough, noise-like input in -0.5..0.5.
fn rough_input(len: usize) -> Vec<f32> {
    (0..len)
        .map(|i| ((i * 7919) % 101) as f32 / 101.0 - 0.5)
        .collect()
}

#[test]
fn process_never_allocates() {
    let bank = dense_bank(700, 55.0);
    let mut e = engine(&bank, 48_000.0);
    let block = 256;
    let (mut l, mut r) = (vec![0.0f32; block], vec![0.0f32; block]);
    let input = rough_input(block);
    // Controls for every block, built before watching.
    let sweeps: Vec<Controls> = (0..200)
        .map(|b| {
            let mut c = Controls::default();
            let t = b as f32 / 199.0;
            for spec in NUMERIC_CONTROLS {
                (spec.set)(
                    &mut c,
                    spec.min + (spec.max - spec.min) * ((t * 7.0 + spec.min.abs()) % 1.0),
                );
            }
            c.polyphony = 1 + b % 64;
            c.material_q = if b % 3 == 0 {
                None
            } else {
                Some(10.0 + 50.0 * b as f32)
            };
            c.exciter = ExciterKind::ALL[b % ExciterKind::ALL.len()];
            c
        })
        .collect();
    let storms: Vec<Vec<NoteEvent>> = (0..200)
        .map(|b| {
            (0..40)
                .map(|i| {
                    let time = ((i * 37 + b * 11) % block) as u32;
                    let note = Note {
                        key: ((i * 29 + b * 3) % 128) as u8,
                        channel: (i % 3) as u8,
                        id: Some(i as i32),
                    };
                    match i % 8 {
                        4 => NoteEvent::off(time, ((i * 13 + b) % 128) as u8),
                        5 if b % 2 == 0 => NoteEvent::Modulate {
                            time,
                            id: (i as i32) - 5,
                            modulation: match b % 4 {
                                0 => VoiceModulation::FineTuneCents(b as f32 - 100.0),
                                _ => VoiceModulation::ContactForce((b % 5) as f32 / 4.0),
                            },
                        },
                        5 => NoteEvent::Controller {
                            time,
                            change: match b % 3 {
                                0 => ControlChange::Bend((b % 7) as f32 / 3.0 - 1.0),
                                1 => ControlChange::ModWheel((b % 5) as f32 / 4.0),
                                _ => ControlChange::Pressure((b % 9) as f32 / 8.0),
                            },
                        },
                        6 => NoteEvent::ChannelExpression {
                            time,
                            channel: (i % 3) as u8,
                            expression: match b % 3 {
                                0 => NoteExpression::Tuning((b % 7) as f32 - 3.0),
                                1 => NoteExpression::Pressure((b % 5) as f32 / 4.0),
                                _ => NoteExpression::Slide((b % 9) as f32 / 8.0),
                            },
                        },
                        7 => NoteEvent::Choke { time, note },
                        _ => NoteEvent::On {
                            time,
                            note,
                            velocity: (i % 10) as f32 / 9.0,
                        },
                    }
                })
                .collect::<Vec<_>>()
        })
        .map(|mut v| {
            v.sort_by_key(|e| e.time());
            v
        })
        .collect();
    let mut ended = 0;
    let count = allocations_in(|| {
        for b in 0..200 {
            e.set_controls(&sweeps[b]);
            let input = (b % 2 == 0).then_some(&input[..]);
            e.process(&storms[b], input, &mut l, &mut r);
            // Ended notes are handed over without allocating.
            ended += e.take_ended_voices().count();
            if b == 100 {
                e.reset();
            }
        }
        e.process(
            &[
                NoteEvent::AllNotesOff { time: 0 },
                NoteEvent::AllSoundOff { time: 10 },
            ],
            None,
            &mut l,
            &mut r,
        );
    });
    assert_eq!(count, 0, "process allocated or freed {count} times");
    assert!(ended > 0, "no note ended");
    // The counter works: an allocation outside the engine is seen.
    let seen = allocations_in(|| drop(std::hint::black_box(vec![1u8; 10])));
    assert!(seen >= 1);
}

#[test]
fn pruning_and_the_budget_never_allocate() {
    let bank = dense_bank(700, 55.0);
    let mut e = engine(&bank, 48_000.0);
    let block = 256;
    let (mut l, mut r) = (vec![0.0f32; block], vec![0.0f32; block]);
    let input = rough_input(block);
    // Pruning on throughout, its settings moving; budgets fixed and automatic coming and going.
    let settings: Vec<Controls> = (0..300)
        .map(|b| {
            let mut c = e.controls().clone();
            c.pruning = b % 50 < 45;
            c.masking_offset_db = [2.5, 5.0, 10.0, 0.0][b / 20 % 4];
            c.playback_level_db_spl = 60.0 + (b % 7) as f32 * 8.0;
            c.analysis_frame_ms = [2.0, 20.0, 46.0][b / 30 % 3];
            c.mode_budget = [0, 40, 300][b / 25 % 3];
            c.target_load_pct = [0.0, 1.0, 20.0][b / 35 % 3];
            c.exciter = ExciterKind::ALL[b / 10 % ExciterKind::ALL.len()];
            c.output_gain_db = -((b % 5) as f32) * 3.0;
            c.size_ratio = 1.0 + (b % 9) as f32 * 0.01;
            c
        })
        .collect();
    let storms: Vec<Vec<NoteEvent>> = (0..300)
        .map(|b| {
            (0..6)
                .map(|i| {
                    NoteEvent::on(
                        ((i * 41 + b * 13) % block) as u32,
                        (30 + (b * 7 + i * 11) % 60) as u8,
                        ((b + i) % 10) as f32 / 9.0 + 0.05,
                    )
                })
                .collect::<Vec<_>>()
        })
        .map(|mut v| {
            v.sort_by_key(|e| e.time());
            v
        })
        .collect();
    let mut dormant = 0;
    let count = allocations_in(|| {
        for b in 0..300 {
            e.set_controls(&settings[b]);
            let events = if b % 3 == 0 { &storms[b][..] } else { &[] };
            let input = (b % 40 == 7).then_some(&input[..]);
            e.process(events, input, &mut l, &mut r);
            let _ = e.take_ended_voices().count();
            dormant += e.stats().dormant_modes;
            e.visit_switched_off_modes(|m| dormant += m.min(1));
            if b == 200 {
                e.reset();
            }
        }
    });
    assert_eq!(count, 0, "process allocated or freed {count} times");
    assert!(dormant > 0, "pruning never switched a mode off");
    assert!(
        e.pruning_stats().absorbed > 0,
        "no strike met a dormant mode"
    );
}

#[test]
fn a_scene_steps_without_allocating() {
    use modal_resonator::scene::{Scene, SceneSource};
    // Objects struck, scraped and simulated, heard binaurally, stepped in blocks of mixed sizes.
    let text = r#"{"format": "modal-scene", "version": 1,
        "objects": [
          {"name": "floor", "bank": "spruce-panel", "position": [0, -0.05, -1],
           "body": {"collider": {"cuboid": {"half_extents_m": [1, 0.05, 1]}}}},
          {"name": "ball", "position": [0, 0.5, -1],
           "body": {"dynamic": true, "collider": {"ball": {"radius_m": 0.02}}}},
          {"name": "bar", "bank": "steel-free-free-bar", "position": [-1, 0, -1]}],
        "events": [
          {"time_s": 0.01, "object": "bar", "impact": {"speed_m_per_s": 1}},
          {"time_s": 0.02, "object": "bar", "impact": {"speed_m_per_s": 2}},
          {"time_s": 0.1, "object": "floor",
           "contact": {"duration_s": 0.5, "speed_m_per_s": [0.2, 1], "force": [0.5, 0.5]}}],
        "physics": {"duration_s": 1.5},
        "listener": {"position": [0, 1, 0], "output": "binaural"}}"#;
    let source = SceneSource::from_str(text, "test", std::path::Path::new(".")).unwrap();
    assert!(source.events().len() > 4, "the ball strikes the floor");
    let mut scene = Scene::new(&source, 48_000, 512);
    let (mut l, mut r) = (vec![0.0f32; 512], vec![0.0f32; 512]);
    let mut heard = 0.0f32;
    let count = allocations_in(|| {
        for k in 0..200 {
            let n = [512, 64, 1, 300][k % 4];
            scene.process(&mut l[..n], &mut r[..n]);
            heard = heard.max(l[..n].iter().fold(0.0, |a, v| a.max(v.abs())));
        }
    });
    assert!(heard > 0.0);
    assert_eq!(count, 0, "the scene allocated {count} times while playing");
}
