//! Every host parameter of both plugins, with stable ids, ranges and units, and how they become
//! the engine's [`Controls`]. The ids never change once released.

use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::sync::RwLock;

use nice_plug::params::persist::PersistentField;
use nice_plug::prelude::*;

use crate::bank::factory::{factory_bank, DEFAULT_FACTORY_BANK};
use crate::engine::{
    control_range, Controls, ExciterKind, Material, VoiceModulation, MATERIAL_Q_RANGE,
    MAX_POLYPHONY,
};

mod pruning;

pub use pruning::PruningParams;

/// Polyphonic modulation ids (CLAP): a host can offset these parameters for one note alone.
pub mod poly_id {
    /// Fine tune.
    pub const FINE_TUNE: u32 = 0;
    /// Size.
    pub const SIZE: u32 = 1;
    /// Strike position X.
    pub const STRIKE_X: u32 = 2;
    /// Strike position Y.
    pub const STRIKE_Y: u32 = 3;
    /// Hardness.
    pub const HARDNESS: u32 = 4;
    /// Contact speed.
    pub const CONTACT_SPEED: u32 = 5;
    /// Contact force.
    pub const CONTACT_FORCE: u32 = 6;
    /// How many there are.
    pub const COUNT: usize = 7;
}

/// Default per-note pitch-bend range of MPE member channels, in semitones (the MPE
/// specification's default).
pub const MPE_DEFAULT_BEND_RANGE: f32 = crate::engine::MPE_DEFAULT_BEND_RANGE_SEMITONES;

/// Version of the plugin state's own fields; raised when they change meaning.
pub const STATE_FORMAT: u32 = 2;

/// The state field holding [`STATE_FORMAT`].
pub const STATE_FORMAT_FIELD: &str = "state-format";

/// Material: the bank as authored, a shortcut, or the Q and tilt knobs.
#[derive(Enum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum MaterialChoice {
    /// The bank's own decays; the tilt knob still applies.
    #[id = "authored"]
    #[name = "As authored"]
    Authored,
    /// Q and tilt from their knobs.
    #[id = "custom"]
    Custom,
    #[id = "plastic"]
    Plastic,
    #[id = "wood"]
    Wood,
    #[id = "ceramic"]
    Ceramic,
    #[id = "glass"]
    Glass,
    #[id = "metal"]
    Metal,
}

/// What strikes the object.
#[derive(Enum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExciterChoice {
    #[id = "mallet"]
    Mallet,
    #[id = "impulse"]
    Impulse,
    #[id = "noise"]
    #[name = "Noise burst"]
    Noise,
    /// Scraping along a rough surface while the note is held.
    #[id = "scrape"]
    Scrape,
    /// Rolling on a rough surface while the note is held.
    #[id = "roll"]
    Roll,
    /// Rubbing with stick-slip friction while the note is held: a wine glass, a singing bowl.
    #[id = "rub"]
    Rub,
}

impl ExciterChoice {
    /// The choice that plays `kind`.
    pub fn of(kind: ExciterKind) -> Self {
        match kind {
            ExciterKind::Impulse => ExciterChoice::Impulse,
            ExciterKind::Mallet => ExciterChoice::Mallet,
            ExciterKind::Noise => ExciterChoice::Noise,
            ExciterKind::Scrape => ExciterChoice::Scrape,
            ExciterKind::Roll => ExciterChoice::Roll,
            ExciterKind::Rub => ExciterChoice::Rub,
        }
    }

    /// The exciter this choice plays.
    pub fn kind(self) -> ExciterKind {
        match self {
            ExciterChoice::Mallet => ExciterKind::Mallet,
            ExciterChoice::Impulse => ExciterKind::Impulse,
            ExciterChoice::Noise => ExciterKind::Noise,
            ExciterChoice::Scrape => ExciterKind::Scrape,
            ExciterChoice::Roll => ExciterKind::Roll,
            ExciterChoice::Rub => ExciterKind::Rub,
        }
    }
}

/// What the audio input does.
#[derive(Enum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputMode {
    /// Ignored.
    #[id = "off"]
    Off,
    /// Drives the modes directly, like a filter bank.
    #[id = "direct"]
    Direct,
    /// Its onsets strike the object.
    #[id = "trigger"]
    Trigger,
}

/// Where the mod wheel or channel pressure goes.
#[derive(Enum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExpressionTarget {
    #[id = "none"]
    None,
    /// Moves the strike position towards the far end.
    #[id = "position"]
    #[name = "Strike position"]
    Position,
    /// Damps the object, as a hand pressing on it (channel pressure routed here presses a
    /// contact instead: its force).
    #[id = "damping"]
    Damping,
    /// Sets the speed of a scrape, roll or rub, from still to the fastest.
    #[id = "speed"]
    #[name = "Contact speed"]
    Speed,
    /// Sets the force of a scrape, roll or rub.
    #[id = "force"]
    #[name = "Contact force"]
    Force,
}

impl ExpressionTarget {
    /// The engine's target.
    pub fn target(self) -> crate::engine::ExpressionTarget {
        use crate::engine::ExpressionTarget as T;
        match self {
            ExpressionTarget::None => T::None,
            ExpressionTarget::Position => T::Position,
            ExpressionTarget::Damping => T::Damping,
            ExpressionTarget::Speed => T::Speed,
            ExpressionTarget::Force => T::Force,
        }
    }
}

/// The bank in use, saved in the plugin state as its JSON text, so a project reopens with the
/// same sound even when the file has moved. An empty text means the default factory bank.
#[derive(Default)]
pub struct BankField {
    /// The bank's JSON.
    pub json: RwLock<String>,
    /// Incremented on every change, so the audio thread notices a restored or loaded bank.
    pub generation: AtomicU64,
}

impl BankField {
    /// Replaces the bank's JSON (from the GUI or a host restoring state).
    pub fn replace(&self, json: String) {
        *self.json.write().unwrap_or_else(|e| e.into_inner()) = json;
        self.generation.fetch_add(1, Ordering::AcqRel);
    }

    /// A copy of the bank's JSON (empty for the default bank).
    pub fn json_text(&self) -> String {
        self.json.read().unwrap_or_else(|e| e.into_inner()).clone()
    }

    /// Puts back `json`, the bank still playing, in place of the text of `generation` that
    /// failed to load, so a saved project holds what was heard. Nothing changes if another bank
    /// has arrived since.
    pub fn restore(&self, generation: u64, json: &str) {
        let mut text = self.json.write().unwrap_or_else(|e| e.into_inner());
        if self.generation.load(Ordering::Acquire) == generation {
            json.clone_into(&mut text);
        }
    }
}

impl<'a> PersistentField<'a, String> for BankField {
    fn set(&self, new_value: String) {
        self.replace(new_value);
    }

    fn map<F, R>(&self, f: F) -> R
    where
        F: Fn(&String) -> R,
    {
        f(&self.json.read().unwrap_or_else(|e| e.into_inner()))
    }
}

/// The parameters shared by the instrument and the effect, in the groups hosts show (VST3 units,
/// CLAP modules) and the editor draws.
#[derive(Params)]
pub struct ModalParams {
    /// The bank, as JSON.
    #[persist = "bank"]
    pub bank: BankField,
    /// [`STATE_FORMAT`] of the state this was saved with.
    #[persist = "state-format"]
    pub state_format: AtomicU32,
    /// The editor window's size in logical points, as the player left it (`None`: the default).
    #[persist = "editor-size"]
    pub editor_size: std::sync::RwLock<Option<(f32, f32)>>,

    /// The object's size and tuning.
    #[nested(group = "Object")]
    pub object: ObjectParams,
    /// Where and how the object is struck.
    #[nested(group = "Strike")]
    pub strike: StrikeParams,
    /// What the object is made of: how its modes decay.
    #[nested(group = "Material")]
    pub material: MaterialParams,
    /// Polyphony, truncation and how MIDI expression plays the voices.
    #[nested(group = "Voices")]
    pub voices: VoiceParams,
    /// The output's level, stereo width and mix.
    #[nested(group = "Output")]
    pub output: OutputParams,
    /// The audio input: driving the modes or triggering strikes.
    #[nested(group = "Input")]
    pub input: InputParams,
    /// The host's bypass button: the output crossfades to the effect's dry input, or to silence
    /// for the instrument; the object keeps ringing underneath.
    #[id = "bypass"]
    pub bypass: BoolParam,
    /// Perceptual pruning and the mode budget.
    #[nested(group = "Pruning")]
    pub pruning: PruningParams,
}

/// The object's size and tuning. Group "Object".
#[derive(Params)]
pub struct ObjectParams {
    /// Size: scales every frequency (larger is lower).
    #[id = "size"]
    pub size: FloatParam,
    /// How far the pitch follows the keys, in percent.
    #[id = "keytrk"]
    pub key_tracking: FloatParam,
    /// Fine tune in cents.
    #[id = "fine"]
    pub fine_tune: FloatParam,
    /// Pitch-bend range in semitones.
    #[id = "bendrg"]
    pub bend_range: FloatParam,
}

/// Where and how the object is struck. Group "Strike".
#[derive(Params)]
pub struct StrikeParams {
    /// Strike position along the object.
    #[id = "posx"]
    pub strike_x: FloatParam,
    /// Strike position across the object (2-D banks).
    #[id = "posy"]
    pub strike_y: FloatParam,
    /// Random variation of the strike position from strike to strike.
    #[id = "posvar"]
    pub position_variation: FloatParam,
    /// Random variation of each strike's pitch, decay and mode gains.
    #[id = "strvar"]
    pub strike_variation: FloatParam,
    /// What strikes the object: mallet, impulse or noise burst.
    #[id = "exc"]
    pub exciter: EnumParam<ExciterChoice>,
    /// Mallet contact time in ms (short = hard and bright).
    #[id = "hard"]
    pub hardness: FloatParam,
    /// How much velocity sets the level.
    #[id = "velsns"]
    pub velocity_sensitivity: FloatParam,
    /// How much velocity shortens the contact (harder strikes are brighter).
    #[id = "velhrd"]
    pub velocity_to_hardness: FloatParam,
    /// Roughness of a scraped or rolled surface and of a rolling object.
    #[id = "rough"]
    pub roughness: FloatParam,
    /// Radius of a rolling object, in mm.
    #[id = "radius"]
    pub rolling_radius: FloatParam,
    /// Speed of a scrape, roll or rub, in m/s.
    #[id = "cspeed"]
    pub contact_speed: FloatParam,
    /// Force of a scrape, roll or rub at full velocity.
    #[id = "cforce"]
    pub contact_force: FloatParam,
}

/// What the object is made of: how its modes decay. Group "Material".
#[derive(Params)]
pub struct MaterialParams {
    /// Material: the bank as authored, a preset material, or Q and tilt.
    #[id = "mat"]
    pub material: EnumParam<MaterialChoice>,
    /// Material quality factor Q (for the custom material).
    #[id = "q"]
    pub material_q: FloatParam,
    /// Damping tilt: decays scale by `(f / f_lowest) ^ tilt`.
    #[id = "tilt"]
    pub damping_tilt: FloatParam,
    /// How fast a released note is damped (0 = it rings on).
    #[id = "reldmp"]
    pub release_damping: FloatParam,
}

/// Polyphony, truncation and how MIDI expression plays the voices. Group "Voices".
#[derive(Params)]
pub struct VoiceParams {
    /// Most voices at once.
    #[id = "poly"]
    pub polyphony: IntParam,
    /// Level below which a mode stops being computed.
    #[id = "trunc"]
    pub truncation: FloatParam,
    /// What the mod wheel moves.
    #[id = "modwhl"]
    pub mod_wheel_target: EnumParam<ExpressionTarget>,
    /// What channel pressure moves.
    #[id = "press"]
    pub pressure_target: EnumParam<ExpressionTarget>,
    /// MIDI Polyphonic Expression: each note on its own channel (2 to 16), whose pitch bend and
    /// pressure shape that note alone; channel 1 stays global.
    #[id = "mpe"]
    pub mpe: BoolParam,
    /// Pitch-bend range of MPE member channels, in semitones.
    #[id = "mpebnd"]
    pub mpe_bend_range: FloatParam,
}

/// The output's level, stereo width and mix. Group "Output".
#[derive(Params)]
pub struct OutputParams {
    /// Output gain in dB.
    #[id = "gain"]
    pub output_gain: FloatParam,
    /// Stereo width of the modes.
    #[id = "width"]
    pub width: FloatParam,
    /// Mix of the dry input (the effect's audio, the instrument's exciter) and the modes.
    #[id = "mix"]
    pub dry_wet: FloatParam,
}

/// The audio input: driving the modes or triggering strikes. Group "Input".
#[derive(Params)]
pub struct InputParams {
    /// What the audio input does: nothing, drive the modes, or trigger strikes.
    #[id = "inmode"]
    pub input_mode: EnumParam<InputMode>,
    /// Gain of the audio input in dB.
    #[id = "ingain"]
    pub input_gain: FloatParam,
    /// Level of an onset that triggers a strike.
    #[id = "trigth"]
    pub trigger_threshold: FloatParam,
    /// Shortest time between triggered strikes, in ms.
    #[id = "retrig"]
    pub retrigger: FloatParam,
}

fn percent(name: &str, default: f32) -> FloatParam {
    FloatParam::new(name, default, FloatRange::Linear { min: 0.0, max: 1.0 })
        .with_unit("%")
        .with_value_to_string(formatters::v2s_f32_percentage(0))
        .with_string_to_value(formatters::s2v_f32_percentage())
}

/// Range of the onset trigger's threshold in dB: the input mode's own, with no engine control.
const TRIGGER_THRESHOLD_RANGE_DB: (f32, f32) = (-80.0, 0.0);

/// A parameter over the range of the numeric control `control`, skewed by `skew` (negative
/// gives the low end more of the travel).
fn skewed(name: &str, default: f32, control: &str, skew: f32) -> FloatParam {
    let (min, max) = control_range(control);
    FloatParam::new(
        name,
        default,
        FloatRange::Skewed {
            min,
            max,
            factor: FloatRange::skew_factor(skew),
        },
    )
}

/// A linear range from `(min, max)`.
fn linear((min, max): (f32, f32)) -> FloatRange {
    FloatRange::Linear { min, max }
}

/// Steps of a numeric parameter, with its text rounded to the step.
trait RoundedSteps {
    /// `self` moving in steps of `step_size`, its text rounded to the step's decimals and never
    /// negative zero: a value just under zero would print "-0.0 dB", which reads back as 0 and
    /// prints "0.0 dB", so the host's text would not read back as itself (clap-validator's
    /// conversion test).
    fn with_rounded_steps(self, step_size: f32) -> Self;
}

impl RoundedSteps for FloatParam {
    fn with_rounded_steps(self, step_size: f32) -> Self {
        // 1 gives 0 decimals, 0.1 one, 0.01 two.
        let decimals = (-step_size.log10()).ceil().max(0.0) as usize;
        self.with_step_size(step_size)
            .with_value_to_string(formatters::v2s_f32_rounded(decimals))
    }
}

/// A level in dB over `range`, in steps of 0.1 dB.
fn decibels(name: &str, default: f32, range: (f32, f32)) -> FloatParam {
    FloatParam::new(name, default, linear(range))
        .with_unit(" dB")
        .with_rounded_steps(0.1)
}

impl ObjectParams {
    /// The object's parameters, with defaults `d` (the default bank's).
    fn new(d: &Controls) -> Self {
        Self {
            size: FloatParam::new(
                "Size",
                1.0,
                FloatRange::SymmetricalSkewed {
                    min: control_range("size_ratio").0,
                    max: control_range("size_ratio").1,
                    factor: FloatRange::skew_factor(-1.0),
                    center: 1.0,
                },
            )
            .with_unit(" x")
            .with_rounded_steps(0.001)
            .with_smoother(SmoothingStyle::None)
            .with_poly_modulation_id(poly_id::SIZE),
            key_tracking: percent("Key tracking", d.key_tracking),
            fine_tune: FloatParam::new("Fine tune", 0.0, linear(control_range("fine_tune_cents")))
                .with_unit(" ct")
                .with_rounded_steps(0.1)
                .with_poly_modulation_id(poly_id::FINE_TUNE),
            bend_range: FloatParam::new(
                "Pitch bend range",
                2.0,
                linear(control_range("bend_range_semitones")),
            )
            .with_unit(" st")
            .with_rounded_steps(1.0),
        }
    }
}

impl StrikeParams {
    /// The strike's and contact's parameters, with defaults `d` (the default bank's).
    fn new(d: &Controls) -> Self {
        Self {
            strike_x: percent("Strike position", d.strike_x)
                .with_poly_modulation_id(poly_id::STRIKE_X),
            strike_y: percent("Strike position Y", d.strike_y)
                .with_poly_modulation_id(poly_id::STRIKE_Y),
            position_variation: percent("Position variation", 0.0),
            strike_variation: percent("Strike variation", 0.0),
            exciter: EnumParam::new("Exciter", ExciterChoice::of(d.exciter)),
            hardness: skewed("Hardness", d.hardness_ms, "hardness_ms", -2.5)
                .with_unit(" ms")
                .with_rounded_steps(0.01)
                .with_poly_modulation_id(poly_id::HARDNESS),
            velocity_sensitivity: percent("Velocity sensitivity", 0.8),
            velocity_to_hardness: percent("Velocity to hardness", 0.5),
            roughness: percent("Roughness", d.roughness),
            rolling_radius: skewed(
                "Rolling radius",
                d.rolling_radius_mm,
                "rolling_radius_mm",
                -1.5,
            )
            .with_unit(" mm")
            .with_rounded_steps(0.1),
            contact_speed: skewed(
                "Contact speed",
                d.contact_speed_m_per_s,
                "contact_speed_m_per_s",
                -1.0,
            )
            .with_unit(" m/s")
            .with_rounded_steps(0.01)
            .with_poly_modulation_id(poly_id::CONTACT_SPEED),
            contact_force: percent("Contact force", d.contact_force)
                .with_poly_modulation_id(poly_id::CONTACT_FORCE),
        }
    }
}

impl MaterialParams {
    /// The material's parameters, with defaults `d` (the default bank's).
    fn new(d: &Controls) -> Self {
        Self {
            material: EnumParam::new("Material", MaterialChoice::Authored),
            material_q: FloatParam::new(
                "Q",
                1000.0,
                FloatRange::Skewed {
                    min: MATERIAL_Q_RANGE.0,
                    max: MATERIAL_Q_RANGE.1,
                    factor: FloatRange::skew_factor(-2.0),
                },
            )
            .with_rounded_steps(1.0),
            damping_tilt: FloatParam::new(
                "Damping tilt",
                d.damping_tilt,
                linear(control_range("damping_tilt")),
            )
            .with_rounded_steps(0.01),
            release_damping: percent("Release damping", 0.0),
        }
    }
}

impl VoiceParams {
    /// The voices' parameters.
    fn new() -> Self {
        Self {
            polyphony: IntParam::new(
                "Polyphony",
                16,
                IntRange::Linear {
                    min: 1,
                    max: MAX_POLYPHONY as i32,
                },
            ),
            truncation: decibels(
                "Truncation threshold",
                -96.0,
                control_range("truncation_db"),
            ),
            mod_wheel_target: EnumParam::new("Mod wheel", ExpressionTarget::Position),
            pressure_target: EnumParam::new("Pressure", ExpressionTarget::Damping),
            mpe: BoolParam::new("MPE", false),
            mpe_bend_range: FloatParam::new(
                "MPE bend range",
                MPE_DEFAULT_BEND_RANGE,
                linear(control_range("mpe_bend_range_semitones")),
            )
            .with_unit(" st")
            .with_rounded_steps(1.0),
        }
    }
}

impl OutputParams {
    /// The output's parameters; an effect's (`is_effect`) is half wet.
    fn new(is_effect: bool) -> Self {
        Self {
            output_gain: decibels("Output gain", 0.0, control_range("output_gain_db")),
            width: percent("Stereo width", 0.5),
            dry_wet: percent("Dry/wet", if is_effect { 0.5 } else { 1.0 }),
        }
    }
}

impl InputParams {
    /// The audio input's parameters; an effect's (`is_effect`) drives the modes.
    fn new(is_effect: bool) -> Self {
        Self {
            input_mode: EnumParam::new(
                "Input mode",
                if is_effect {
                    InputMode::Direct
                } else {
                    InputMode::Off
                },
            ),
            input_gain: decibels(
                "Input gain",
                if is_effect { -24.0 } else { 0.0 },
                control_range("input_gain_db"),
            ),
            trigger_threshold: decibels("Trigger threshold", -30.0, TRIGGER_THRESHOLD_RANGE_DB),
            retrigger: FloatParam::new(
                "Retrigger time",
                50.0,
                FloatRange::Linear {
                    min: 5.0,
                    max: 500.0,
                },
            )
            .with_unit(" ms")
            .with_rounded_steps(1.0),
        }
    }
}

impl ModalParams {
    /// The parameters with their defaults; `is_effect` sets defaults that suit the effect (input
    /// driving the modes, half wet).
    pub fn new(is_effect: bool) -> Self {
        // Defaults that suit the bank a new instance plays: its typical strike point and mallet.
        let bank = factory_bank(DEFAULT_FACTORY_BANK).expect("the default factory bank exists");
        let d = Controls::for_bank(&bank);
        Self {
            bank: BankField::default(),
            state_format: AtomicU32::new(STATE_FORMAT),
            editor_size: std::sync::RwLock::new(None),
            object: ObjectParams::new(&d),
            strike: StrikeParams::new(&d),
            material: MaterialParams::new(&d),
            voices: VoiceParams::new(),
            output: OutputParams::new(is_effect),
            input: InputParams::new(is_effect),
            bypass: BoolParam::new("Bypass", false).make_bypass(),
            pruning: PruningParams::new(&d),
        }
    }

    /// The parameter with polyphonic modulation id `poly_id`.
    fn poly_param(&self, poly_id: u32) -> Option<&FloatParam> {
        Some(match poly_id {
            poly_id::FINE_TUNE => &self.object.fine_tune,
            poly_id::SIZE => &self.object.size,
            poly_id::STRIKE_X => &self.strike.strike_x,
            poly_id::STRIKE_Y => &self.strike.strike_y,
            poly_id::HARDNESS => &self.strike.hardness,
            poly_id::CONTACT_SPEED => &self.strike.contact_speed,
            poly_id::CONTACT_FORCE => &self.strike.contact_force,
            _ => return None,
        })
    }

    /// The normalised value of the parameter with polyphonic modulation id `poly_id`, before
    /// modulation.
    pub fn poly_base(&self, poly_id: u32) -> Option<f32> {
        self.poly_param(poly_id)
            .map(|p| p.unmodulated_normalized_value())
    }

    /// What one voice holds when the parameter with polyphonic modulation id `poly_id` is at
    /// `normalized` for it (clamped to the parameter's range).
    pub fn voice_modulation(&self, poly_id: u32, normalized: f32) -> Option<VoiceModulation> {
        let value = self.poly_param(poly_id)?.preview_plain(normalized);
        Some(match poly_id {
            poly_id::FINE_TUNE => VoiceModulation::FineTuneCents(value),
            poly_id::SIZE => VoiceModulation::SizeRatio(value),
            poly_id::STRIKE_X => VoiceModulation::StrikeX(value),
            poly_id::STRIKE_Y => VoiceModulation::StrikeY(value),
            poly_id::CONTACT_SPEED => VoiceModulation::ContactSpeed(value),
            poly_id::CONTACT_FORCE => VoiceModulation::ContactForce(value),
            _ => VoiceModulation::HardnessMs(value),
        })
    }

    /// Notes at once, 1 to [`MAX_POLYPHONY`].
    pub fn polyphony(&self) -> usize {
        self.voices.polyphony.value().clamp(1, MAX_POLYPHONY as i32) as usize
    }

    /// The engine controls for the current values (which the engine's channel-wide controllers
    /// then move: [`Controls::expressed`]).
    pub fn controls(&self) -> Controls {
        let (material_q, damping_tilt) = match self.material.material.value() {
            MaterialChoice::Authored => (None, self.material.damping_tilt.value()),
            MaterialChoice::Custom => (
                Some(self.material.material_q.value()),
                self.material.damping_tilt.value(),
            ),
            MaterialChoice::Plastic => (
                Some(Material::Plastic.q()),
                Material::Plastic.damping_tilt(),
            ),
            MaterialChoice::Wood => (Some(Material::Wood.q()), Material::Wood.damping_tilt()),
            MaterialChoice::Ceramic => (
                Some(Material::Ceramic.q()),
                Material::Ceramic.damping_tilt(),
            ),
            MaterialChoice::Glass => (Some(Material::Glass.q()), Material::Glass.damping_tilt()),
            MaterialChoice::Metal => (Some(Material::Metal.q()), Material::Metal.damping_tilt()),
        };
        Controls {
            material_q,
            damping_tilt,
            size_ratio: self.object.size.value(),
            key_tracking: self.object.key_tracking.value(),
            fine_tune_cents: self.object.fine_tune.value(),
            pitch_bend_semitones: 0.0,
            bend_range_semitones: self.object.bend_range.value(),
            mod_wheel_target: self.voices.mod_wheel_target.value().target(),
            pressure_target: self.voices.pressure_target.value().target(),
            mpe: self.voices.mpe.value(),
            mpe_bend_range_semitones: self.voices.mpe_bend_range.value(),
            strike_x: self.strike.strike_x.value(),
            strike_y: self.strike.strike_y.value(),
            position_variation: self.strike.position_variation.value(),
            strike_variation: self.strike.strike_variation.value(),
            exciter: self.strike.exciter.value().kind(),
            roughness: self.strike.roughness.value(),
            rolling_radius_mm: self.strike.rolling_radius.value(),
            contact_speed_m_per_s: self.strike.contact_speed.value(),
            contact_force: self.strike.contact_force.value(),
            hardness_ms: self.strike.hardness.value(),
            velocity_sensitivity: self.strike.velocity_sensitivity.value(),
            velocity_to_hardness: self.strike.velocity_to_hardness.value(),
            release_damping: self.material.release_damping.value(),
            extra_damping: 0.0,
            truncation_db: self.voices.truncation.value(),
            polyphony: self.polyphony(),
            width: self.output.width.value(),
            output_gain_db: self.output.output_gain.value(),
            input_gain_db: self.input.input_gain.value(),
            ..self.pruning.apply(Controls::default())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each host parameter that sets a numeric control spans that control's range.
    #[test]
    fn parameters_span_their_controls_ranges() {
        for is_effect in [false, true] {
            let p = ModalParams::new(is_effect);
            for (param, control) in [
                (&p.object.size, "size_ratio"),
                (&p.object.fine_tune, "fine_tune_cents"),
                (&p.object.bend_range, "bend_range_semitones"),
                (&p.strike.hardness, "hardness_ms"),
                (&p.strike.roughness, "roughness"),
                (&p.strike.rolling_radius, "rolling_radius_mm"),
                (&p.strike.contact_speed, "contact_speed_m_per_s"),
                (&p.strike.contact_force, "contact_force"),
                (&p.material.damping_tilt, "damping_tilt"),
                (&p.voices.truncation, "truncation_db"),
                (&p.voices.mpe_bend_range, "mpe_bend_range_semitones"),
                (&p.output.output_gain, "output_gain_db"),
                (&p.input.input_gain, "input_gain_db"),
                (&p.pruning.masking_offset, "masking_offset_db"),
                (&p.pruning.playback_level, "playback_level_db_spl"),
            ] {
                let (min, max) = control_range(control);
                let ends = (param.preview_plain(0.0), param.preview_plain(1.0));
                assert_eq!(ends, (min, max), "{} and {control}", param.name());
            }
        }
    }

    /// Normalised values to try on `param`: a fine grid over its range, and plain values just
    /// either side of zero, where a number rounded for display can print as "-0.0".
    fn values_to_try(param: &ParamPtr) -> Vec<f32> {
        const GRID: u16 = 1000;
        let grid = (0..=GRID).map(|i| f32::from(i) / f32::from(GRID));
        let near_zero = [
            -0.5, -0.049, -0.04, -0.004, -1e-6, 0.0, 1e-6, 0.004, 0.04, 0.049, 0.5,
        ];
        // SAFETY: the parameter lives as long as the test's `ModalParams`.
        let near_zero = near_zero.map(|plain| unsafe { param.preview_normalized(plain) });
        grid.chain(near_zero).collect()
    }

    /// Every parameter's text reads back as the same text, with and without its unit:
    /// clap-validator's conversion test (value to text, to value, to text again) at many
    /// values, so a host showing a value and a player typing it back agree.
    #[test]
    fn every_parameters_text_reads_back_as_itself() {
        for is_effect in [false, true] {
            let p = ModalParams::new(is_effect);
            for (id, param, _) in p.param_map() {
                for normalized in values_to_try(&param) {
                    for unit in [true, false] {
                        // SAFETY: as above.
                        let (text, back, again) = unsafe {
                            let text = param.normalized_value_to_string(normalized, unit);
                            let back = param.string_to_normalized_value(&text);
                            let again = back.map(|b| param.normalized_value_to_string(b, unit));
                            (text, back, again)
                        };
                        assert_eq!(
                            again.as_deref(),
                            Some(text.as_str()),
                            "{id} at {normalized}: {text:?} reads back as {back:?}"
                        );
                    }
                }
            }
        }
    }
}
