//! The engine's controls: plain values in natural units, with their ranges, defaults and names in
//! one table shared by the plugin's parameters, the command line and the tests.

mod by_name;
mod target;

pub use target::ExpressionTarget;

use super::position::PositionMap;
use crate::bank::validate::{
    NumberRange, CONTACT_FORCE, CONTACT_SPEED_M_PER_S, DAMPING_TILT, HARDNESS_MS, MATERIAL_Q,
    ROLLING_RADIUS_MM, ROUGHNESS,
};
use crate::bank::Bank;
use crate::dsp::ExciterKind;

/// Most voices the engine can play at once.
pub const MAX_POLYPHONY: usize = 64;

/// A material shortcut: sets material Q and damping tilt together.
///
/// Q values span the useful range seed 004 section 5.1.2 found by listening (about 20 for plastic
/// to 5000 for metal); the tilt lets high modes die faster in lossy materials (wood's internal
/// friction grows with frequency) and ring on in metal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Material {
    /// Dull, short knock.
    Plastic,
    /// Warm, short ring, highs die first.
    Wood,
    /// Bright clink.
    Ceramic,
    /// Clear, long ring.
    Glass,
    /// Long, shimmering ring.
    Metal,
}

impl Material {
    /// Every shortcut, from most to least damped.
    pub const ALL: [Material; 5] = [
        Material::Plastic,
        Material::Wood,
        Material::Ceramic,
        Material::Glass,
        Material::Metal,
    ];

    /// Lowercase name.
    pub fn name(self) -> &'static str {
        match self {
            Material::Plastic => "plastic",
            Material::Wood => "wood",
            Material::Ceramic => "ceramic",
            Material::Glass => "glass",
            Material::Metal => "metal",
        }
    }

    /// The material with this lowercase name.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name)
    }

    /// Quality factor Q = pi f / d.
    pub fn q(self) -> f32 {
        match self {
            Material::Plastic => 40.0,
            Material::Wood => 120.0,
            Material::Ceramic => 900.0,
            Material::Glass => 2000.0,
            Material::Metal => 5000.0,
        }
    }

    /// Damping tilt: decays scale by `(f / f_lowest) ^ tilt`.
    pub fn damping_tilt(self) -> f32 {
        match self {
            Material::Plastic => 0.4,
            Material::Wood => 0.7,
            Material::Ceramic => 0.2,
            Material::Glass => 0.1,
            Material::Metal => -0.1,
        }
    }
}

/// Every control of the engine.
#[derive(Debug, Clone, PartialEq)]
pub struct Controls {
    /// Material quality factor; `None` plays the bank's decays as authored.
    pub material_q: Option<f32>,
    /// Decays scale by `(f / f_lowest) ^ damping_tilt`: positive damps high modes.
    pub damping_tilt: f32,
    /// Object size relative to the bank; frequencies divide by it.
    pub size_ratio: f32,
    /// How far pitch follows the MIDI key, 0 (not at all) to 1 (equal temperament).
    pub key_tracking: f32,
    /// Fine tuning in cents.
    pub fine_tune_cents: f32,
    /// Pitch bend in semitones, besides the wheel's (which moves it by up to
    /// `bend_range_semitones` either way).
    pub pitch_bend_semitones: f32,
    /// How far the pitch-bend wheel bends, in semitones either way.
    pub bend_range_semitones: f32,
    /// What the mod wheel moves.
    pub mod_wheel_target: ExpressionTarget,
    /// What channel pressure moves.
    pub pressure_target: ExpressionTarget,
    /// MPE (lower zone): the bend, pressure and slide of member channels 2 to 16 are their
    /// notes' own.
    pub mpe: bool,
    /// How far an MPE member channel's bend bends its note, in semitones either way.
    pub mpe_bend_range_semitones: f32,
    /// Strike position along the bank's positions, 0 to 1 (first axis of 2-D banks).
    pub strike_x: f32,
    /// Strike position on the second axis of 2-D banks, 0 to 1.
    pub strike_y: f32,
    /// Random change of the strike position per strike, as a fraction of the range.
    pub position_variation: f32,
    /// Random change of each strike's sound (seed 004 section 5.4), 0 (every strike alike) to 1:
    /// up to [`VARIATION_CENTS`] of pitch, [`VARIATION_DECAY`] of decay and [`VARIATION_GAIN_DB`]
    /// of each mode's gain. Drawn from the engine's seeded generator, so a render repeats.
    pub strike_variation: f32,
    /// Shape of a strike.
    pub exciter: ExciterKind,
    /// Mallet contact time at full velocity in ms: short is hard and bright.
    pub hardness_ms: f32,
    /// How much velocity sets strike force: 0 = every note at full force, 1 = force ~ velocity^2.
    pub velocity_sensitivity: f32,
    /// How much softer notes lengthen the contact time (up to 4x at velocity 0).
    pub velocity_to_hardness: f32,
    /// Roughness of a scraped or rolled surface and of a rolling object, 0 (smooth) to 1.
    pub roughness: f32,
    /// Radius of a rolling object, in mm.
    pub rolling_radius_mm: f32,
    /// Contact speed of a scrape, roll or rub, in m/s.
    pub contact_speed_m_per_s: f32,
    /// Normal force of a scrape, roll or rub at full velocity, 0 to 1.
    pub contact_force: f32,
    /// Damping applied on note-off: 0 lets the object ring on, 1 damps it within about 50 ms.
    pub release_damping: f32,
    /// Extra damping of every mode, 0 (none) to 1 (decays 20 times faster), for expression
    /// (a hand pressing on the object).
    pub extra_damping: f32,
    /// A mode stops being computed once its amplitude is below this level, in dBFS.
    pub truncation_db: f32,
    /// Voices that may sound at once.
    pub polyphony: usize,
    /// Stereo spread of the modes, 0 (mono) to 1 (full width).
    pub width: f32,
    /// Output level in dB.
    pub output_gain_db: f32,
    /// Level of an audio input driving the modes, in dB.
    pub input_gain_db: f32,
    /// Perceptual pruning (seed 001): modes below the threshold of hearing or masked by louder
    /// ones are not computed.
    pub pruning: bool,
    /// Masking offset `a_v` of pruning in dB: how far below a masker's curve a mode must lie to be
    /// dropped; larger prunes less (5 dB was transparent in seed 001).
    pub masking_offset_db: f32,
    /// Playback level: dB SPL of a full-scale sine. Calibrates mode levels against the threshold
    /// of hearing and the level-dependent masking curves.
    pub playback_level_db_spl: f32,
    /// How often pruning looks at the modes, in ms (rounded to whole control periods).
    pub analysis_frame_ms: f32,
    /// Most modes computed at once, the most energetic kept (seed 000 section 5.5); 0 = no cap.
    pub mode_budget: usize,
    /// Automatic budget: cap the modes so the estimated synthesis cost stays under this share of
    /// real time, in percent, from the engine's own cost measured when prepared; 0 = off.
    pub target_load_pct: f32,
}

impl Default for Controls {
    fn default() -> Self {
        Self {
            material_q: None,
            damping_tilt: 0.0,
            size_ratio: 1.0,
            key_tracking: 1.0,
            fine_tune_cents: 0.0,
            pitch_bend_semitones: 0.0,
            bend_range_semitones: 2.0,
            mod_wheel_target: ExpressionTarget::Position,
            pressure_target: ExpressionTarget::Damping,
            mpe: false,
            mpe_bend_range_semitones: MPE_DEFAULT_BEND_RANGE_SEMITONES,
            strike_x: 0.0,
            strike_y: 0.0,
            position_variation: 0.0,
            strike_variation: 0.0,
            exciter: ExciterKind::Mallet,
            hardness_ms: 0.25,
            velocity_sensitivity: 0.8,
            velocity_to_hardness: 0.5,
            roughness: 0.5,
            rolling_radius_mm: 20.0,
            contact_speed_m_per_s: 0.5,
            contact_force: 0.7,
            release_damping: 0.0,
            extra_damping: 0.0,
            truncation_db: -96.0,
            polyphony: 16,
            width: 0.5,
            output_gain_db: 0.0,
            input_gain_db: 0.0,
            pruning: false,
            masking_offset_db: 5.0,
            playback_level_db_spl: 90.0,
            analysis_frame_ms: 20.0,
            mode_budget: 0,
            target_load_pct: 0.0,
        }
    }
}

/// A numeric control: its name on the command line, unit, range and default.
pub struct ControlSpec {
    /// Name used by `--set name=value`.
    pub name: &'static str,
    /// Unit shown next to the value.
    pub unit: &'static str,
    /// Smallest value.
    pub min: f32,
    /// Largest value.
    pub max: f32,
    /// Whether only whole numbers are meaningful.
    pub integer: bool,
    /// Reads the control.
    pub get: fn(&Controls) -> f32,
    /// Writes the control (the value is already clamped to the range).
    pub set: fn(&mut Controls, f32),
}

macro_rules! spec {
    ($name:literal, $unit:literal, $min:expr, $max:expr, $field:ident) => {
        spec!($name, $unit, $min, $max, $field, false)
    };
    ($name:literal, $unit:literal, $min:expr, $max:expr, $field:ident, $integer:expr) => {
        ControlSpec {
            name: $name,
            unit: $unit,
            min: $min,
            max: $max,
            integer: $integer,
            get: |c| c.$field as f32,
            set: |c, v| c.$field = v as _,
        }
    };
}

/// The numeric controls. `material_q`, `material` and `exciter` are handled by name in
/// [`Controls::set_by_name`] since they are not plain numbers.
pub const NUMERIC_CONTROLS: &[ControlSpec] = &[
    spec!(
        "damping_tilt",
        "",
        DAMPING_TILT.min as f32,
        DAMPING_TILT.max as f32,
        damping_tilt
    ),
    spec!("size_ratio", "x", 0.25, 4.0, size_ratio),
    spec!("key_tracking", "", 0.0, 1.0, key_tracking),
    spec!("fine_tune_cents", "ct", -100.0, 100.0, fine_tune_cents),
    spec!(
        "pitch_bend_semitones",
        "st",
        -48.0,
        48.0,
        pitch_bend_semitones
    ),
    spec!(
        "bend_range_semitones",
        "st",
        0.0,
        48.0,
        bend_range_semitones
    ),
    spec!(
        "mpe_bend_range_semitones",
        "st",
        0.0,
        96.0,
        mpe_bend_range_semitones
    ),
    ControlSpec {
        name: "mpe",
        unit: "",
        min: 0.0,
        max: 1.0,
        integer: true,
        get: |c| c.mpe as u8 as f32,
        set: |c, v| c.mpe = v >= 0.5,
    },
    spec!("strike_x", "", 0.0, 1.0, strike_x),
    spec!("strike_y", "", 0.0, 1.0, strike_y),
    spec!("position_variation", "", 0.0, 1.0, position_variation),
    spec!("strike_variation", "", 0.0, 1.0, strike_variation),
    spec!(
        "hardness_ms",
        "ms",
        HARDNESS_RANGE_MS.0,
        HARDNESS_RANGE_MS.1,
        hardness_ms
    ),
    spec!("velocity_sensitivity", "", 0.0, 1.0, velocity_sensitivity),
    spec!("velocity_to_hardness", "", 0.0, 1.0, velocity_to_hardness),
    spec!(
        "roughness",
        "",
        span(ROUGHNESS).0,
        span(ROUGHNESS).1,
        roughness
    ),
    spec!(
        "rolling_radius_mm",
        "mm",
        span(ROLLING_RADIUS_MM).0,
        span(ROLLING_RADIUS_MM).1,
        rolling_radius_mm
    ),
    spec!(
        "contact_speed_m_per_s",
        "m/s",
        span(CONTACT_SPEED_M_PER_S).0,
        span(CONTACT_SPEED_M_PER_S).1,
        contact_speed_m_per_s
    ),
    spec!(
        "contact_force",
        "",
        span(CONTACT_FORCE).0,
        span(CONTACT_FORCE).1,
        contact_force
    ),
    spec!("release_damping", "", 0.0, 1.0, release_damping),
    spec!("extra_damping", "", 0.0, 1.0, extra_damping),
    spec!("truncation_db", "dBFS", -140.0, -60.0, truncation_db),
    spec!(
        "polyphony",
        "voices",
        1.0,
        MAX_POLYPHONY as f32,
        polyphony,
        true
    ),
    spec!("width", "", 0.0, 1.0, width),
    spec!("output_gain_db", "dB", -60.0, 12.0, output_gain_db),
    spec!("input_gain_db", "dB", -60.0, 24.0, input_gain_db),
    ControlSpec {
        name: "pruning",
        unit: "",
        min: 0.0,
        max: 1.0,
        integer: true,
        get: |c| c.pruning as u8 as f32,
        set: |c, v| c.pruning = v >= 0.5,
    },
    spec!(
        "masking_offset_db",
        "dB",
        MASKING_OFFSET_RANGE_DB.0,
        MASKING_OFFSET_RANGE_DB.1,
        masking_offset_db
    ),
    spec!(
        "playback_level_db_spl",
        "dB SPL",
        PLAYBACK_LEVEL_RANGE_DB_SPL.0,
        PLAYBACK_LEVEL_RANGE_DB_SPL.1,
        playback_level_db_spl
    ),
    spec!(
        "analysis_frame_ms",
        "ms",
        ANALYSIS_FRAME_RANGE_MS.0,
        ANALYSIS_FRAME_RANGE_MS.1,
        analysis_frame_ms
    ),
    spec!(
        "mode_budget",
        "modes",
        0.0,
        MAX_MODE_BUDGET as f32,
        mode_budget,
        true
    ),
    spec!(
        "target_load_pct",
        "%",
        0.0,
        MAX_TARGET_LOAD_PCT,
        target_load_pct
    ),
];

/// The range of the numeric control `name` (see [`NUMERIC_CONTROLS`]), where the host
/// parameters take theirs from, so each range is written once.
///
/// # Panics
/// If no numeric control has that name: a programming error, caught by the first test that
/// builds the parameters.
pub fn control_range(name: &str) -> (f32, f32) {
    let spec = NUMERIC_CONTROLS
        .iter()
        .find(|s| s.name == name)
        .unwrap_or_else(|| panic!("no numeric control named {name}"));
    (spec.min, spec.max)
}

/// An MPE member channel's bend range by default, in semitones (the MPE specification's).
pub const MPE_DEFAULT_BEND_RANGE_SEMITONES: f32 = 48.0;

/// Most a strike's pitch moves at full strike variation, in cents (either way).
pub const VARIATION_CENTS: f32 = 5.0;

/// Most a strike's decay changes at full strike variation, as a share (either way).
pub const VARIATION_DECAY: f32 = 0.05;

/// Most a mode's gain changes at full strike variation, in dB (either way).
pub const VARIATION_GAIN_DB: f32 = 1.5;

/// Fastest scrape, roll or rub, in m/s: a quick stroke of the hand.
pub const CONTACT_SPEED_MAX_M_PER_S: f32 = CONTACT_SPEED_M_PER_S.max as f32;

/// A bank format range as the `(min, max)` of a control.
const fn span(range: NumberRange) -> (f32, f32) {
    (range.min as f32, range.max as f32)
}

/// Range of the masking offset `a_v` in dB (seed 001 found 5 dB transparent, 20 dB the
/// laboratory figure for tone-on-tone masking).
pub const MASKING_OFFSET_RANGE_DB: (f32, f32) = (0.0, 20.0);

/// Range of the playback level: dB SPL of a full-scale sine, from quiet listening to loud.
pub const PLAYBACK_LEVEL_RANGE_DB_SPL: (f32, f32) = (40.0, 120.0);

/// Range of the pruning analysis frame in ms (seed 001: a few ms, the ear's pitch detection
/// time, to 46 ms, its audio frame).
pub const ANALYSIS_FRAME_RANGE_MS: (f32, f32) = (2.0, 100.0);

/// Largest fixed mode budget (0 is no cap).
pub const MAX_MODE_BUDGET: usize = 100_000;

/// Highest target load of the automatic budget, percent of real time (0 is off).
pub const MAX_TARGET_LOAD_PCT: f32 = 100.0;

/// Range of material Q.
pub const MATERIAL_Q_RANGE: (f32, f32) = (MATERIAL_Q.min as f32, MATERIAL_Q.max as f32);

/// Range of a strike's contact time in ms, whatever velocity makes of the hardness control.
pub const HARDNESS_RANGE_MS: (f32, f32) = (HARDNESS_MS.min as f32, HARDNESS_MS.max as f32);

impl Controls {
    /// The defaults for `bank`: struck at its first position, with the bank's own `defaults`
    /// applied on top.
    pub fn for_bank(bank: &Bank) -> Self {
        let mut c = Self::default();
        let coords: Vec<Vec<f64>> = bank.positions.iter().map(|p| p.coords.clone()).collect();
        if let Some(first) = PositionMap::new(&coords).coords().first() {
            c.strike_x = first[0] as f32;
            c.strike_y = first[1] as f32;
        }
        if let Some(d) = &bank.defaults {
            if let Some(q) = d.material_q {
                c.material_q = Some(q as f32);
            }
            if let Some(t) = d.damping_tilt {
                c.damping_tilt = t as f32;
            }
            if let Some(h) = d.hardness_ms {
                c.hardness_ms = h as f32;
            }
            if let Some(p) = d.strike_position {
                c.strike_x = p as f32;
            }
            if let Some(k) = d.key_tracking_pct {
                c.key_tracking = (k / 100.0) as f32;
            }
            if let Some(kind) = d.exciter.as_deref().and_then(ExciterKind::from_name) {
                c.exciter = kind;
            }
            for (value, control) in [
                (d.roughness, &mut c.roughness),
                (d.rolling_radius_mm, &mut c.rolling_radius_mm),
                (d.contact_speed_m_per_s, &mut c.contact_speed_m_per_s),
                (d.contact_force, &mut c.contact_force),
            ] {
                if let Some(v) = value {
                    *control = v as f32;
                }
            }
        }
        c.sanitized()
    }

    /// Applies a material shortcut.
    pub fn set_material(&mut self, material: Material) {
        self.material_q = Some(material.q());
        self.damping_tilt = material.damping_tilt();
    }

    /// Every value within its range; a value that is not a number takes its default.
    pub fn sanitized(&self) -> Self {
        let defaults = Self::default();
        let mut c = self.clone();
        for spec in NUMERIC_CONTROLS {
            let v = (spec.get)(&c);
            let v = if v.is_nan() {
                (spec.get)(&defaults)
            } else {
                v.clamp(spec.min, spec.max)
            };
            (spec.set)(&mut c, v);
        }
        c.material_q = c
            .material_q
            .filter(|q| !q.is_nan())
            .map(|q| q.clamp(MATERIAL_Q_RANGE.0, MATERIAL_Q_RANGE.1));
        c
    }
}

#[cfg(test)]
mod tests;
