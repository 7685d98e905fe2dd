//! Voices and routing: the single entry used by the plugin, the renderer, the tests and the
//! benchmarks.
//!
//! # Lifecycle
//! - [`Engine::new`] is cheap and allocates no voices.
//! - [`Engine::reserve_voices`] says how many notes at once the voices are for (every voice
//!   by default; a large bank gets only what the polyphony needs).
//! - [`Engine::prepare`] sizes everything for a sample rate and allocates.
//! - [`Engine::set_bank`] swaps the bank, reusing storage when it is large enough.
//! - [`Engine::reset`] silences every voice without allocating.
//! - [`Engine::process`] never allocates, locks, logs or does I/O.
//!
//! # Timing
//! Control values are smoothed and applied on a fixed grid of [`CONTROL_PERIOD`] samples counted
//! from the last reset, and note events land on their exact sample, so the output does not depend
//! on how the host cuts the stream into blocks.

mod budget;
mod controls;
mod crossfade;
mod expression;
mod midi;
mod mix;
mod mode_fade;
mod pitch_level;
mod position;
mod prepared;
mod pruning;
mod stereo;
mod voice;

use std::sync::Arc;

/// How a note excites the bank: the engine's controls name it, the layers above set it.
pub use crate::dsp::ExciterKind;
pub use controls::{
    control_range, ControlSpec, Controls, ExpressionTarget, Material, ANALYSIS_FRAME_RANGE_MS,
    CONTACT_SPEED_MAX_M_PER_S, HARDNESS_RANGE_MS, MASKING_OFFSET_RANGE_DB, MATERIAL_Q_RANGE,
    MAX_MODE_BUDGET, MAX_POLYPHONY, MAX_TARGET_LOAD_PCT, MPE_DEFAULT_BEND_RANGE_SEMITONES,
    NUMERIC_CONTROLS, PLAYBACK_LEVEL_RANGE_DB_SPL, VARIATION_CENTS, VARIATION_DECAY,
    VARIATION_GAIN_DB,
};
pub use crossfade::BankCrossfade;
pub use expression::{ControlChange, Controllers};
pub use midi::{bend_of, MidiInput, MidiMessage, CHANNELS, MPE_MANAGER_CHANNEL, SLIDE_CC};
pub use mix::{
    mix_to_mono, Bypass, DryWet, OnsetTrigger, OutputStage, BANK_CROSSFADE_S, BYPASS_FADE_S,
};
pub use position::{PositionMap, PositionWeights, StrikeAxis};
pub use prepared::{PreparedBank, TARGET_PEAK};
use pruning::Pruner;
pub use pruning::PruningStats;
use stereo::lane_weights;
use voice::{PendingStrike, Tuning, Voice, VoiceOverrides, VoiceState};

use crate::bank::format::MIN_DECAY_PER_S;
use crate::dsp::denormal::FlushDenormals;
use crate::dsp::{Kernel, COLUMNS};
use crate::rng::Rng;
use crate::units::{db_to_gain, t60_to_decay};

/// Samples between control updates: smoothing steps, coefficient updates and mode truncation.
pub const CONTROL_PERIOD: usize = 64;

/// Decay multiplier at full extra damping.
const MAX_EXTRA_DAMPING: f64 = 20.0;

/// Largest per-note tuning offset, in semitones.
const MAX_EXPRESSION_SEMITONES: f32 = 48.0;

/// Voices beyond the polyphony limit, used by stolen voices while they fade (fewer when fewer
/// voices are allocated).
const FADE_SLOTS: usize = 8;

/// Heap the voices of an engine may take whatever polyphony was asked for: a bank small enough
/// gets every voice, so raising the polyphony never reallocates; a larger one gets the voices
/// the polyphony needs.
const VOICE_MEMORY_ALLOWANCE: usize = 64 << 20;

/// Heap a voice takes per mode of its bank, to within a few percent: its resonators (a slot and
/// a ghost slot per mode) and its share of the pruner's per-voice analysis.
const VOICE_BYTES_PER_MODE: usize = 288;

/// How long a stolen voice fades, in seconds.
const STEAL_FADE_S: f64 = 0.005;

/// Time constant of pitch smoothing, in seconds: a 2-semitone bend in 10 ms is followed closely.
const PITCH_SMOOTHING_S: f64 = 0.002;

/// Time constant of material (Q, tilt) smoothing, in seconds.
const DAMPING_SMOOTHING_S: f64 = 0.02;

/// Time constant of output gain smoothing, in seconds.
const GAIN_SMOOTHING_S: f64 = 0.01;

/// Most ended voices kept between two calls to [`Engine::take_ended_voices`]; more are not
/// reported.
const MAX_ENDED: usize = 4 * (MAX_POLYPHONY + FADE_SLOTS);

/// Time constant of input gain smoothing, in seconds.
const INPUT_GAIN_SMOOTHING_S: f64 = 0.01;

/// Seed of the engine's random numbers (strike variation, noise), restored by `reset`.
const SEED: u32 = 0x5EED_0001;

/// Notes at once that voices are allocated for, for a bank of `num_modes` modes and `polyphony`
/// asked: at least `polyphony`, and every voice that fits in [`VOICE_MEMORY_ALLOWANCE`] (fade
/// slots and the input voice counted).
fn voices_for(num_modes: usize, polyphony: usize) -> usize {
    let fit = VOICE_MEMORY_ALLOWANCE / (VOICE_BYTES_PER_MODE * num_modes.max(1));
    let affordable = (1..=MAX_POLYPHONY)
        .rev()
        .find(|&c| c + c.min(FADE_SLOTS) < fit)
        .unwrap_or(0);
    polyphony.clamp(1, MAX_POLYPHONY).max(affordable)
}

/// Which note an event is about: a key on a MIDI channel, and the host's id for the note when it
/// gives one (CLAP note ids).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Note {
    /// MIDI key, 0 to 127 (larger values match no voice by key).
    pub key: u8,
    /// MIDI channel, 0 to 15: notes on different channels are different voices (MPE).
    pub channel: u8,
    /// The host's id for the note, if any.
    pub id: Option<i32>,
}

impl Note {
    /// `key` on the first channel, without an id.
    pub const fn key(key: u8) -> Self {
        Self {
            key,
            channel: 0,
            id: None,
        }
    }

    /// Whether this note names voice `v`: by id when both have one, else by key and channel.
    fn names(&self, v: &Voice) -> bool {
        match (self.id, v.id) {
            (Some(a), Some(b)) if a == b => true,
            _ => v.key == self.key && v.channel == self.channel,
        }
    }
}

/// A note event at a sample offset within the block passed to [`Engine::process`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NoteEvent {
    /// Strike `note` with `velocity` (0 to 1; 0 acts as a note-off).
    On {
        time: u32,
        note: Note,
        velocity: f32,
    },
    /// Release `note`.
    Off { time: u32, note: Note },
    /// Release every note (MIDI CC 123).
    AllNotesOff { time: u32 },
    /// Silence every voice at once (MIDI CC 120).
    AllSoundOff { time: u32 },
    /// Silence the voice of `note` at once (a hi-hat choke; CLAP choke events).
    Choke { time: u32, note: Note },
    /// Change the sounding `note` alone (CLAP note expressions).
    Expression {
        time: u32,
        note: Note,
        expression: NoteExpression,
    },
    /// Change every note sounding on `channel` (MPE: a member channel's bend and pressure).
    ChannelExpression {
        time: u32,
        channel: u8,
        expression: NoteExpression,
    },
    /// Set a control of the voice the host knows as `id` alone (CLAP polyphonic modulation).
    Modulate {
        time: u32,
        id: i32,
        modulation: VoiceModulation,
    },
    /// A channel-wide controller moves (pitch bend, mod wheel, channel pressure): the controls
    /// follow it from this sample ([`Controls::expressed`]).
    Controller { time: u32, change: ControlChange },
}

/// A per-note change.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NoteExpression {
    /// Tuning offset in semitones, smoothed like pitch bend.
    Tuning(f32),
    /// Pressure 0 to 1: the force of a contact note (scrape, roll, rub); on a struck note, damping
    /// like a hand pressing on the object.
    Pressure(f32),
    /// Slide 0 to 1 (MPE's CC 74, CLAP's brightness): the speed of a contact note, from still
    /// to the fastest contact speed.
    Slide(f32),
    /// The speed of a contact note in m/s (a rendered note's speed curve), as a slide sets it.
    ContactSpeed(f32),
}

/// A control one voice holds in place of the engine's, in the same units as [`Controls`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VoiceModulation {
    /// Fine tune in cents.
    FineTuneCents(f32),
    /// Size ratio (pitch falls as size grows).
    SizeRatio(f32),
    /// Strike position along the first axis, 0 to 1.
    StrikeX(f32),
    /// Strike position along the second axis, 0 to 1.
    StrikeY(f32),
    /// Mallet contact time in milliseconds.
    HardnessMs(f32),
    /// Contact speed in m/s (while no slide sets it).
    ContactSpeed(f32),
    /// Contact force at full velocity, 0 to 1 (until the note's own pressure sets it).
    ContactForce(f32),
}

impl VoiceModulation {
    /// The modulation clamped to its control's range, or `None` when its value is NaN.
    fn sanitized(self) -> Option<Self> {
        let (name, value) = match self {
            VoiceModulation::FineTuneCents(v) => ("fine_tune_cents", v),
            VoiceModulation::SizeRatio(v) => ("size_ratio", v),
            VoiceModulation::StrikeX(v) => ("strike_x", v),
            VoiceModulation::StrikeY(v) => ("strike_y", v),
            VoiceModulation::HardnessMs(v) => ("hardness_ms", v),
            VoiceModulation::ContactSpeed(v) => ("contact_speed_m_per_s", v),
            VoiceModulation::ContactForce(v) => ("contact_force", v),
        };
        if value.is_nan() {
            return None;
        }
        let spec = NUMERIC_CONTROLS.iter().find(|s| s.name == name)?;
        let v = value.clamp(spec.min, spec.max);
        Some(match self {
            VoiceModulation::FineTuneCents(_) => VoiceModulation::FineTuneCents(v),
            VoiceModulation::SizeRatio(_) => VoiceModulation::SizeRatio(v),
            VoiceModulation::StrikeX(_) => VoiceModulation::StrikeX(v),
            VoiceModulation::StrikeY(_) => VoiceModulation::StrikeY(v),
            VoiceModulation::HardnessMs(_) => VoiceModulation::HardnessMs(v),
            VoiceModulation::ContactSpeed(_) => VoiceModulation::ContactSpeed(v),
            VoiceModulation::ContactForce(_) => VoiceModulation::ContactForce(v),
        })
    }
}

/// A voice that stopped sounding, so a host can release what it keeps for the note.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EndedVoice {
    /// Sample offset within the block of the `process` call in which it ended.
    pub time: u32,
    /// The note it played.
    pub note: Note,
}

impl NoteEvent {
    /// Strike `key` on the first channel.
    pub const fn on(time: u32, key: u8, velocity: f32) -> Self {
        NoteEvent::On {
            time,
            note: Note::key(key),
            velocity,
        }
    }

    /// Release `key` on the first channel.
    pub const fn off(time: u32, key: u8) -> Self {
        NoteEvent::Off {
            time,
            note: Note::key(key),
        }
    }

    /// Sample offset of the event within its block.
    pub fn time(&self) -> u32 {
        match *self {
            NoteEvent::On { time, .. }
            | NoteEvent::Off { time, .. }
            | NoteEvent::AllNotesOff { time }
            | NoteEvent::AllSoundOff { time }
            | NoteEvent::Choke { time, .. }
            | NoteEvent::Expression { time, .. }
            | NoteEvent::ChannelExpression { time, .. }
            | NoteEvent::Modulate { time, .. }
            | NoteEvent::Controller { time, .. } => time,
        }
    }

    /// The same event at sample `time`.
    pub fn at(mut self, at: u32) -> Self {
        match &mut self {
            NoteEvent::On { time, .. }
            | NoteEvent::Off { time, .. }
            | NoteEvent::AllNotesOff { time }
            | NoteEvent::AllSoundOff { time }
            | NoteEvent::Choke { time, .. }
            | NoteEvent::Expression { time, .. }
            | NoteEvent::ChannelExpression { time, .. }
            | NoteEvent::Modulate { time, .. }
            | NoteEvent::Controller { time, .. } => *time = at,
        }
        self
    }
}

/// How far the decay table lags the smoothed material.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Stale {
    /// Up to date.
    Fresh,
    /// Q moved: rescale the tilted decays.
    Damping,
    /// Tilt moved (or a new bank): recompute the tilted decays too.
    Tilt,
}

/// What the engine is doing, for meters.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EngineStats {
    /// Voices sounding (not counting fading or input voices).
    pub voices: usize,
    /// Modes above the truncation threshold, over all voices.
    pub live_modes: usize,
    /// Modes the kernels advance per sample (live modes plus row padding).
    pub computed_modes: usize,
    /// Live modes switched off by pruning or the budget, their state carried analytically.
    pub dormant_modes: usize,
    /// Modes fading in or out.
    pub fading_modes: usize,
    /// Mode-samples computed since the engine was prepared (row padding included).
    pub computed_mode_samples: u64,
}

/// Smoothed values and ramps that change on control ticks.
#[derive(Debug, Clone)]
struct Smoothed {
    /// Natural log of the decay multiplier `Q_ref / Q`.
    log_damping: f64,
    /// Damping tilt.
    tilt: f64,
    /// Output gain, linear, smoothed per sample.
    gain: f32,
    /// Input gain, linear, smoothed per sample.
    input_gain: f32,
    /// Left and right column weights now.
    weights: ([f32; COLUMNS], [f32; COLUMNS]),
    /// Per-sample change of the weights while ramping.
    weight_step: ([f32; COLUMNS], [f32; COLUMNS]),
    /// Where the weight ramp ends.
    weight_target: ([f32; COLUMNS], [f32; COLUMNS]),
    /// Samples left in the weight ramp.
    weight_ramp_left: usize,
}

/// The modal synthesis engine.
pub struct Engine {
    /// The bank being played.
    bank: Arc<PreparedBank>,
    /// Control targets as set, sanitised.
    controls: Controls,
    /// Where the channel-wide controllers are.
    controllers: Controllers,
    /// Control targets as the controllers move them: what plays.
    expressed: Controls,
    /// Resonator implementation.
    kernel: Kernel,
    /// Sample rate in Hz.
    sample_rate_hz: f64,
    /// Voice pool once prepared: `capacity` voices and up to `FADE_SLOTS` more for stolen
    /// voices while they fade.
    voices: Vec<Voice>,
    /// Notes the voices can play at once: the polyphony control is held to it.
    capacity: usize,
    /// The polyphony voices are allocated for (see [`Engine::reserve_voices`]).
    reserved_polyphony: usize,
    /// The voice driven by the audio input.
    input_voice: Option<Voice>,
    /// Whether the input voice has had non-silent input since the last control tick.
    input_heard: bool,
    /// Whether the input voice has lost modes to truncation since input last started them.
    input_dormant: bool,
    /// Decay rate of each mode with the smoothed damping tilt applied, before Q and pitch.
    tilted_decay: Vec<f64>,
    /// Every mode's gain at the strike point of the strike in hand.
    strike_gains: Vec<f32>,
    /// Damped decay rate of each mode at the smoothed material, before pitch scaling.
    decay: Vec<f64>,
    /// How far `decay` lags the smoothed material.
    decay_stale: Stale,
    /// Incremented whenever `decay` changes.
    damping_version: u64,
    /// Smoothed controls.
    smoothed: Smoothed,
    /// Samples since reset.
    clock: u64,
    /// Voices allocated so far, for ages.
    allocations: u64,
    /// The last key struck, which tunes the input voice.
    last_key: Option<u8>,
    /// Strike position variation.
    rng: Rng,
    /// Per-sample column sums of the current run.
    acc: Vec<[f32; COLUMNS]>,
    /// Column sums of one fading voice.
    fade_acc: Vec<[f32; COLUMNS]>,
    /// Excitation of one voice for the current run.
    excitation: Vec<f32>,
    /// Voices that stopped sounding since the host last asked.
    ended: Vec<EndedVoice>,
    /// Sample offset within the current `process` call.
    block_pos: u32,
    /// Most voices sounding at once since [`Engine::take_peak_voices`] was last called,
    /// counted as notes strike, so a voice struck and ended within one block counts.
    peak_voices: usize,
    /// Perceptual pruning.
    pruner: Pruner,
    /// The computation budget.
    budget: budget::Budget,
}

impl Engine {
    /// An engine for `bank` with its default controls. Cheap: voices are allocated by
    /// [`Engine::prepare`].
    pub fn new(bank: Arc<PreparedBank>) -> Self {
        let controls = Controls::for_bank(&bank.source);
        let smoothed = Smoothed {
            log_damping: 0.0,
            tilt: 0.0,
            gain: 1.0,
            input_gain: 1.0,
            weights: lane_weights(controls.width, &bank.column_pan),
            weight_target: lane_weights(controls.width, &bank.column_pan),
            weight_step: ([0.0; COLUMNS], [0.0; COLUMNS]),
            weight_ramp_left: 0,
        };
        Self {
            bank,
            expressed: controls.clone(),
            controllers: Controllers::default(),
            controls,
            kernel: Kernel::from_env_or_detect(),
            sample_rate_hz: 48_000.0,
            voices: Vec::new(),
            capacity: 0,
            reserved_polyphony: MAX_POLYPHONY,
            input_voice: None,
            input_heard: false,
            input_dormant: true,
            tilted_decay: Vec::new(),
            strike_gains: Vec::new(),
            decay: Vec::new(),
            decay_stale: Stale::Tilt,
            damping_version: 0,
            smoothed,
            clock: 0,
            allocations: 0,
            last_key: None,
            rng: Rng::new(SEED),
            acc: Vec::new(),
            fade_acc: Vec::new(),
            excitation: Vec::new(),
            ended: Vec::new(),
            block_pos: 0,
            peak_voices: 0,
            pruner: Pruner::new(),
            budget: budget::Budget::default(),
        }
    }

    /// Sizes everything for `sample_rate_hz` and resets. Allocates. Blocks of any length can be
    /// processed afterwards; `_max_block` is accepted for hosts that announce it. The first
    /// engine prepared in a process also measures its speed for the automatic budget (a few
    /// milliseconds): never call it on the audio thread.
    pub fn prepare(&mut self, sample_rate_hz: f32, _max_block: usize) {
        self.prepare_storage(sample_rate_hz);
        self.budget.calibrate(self.kernel, self.sample_rate_hz);
    }

    /// [`Engine::prepare`] without measuring the engine's speed.
    fn prepare_storage(&mut self, sample_rate_hz: f32) {
        assert!(
            sample_rate_hz.is_finite() && sample_rate_hz > 0.0,
            "sample rate {sample_rate_hz} Hz is not supported"
        );
        self.sample_rate_hz = sample_rate_hz as f64;
        self.acc = vec![[0.0; COLUMNS]; CONTROL_PERIOD];
        self.fade_acc = vec![[0.0; COLUMNS]; CONTROL_PERIOD];
        self.excitation = vec![0.0; CONTROL_PERIOD];
        self.ended = Vec::with_capacity(MAX_ENDED);
        self.allocate_voices();
        self.reset();
    }

    /// Plays `bank` from now on, silencing every voice. Allocates only when the bank has more
    /// modes than the voices can hold. Call it off the audio thread, or with storage known to fit.
    pub fn set_bank(&mut self, bank: Arc<PreparedBank>) {
        self.bank = bank;
        let fits = self
            .voices
            .first()
            .is_some_and(|v| v.modes.num_modes() >= self.bank.num_modes());
        if !self.voices.is_empty() && !fits {
            self.allocate_voices();
        } else {
            self.end_all_voices();
        }
        self.decay.resize(self.bank.num_modes(), 0.0);
        self.tilted_decay.resize(self.bank.num_modes(), 0.0);
        self.strike_gains.resize(self.bank.num_modes(), 0.0);
        self.input_dormant = true;
        self.decay_stale = Stale::Tilt;
        self.rebuild_decay_table();
    }

    /// Allocates voices for up to `polyphony` notes at once (1 to [`MAX_POLYPHONY`]; the default
    /// is every voice), or for more when the bank is small enough that more fit in 64 MiB. The
    /// polyphony control plays at most [`Engine::voice_capacity`] notes. Allocates, and
    /// silences every voice when the engine is already prepared: call it before
    /// [`Engine::prepare`], off the audio thread.
    pub fn reserve_voices(&mut self, polyphony: usize) {
        self.reserved_polyphony = polyphony.clamp(1, MAX_POLYPHONY);
        if !self.voices.is_empty()
            && voices_for(self.bank.num_modes(), self.reserved_polyphony) != self.capacity
        {
            self.allocate_voices();
            self.reset();
        }
    }

    /// Notes the allocated voices can play at once (0 before [`Engine::prepare`]).
    pub fn voice_capacity(&self) -> usize {
        self.capacity
    }

    fn allocate_voices(&mut self) {
        let n = self.bank.num_modes();
        self.capacity = voices_for(n, self.reserved_polyphony);
        self.voices = (0..self.capacity + self.capacity.min(FADE_SLOTS))
            .map(|i| Voice::new(n, SEED ^ (i as u32 + 1)))
            .collect();
        self.input_voice = Some(Voice::new(n, SEED ^ 0xFFFF));
        self.pruner.reserve(self.voices.len() + 1, n);
        self.decay = vec![0.0; n];
        self.tilted_decay = vec![0.0; n];
        self.strike_gains = vec![0.0; n];
    }

    /// Silences every voice and restarts smoothing and random sequences. Does not allocate.
    pub fn reset(&mut self) {
        for v in self.voices.iter_mut().chain(self.input_voice.as_mut()) {
            v.free();
        }
        self.clock = 0;
        self.allocations = 0;
        self.last_key = None;
        self.input_heard = false;
        self.input_dormant = true;
        self.rng = Rng::new(SEED);
        self.pruner.forget();
        // A reset ends every note for the host too: nothing left to report.
        self.ended.clear();
        let (log_damping, tilt) = self.damping_targets();
        self.smoothed = Smoothed {
            log_damping,
            tilt,
            gain: db_to_gain(self.expressed.output_gain_db),
            input_gain: db_to_gain(self.expressed.input_gain_db),
            weights: lane_weights(self.expressed.width, &self.bank.column_pan),
            weight_target: lane_weights(self.expressed.width, &self.bank.column_pan),
            weight_step: ([0.0; COLUMNS], [0.0; COLUMNS]),
            weight_ramp_left: 0,
        };
        self.decay_stale = Stale::Tilt;
        self.rebuild_decay_table();
    }

    /// The bank being played.
    pub fn bank(&self) -> &Arc<PreparedBank> {
        &self.bank
    }

    /// The control targets as set (before the controllers move them).
    pub fn controls(&self) -> &Controls {
        &self.controls
    }

    /// Sets the control targets (sanitised: out-of-range values are clamped, NaN takes the
    /// default), which the channel-wide controllers then move. Changes are smoothed from the
    /// next control tick. Does not allocate.
    pub fn set_controls(&mut self, controls: &Controls) {
        self.controls = controls.sanitized();
        self.expressed = self.controls.expressed(&self.controllers).sanitized();
    }

    /// Where the channel-wide controllers are.
    pub fn controllers(&self) -> Controllers {
        self.controllers
    }

    /// Puts the channel-wide controllers where `controllers` has them (an engine taking over
    /// from another, where the player left the wheels).
    pub fn set_controllers(&mut self, controllers: Controllers) {
        self.controllers = Controllers::default();
        for change in [
            ControlChange::Bend(controllers.bend),
            ControlChange::ModWheel(controllers.mod_wheel),
            ControlChange::Pressure(controllers.pressure),
        ] {
            self.controllers.apply(change);
        }
        self.expressed = self.controls.expressed(&self.controllers).sanitized();
    }

    /// The resonator implementation in use.
    pub fn kernel(&self) -> Kernel {
        self.kernel
    }

    /// Uses `kernel` from now on (it must be supported by this CPU), with its cost for the
    /// automatic budget (measured the first time a kernel is used in this process: a few
    /// milliseconds, not on the audio thread).
    pub fn set_kernel(&mut self, kernel: Kernel) {
        assert!(
            kernel.is_supported(),
            "kernel {} is not supported here",
            kernel.name()
        );
        self.kernel = kernel;
        if !self.voices.is_empty() {
            self.budget.calibrate(kernel, self.sample_rate_hz);
        }
    }

    /// Sample rate in Hz.
    pub fn sample_rate_hz(&self) -> f32 {
        self.sample_rate_hz as f32
    }

    /// The most voices that sounded at once since the last call (or since the engine was
    /// prepared), counting a voice struck and ended within one block; starts the count again
    /// from the voices sounding now. For a render's summary; does not allocate.
    pub fn take_peak_voices(&mut self) -> usize {
        let now = self.voices.iter().filter(|v| v.is_sounding()).count();
        std::mem::replace(&mut self.peak_voices, now).max(now)
    }

    /// Meters.
    pub fn stats(&self) -> EngineStats {
        let mut s = EngineStats::default();
        for v in self.voices.iter().chain(self.input_voice.as_ref()) {
            s.voices += v.is_sounding() as usize;
            s.live_modes += v.modes.num_live();
            s.computed_modes += v.modes.num_computed(self.kernel);
            s.dormant_modes += v.modes.num_dormant();
            s.fading_modes += v.modes.num_fading();
            s.computed_mode_samples += v.modes.computed_mode_samples();
        }
        s
    }

    /// Calls `visit(mode, energy)` for every mode sounding in a voice (the input voice
    /// included), computed or switched off by pruning, with its squared amplitude `|z|^2`; a
    /// mode sounding in several voices is visited once per voice. Modes are numbered as in [`PreparedBank`] (ascending frequency).
    /// Modes never visited are silent everywhere: truncated, not struck, or above the highest
    /// frequency played. For meters: does not allocate.
    pub fn visit_mode_energies(&self, mut visit: impl FnMut(usize, f32)) {
        for v in self.voices.iter().chain(self.input_voice.as_ref()) {
            v.modes.visit_energies(&mut visit);
        }
    }

    /// Silences every voice at once, reporting each as ended. Does not allocate.
    pub fn end_all_voices(&mut self) {
        for v in self.voices.iter_mut() {
            end_voice(v, &mut self.ended, self.block_pos);
        }
        if let Some(v) = self.input_voice.as_mut() {
            v.free();
        }
    }

    /// The notes of every voice sounding or fading out.
    pub fn notes(&self) -> impl Iterator<Item = Note> + '_ {
        self.voices
            .iter()
            .filter(|v| v.state != VoiceState::Free)
            .map(|v| Note {
                key: v.key,
                channel: v.channel,
                id: v.id,
            })
    }

    /// Whether a voice sounds for the host's note `id`.
    pub fn has_note_id(&self, id: i32) -> bool {
        self.voices
            .iter()
            .any(|v| v.is_sounding() && v.id == Some(id))
    }

    /// Tunes the input voice to `key` (else the bank's root) until a note is played: the last key
    /// the player struck, carried over to an engine built for a new bank.
    pub fn set_last_key(&mut self, key: Option<u8>) {
        self.last_key = key;
    }

    /// Hands over the voices that stopped sounding during the last `process` calls (freed,
    /// choked, faded out after stealing, or taken over by a new note with another id), each
    /// with its sample offset in the call where it ended. Does not allocate.
    pub fn take_ended_voices(&mut self) -> impl Iterator<Item = EndedVoice> + '_ {
        self.ended.drain(..)
    }

    /// The keys of the voices sounding now (held or ringing after release), in voice order.
    pub fn sounding_keys(&self) -> impl Iterator<Item = u8> + '_ {
        self.voices
            .iter()
            .filter(|v| v.is_sounding())
            .map(|v| v.key)
    }

    /// Whether nothing sounds and nothing is about to.
    pub fn is_silent(&self) -> bool {
        self.voices
            .iter()
            .chain(self.input_voice.as_ref())
            .all(|v| v.state == VoiceState::Free && v.modes.num_live() == 0)
    }
}

/// Frees `v`, recording it in `ended` (while there is room) when it was playing a note.
fn end_voice(v: &mut Voice, ended: &mut Vec<EndedVoice>, time: u32) {
    if v.state != VoiceState::Free && ended.len() < ended.capacity() {
        ended.push(EndedVoice {
            time,
            note: Note {
                key: v.key,
                channel: v.channel,
                id: v.id,
            },
        });
    }
    v.free();
}

mod process;
