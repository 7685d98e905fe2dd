//! Scenes: many objects, each a bank placed in space, sounded by timed impacts and contacts and
//! heard from one listener's place (seed 001 sections 4-5, seed 003, seed 004).
//!
//! A scene file ([`format`], read and checked by [`validate`]) names the objects, the events and the listener; the rigid bodies'
//! impacts ([`physics`], by rapier3d) and hail or rain from emitters are events too. Each
//! object plays its bank through an engine of its own (two when it is both struck and scraped:
//! the exciter is an engine's); the listener ([`listener`]) hears it through
//!
//! - a distance gain, `1/r` re 1 m, held at its value at [`listener::NEAR_M`] closer in;
//! - the air's absorption over that distance (ISO 9613-1), a gain per mode, since it depends on
//!   the frequency;
//! - the time sound takes to arrive, and its direction: equal-power stereo by azimuth, or a
//!   spherical head's two ears (Brown and Duda 1998: each ear's delay and head shadow).
//!
//! Sounding objects and the listener stand still (a dynamic body cannot have a bank yet), so the
//! arrival time shifts each object's events, whole samples, and only the fraction of a sample
//! and the ears' difference pass through a delay line.
//!
//! An impact's loudness is proportional to its relative normal speed (seed 004 takes the
//! impulse, `m u`): each object's strikes play at velocity `speed / s_ref` with a linear velocity
//! curve and their output is scaled by `s_ref`, the strongest impact on it (at least 1 m/s), so
//! an impact twice as fast is 6 dB louder wherever it falls; its contacts play apart, at the
//! level their force curves give. The velocity's effect on hardness is off unless the object's
//! `set` turns it on (`velocity_to_hardness`).

pub mod format;
pub mod listener;
mod object;
pub mod physics;
pub mod validate;

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use crate::bank::factory::factory_bank;
use crate::bank::validate::Problem;
use crate::bank::{load_bank_file, Bank};
use crate::engine::{Controls, ExciterKind, PreparedBank};
use crate::render::{schedule, Note};
use crate::units::db_to_gain;
use format::{SceneError, SceneEvent, SceneFile, SceneObject};
use listener::{air_absorption_db_per_m, place};
use object::SoundingObject;

pub use format::{scene_schema_json, SCENE_FORMAT, SCENE_VERSION};
pub use validate::parse_scene_str;

/// Key every object's notes are played on: with key tracking off, any key plays the bank as
/// authored.
const KEY: u8 = 60;

/// Slowest impact an object's levels are referred to, m/s: impacts at 1 m/s play at the bank's
/// own level (and its `gain_db`).
const REFERENCE_SPEED_M_PER_S: f64 = 1.0;

/// Controls an object's `set` may not give, and why: the scene's laws rest on them.
const SET_BY_THE_SCENE: [(&str, &str); 4] = [
    ("size_ratio", "give the object's \"scale\" instead"),
    (
        "key_tracking",
        "every object plays its bank as authored, lowered by its scale",
    ),
    (
        "velocity_sensitivity",
        "an impact's loudness is proportional to its speed",
    ),
    (
        "target_load_pct",
        "a load target depends on the machine; use mode_budget",
    ),
];

/// Silence kept after the last sound, in seconds.
pub const TAIL_S: f64 = 0.1;

/// A scene with its banks, read and checked, not yet prepared to play.
#[derive(Debug, Clone)]
pub struct SceneSource {
    /// The scene.
    file: SceneFile,
    /// The banks, one per distinct `bank` of the objects.
    banks: Vec<Bank>,
    /// Index into `banks` of each object's bank; `None` for a silent object.
    bank_of: Vec<Option<usize>>,
    /// Every event: the file's, then the impacts the physics found.
    events: Vec<SceneEvent>,
    /// Physics steps taken.
    physics_steps: usize,
    /// Whether the physics found more impacts than a scene may hold, and the rest were left out.
    events_capped: bool,
    /// Seconds the physics took to simulate.
    physics_s: f64,
}

impl SceneSource {
    /// A scene read from `path`, its bank files found relative to the scene's folder.
    pub fn from_file(path: &Path) -> Result<Self, SceneError> {
        let origin = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| SceneError {
            origin: origin.clone(),
            problems: vec![Problem {
                path: String::new(),
                message: format!("cannot read the scene: {e}"),
            }],
        })?;
        let dir = path.parent().unwrap_or(Path::new("."));
        Self::from_str(&text, &origin, dir)
    }

    /// A scene from JSON text, its bank files found relative to `dir`; `origin` names the text
    /// in errors.
    pub fn from_str(text: &str, origin: &str, dir: &Path) -> Result<Self, SceneError> {
        let file = parse_scene_str(text, origin)?;
        Self::new(file, origin, |spec| resolve_bank(spec, dir))
    }

    /// `file` with each object's bank from `resolve` (given the object's `bank`); `origin` names
    /// the scene in errors.
    pub fn new(
        file: SceneFile,
        origin: &str,
        mut resolve: impl FnMut(&str) -> Result<Bank, String>,
    ) -> Result<Self, SceneError> {
        let invalid = |problems: Vec<Problem>| SceneError {
            origin: origin.to_string(),
            problems,
        };
        let problems = validate::validate(&file);
        if !problems.is_empty() {
            return Err(invalid(problems));
        }
        let mut banks = Vec::new();
        let mut index: HashMap<&str, usize> = HashMap::new();
        let mut bank_of = Vec::with_capacity(file.objects.len());
        let mut problems = Vec::new();
        for (i, o) in file.objects.iter().enumerate() {
            let Some(spec) = o.bank.as_deref() else {
                bank_of.push(None);
                continue;
            };
            if let Some(&k) = index.get(spec) {
                bank_of.push(Some(k));
                continue;
            }
            match resolve(spec) {
                Ok(bank) => {
                    index.insert(spec, banks.len());
                    bank_of.push(Some(banks.len()));
                    banks.push(bank);
                }
                Err(message) => {
                    problems.push(Problem {
                        path: format!("objects[{i}].bank"),
                        message,
                    });
                    bank_of.push(None);
                }
            }
        }
        problems.extend(physics::check_places(&file));
        if !problems.is_empty() {
            return Err(SceneError {
                origin: origin.to_string(),
                problems,
            });
        }
        // Controls are checked before anything is simulated.
        for (i, o) in file.objects.iter().enumerate() {
            let Some(k) = bank_of[i] else { continue };
            Self::controls(o, &banks[k]).map_err(|(name, message)| {
                invalid(vec![Problem {
                    path: format!("objects[{i}].set.{name}"),
                    message,
                }])
            })?;
        }
        let started = std::time::Instant::now();
        let simulated = physics::simulate(&file);
        let physics_s = started.elapsed().as_secs_f64();
        let mut events = file.events.clone();
        events.extend(simulated.events);
        Ok(Self {
            file,
            banks,
            bank_of,
            events,
            physics_steps: simulated.steps,
            physics_s,
            events_capped: simulated.capped,
        })
    }

    /// The scene.
    pub fn file(&self) -> &SceneFile {
        &self.file
    }

    /// Every event, the file's and the impacts its physics found.
    pub fn events(&self) -> &[SceneEvent] {
        &self.events
    }

    /// Whether the physics found more impacts than a scene may hold (the rest left out).
    pub fn events_capped(&self) -> bool {
        self.events_capped
    }

    /// Physics steps taken, and the seconds they took.
    pub fn physics_cost(&self) -> (usize, f64) {
        (self.physics_steps, self.physics_s)
    }

    /// The object's controls: the bank's defaults, the scene's (key tracking and the velocity's
    /// hardness off, a linear velocity curve, width 0, the scale as the size), then its `set`.
    fn controls(o: &SceneObject, bank: &Bank) -> Result<Controls, (String, String)> {
        let mut c = Controls::for_bank(bank);
        c.key_tracking = 0.0;
        c.velocity_sensitivity = 0.5;
        c.velocity_to_hardness = 0.0;
        c.width = 0.0;
        c.size_ratio = o.scale as f32;
        for (name, value) in &o.set {
            if let Some(instead) = SET_BY_THE_SCENE.iter().find(|(n, _)| n == name) {
                return Err((name.clone(), format!("set by the scene: {}", instead.1)));
            }
            c.set_by_name(name, value).map_err(|e| (name.clone(), e))?;
        }
        Ok(c)
    }
}

/// A bank named in a scene: a factory bank's name (no folder, no extension), else a file,
/// relative to `dir`.
fn resolve_bank(spec: &str, dir: &Path) -> Result<Bank, String> {
    let path = Path::new(spec);
    let bare = path.components().count() == 1 && path.extension().is_none();
    if bare {
        if let Some(bank) = factory_bank(spec) {
            return Ok(bank);
        }
    }
    let file = dir.join(path);
    if !file.exists() {
        return Err(if bare {
            format!(
                "no factory bank named \"{spec}\" and no file {} (`modal-resonator list` shows \
                 the factory banks)",
                file.display()
            )
        } else {
            format!("no bank file {}", file.display())
        });
    }
    load_bank_file(&file).map_err(|e| e.to_string())
}

/// What a scene holds and did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SceneStats {
    /// Objects.
    pub objects: usize,
    /// Impacts.
    pub impacts: usize,
    /// Contacts.
    pub contacts: usize,
}

/// A scene prepared to play: step it with [`Scene::process`]. Building allocates; processing
/// never does. The same blocks give the same samples; other block sizes may differ in the last
/// bits (an idle object's engine waits, so its control ticks fall where its blocks do).
pub struct Scene {
    /// The objects.
    objects: Vec<SoundingObject>,
    /// Sample at the listener of the next block's start.
    clock: u64,
    /// Largest block.
    max_block: usize,
    /// The sample at the listener of the last event.
    last_event: u64,
    /// Counts.
    stats: SceneStats,
}

impl Scene {
    /// Prepares `source` to play at `sample_rate_hz` in blocks of at most `max_block` samples.
    pub fn new(source: &SceneSource, sample_rate_hz: u32, max_block: usize) -> Self {
        let max_block = max_block.max(1);
        let rate = sample_rate_hz as f64;
        let prepared: Vec<Arc<PreparedBank>> = source
            .banks
            .iter()
            .map(|b| Arc::new(PreparedBank::new(b)))
            .collect();
        let file = &source.file;
        let mut by_object: Vec<Vec<&SceneEvent>> = vec![Vec::new(); file.objects.len()];
        let index: HashMap<&str, usize> = file
            .objects
            .iter()
            .enumerate()
            .map(|(i, o)| (o.name.as_str(), i))
            .collect();
        for e in &source.events {
            by_object[index[e.object.as_str()]].push(e);
        }
        let mut stats = SceneStats {
            objects: file.objects.len(),
            ..SceneStats::default()
        };
        let objects: Vec<SoundingObject> = file
            .objects
            .iter()
            .enumerate()
            .filter_map(|(i, o)| Some((i, o, source.bank_of[i]?)))
            .map(|(i, o, k)| {
                let bank = &source.banks[k];
                let controls = SceneSource::controls(o, bank)
                    .expect("controls were checked when the scene was read");
                let placement = place(&file.listener, o.position);
                let r = placement.distance_m;
                let scale = o.scale;
                // The air's absorption over the distance, at each mode's frequency as played.
                let heard = prepared[k].with_mode_gains(|f| {
                    db_to_gain((-air_absorption_db_per_m(f / scale) * r) as f32)
                });
                let events = &by_object[i];
                let fastest = events
                    .iter()
                    .filter_map(|e| e.impact.map(|x| x.strength()))
                    .fold(REFERENCE_SPEED_M_PER_S, f64::max);
                let parts = parts(&controls, events, fastest, rate, &mut stats);
                let gain = db_to_gain(o.gain_db as f32) as f64;
                SoundingObject::new(&Arc::new(heard), parts, &placement, gain, rate, max_block)
            })
            .collect();
        let last_event = objects
            .iter()
            .filter_map(SoundingObject::last_event_sample)
            .max()
            .unwrap_or(0);
        Self {
            objects,
            clock: 0,
            max_block,
            last_event,
            stats,
        }
    }

    /// The next `left.len()` samples at the listener (at most the block size given to
    /// [`Scene::new`]), written to `left` and `right`.
    pub fn process(&mut self, left: &mut [f32], right: &mut [f32]) {
        assert!(left.len() <= self.max_block && left.len() == right.len());
        left.fill(0.0);
        right.fill(0.0);
        for o in &mut self.objects {
            o.add_to(self.clock, left, right);
        }
        self.clock += left.len() as u64;
    }

    /// Whether every event has been played and everything has fallen silent.
    pub fn is_done(&self) -> bool {
        self.objects.iter().all(SoundingObject::is_done)
    }

    /// The sample at the listener where the last event begins to be heard.
    pub fn last_event_sample(&self) -> u64 {
        self.last_event
    }

    /// What the scene holds.
    pub fn stats(&self) -> SceneStats {
        self.stats
    }
}

/// An object's parts: an engine for its impacts and one for its contacts, each with its events
/// as notes scheduled at `rate` and its gain: impacts at velocity `strength / fastest`, their
/// output scaled by `fastest` (in m/s over the reference speed); contacts at velocity 1 and
/// gain 1, their level set by their force curves.
fn parts(
    controls: &Controls,
    events: &[&SceneEvent],
    fastest: f64,
    rate: f64,
    stats: &mut SceneStats,
) -> Vec<(Controls, Vec<crate::render::TimedEvent>, f64)> {
    let mut strikes = Vec::new();
    let mut contacts = Vec::new();
    for e in events {
        if let Some(impact) = e.impact {
            strikes.push(Note::new(
                KEY,
                (impact.strength() / fastest) as f32,
                e.time_s,
                None,
            ));
        }
        if let Some(c) = e.contact {
            contacts.push(Note {
                key: KEY,
                velocity: 1.0,
                time_s: e.time_s,
                duration_s: Some(c.duration_s),
                speed_m_per_s: Some((c.speed_m_per_s[0], c.speed_m_per_s[1])),
                force: Some((c.force[0], c.force[1])),
            });
        }
    }
    stats.impacts += strikes.len();
    stats.contacts += contacts.len();
    let mut out = Vec::new();
    let until_s = f64::INFINITY;
    if !strikes.is_empty() {
        let mut c = controls.clone();
        if c.exciter.is_contact() {
            c.exciter = ExciterKind::Mallet;
        }
        out.push((
            c,
            schedule(&strikes, rate, until_s),
            fastest / REFERENCE_SPEED_M_PER_S,
        ));
    }
    if !contacts.is_empty() {
        let mut c = controls.clone();
        if !c.exciter.is_contact() {
            c.exciter = ExciterKind::Scrape;
        }
        out.push((c, schedule(&contacts, rate, until_s), 1.0));
    }
    out
}

/// What [`render_scene`] made.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderedScene {
    /// Left channel.
    pub left: Vec<f32>,
    /// Right channel.
    pub right: Vec<f32>,
    /// Whether `max_seconds` cut it while it still sounded.
    pub cut_short: bool,
    /// What the scene held.
    pub stats: SceneStats,
}

/// What [`render_scene_to`] rendered.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneSummary {
    /// Samples per channel.
    pub len: usize,
    /// Largest sample magnitude.
    pub peak: f32,
    /// Whether `max_seconds` cut it while it still sounded.
    pub cut_short: bool,
    /// What the scene held.
    pub stats: SceneStats,
}

/// Renders `source` at `sample_rate_hz` into memory, as [`render_scene_to`] renders it.
pub fn render_scene(
    source: &SceneSource,
    sample_rate_hz: u32,
    max_seconds: f64,
    progress: impl FnMut(f64),
) -> RenderedScene {
    let (mut left, mut right) = (Vec::new(), Vec::new());
    let sink = |l: &[f32], r: &[f32]| {
        left.extend_from_slice(l);
        right.extend_from_slice(r);
        Ok::<(), std::convert::Infallible>(())
    };
    let Ok(summary) = render_scene_to(source, sample_rate_hz, max_seconds, progress, sink);
    RenderedScene {
        left,
        right,
        cut_short: summary.cut_short,
        stats: summary.stats,
    }
}

/// Samples a scene is rendered in at a time.
const RENDER_BLOCK: usize = 256;

/// Renders `source` at `sample_rate_hz`, handing the stereo samples to `sink` in order as they
/// are made, up to `max_seconds` (the last 10 ms before it faded out, for a scene still
/// sounding there), [`TAIL_S`] of silence kept after the last sound or event; `progress` hears
/// the share done (an estimate until the end). Memory does not grow with the length: only a
/// run of silence, counted, waits before going to the sink. Stops at the first error of `sink`.
pub fn render_scene_to<E>(
    source: &SceneSource,
    sample_rate_hz: u32,
    max_seconds: f64,
    mut progress: impl FnMut(f64),
    mut sink: impl FnMut(&[f32], &[f32]) -> Result<(), E>,
) -> Result<SceneSummary, E> {
    let rate = sample_rate_hz as f64;
    let max_samples = (max_seconds.max(0.0) * rate).round() as usize;
    let fade_len = ((0.01 * rate) as usize).clamp(1, max_samples.max(1));
    let fade_start = max_samples.saturating_sub(fade_len);
    let mut scene = Scene::new(source, sample_rate_hz, RENDER_BLOCK);
    let (mut l, mut r) = (vec![0.0f32; RENDER_BLOCK], vec![0.0f32; RENDER_BLOCK]);
    // Samples given to the sink, and silence made since, held back.
    let (mut written, mut pos) = (0usize, 0usize);
    let mut peak = 0.0f32;
    let estimate = (scene.last_event_sample() as f64 + 2.0 * rate).min(max_samples as f64);
    while pos < max_samples && !(scene.is_done() && pos as u64 > scene.last_event) {
        let n = RENDER_BLOCK.min(max_samples - pos);
        scene.process(&mut l[..n], &mut r[..n]);
        for k in (fade_start.max(pos) - pos)..n {
            let g = 1.0 - (pos + k - fade_start + 1) as f32 / fade_len as f32;
            l[k] *= g;
            r[k] *= g;
        }
        if let Some(k) = (0..n).rev().find(|&k| l[k] != 0.0 || r[k] != 0.0) {
            write_silence(&mut sink, pos - written)?;
            sink(&l[..=k], &r[..=k])?;
            peak = l[..=k]
                .iter()
                .chain(&r[..=k])
                .fold(peak, |a, v| a.max(v.abs()));
            written = pos + k + 1;
        }
        pos += n;
        progress((pos as f64 / estimate.max(1.0)).min(0.99));
    }
    let cut_short = !scene.is_done();
    let end = if cut_short {
        pos
    } else {
        // Silent from `written` on: the tail's silence after the last sound or event.
        let heard_to = written.max(scene.last_event_sample() as usize + 1);
        (heard_to + (TAIL_S * rate) as usize).min(max_samples)
    };
    write_silence(&mut sink, end.saturating_sub(written))?;
    progress(1.0);
    Ok(SceneSummary {
        len: end.max(written),
        peak,
        cut_short,
        stats: scene.stats(),
    })
}

/// Hands `n` samples of silence to `sink`, a block at a time.
fn write_silence<E>(
    sink: &mut impl FnMut(&[f32], &[f32]) -> Result<(), E>,
    mut n: usize,
) -> Result<(), E> {
    let zeros = [0.0f32; RENDER_BLOCK];
    while n > 0 {
        let k = n.min(RENDER_BLOCK);
        sink(&zeros[..k], &zeros[..k])?;
        n -= k;
    }
    Ok(())
}
