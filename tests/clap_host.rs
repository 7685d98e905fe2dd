//! The built `.clap` bundle in a real CLAP host (clack-host): descriptors, notes in, pitch and
//! level out, the exciter input, the effect, and a state round trip with a bank in it.
//!
//! Needs the bundle: `cargo xtask bundle modal-resonator --release` (the README's test command
//! builds it first).

mod common;

use clack_host::events::event_types::NoteExpressionType;
use clack_host::prelude::*;
use common::clap::*;
use common::{magnitude_at, peak, pitch_hz, spectral_peak_hz};
use modal_resonator::bank::{Bank, Mode, Position};
use modal_resonator::units::gain_to_db;

#[test]
fn the_bundle_offers_the_instrument_and_the_effect() {
    let factory = entry(Build::Release).get_plugin_factory().unwrap();
    let found: Vec<(String, Vec<String>)> = factory
        .plugin_descriptors()
        .map(|d| {
            let id = d.id().unwrap().to_string_lossy().into_owned();
            (
                id,
                d.features()
                    .map(|f| f.to_string_lossy().into_owned())
                    .collect(),
            )
        })
        .collect();
    let features = |id: &str| {
        found
            .iter()
            .find(|(i, _)| i == id)
            .map(|(_, f)| f.clone())
            .unwrap_or_default()
    };
    assert!(
        features("org.modal-resonator.instrument").contains(&"instrument".to_string()),
        "{found:?}"
    );
    assert!(
        features("org.modal-resonator.effect").contains(&"audio-effect".to_string()),
        "{found:?}"
    );
}

#[test]
fn notes_sound_at_their_pitch_and_level_on_their_sample() {
    // The default bank (a marimba bar rooted at C4) played at A4.
    let s = session(
        INSTRUMENT,
        None,
        &[(1_000, Send::On(69, 1.0))],
        None,
        48_000,
    );
    let first = s.left.iter().position(|&v| v != 0.0).expect("sound");
    assert_eq!(
        first, 1_001,
        "the note starts on its own sample (sounding from the next)"
    );
    let level = peak(&s.left).max(peak(&s.right));
    assert!(level > 0.06 && level < 1.0, "peak {level}");
    let got = pitch_hz(&s.left[1_100..], RATE, 300.0, 600.0);
    assert!((got / 440.0 - 1.0).abs() < 0.005, "A4 played at {got} Hz");
    assert!(s.left.iter().chain(&s.right).all(|v| v.is_finite()));

    // With full release damping, a note-off silences the note within 100 ms.
    let events = [
        (0, Send::Param("reldmp", 1.0)),
        (1_000, Send::On(69, 1.0)),
        (12_000, Send::Off(69)),
    ];
    let s = session(INSTRUMENT, None, &events, None, 24_000);
    assert!(
        peak(&s.left[6_000..12_000]) > 0.01,
        "sounding before the note-off"
    );
    assert!(
        peak(&s.left[16_800..]) < 1e-3,
        "still sounding 100 ms after the note-off: {}",
        peak(&s.left[16_800..])
    );
}

#[test]
fn state_round_trips_with_the_bank_in_it() {
    // Save a state, put a one-mode bank at 1 kHz into it, and play it in a fresh instance.
    let first = session(INSTRUMENT, None, &[], None, BLOCK);
    let bytes = with_bank(&first.state, &sine_bank(1_000.0));
    // Root 1 kHz is key 83.21: its nearest key, B5 (83), plays the bank at 1 kHz.
    let s = session(
        INSTRUMENT,
        Some(&bytes),
        &[(0, Send::On(83, 1.0))],
        None,
        24_000,
    );
    let want = 1_000.0;
    let got = pitch_hz(&s.left[10..], RATE, 700.0, 1_400.0);
    assert!(
        (got / want - 1.0).abs() < 0.003,
        "restored bank plays {got} Hz, want {want}"
    );
    // Saving again keeps the bank and every parameter.
    let again: serde_json::Value = serde_json::from_slice(&s.state[8..]).unwrap();
    let loaded: serde_json::Value = serde_json::from_slice(&bytes[8..]).unwrap();
    assert_eq!(again["fields"]["bank"], loaded["fields"]["bank"]);
    assert_eq!(again["params"], loaded["params"]);
}

#[test]
fn a_bank_loaded_while_playing_takes_over_without_a_gap() {
    let first = session(INSTRUMENT, None, &[], None, BLOCK);
    let bytes = with_bank(&first.state, &sine_bank(1_000.0));
    // Notes on A4 every 0.1 s; the 1 kHz bank arrives at 0.5 s.
    let notes: Vec<(usize, Send)> = (0..20).map(|i| (i * 4_800, Send::On(69, 1.0))).collect();
    let s = run(&Script {
        events: &notes,
        swap: Some((24_000, &bytes)),
        ..Script::new(INSTRUMENT, 96_000)
    });
    let before = pitch_hz(&s.left[4_900..9_500], RATE, 300.0, 600.0);
    assert!(
        (before / 440.0 - 1.0).abs() < 0.005,
        "before the swap: {before} Hz"
    );
    // By the last note the new bank plays: key 69 on a bank rooted at 1 kHz, whose nearest key
    // (83) plays it there.
    let want = 1_000.0 * 2f64.powf((69.0 - 83.0) / 12.0);
    let after = pitch_hz(&s.left[91_300..95_900], RATE, 300.0, 600.0);
    assert!(
        (after / want - 1.0).abs() < 0.005,
        "after the swap: {after} Hz, want {want}"
    );
    // Every note still sounded: no block of silence while the new bank was built.
    for i in 0..20 {
        let note = &s.left[i * 4_800 + 10..i * 4_800 + 2_000];
        assert!(peak(note) > 0.01, "note {i} is silent");
    }
}

/// The parameter ids of the plugins, as in `src/params.rs`.
const PARAM_IDS: &[&str] = &[
    "mat", "q", "tilt", "size", "keytrk", "fine", "bendrg", "posx", "posy", "posvar", "strvar",
    "exc", "hard", "velsns", "velhrd", "rough", "radius", "cspeed", "cforce", "reldmp", "trunc",
    "poly", "width", "gain", "inmode", "ingain", "trigth", "retrig", "mix", "modwhl", "press",
    "mpe", "mpebnd", "prune", "maskav", "spl", "prfrm", "budget", "load", "bypass",
];

#[test]
fn process_never_allocates_through_storms_sweeps_and_bank_swaps() {
    // The debug bundle built with assert_process_allocs aborts the whole process on any
    // allocation or free inside `process`: surviving this session is the proof.
    let notes_per_block = 48;
    let blocks = 160;
    let mut events = Vec::new();
    for b in 0..blocks {
        let t0 = b * BLOCK;
        for i in 0..notes_per_block {
            let key = ((b * 7 + i * 13) % 88 + 21) as u16;
            let t = t0 + (i * 5) % BLOCK;
            events.push((
                t,
                if i % 4 == 3 {
                    Send::Off(key)
                } else {
                    Send::On(key, (i % 10) as f64 / 9.0 + 0.05)
                },
            ));
        }
        for (k, id) in PARAM_IDS.iter().enumerate() {
            // Sweep each parameter through its range, enums through their first entries.
            let phase = ((b + k * 5) % 40) as f64 / 39.0;
            let value = match *id {
                "mat" => ((b + k) % 7) as f64,
                // Every exciter, contacts included.
                "exc" => ((b + k) % 6) as f64,
                "inmode" => ((b + k) % 3) as f64,
                "modwhl" | "press" => ((b + k) % 5) as f64,
                _ => phase,
            };
            events.push((t0 + (k * 3) % BLOCK, Send::Param(id, value)));
        }
        // Notes with ids on MPE channels, their polyphonic modulation, member-channel bends and
        // pressure, and the mod wheel.
        for i in 0..8 {
            let t = t0 + (i * 31) % BLOCK;
            let id = (b * 8 + i) as u32;
            let channel = (i % 4) as u16;
            events.push((t, Send::NoteOn((30 + i * 9) as u16, channel, id, 0.8)));
            let param = ["fine", "size", "posx", "posy", "hard", "cspeed", "cforce"][i % 7];
            events.push((t, Send::Mod(param, id, (i as f64 - 4.0) / 8.0)));
            let byte = ((b * 5 + i * 17) % 128) as u8;
            events.push((t + 1, Send::Midi([0xE0 | channel as u8, byte, byte])));
            events.push((t + 2, Send::Midi([0xD0 | channel as u8, byte, 0])));
            events.push((t + 3, Send::Midi([0xB0, 1, byte])));
            // Slide, polyphonic pressure and the sustain pedal.
            events.push((t + 4, Send::Midi([0xB0 | channel as u8, 74, byte])));
            events.push((
                t + 5,
                Send::Midi([0xA0 | channel as u8, 30 + i as u8 * 9, byte]),
            ));
            events.push((t + 6, Send::Midi([0xB0 | channel as u8, 64, byte])));
        }
    }
    events.sort_by_key(|(t, _)| *t);
    let first = run(&Script {
        build: Build::AllocCheck,
        ..Script::new(INSTRUMENT, BLOCK)
    });
    let bytes = with_bank(&first.state, &sine_bank(700.0));
    let noise: Vec<f32> = (0..blocks * BLOCK)
        .map(|i| ((i * 7_919) % 1_000) as f32 / 4_000.0 - 0.125)
        .collect();
    let input = [noise.clone(), noise];
    let s = run(&Script {
        build: Build::AllocCheck,
        events: &events,
        input: Some(&input),
        swap: Some((blocks * BLOCK / 2, &bytes)),
        // Blocks of varying size. (Blocks beyond the announced maximum are a host error that
        // nice-plug answers by growing its own buffers, so they are left out here.)
        blocks: &[BLOCK, 100, 1, 37],
        ..Script::new(INSTRUMENT, blocks * BLOCK)
    });
    assert_eq!(s.left.len(), blocks * BLOCK);
    assert!(s.left.iter().chain(&s.right).all(|v| v.is_finite()));
    assert!(peak(&s.left) > 0.0);
}

#[test]
fn a_broken_bank_in_the_state_keeps_a_bank_playing() {
    let first = session(INSTRUMENT, None, &[], None, BLOCK);
    let mut state: serde_json::Value = serde_json::from_slice(&first.state[8..]).unwrap();
    state["fields"]["bank"] = serde_json::Value::String(
        serde_json::to_string("{\"format\": \"modal-bank\", \"version\": 7}").unwrap(),
    );
    let text = serde_json::to_string(&state).unwrap();
    let mut bytes = (text.len() as u64).to_le_bytes().to_vec();
    bytes.extend_from_slice(text.as_bytes());
    let s = session(
        INSTRUMENT,
        Some(&bytes),
        &[(0, Send::On(60, 1.0))],
        None,
        12_000,
    );
    assert!(
        peak(&s.left) > 0.1,
        "the instrument went silent on a broken bank"
    );
}

#[test]
fn the_exciter_input_drives_the_modes_in_direct_mode() {
    // A click train into the "Exciter" port, input mode "direct" (enum index 1).
    let clicks: Vec<f32> = (0..24_000)
        .map(|i| if i % 4_800 == 100 { 0.5 } else { 0.0 })
        .collect();
    let input = [clicks.clone(), clicks];
    let off = session(INSTRUMENT, None, &[], Some(&input), 24_000);
    assert_eq!(peak(&off.left), 0.0, "input mode off ignores the exciter");
    let direct = session(
        INSTRUMENT,
        None,
        &[(0, Send::Param("inmode", 1.0))],
        Some(&input),
        24_000,
    );
    assert!(
        peak(&direct.left) > 0.01,
        "the exciter did not ring the object: {}",
        peak(&direct.left)
    );
}

#[test]
fn the_effect_rings_its_input_and_mixes_it_dry() {
    let mut seed = 7u32;
    let noise: Vec<f32> = (0..24_000)
        .map(|i| {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            if i < 2_400 {
                (seed as f32 / u32::MAX as f32 - 0.5) * 0.5
            } else {
                0.0
            }
        })
        .collect();
    let input = [noise.clone(), noise.clone()];
    // Fully dry: the input passes unchanged.
    let dry = session(
        EFFECT,
        None,
        &[(0, Send::Param("mix", 0.0))],
        Some(&input),
        24_000,
    );
    for (i, (a, b)) in dry.left.iter().zip(&noise).enumerate() {
        assert!((a - b).abs() < 1e-6, "dry sample {i}: {a} vs {b}");
    }
    // Fully wet: the resonators ring on after the noise stops.
    let wet = session(
        EFFECT,
        None,
        &[(0, Send::Param("mix", 1.0))],
        Some(&input),
        24_000,
    );
    assert!(
        peak(&wet.left[4_800..]) > 1e-3,
        "no ringing after the input: {}",
        peak(&wet.left[4_800..])
    );
}

#[test]
fn any_rate_and_any_block_size_give_the_same_note() {
    // Blocks from 1 to 8192 samples at 44.1 and 192 kHz: the note keeps its pitch and timing,
    // and the output does not depend on how the host cuts the stream.
    for rate in [44_100.0, 192_000.0] {
        let samples = (rate * 0.5) as usize;
        let at = (rate * 0.1) as usize;
        let events = [(at, Send::On(69, 1.0))];
        let steady = run(&Script {
            rate,
            events: &events,
            blocks: &[512],
            ..Script::new(INSTRUMENT, samples)
        });
        let varied = run(&Script {
            rate,
            events: &events,
            blocks: &[1, 8192, 7, 64, 333, 4096],
            ..Script::new(INSTRUMENT, samples)
        });
        assert!(
            steady.left == varied.left,
            "{rate} Hz: block sizes changed the output"
        );
        assert_eq!(
            varied.left.iter().position(|&v| v != 0.0),
            Some(at + 1),
            "{rate} Hz: note timing"
        );
        let got = pitch_hz(&varied.left[at + 10..], rate, 300.0, 600.0);
        assert!(
            (got / 440.0 - 1.0).abs() < 0.005,
            "{rate} Hz: A4 at {got} Hz"
        );
    }
}

#[test]
fn the_plugins_play_at_any_rate_a_host_asks() {
    // The extremes the validators try: the note plays in tune where it lies below Nyquist, and
    // every sample is a finite, sensible level; the effect rings its input.
    for rate in [1_234.567_8, 1_234_567.8] {
        let samples = (rate * 0.5) as usize;
        let at = (rate * 0.1) as usize;
        let note = run(&Script {
            rate,
            events: &[(at, Send::On(69, 1.0))],
            blocks: &[256, 1, 1_000],
            ..Script::new(INSTRUMENT, samples)
        });
        for channel in [&note.left, &note.right] {
            assert!(
                channel.iter().all(|v| v.is_finite() && v.abs() < 4.0),
                "{rate} Hz: output out of range"
            );
        }
        assert!(peak(&note.left[at..]) > 0.01, "{rate} Hz: no note");
        // Under three samples a period at the lowest rate: the spectrum's peak, not the period.
        let got = spectral_peak_hz(
            &note.left[at..at + (rate * 0.2) as usize],
            rate,
            300.0,
            600.0,
        );
        assert!(
            (got / 440.0 - 1.0).abs() < 0.005,
            "{rate} Hz: A4 at {got} Hz"
        );
        let click: Vec<f32> = (0..samples)
            .map(|i| if i == at { 0.5 } else { 0.0 })
            .collect();
        let input = [click.clone(), click];
        let rung = run(&Script {
            rate,
            events: &[(0, Send::Param("mix", 1.0))],
            input: Some(&input),
            ..Script::new(EFFECT, samples)
        });
        assert!(
            rung.left.iter().all(|v| v.is_finite() && v.abs() < 4.0),
            "{rate} Hz: effect output out of range"
        );
        assert!(
            peak(&rung.left[at + (rate * 0.05) as usize..]) > 1e-4,
            "{rate} Hz: the effect does not ring"
        );
    }
}

#[test]
fn no_subnormal_sample_leaves_either_plugin_whatever_the_host_does() {
    // Randomised parameters, rates, block sizes and notes, with subnormal input on the input
    // port between bursts of noise: every output sample is finite and not subnormal.
    let mut rng = modal_resonator::rng::Rng::new(0x9e37_79b9);
    let mut next = move || rng.next_u32() as f64 / u32::MAX as f64;
    let rates = [
        1_234.567_8,
        11_025.0,
        44_100.0,
        48_000.0,
        96_000.0,
        384_000.0,
        1_234_567.8,
    ];
    for case in 0..16 {
        let plugin = if case % 2 == 0 { INSTRUMENT } else { EFFECT };
        let rate = rates[(next() * rates.len() as f64) as usize % rates.len()];
        let samples = (rate * 0.4) as usize;
        let blocks: Vec<usize> = (0..3).map(|_| 1 + (next() * 700.0) as usize).collect();
        let mut events = Vec::new();
        for at in [0, samples / 2] {
            for &id in PARAM_IDS {
                // Continuous parameters normalised, enums by index.
                let value = match id {
                    "mat" => (next() * 7.0).floor(),
                    "exc" | "inmode" | "modwhl" | "press" => (next() * 3.0).floor(),
                    _ => next(),
                };
                events.push((at, Send::Param(id, value)));
            }
        }
        for _ in 0..6 {
            let at = (next() * samples as f64) as usize;
            events.push((at, Send::On(30 + (next() * 70.0) as u16, next())));
        }
        events.sort_by_key(|e| e.0);
        let input: Vec<f32> = (0..samples)
            .map(|i| {
                let v = next() as f32 - 0.5;
                match (i * 8 / samples) % 4 {
                    0 => v * 2e-38,
                    1 => v * 0.5,
                    2 => 0.0,
                    _ => f32::from_bits(1 + (next() * 1000.0) as u32) * v.signum(),
                }
            })
            .collect();
        let input = [input.clone(), input];
        let out = run(&Script {
            rate,
            events: &events,
            input: Some(&input),
            blocks: &blocks,
            ..Script::new(plugin, samples)
        });
        for (channel, name) in [(&out.left, "left"), (&out.right, "right")] {
            if let Some(i) = channel
                .iter()
                .position(|v| v.is_subnormal() || !v.is_finite())
            {
                panic!(
                    "case {case} ({plugin:?} at {rate} Hz, blocks {blocks:?}): {name} sample {i} \
                     is {:e}",
                    channel[i]
                );
            }
        }
    }
}

#[test]
fn the_bypass_fades_to_the_dry_input_or_to_silence_and_back() {
    // Parameters change at the start of the host's block that holds the change.
    let fade = (0.01 * RATE) as usize;
    let block_start = |at: usize| at / BLOCK * BLOCK;
    // The effect, wet, bypassed at 0.1 s: from the end of the fade its output is its input.
    let noise: Vec<f32> = (0..24_000)
        .map(|i| (i as f32 * 0.731).sin() * 0.3 + (i as f32 * 0.117).cos() * 0.2)
        .collect();
    let input = [noise.clone(), noise.clone()];
    let at = 4_800;
    let fx = run(&Script {
        events: &[
            (0, Send::Param("mix", 1.0)),
            (at, Send::Param("bypass", 1.0)),
        ],
        input: Some(&input),
        ..Script::new(EFFECT, 24_000)
    });
    assert!(
        fx.left[..block_start(at)]
            .iter()
            .zip(&noise)
            .any(|(a, b)| (a - b).abs() > 0.01),
        "the wet effect already passes its input"
    );
    let from = block_start(at) + fade;
    for (i, (got, want)) in fx.left.iter().zip(&noise).enumerate().skip(from) {
        assert!(
            (got - want).abs() < 1e-6,
            "bypassed sample {i}: {got} vs {want}"
        );
    }
    // The instrument: a ringing note bypassed at 0.2 s falls silent without a click, and
    // sounds again when the bypass is lifted at 0.3 s.
    let (on, off) = (block_start(9_600), block_start(14_400));
    let inst = run(&Script {
        events: &[
            (0, Send::On(69, 1.0)),
            (on, Send::Param("bypass", 1.0)),
            (off, Send::Param("bypass", 0.0)),
        ],
        ..Script::new(INSTRUMENT, 24_000)
    });
    let l = &inst.left;
    assert!(peak(&l[on - 480..on]) > 0.01, "no note before the bypass");
    assert!(
        l[on + fade..off].iter().all(|&v| v == 0.0),
        "the bypassed instrument still sounds"
    );
    assert!(peak(&l[off + fade..]) > 0.005, "no sound after the bypass");
    // No step larger than the note's own: the fade does not click.
    let step = |x: &[f32]| {
        x.windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f32::max)
    };
    let ringing = step(&l[on - 480..on]);
    assert!(
        step(&l[on - 1..on + fade + 1]) <= ringing,
        "the fade out clicks"
    );
    assert!(
        step(&l[off - 1..off + fade + 1]) <= ringing,
        "the fade in clicks"
    );
    // It fades rather than cuts: halfway through, the note is neither whole nor gone.
    let half = peak(&l[on + fade / 2 - 50..on + fade / 2 + 50]);
    assert!(
        half > 0.1 * peak(&l[on - 100..on]) && half < 0.9 * peak(&l[on - 100..on]),
        "no fade: {half}"
    );
}

#[test]
fn taps_on_the_exciter_strike_in_trigger_mode() {
    // Three taps into the exciter input, input mode "trigger" (enum index 2).
    let taps: Vec<f32> = (0..48_000)
        .map(|i| {
            let t = i % 16_000;
            if (4_000..4_400).contains(&t) {
                let sign = if t % 2 == 0 { 1.0 } else { -1.0 };
                0.6 * (-((t - 4_000) as f32) / 60.0).exp() * sign
            } else {
                0.0
            }
        })
        .collect();
    let input = [taps.clone(), taps];
    let s = run(&Script {
        events: &[(0, Send::Param("inmode", 2.0))],
        input: Some(&input),
        ..Script::new(INSTRUMENT, 48_000)
    });
    assert_eq!(peak(&s.left[..4_000]), 0.0, "nothing before the first tap");
    for k in 0..3 {
        let start = k * 16_000 + 4_000;
        assert!(
            peak(&s.left[start..start + 4_000]) > 0.01,
            "tap {k} did not strike"
        );
    }
}

#[test]
fn all_sound_off_silences_at_once() {
    // MIDI CC 120 (all sound off) through the host: silence right after it.
    let s = run(&Script {
        events: &[(0, Send::On(60, 1.0)), (12_000, Send::Midi([0xB0, 120, 0]))],
        ..Script::new(INSTRUMENT, 24_000)
    });
    assert!(peak(&s.left[..12_000]) > 0.05);
    assert_eq!(peak(&s.left[12_001..]), 0.0, "sound after CC 120");
}

#[test]
fn silence_in_gives_silence_out_and_the_plugin_says_it_is_idle() {
    // A note damped on release: busy while it sounds, idle (may sleep) once it is gone.
    let events = [
        (0, Send::Param("reldmp", 1.0)),
        (0, Send::On(60, 1.0)),
        (4_800, Send::Off(60)),
    ];
    let s = run(&Script {
        events: &events,
        ..Script::new(INSTRUMENT, 48_000)
    });
    assert_eq!(
        s.statuses[1],
        ProcessStatus::Continue,
        "sounding: keep processing"
    );
    let last = *s.statuses.last().unwrap();
    assert_eq!(
        last,
        ProcessStatus::ContinueIfNotQuiet,
        "after the tail the plugin must report it is idle"
    );
    assert_eq!(
        peak(&s.left[40_000..]),
        0.0,
        "silence once the note has gone"
    );
    // The effect with silent input: silent output, idle from the start.
    let silent = [vec![0.0f32; 24_000], vec![0.0f32; 24_000]];
    let fx = run(&Script {
        input: Some(&silent),
        ..Script::new(EFFECT, 24_000)
    });
    assert_eq!(peak(&fx.left), 0.0);
    assert!(fx
        .statuses
        .iter()
        .all(|st| *st == ProcessStatus::ContinueIfNotQuiet));
}

#[test]
fn all_notes_off_releases_every_note() {
    // MIDI CC 123 with full release damping: the chord dies within 100 ms of it.
    let events = [
        (0, Send::Param("reldmp", 1.0)),
        (0, Send::On(60, 1.0)),
        (0, Send::On(64, 1.0)),
        (0, Send::On(67, 1.0)),
        (12_000, Send::Midi([0xB0, 123, 0])),
    ];
    let s = run(&Script {
        events: &events,
        ..Script::new(INSTRUMENT, 24_000)
    });
    assert!(
        peak(&s.left[6_000..12_000]) > 0.01,
        "the chord sounds before CC 123"
    );
    assert!(
        peak(&s.left[16_800..]) < 1e-3,
        "still sounding 100 ms after CC 123: {}",
        peak(&s.left[16_800..])
    );
}

#[test]
fn clap_note_expressions_retune_and_damp_one_note() {
    let tuned = run(&Script {
        events: &[
            (0, Send::On(69, 1.0)),
            (0, Send::Expression(NoteExpressionType::Tuning, 69, 2.0)),
        ],
        ..Script::new(INSTRUMENT, 24_000)
    });
    let got = pitch_hz(&tuned.left[2_400..], RATE, 300.0, 700.0);
    let want = 440.0 * 2f64.powf(2.0 / 12.0);
    assert!(
        (got / want - 1.0).abs() < 0.005,
        "tuning expression: {got} Hz, want {want}"
    );
    let plain = run(&Script {
        events: &[(0, Send::On(69, 1.0))],
        ..Script::new(INSTRUMENT, 24_000)
    });
    let pressed = run(&Script {
        events: &[
            (0, Send::On(69, 1.0)),
            (0, Send::Expression(NoteExpressionType::Pressure, 69, 1.0)),
        ],
        ..Script::new(INSTRUMENT, 24_000)
    });
    assert!(
        peak(&pressed.left[12_000..]) < 0.5 * peak(&plain.left[12_000..]),
        "pressure expression did not damp"
    );
}

/// A bank of two modes rooted at A4, each struck at one of two positions alone: 440 Hz at the
/// first, 1320 Hz at the second.
fn two_position_bank() -> Bank {
    let mut bank = Bank::new(
        "two positions",
        vec![
            Position {
                name: "end".into(),
                coords: vec![0.0],
            },
            Position {
                name: "middle".into(),
                coords: vec![0.5],
            },
        ],
    );
    bank.modes = vec![
        Mode {
            freq_hz: 440.0,
            decay_per_s: 3.0,
            gains: vec![1.0, 0.0],
        },
        Mode {
            freq_hz: 1_320.0,
            decay_per_s: 3.0,
            gains: vec![0.0, 1.0],
        },
    ];
    bank.root_hz = Some(440.0);
    bank
}

/// A state holding `bank`.
fn state_with(bank: &Bank) -> Vec<u8> {
    let first = session(INSTRUMENT, None, &[], None, BLOCK);
    with_bank(&first.state, bank)
}

#[test]
fn polyphonic_modulation_shapes_one_note_and_the_host_hears_when_it_ends() {
    let state = state_with(&sine_bank(440.0));
    // Two notes with ids; the first is tuned up 100 cents (fine tune spans -100..100 cents, so
    // +0.5 normalised) from its first sample, the second is left alone.
    let s = run(&Script {
        state: Some(&state),
        events: &[
            (0, Send::Param("reldmp", 1.0)),
            (100, Send::NoteOn(69, 0, 1, 1.0)),
            (100, Send::Mod("fine", 1, 0.5)),
            (100, Send::NoteOn(57, 0, 2, 1.0)),
            (12_000, Send::Off(69)),
            (12_000, Send::Off(57)),
        ],
        ..Script::new(INSTRUMENT, 36_000)
    });
    let ringing = &s.left[200..12_000];
    let up = 440.0 * 2f64.powf(1.0 / 12.0);
    let got = spectral_peak_hz(ringing, RATE, 400.0, 600.0);
    assert!(
        (got / up - 1.0).abs() < 0.002,
        "modulated note at {got} Hz, want {up}"
    );
    let other = spectral_peak_hz(ringing, RATE, 150.0, 300.0);
    assert!(
        (other / 220.0 - 1.0).abs() < 0.002,
        "other note at {other} Hz"
    );
    assert!(
        magnitude_at(ringing, RATE, 440.0) < 0.1 * magnitude_at(ringing, RATE, up),
        "the modulated note also sounds unmodulated"
    );
    // Both notes die after their note-offs (full release damping): the host hears of each,
    // with its id, key and channel.
    let mut ends: Vec<_> = s
        .note_ends
        .iter()
        .map(|&(_, id, key, ch)| (id, key, ch))
        .collect();
    ends.sort();
    assert_eq!(ends, vec![(1, 69, 0), (2, 57, 0)], "{:?}", s.note_ends);
    for &(t, ..) in &s.note_ends {
        assert!(
            (12_000..36_000).contains(&t),
            "ended at {t}: {:?}",
            s.note_ends
        );
    }

    // Modulating the strike position with the note-on strikes at the modulated point: the
    // middle position alone has the 1320 Hz mode. The bank's positions run from an end to the
    // middle, so the position is a place along the whole bar: +0.5 moves from the end to the middle.
    let state = state_with(&two_position_bank());
    let strike = |modulate: bool| {
        let mut events = vec![
            (0, Send::Param("posx", 0.0)),
            (100, Send::NoteOn(69, 0, 7, 1.0)),
        ];
        if modulate {
            events.push((100, Send::Mod("posx", 7, 0.5)));
        }
        let s = run(&Script {
            state: Some(&state),
            events: &events,
            ..Script::new(INSTRUMENT, 12_000)
        });
        let x = &s.left[200..];
        (magnitude_at(x, RATE, 440.0), magnitude_at(x, RATE, 1_320.0))
    };
    let (low, high) = strike(false);
    assert!(
        high < 1e-2 * low,
        "unmodulated: {low} at 440 Hz, {high} at 1320 Hz"
    );
    let (low, high) = strike(true);
    assert!(
        low < 1e-2 * high,
        "modulated: {low} at 440 Hz, {high} at 1320 Hz"
    );
}

#[test]
fn mpe_member_channels_bend_their_own_notes() {
    let state = state_with(&sine_bank(440.0));
    // MPE on (bend range 48 semitones). Channel 2 bends up 12 semitones before its note starts;
    // channel 3 plays a fifth below without a bend. A14-bit bend of 10240 is +0.25 of the range.
    let events = [
        (0, Send::Param("mpe", 1.0)),
        (50, Send::Midi([0xE1, 0x00, 0x50])),
        (100, Send::Midi([0x91, 69, 127])),
        (100, Send::Midi([0x92, 62, 127])),
    ];
    let s = run(&Script {
        state: Some(&state),
        events: &events,
        ..Script::new(INSTRUMENT, 12_000)
    });
    let x = &s.left[200..];
    let bent = spectral_peak_hz(x, RATE, 700.0, 1_100.0);
    assert!((bent / 880.0 - 1.0).abs() < 0.002, "bent note at {bent} Hz");
    let plain = spectral_peak_hz(x, RATE, 250.0, 400.0);
    let want = 440.0 * 2f64.powf(-7.0 / 12.0);
    assert!(
        (plain / want - 1.0).abs() < 0.002,
        "other channel at {plain} Hz"
    );
    assert!(
        magnitude_at(x, RATE, 440.0) < 0.05 * magnitude_at(x, RATE, 880.0),
        "the bent note glided from its unbent pitch"
    );

    // Without MPE the same bend acts on every note, by the global range (2 semitones).
    let s = run(&Script {
        state: Some(&state),
        events: &events[1..],
        ..Script::new(INSTRUMENT, 12_000)
    });
    let x = &s.left[2_000..];
    let got = spectral_peak_hz(x, RATE, 400.0, 600.0);
    let want = 440.0 * 2f64.powf(0.5 / 12.0);
    assert!(
        (got / want - 1.0).abs() < 0.002,
        "global bend: {got} Hz, want {want}"
    );
}

#[test]
fn a_bend_acts_from_its_sample_whatever_the_block_size() {
    // A full bend up at sample 3000, inside a 4096-sample block: the output equals the one
    // rendered in 64-sample blocks, and the pitch before the bend is the unbent one.
    let events = [
        (0, Send::On(69, 1.0)),
        (3_000, Send::Midi([0xE0, 0x7F, 0x7F])),
    ];
    let render = |blocks: &'static [usize]| {
        run(&Script {
            events: &events,
            blocks,
            ..Script::new(INSTRUMENT, 8_192)
        })
    };
    let (long, short) = (render(&[4_096]), render(&[64]));
    assert!(
        long.left == short.left,
        "a 4096-sample block differs from 64-sample blocks"
    );
    let before = pitch_hz(&long.left[200..2_900], RATE, 400.0, 600.0);
    assert!(
        (before / 440.0 - 1.0).abs() < 0.005,
        "before the bend: {before} Hz"
    );
    let after = pitch_hz(&long.left[4_000..8_192], RATE, 400.0, 600.0);
    let want = 440.0 * 2f64.powf(2.0 / 12.0);
    assert!(
        (after / want - 1.0).abs() < 0.005,
        "after the bend: {after} Hz, want {want}"
    );
}

#[test]
fn blocks_longer_than_announced_still_play() {
    let events = [(10, Send::On(69, 1.0)), (700, Send::On(72, 0.7))];
    let announced = run(&Script {
        events: &events,
        blocks: &[256],
        ..Script::new(INSTRUMENT, 6_000)
    });
    let longer = run(&Script {
        events: &events,
        blocks: &[1_000],
        max_block: Some(256),
        ..Script::new(INSTRUMENT, 6_000)
    });
    assert!(peak(&longer.left) > 0.05, "silent");
    assert!(
        longer.left == announced.left && longer.right == announced.right,
        "blocks of 1000 after announcing 256 differ from blocks of 256"
    );
}

#[test]
fn a_bank_swap_fades_the_ringing_bank_out_without_a_click() {
    let state = state_with(&sine_bank(440.0));
    let swap = with_bank(&state, &sine_bank(1_000.0));
    let s = run(&Script {
        state: Some(&state),
        events: &[(0, Send::On(69, 1.0))],
        swap: Some((24_000, &swap)),
        ..Script::new(INSTRUMENT, 48_000)
    });
    // The 440 Hz note rings until the swap and then fades over 50 ms: its largest step between
    // samples never exceeds what the sine itself makes.
    let sine_step =
        2.0 * std::f32::consts::PI * 440.0 / RATE as f32 * peak(&s.left[20_000..24_000]);
    let worst = s.left[20_000..]
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f32::max);
    assert!(
        worst <= 1.05 * sine_step,
        "step {worst} against the sine's {sine_step}"
    );
    // Once the new bank (with no notes yet) takes over, the old note fades out over about
    // 50 ms rather than stopping.
    let level = peak(&s.left[20_000..24_000]);
    let end = s.left.iter().rposition(|v| v.abs() > 1e-4 * level).unwrap();
    assert!(
        end > 24_000 && end < 40_000,
        "the old note ends at sample {end}"
    );
    assert!(
        s.left[end + 1..].iter().all(|&v| v.abs() <= 1e-4 * level),
        "sound after the fade"
    );
    let fading = peak(&s.left[end - 2_000..end - 1_500]);
    assert!(
        fading > 0.5 * level,
        "40 ms before its end the old note was at {fading}, against {level} before the swap"
    );
}

#[test]
fn the_default_bank_peaks_near_minus_6_dbfs_at_its_root() {
    // Default parameters strike the default bank at its typical point with its own mallet.
    let bank = modal_resonator::bank::factory::factory_bank(
        modal_resonator::bank::factory::DEFAULT_FACTORY_BANK,
    )
    .unwrap();
    let root = modal_resonator::units::hz_to_midi_key(bank.effective_root_hz()).round() as u16;
    let s = session(INSTRUMENT, None, &[(0, Send::On(root, 1.0))], None, 24_000);
    let level = gain_to_db(peak(&s.left).max(peak(&s.right)));
    assert!((level + 6.0).abs() < 1.5, "peak {level} dBFS");
}

#[test]
fn the_plugins_list_every_parameter_under_its_stable_id() {
    for (plugin, extra) in [(INSTRUMENT, 0), (EFFECT, 0)] {
        let infos = param_infos(plugin);
        let mut got: Vec<u32> = infos.iter().map(|p| p.id.get()).collect();
        got.sort();
        let mut want: Vec<u32> = PARAM_IDS.iter().map(|id| param_id(id).get()).collect();
        want.sort();
        assert_eq!(got.len(), want.len() + extra, "{plugin:?} lists {infos:?}");
        assert_eq!(got, want, "{plugin:?}: ids differ from the stable ones");
        let names: Vec<&str> = infos.iter().map(|p| p.name.as_str()).collect();
        for name in ["Strike position", "Hardness", "Fine tune", "MPE", "Dry/wet"] {
            assert!(names.contains(&name), "{plugin:?} lacks {name}: {names:?}");
        }
        // The host's bypass button drives the one bypass parameter, outside every group.
        let bypass: Vec<&ParamDesc> = infos.iter().filter(|p| p.bypass).collect();
        assert!(
            bypass.len() == 1 && bypass[0].name == "Bypass" && bypass[0].module.is_empty(),
            "{plugin:?}: bypass parameters {:?}",
            bypass
                .iter()
                .map(|p| (&p.name, &p.module))
                .collect::<Vec<_>>()
        );
        // Every other parameter sits in the group the editor shows it in.
        let module_of = |name: &str| {
            let p = infos.iter().find(|p| p.name == name).expect(name);
            p.module.clone()
        };
        for (name, module) in [
            ("Strike position", "Strike"),
            ("Hardness", "Strike"),
            ("Fine tune", "Object"),
            ("Polyphony", "Voices"),
            ("Dry/wet", "Output"),
            ("Pruning", "Pruning"),
        ] {
            assert_eq!(module_of(name), module, "{plugin:?}: {name}");
        }
        let ungrouped: Vec<&str> = infos
            .iter()
            .filter(|p| p.module.is_empty() && !p.bypass)
            .map(|p| p.name.as_str())
            .collect();
        assert!(ungrouped.is_empty(), "{plugin:?}: ungrouped {ungrouped:?}");
    }
}

#[test]
fn the_plugins_declare_their_categories() {
    let factory = entry(Build::Release).get_plugin_factory().unwrap();
    for d in factory.plugin_descriptors() {
        let id = d.id().unwrap().to_string_lossy().into_owned();
        let features: Vec<String> = d
            .features()
            .map(|f| f.to_string_lossy().into_owned())
            .collect();
        let want: &[&str] = if id.ends_with("instrument") {
            &["instrument", "synthesizer", "stereo"]
        } else {
            &["audio-effect", "filter", "stereo"]
        };
        for f in want {
            assert!(
                features.iter().any(|g| g == f),
                "{id} lacks {f}: {features:?}"
            );
        }
        assert!(d.name().is_some() && d.vendor().is_some() && d.version().is_some());
    }
}

#[test]
fn a_host_restart_silences_every_voice_and_forgets_the_test_note() {
    // Notes ring, the host stops and restarts processing (nice-plug resets the plugin), and
    // nothing of them is heard after; a tap in trigger mode then plays at the bank's root, not
    // at the key struck before the reset.
    let state = state_with(&sine_bank(440.0));
    // A tap: a decaying burst at 30_000.
    let tap: Vec<f32> = (0..48_000)
        .map(|i| match i {
            30_000..30_400 => {
                let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
                0.6 * (-((i - 30_000) as f32) / 60.0).exp() * sign
            }
            _ => 0.0,
        })
        .collect();
    let input = [tap.clone(), tap];
    let s = run(&Script {
        state: Some(&state),
        events: &[
            (0, Send::Param("inmode", 2.0)),
            (100, Send::On(81, 1.0)),
            (200, Send::On(76, 1.0)),
        ],
        input: Some(&input),
        restart_at: Some(24_064),
        ..Script::new(INSTRUMENT, 48_000)
    });
    assert!(
        peak(&s.left[20_000..24_000]) > 0.01,
        "nothing rang before the restart"
    );
    assert!(
        peak(&s.left[24_064..30_000]) == 0.0,
        "sound after the restart: {}",
        peak(&s.left[24_064..30_000])
    );
    let struck = &s.left[30_100..];
    assert!(peak(struck) > 1e-3, "the tap did not strike");
    let got = spectral_peak_hz(struck, RATE, 300.0, 1_000.0);
    assert!(
        (got / 440.0 - 1.0).abs() < 0.002,
        "the tap played {got} Hz, not the root"
    );
}

#[test]
fn direct_input_rings_at_the_last_note_played() {
    // Key 76 (E5) struck and released with full damping; noise on the exciter input then rings
    // the input voice at E5 on the 440 Hz bank.
    let state = state_with(&sine_bank(440.0));
    // White noise (a linear congruential generator, so it has no period within the render).
    let mut seed: u32 = 12_345;
    let noise: Vec<f32> = (0..48_000)
        .map(|i| {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            if i < 12_000 {
                0.0
            } else {
                ((seed >> 8) as f32 / (1u32 << 24) as f32 - 0.5) * 0.1
            }
        })
        .collect();
    let input = [noise.clone(), noise];
    let s = run(&Script {
        state: Some(&state),
        events: &[
            (0, Send::Param("inmode", 1.0)),
            (0, Send::Param("reldmp", 1.0)),
            (100, Send::On(76, 1.0)),
            (200, Send::Off(76)),
        ],
        input: Some(&input),
        ..Script::new(INSTRUMENT, 48_000)
    });
    let driven = &s.left[24_000..];
    assert!(peak(driven) > 1e-3, "the input did not ring the modes");
    let want = 440.0 * 2f64.powf(7.0 / 12.0);
    let got = spectral_peak_hz(driven, RATE, 300.0, 1_000.0);
    assert!(
        (got / want - 1.0).abs() < 0.003,
        "input rings at {got} Hz, want {want}"
    );
}

#[test]
fn the_effect_strikes_at_the_pitch_of_its_midi_notes() {
    let state = {
        let first = session(EFFECT, None, &[], None, BLOCK);
        with_bank(&first.state, &sine_bank(440.0))
    };
    let s = run(&Script {
        state: Some(&state),
        events: &[(100, Send::On(64, 1.0))],
        ..Script::new(EFFECT, 24_000)
    });
    let x = &s.left[200..];
    assert!(peak(x) > 0.01, "the effect did not strike on a note");
    let want = 440.0 * 2f64.powf(-5.0 / 12.0);
    let got = spectral_peak_hz(x, RATE, 200.0, 800.0);
    assert!((got / want - 1.0).abs() < 0.002, "{got} Hz, want {want}");
}

#[test]
fn a_broken_bank_loaded_while_playing_keeps_the_bank_and_the_state_holds_it() {
    let state = state_with(&sine_bank(440.0));
    let good = bank_text(&state);
    let broken = with_bank_text(&state, &good[..good.len() / 2]);
    let notes: Vec<(usize, Send)> = (0..8).map(|i| (i * 6_000, Send::On(69, 1.0))).collect();
    let s = run(&Script {
        state: Some(&state),
        events: &notes,
        swap: Some((12_000, &broken)),
        ..Script::new(INSTRUMENT, 48_000)
    });
    let after = &s.left[36_100..42_000];
    let got = spectral_peak_hz(after, RATE, 300.0, 600.0);
    assert!(
        (got / 440.0 - 1.0).abs() < 0.002,
        "after the broken bank: {got} Hz"
    );
    assert_eq!(
        bank_text(&s.state),
        good,
        "the saved state lost the playing bank"
    );
    let saved = String::from_utf8_lossy(&s.state[8..]).into_owned();
    assert!(
        saved.contains("\"state-format\":\"2\""),
        "no state format: {saved}"
    );
}

#[test]
fn the_pruning_parameters_reach_the_engine() {
    // Quiet playback (40 dB SPL at full scale): with pruning on, the bank's quieter modes fall
    // under the threshold of hearing and are switched off; with it off, the level changes nothing.
    let note = |prune: f64, spl: f64| {
        session(
            INSTRUMENT,
            None,
            &[
                (0, Send::Param("prune", prune)),
                (0, Send::Param("spl", spl)),
                (0, Send::On(60, 1.0)),
            ],
            None,
            24_000,
        )
    };
    let largest_difference = |a: &[f32], b: &[f32]| {
        a.iter()
            .zip(b)
            .fold(0.0f32, |m, (x, y)| m.max((x - y).abs()))
    };
    let full = note(0.0, 0.0);
    let plain = session(INSTRUMENT, None, &[(0, Send::On(60, 1.0))], None, 24_000);
    assert_eq!(
        full.left, plain.left,
        "the playback level acts without pruning"
    );
    let pruned = note(1.0, 0.0);
    let scale = peak(&full.left);
    let diff = largest_difference(&full.left, &pruned.left);
    assert!(
        diff > 1e-3 * scale,
        "pruning at 40 dB SPL changed nothing (largest difference {diff}, peak {scale})"
    );
    assert!(
        peak(&pruned.left[19_200..]) > 1e-3 * scale,
        "the pruned note fell silent"
    );
    // Loud playback (120 dB SPL) brings quiet modes above the threshold of hearing again.
    let loud = note(1.0, 1.0);
    let diff = largest_difference(&loud.left, &pruned.left);
    assert!(
        diff > 1e-3 * scale,
        "the playback level changed nothing (largest difference {diff}, peak {scale})"
    );
}

/// Samples per tick of the MIDI file below: 480 ticks a quarter at 120 bpm is 960 a second.
const SAMPLES_PER_TICK: usize = 50;

/// The MIDI a player sends with bends, pressure, slide, the wheel and the pedal: (sample,
/// bytes); a two-byte message carries a 0 third byte.
const GESTURES: [(usize, [u8; 3]); 13] = [
    (2_400, [0x90, 60, 100]),
    (4_800, [0xE0, 0x00, 0x60]),
    (6_000, [0x90, 67, 80]),
    (7_200, [0xB0, 74, 90]),
    (9_600, [0xD0, 80, 0]),
    (12_000, [0xB0, 1, 64]),
    (14_400, [0xA0, 60, 100]),
    (16_800, [0xB0, 64, 127]),
    (19_200, [0x80, 60, 0]),
    (20_000, [0xE0, 0x7F, 0x7F]),
    (21_600, [0x90, 64, 90]),
    (22_800, [0x80, 67, 0]),
    (24_000, [0xB0, 64, 0]),
];

/// `GESTURES` on MIDI channel `channel` (0 to 15).
fn gestures_on(channel: u8) -> Vec<(usize, [u8; 3])> {
    GESTURES
        .iter()
        .map(|&(at, [status, a, b])| (at, [status | channel, a, b]))
        .collect()
}

/// `gestures` as a standard MIDI file.
fn gestures_file(path: &std::path::Path, gestures: &[(usize, [u8; 3])]) {
    use midly::num::{u15, u28};
    use midly::{live::LiveEvent, Format, Header, Smf, Timing, TrackEvent, TrackEventKind};
    let mut track = Vec::new();
    let mut last = 0;
    for &(sample, bytes) in gestures {
        assert_eq!(sample % SAMPLES_PER_TICK, 0);
        let tick = sample / SAMPLES_PER_TICK;
        let len = if bytes[0] & 0xF0 == 0xD0 { 2 } else { 3 };
        let LiveEvent::Midi { channel, message } = LiveEvent::parse(&bytes[..len]).unwrap() else {
            panic!("not a channel message");
        };
        track.push(TrackEvent {
            delta: u28::new((tick - last) as u32),
            kind: TrackEventKind::Midi { channel, message },
        });
        last = tick;
    }
    track.push(TrackEvent {
        delta: u28::new(0),
        kind: TrackEventKind::Meta(midly::MetaMessage::EndOfTrack),
    });
    Smf {
        header: Header::new(Format::SingleTrack, Timing::Metrical(u15::new(480))),
        tracks: vec![track],
    }
    .save(path)
    .unwrap();
}

#[test]
fn a_midi_file_rendered_offline_equals_the_plugin_playing_it() {
    use modal_resonator::dsp::ExciterKind;
    use modal_resonator::engine::PreparedBank;
    use modal_resonator::params::ModalParams;
    use modal_resonator::render::{read_midi_file, render, RenderSettings};
    use std::sync::Arc;

    let dir = tempfile::tempdir().unwrap();
    let bank = two_position_bank();
    let state = state_with(&bank);
    let samples = 36_000;
    // Struck (pressure damps, the wheel moves the strike), scraped (pressure is the force, slide
    // the speed), and rubbed on an MPE member channel (its bend, pressure and slide the note's).
    for (exciter, index, mpe) in [
        (ExciterKind::Mallet, 0.0, false),
        (ExciterKind::Scrape, 3.0, false),
        (ExciterKind::Rub, 5.0, true),
    ] {
        let gestures = gestures_on(if mpe { 2 } else { 0 });
        let path = dir.path().join(format!("{}.mid", exciter.name()));
        gestures_file(&path, &gestures);
        let messages = read_midi_file(&path).unwrap();
        let mut events: Vec<(usize, Send)> = vec![
            (0, Send::Param("exc", index)),
            (0, Send::Param("mpe", if mpe { 1.0 } else { 0.0 })),
        ];
        events.extend(gestures.iter().map(|&(at, bytes)| (at, Send::Midi(bytes))));
        let played = run(&Script {
            state: Some(&state),
            events: &events,
            ..Script::new(INSTRUMENT, samples)
        });
        let mut controls = ModalParams::new(false).controls();
        controls.exciter = exciter;
        controls.mpe = mpe;
        let settings = RenderSettings {
            controls,
            max_seconds: samples as f64 / RATE,
            block: BLOCK,
            ..RenderSettings::default()
        };
        let rendered = render(
            &Arc::new(PreparedBank::new(&bank)),
            &messages,
            &settings,
            |_| {},
        );
        // The render fades its last 10 ms out when cut while sounding.
        let n = samples - 480;
        assert!(peak(&played.left[2_400..n]) > 0.01, "{exciter:?}: silent");
        let first_difference = (0..n)
            .find(|&i| played.left[i] != rendered.left[i] || played.right[i] != rendered.right[i]);
        assert_eq!(
            first_difference, None,
            "{exciter:?}: the plugin and the render part at sample {first_difference:?}"
        );
    }
}
