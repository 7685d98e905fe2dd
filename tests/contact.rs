//! Contact notes in the engine: a scrape or roll sounds for as long as its note is held, rings on
//! after it, starts and stops without a click, follows speed and force from the controls and the
//! note's expression, a roll repeats once a revolution in the output, a held scrape settles to a
//! steady level, and a rub sings louder the faster it goes.

mod common;

use common::*;
use modal_resonator::bank::Bank;
use modal_resonator::dsp::ExciterKind;
use modal_resonator::engine::{Engine, Note, NoteEvent, NoteExpression};

const RATE: f32 = 48_000.0;
const KEY: u8 = 60;

fn note() -> Note {
    Note {
        key: KEY,
        channel: 0,
        id: None,
    }
}

fn contact_engine(bank: &Bank, kind: ExciterKind, speed: f32) -> Engine {
    let mut e = engine(bank, RATE);
    let mut c = e.controls().clone();
    c.exciter = kind;
    c.contact_speed_m_per_s = speed;
    c.key_tracking = 0.0;
    e.set_controls(&c);
    e
}

/// Mono sum of a render with `events`.
fn play(e: &mut Engine, events: &[NoteEvent], seconds: f64) -> Vec<f32> {
    let (l, r) = render(e, events, seconds, 256);
    l.iter().zip(&r).map(|(a, b)| a + b).collect()
}

fn rms(x: &[f32]) -> f64 {
    (x.iter().map(|&v| (v as f64).powi(2)).sum::<f64>() / x.len().max(1) as f64).sqrt()
}

fn span(x: &[f32], from_s: f64, to_s: f64) -> &[f32] {
    &x[(from_s * RATE as f64) as usize..(to_s * RATE as f64) as usize]
}

fn release_at(seconds: f64) -> NoteEvent {
    NoteEvent::Off {
        time: (seconds * RATE as f64) as u32,
        note: note(),
    }
}

#[test]
fn a_held_scrape_sounds_until_released_then_rings_on() {
    let bank = dense_bank(200, 110.0);
    let mut e = contact_engine(&bank, ExciterKind::Scrape, 0.5);
    let x = play(&mut e, &[on(0, KEY, 1.0), release_at(1.0)], 2.5);
    let (early, late) = (rms(span(&x, 0.4, 0.7)), rms(span(&x, 0.7, 1.0)));
    assert!(early > 1e-3, "silent while held: {early}");
    let held_db = 20.0 * (late / early).log10();
    assert!(
        held_db.abs() < 3.0,
        "not sustained: {held_db:.1} dB from 0.4-0.7 s to 0.7-1.0 s"
    );
    // After the release the object rings on, and dies away.
    let after = rms(span(&x, 1.1, 1.3));
    assert!(
        after > 0.05 * late && after < late,
        "after release {after} against {late}"
    );
    assert!(rms(span(&x, 2.3, 2.5)) < 0.5 * after);
    // With a strike at the same velocity, a contact is about as loud as a struck note.
    let mut s = contact_engine(&bank, ExciterKind::Mallet, 0.5);
    let struck = rms(span(&play(&mut s, &[on(0, KEY, 1.0)], 0.5), 0.0, 0.5));
    let db = 20.0 * (late / struck).log10();
    println!("scrape at 0.5 m/s: {db:.1} dB against a mallet strike over its first 0.5 s");
    assert!(db.abs() < 6.0, "scrape {db:.1} dB against a strike");
}

/// Level of `x`'s mean square, dB.
fn level_db(x: &[f32]) -> f64 {
    20.0 * rms(x).log10()
}

#[test]
fn a_held_scrape_settles_however_long_its_object_rings() {
    // Forty modes that would ring for minutes (0.05 /s: T60 138 s): left free, a scrape would take
    // tens of seconds (1 / (2 d) = 10 s for each mode's energy) to fill them. The hand on the
    // scraper damps them while it presses, so the level is steady from the first seconds.
    let modes: Vec<(f64, f64, f64)> = (0..40)
        .map(|i| {
            let i = i as f64;
            (150.0 * (1.0 + 0.83 * i), 0.05, 1.0 / (1.0 + 0.1 * i))
        })
        .collect();
    let mut e = contact_engine(&simple_bank(&modes), ExciterKind::Scrape, 0.5);
    let x = play(&mut e, &[on(0, KEY, 1.0)], 30.0);
    let (early, late) = (level_db(span(&x, 2.0, 4.0)), level_db(span(&x, 20.0, 30.0)));
    println!("held scrape: {early:.1} dB over 2-4 s, {late:.1} dB over 20-30 s");
    assert!(
        (late - early).abs() < 1.0,
        "builds up: {early:.1} dB over 2-4 s, {late:.1} dB over 20-30 s"
    );
}

#[test]
fn the_factory_scraped_and_rolled_banks_hold_a_steady_level_without_clipping() {
    use modal_resonator::bank::factory::factory_bank;
    use modal_resonator::units::{gain_to_db, hz_to_midi_key};
    // The steel sheet's lowest mode rings for 25 s; the table top's for 2.3 s.
    for slug in ["scraped-steel-sheet", "spruce-table-top-rolled-ball"] {
        let bank = factory_bank(slug).expect(slug);
        let key = hz_to_midi_key(bank.effective_root_hz()).round() as u8;
        let mut e = engine(&bank, RATE);
        let (l, r) = render(&mut e, &[on(0, key, 1.0)], 30.0, 512);
        let (early, late) = (level_db(span(&l, 2.0, 4.0)), level_db(span(&l, 20.0, 30.0)));
        let peak_db = gain_to_db(peak(&l).max(peak(&r)));
        println!(
            "{slug}: {early:.1} dB over 2-4 s, {late:.1} dB over 20-30 s, peak {peak_db:.1} dBFS"
        );
        // Narrow-band noise (one mode dominates the sheet) wanders by a dB or two over a few
        // seconds even when settled.
        assert!(
            (late - early).abs() < 2.0,
            "{slug} builds up: {early:.1} dB over 2-4 s, {late:.1} dB over 20-30 s"
        );
        assert!(peak_db < -1.0, "{slug} peaks at {peak_db:.1} dBFS in 30 s");
    }
}

#[test]
fn contacts_start_and_stop_without_a_click() {
    let bank = dense_bank(200, 110.0);
    for kind in [ExciterKind::Scrape, ExciterKind::Roll] {
        let mut e = contact_engine(&bank, kind, 0.8);
        let x = play(&mut e, &[on(0, KEY, 1.0), release_at(1.0)], 1.5);
        let steady = max_step(span(&x, 0.3, 1.0));
        let start = max_step(span(&x, 0.0, 0.3));
        // The contact lets go within about 30 ms of the release.
        let stop = max_step(span(&x, 1.0, 1.05));
        assert!(
            start <= steady && stop <= steady,
            "{kind:?}: steps {start} at the start, {stop} at the stop, {steady} held"
        );
    }
}

fn centroid_hz(x: &[f32]) -> f64 {
    let n = x.len().next_power_of_two() / 2;
    let spectrum: Vec<f64> = (1..n / 2)
        .map(|k| magnitude_at(&x[..n], RATE as f64, k as f64 * RATE as f64 / n as f64).powi(2))
        .collect();
    let hz = RATE as f64 / n as f64;
    let total: f64 = spectrum.iter().sum();
    spectrum
        .iter()
        .enumerate()
        .map(|(k, e)| (k + 1) as f64 * hz * e)
        .sum::<f64>()
        / total
}

#[test]
fn speed_and_force_follow_the_controls_and_the_notes_expression() {
    let bank = dense_bank(300, 110.0);
    let held = |e: &mut Engine, extra: &[NoteEvent]| {
        let mut events = vec![on(0, KEY, 1.0)];
        events.extend_from_slice(extra);
        let x = play(e, &events, 0.6);
        span(&x, 0.3, 0.6).to_vec()
    };
    let slow = held(&mut contact_engine(&bank, ExciterKind::Scrape, 0.1), &[]);
    let fast = held(&mut contact_engine(&bank, ExciterKind::Scrape, 1.5), &[]);
    let (c_slow, c_fast) = (centroid_hz(&slow[..8192]), centroid_hz(&fast[..8192]));
    assert!(
        c_fast > 1.5 * c_slow,
        "centroid {c_fast:.0} Hz fast, {c_slow:.0} Hz slow"
    );
    // The note's slide sets the speed instead.
    let slide = |s: f32| NoteEvent::Expression {
        time: 10,
        note: note(),
        expression: NoteExpression::Slide(s),
    };
    let slid = held(
        &mut contact_engine(&bank, ExciterKind::Scrape, 0.1),
        &[slide(0.5)],
    );
    assert!(centroid_hz(&slid[..8192]) > 1.5 * c_slow);
    // Pressure sets the force, in proportion.
    let pressure = |p: f32| NoteEvent::Expression {
        time: 10,
        note: note(),
        expression: NoteExpression::Pressure(p),
    };
    let full = rms(&held(
        &mut contact_engine(&bank, ExciterKind::Scrape, 0.5),
        &[pressure(1.0)],
    ));
    let light = rms(&held(
        &mut contact_engine(&bank, ExciterKind::Scrape, 0.5),
        &[pressure(0.25)],
    ));
    let db = 20.0 * (light / full).log10();
    assert!(
        (db - 20.0 * 0.25f64.log10()).abs() < 1.0,
        "pressure 0.25: {db:.1} dB"
    );
}

#[test]
fn a_roll_repeats_once_a_revolution_in_the_output() {
    // Modes that die within a few tens of ms, so each bump is heard apart.
    let modes: Vec<(f64, f64, f64)> = (0..40)
        .map(|k| (300.0 + 97.0 * k as f64, 60.0, 1.0 / (1.0 + k as f64)))
        .collect();
    let bank = simple_bank(&modes);
    for (radius_mm, speed) in [(20.0f32, 0.5f32), (50.0, 1.2)] {
        let mut e = contact_engine(&bank, ExciterKind::Roll, speed);
        let mut c = e.controls().clone();
        c.rolling_radius_mm = radius_mm;
        c.roughness = 0.8;
        e.set_controls(&c);
        let x = play(&mut e, &[on(0, KEY, 1.0)], 4.5);
        let x = span(&x, 0.5, 4.5);
        // Envelope: mean square over 1 ms.
        let env: Vec<f64> = x.chunks(48).map(|b| rms(b).powi(2)).collect();
        let mean = env.iter().sum::<f64>() / env.len() as f64;
        let d: Vec<f64> = env.iter().map(|v| v - mean).collect();
        let zero: f64 = d.iter().map(|v| v * v).sum();
        let ac = |lag: usize| d.iter().zip(&d[lag..]).map(|(a, b)| a * b).sum::<f64>() / zero;
        let period_ms = std::f64::consts::TAU * radius_mm as f64 * 1e-3 / speed as f64 * 1e3;
        let (lo, hi) = ((0.6 * period_ms) as usize, (1.4 * period_ms) as usize);
        let peak = (lo..hi).max_by(|&a, &b| ac(a).total_cmp(&ac(b))).unwrap();
        let (l, m, r) = (ac(peak - 1), ac(peak), ac(peak + 1));
        let found = peak as f64 + 0.5 * (l - r) / (l - 2.0 * m + r);
        assert!(
            (found / period_ms - 1.0).abs() < 0.02,
            "radius {radius_mm} mm at {speed} m/s: {found:.1} ms against {period_ms:.1} ms"
        );
    }
}

#[test]
fn a_rendered_scrape_follows_its_speed_and_force_curves() {
    use modal_resonator::engine::PreparedBank;
    use modal_resonator::render::{parse_notes, render, RenderSettings};
    use std::sync::Arc;
    let bank = Arc::new(PreparedBank::new(&dense_bank(300, 110.0)));
    let mut settings = RenderSettings {
        max_seconds: 2.2,
        ..RenderSettings::default()
    };
    settings.controls.exciter = ExciterKind::Scrape;
    let take = |notes: &str| {
        let out = render(&bank, &parse_notes(notes).unwrap(), &settings, |_| {});
        let x: Vec<f32> = out
            .left
            .iter()
            .zip(&out.right)
            .map(|(a, b)| a + b)
            .collect();
        (span(&x, 0.2, 0.5).to_vec(), span(&x, 1.6, 1.9).to_vec())
    };
    // Speed from 0.1 to 2 m/s over two seconds: louder at the end (a faster contact point
    // moves up and down faster; that it is brighter too is shown on the force itself, and above
    // for steady speeds: here the bank's own ringing rules the centroid).
    let (start, end) = take("60:1@0+2 speed=0.1..2 force=0.7");
    let louder = 20.0 * (rms(&end) / rms(&start)).log10();
    assert!(louder > 6.0, "speed 0.1 to 2 m/s: {louder:.1} dB");
    // Force from 1 down to 0.1 at a steady speed: quieter at the end, by about the ratio of the
    // mean forces in the two spans (0.84 and 0.21: -12 dB; the object's ringing from louder
    // moments before holds the end up a little: -9.2 dB measured).
    let (loud, soft) = take("60:1@0+2 speed=0.5 force=1..0.1");
    let db = 20.0 * (rms(&soft) / rms(&loud)).log10();
    println!("force 1 to 0.1: {db:.1} dB");
    assert!((-14.0..-6.0).contains(&db), "force 1 to 0.1: {db:.1} dB");
}

#[test]
fn a_contact_held_at_no_force_waits_for_pressure_and_one_released_at_once_lets_go() {
    let bank = dense_bank(200, 110.0);
    let pressure = |t: f64, p: f32| NoteEvent::Expression {
        time: (t * RATE as f64) as u32,
        note: note(),
        expression: NoteExpression::Pressure(p),
    };
    // MPE sends the channel's resting pressure (0) with the note: the velocity's force holds
    // until the player presses.
    let mut e = contact_engine(&bank, ExciterKind::Scrape, 0.5);
    let x = play(&mut e, &[on(0, KEY, 1.0), pressure(0.0, 0.0)], 0.5);
    assert!(
        rms(span(&x, 0.3, 0.5)) > 1e-3,
        "a note with resting pressure is silent"
    );
    // Pressed, then let up to nothing, then pressed again: the note stays and sounds again.
    let mut e = contact_engine(&bank, ExciterKind::Scrape, 0.5);
    let events = [
        on(0, KEY, 1.0),
        pressure(0.1, 0.8),
        pressure(0.4, 0.0),
        pressure(2.0, 0.8),
    ];
    let x = play(&mut e, &events, 2.5);
    let (pressed, lifted, again) = (
        rms(span(&x, 0.2, 0.4)),
        rms(span(&x, 1.8, 2.0)),
        rms(span(&x, 2.3, 2.5)),
    );
    assert!(
        lifted < 0.3 * pressed,
        "no force, yet {lifted} against {pressed}"
    );
    assert!(
        again > 0.5 * pressed,
        "pressed again: {again} against {pressed}"
    );
    // A note released at the sample it starts (a click on the strike pad) lets go at once and
    // rings down, rather than scraping on.
    let mut e = contact_engine(&bank, ExciterKind::Scrape, 0.5);
    let x = play(&mut e, &[on(0, KEY, 1.0), release_at(0.0)], 3.0);
    let (start, end) = (rms(span(&x, 0.0, 0.3)), rms(span(&x, 2.5, 3.0)));
    assert!(
        end < 0.05 * start.max(1e-9),
        "still {end} against {start} at the start"
    );
}

fn zero_crossing_hz(x: &[f32]) -> f64 {
    let crossings: Vec<f64> = x
        .windows(2)
        .enumerate()
        .filter(|(_, w)| w[0] < 0.0 && w[1] >= 0.0)
        .map(|(i, w)| i as f64 + (w[0] / (w[0] - w[1])) as f64)
        .collect();
    let (first, last) = (crossings[0], crossings[crossings.len() - 1]);
    (crossings.len() - 1) as f64 * RATE as f64 / (last - first)
}

#[test]
fn a_rubbed_glass_sings_at_its_clearest_mode_while_held_and_rings_on_after() {
    // A glass: its lowest rim mode rings longest and moves most at the rim.
    let bank = simple_bank(&[
        (660.0, 0.4, 1.0),
        (1_580.0, 1.5, 0.6),
        (2_830.0, 3.0, 0.4),
        (4_350.0, 5.0, 0.3),
    ]);
    let mut e = contact_engine(&bank, ExciterKind::Rub, 0.2);
    let x = play(&mut e, &[on(0, KEY, 1.0), release_at(4.0)], 6.0);
    let held = span(&x, 3.0, 4.0);
    let hz = zero_crossing_hz(held);
    let cents = 1200.0 * (hz / 660.0).log2();
    let (a, b) = (rms(span(&x, 3.0, 3.5)), rms(span(&x, 3.5, 4.0)));
    println!(
        "rubbed at 0.2 m/s: {hz:.2} Hz ({cents:+.2} cents), {:.1} dBFS",
        20.0 * b.log10()
    );
    assert!(cents.abs() < 5.0, "sings at {hz:.2} Hz");
    assert!(
        (20.0 * (b / a).log10()).abs() < 0.5,
        "not steady: {a} then {b}"
    );
    // Let go, it rings on at its own decay (0.4 /s: -1.7 dB in 0.5 s) and dies away.
    let (after, later) = (rms(span(&x, 4.2, 4.7)), rms(span(&x, 5.2, 5.7)));
    assert!(
        after > 0.5 * b && after < b,
        "after release {after} against {b}"
    );
    let db = 20.0 * (later / after).log10();
    assert!(
        (-5.5..-2.0).contains(&db),
        "rings on {db:.1} dB a second later"
    );
    // Click-free: the song grows from nothing, and letting go leaves no step larger than the
    // song's own (1 % for the stick-slip's jitter).
    let steady = max_step(held);
    let (start, stop) = (max_step(span(&x, 0.0, 0.1)), max_step(span(&x, 4.0, 4.1)));
    assert!(
        start <= 0.1 * steady && stop <= 1.01 * steady,
        "steps {start} at the start, {stop} at the stop, {steady} held"
    );
}

#[test]
fn a_rub_sings_louder_the_faster_it_goes_across_the_speed_range() {
    use modal_resonator::bank::factory::factory_bank;
    use modal_resonator::units::{gain_to_db, hz_to_midi_key};
    // The factory glass and bowl at their own force, rubbed from rest at speeds across the
    // contact range (0 to 3 m/s): each sings on its lowest mode, louder the faster, and the fastest
    // does not clip.
    for slug in ["rubbed-wine-glass", "singing-bowl-circled-with-a-stick"] {
        let bank = factory_bank(slug).expect(slug);
        let root = bank.effective_root_hz();
        let key = hz_to_midi_key(root).round() as u8;
        let mut last_db = f64::NEG_INFINITY;
        for speed in [0.1f32, 0.4, 1.0, 2.0, 3.0] {
            let mut e = engine(&bank, RATE);
            let mut c = e.controls().clone();
            c.contact_speed_m_per_s = speed;
            e.set_controls(&c);
            let (l, r) = render(&mut e, &[on(0, key, 1.0)], 5.0, 512);
            let held = span(&l, 4.0, 5.0);
            let db = level_db(held);
            let peak_db = gain_to_db(peak(&l).max(peak(&r))) as f64;
            let hz = spectral_peak_hz(held, RATE as f64, 0.8 * root, 1.25 * root);
            let cents = 1200.0 * (hz / root).log2();
            println!(
                "{slug} at {speed} m/s: {db:.1} dB RMS, peak {peak_db:.1} dBFS, {cents:+.1} cents"
            );
            assert!(db > -45.0, "{slug} silent at {speed} m/s: {db:.1} dB");
            assert!(
                cents.abs() < 25.0,
                "{slug} at {speed} m/s sings at {hz:.1} Hz"
            );
            assert!(
                db > last_db + 2.0,
                "{slug} at {speed} m/s: {db:.1} dB, not louder than {last_db:.1} dB"
            );
            assert!(
                peak_db < -1.0,
                "{slug} at {speed} m/s peaks at {peak_db:.1} dBFS"
            );
            last_db = db;
        }
    }
}

#[test]
fn polyphonic_modulation_sets_one_contact_notes_speed_and_force() {
    use modal_resonator::engine::VoiceModulation;
    let bank = dense_bank(300, 110.0);
    let with_id = Note {
        key: KEY,
        channel: 0,
        id: Some(7),
    };
    let held = |modulation: Option<VoiceModulation>| {
        let mut e = contact_engine(&bank, ExciterKind::Scrape, 0.5);
        let mut events = vec![NoteEvent::On {
            time: 0,
            note: with_id,
            velocity: 1.0,
        }];
        if let Some(modulation) = modulation {
            events.push(NoteEvent::Modulate {
                time: 0,
                id: 7,
                modulation,
            });
        }
        let x = play(&mut e, &events, 0.6);
        span(&x, 0.3, 0.6).to_vec()
    };
    let plain = held(None);
    // Half the force: 6 dB down.
    let light = held(Some(VoiceModulation::ContactForce(0.35)));
    let db = 20.0 * (rms(&light) / rms(&plain)).log10();
    assert!((db + 6.0).abs() < 1.0, "half the force: {db:.1} dB");
    // The note's own speed, whatever the control's (0.5 m/s): faster is brighter.
    let slow = held(Some(VoiceModulation::ContactSpeed(0.1)));
    let fast = held(Some(VoiceModulation::ContactSpeed(1.5)));
    let (c_slow, c_fast) = (centroid_hz(&slow[..8192]), centroid_hz(&fast[..8192]));
    assert!(
        c_fast > 1.5 * c_slow,
        "centroid {c_fast:.0} Hz against {c_slow:.0} Hz"
    );
}

/// Largest sample-to-sample step of each 10 ms window over the window's peak.
fn step_over_peak(x: &[f32]) -> Vec<f32> {
    x.chunks(480)
        .map(|w| max_step(w) / peak(w).max(1e-9))
        .collect()
}

#[test]
fn a_rub_follows_speed_and_force_sweeps_without_a_click() {
    let bank = simple_bank(&[(660.0, 0.4, 1.0), (1_580.0, 1.5, 0.6)]);
    let mut e = contact_engine(&bank, ExciterKind::Rub, 0.2);
    let mut events = vec![on(0, KEY, 1.0)];
    // From 1.5 s, the slide sweeps the speed from 0.15 to 0.45 m/s and back, and the pressure the
    // force from 0.7 to 0.4, in steps of 2 ms as a controller sends them.
    for i in 0..1_000 {
        let t = 1.5 + i as f64 * 0.002;
        let u = i as f32 / 999.0;
        let speed = 0.15 + 0.3 * (1.0 - (2.0 * u - 1.0).abs());
        let time = (t * RATE as f64) as u32;
        events.push(NoteEvent::Expression {
            time,
            note: note(),
            expression: NoteExpression::Slide(speed / 3.0),
        });
        events.push(NoteEvent::Expression {
            time,
            note: note(),
            expression: NoteExpression::Pressure(0.7 - 0.3 * u),
        });
    }
    let x = play(&mut e, &events, 4.0);
    // Louder as it goes faster (the level follows the speed).
    let (slow, fast) = (rms(span(&x, 1.3, 1.5)), rms(span(&x, 2.45, 2.55)));
    assert!(fast > 2.0 * slow, "0.15 m/s: {slow}, 0.45 m/s: {fast}");
    // Every 10 ms window's steps stay within what the steady song's own waveform makes.
    let steady = step_over_peak(span(&x, 1.0, 1.5));
    let held = steady.iter().fold(0.0f32, |a, &b| a.max(b));
    let sweep = step_over_peak(span(&x, 1.5, 3.5));
    let worst = sweep.iter().fold(0.0f32, |a, &b| a.max(b));
    assert!(
        worst < 1.25 * held,
        "a step of {worst} of the window's peak in the sweep, {held} held"
    );
}

#[test]
fn a_scrape_ends_in_a_knock_on_the_same_voice() {
    let bank = dense_bank(200, 110.0);
    // Scraped for a second, then the key struck again at the same velocity: the knock adds a
    // mallet strike on the same voice, and the scrape goes on as it was.
    let mut e = contact_engine(&bank, ExciterKind::Scrape, 0.5);
    let knocked = play(&mut e, &[on(0, KEY, 0.5), on(48_000, KEY, 0.5)], 1.6);
    assert_eq!(e.stats().voices, 1, "the knock took another voice");
    let mut e = contact_engine(&bank, ExciterKind::Scrape, 0.5);
    let scraped = play(&mut e, &[on(0, KEY, 0.5)], 1.6);
    assert_eq!(&knocked[..48_000], &scraped[..48_000]);
    let knock: Vec<f32> = knocked.iter().zip(&scraped).map(|(a, b)| a - b).collect();
    // The difference is a mallet strike at that velocity.
    let mut m = contact_engine(&bank, ExciterKind::Mallet, 0.5);
    let struck = play(&mut m, &[on(0, KEY, 0.5)], 0.6);
    let ratio = peak(span(&knock, 1.0, 1.6)) / peak(&struck);
    assert!(
        (0.7..1.4).contains(&ratio),
        "the knock peaks at {ratio} of a strike"
    );
    // The scrape goes on under the knock's ringing.
    let (scraping, under) = (rms(span(&scraped, 1.4, 1.6)), rms(span(&knocked, 1.4, 1.6)));
    assert!(
        scraping > 1e-3 && under >= scraping,
        "{under} knocked, {scraping} scraped"
    );
}
