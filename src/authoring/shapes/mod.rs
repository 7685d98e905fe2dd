//! Analytic shapes: the closed-form modes of strings, bars (free and clamped), membranes and
//! plates (rectangular and circular), bells and bowls, and the banks built from them (seed 000
//! section 3.1).
//!
//! Each object yields, for every mode, a frequency, and the value of its mode shape `Psi_n` at
//! each strike position, normalised to unit mean square over the object (the norm `alpha_n` of
//! seed 000 eq. 3.6 is then the same for every mode). A strike is an impulse of velocity at the
//! position (seed 000 eqs. 3.9-3.10), so the gain of mode n at position p is
//! `a_n = Psi_n(p) / omega_n` (seed 000 eq. 3.11): striking a node leaves that mode silent, and
//! high modes are weaker by their frequency. Gains are then scaled so that the largest one in the
//! bank is 1. Decays come from the material ([`Material::decay_per_s`], seed 000 eq. 3.13).
//!
//! Modes at or above [`ModeLimits::max_freq_hz`] are dropped, and only the lowest
//! [`ModeLimits::max_modes`] are kept.
//!
//! Each kind of object is one file holding all there is to it: its parameters and modes, how it
//! is struck, tuned and described (the `Object` trait of `shape.rs`), and its entry on the command
//! line ([`ObjectKind`]: name, dimensions and their typical values, default material). One line
//! of the registry below makes it a [`Shape`] and lists it in [`OBJECTS`].

pub mod bar;
pub mod bell;
pub mod bessel;
pub mod bowl;
pub mod cantilever;
pub mod circular_plate;
pub mod design;
mod disc;
mod lattice;
pub mod membrane;
pub mod objects;
pub mod plate;
mod positions;
pub mod rect_membrane;
mod shape;
pub mod string;
pub mod triangle;

pub use bar::{Bar, TunedBar, BAR_TUNINGS, MARIMBA_RATIOS, VIBRAPHONE_RATIOS, XYLOPHONE_RATIOS};
pub use bell::{BellPartial, TunedBell, TUNED_BELL_PARTIALS};
pub use bowl::Bowl;
pub use cantilever::Cantilever;
pub use circular_plate::{CircularPlate, PlateEdge};
pub use design::{design_bank, BankDesign};
pub use membrane::CircularMembrane;
pub use objects::{Dimension, ObjectKind, ObjectOption, ObjectSpec};
pub use plate::RectangularPlate;
pub use rect_membrane::RectangularMembrane;
pub use string::{IdealString, StiffString, StretchedString};

pub(crate) use shape::solid_contact_ms;

// The registry: `Variant(Parameters) => ObjectKind`, one line for each kind of object, in the
// order `modal-resonator shape --help` lists them.
shape::register_shapes! {
    IdealString(IdealString) => string::IDEAL_STRING,
    StiffString(StiffString) => string::STIFF_STRING,
    FreeFreeBar(Bar) => bar::FREE_FREE_BAR,
    ClampedFreeBar(Cantilever) => cantilever::CLAMPED_FREE_BAR,
    TunedBar(TunedBar) => bar::TUNED_BAR,
    CircularMembrane(CircularMembrane) => membrane::CIRCULAR_MEMBRANE,
    RectangularMembrane(RectangularMembrane) => rect_membrane::RECTANGULAR_MEMBRANE,
    RectangularPlate(RectangularPlate) => plate::RECTANGULAR_PLATE,
    CircularPlate(CircularPlate) => circular_plate::CIRCULAR_PLATE,
    Bell(TunedBell) => bell::BELL,
    Bowl(Bowl) => bowl::BOWL,
    Triangle(triangle::Triangle) => triangle::TRIANGLE,
}

use crate::authoring::materials::{Material, AIR_DAMPING_PER_S};
use crate::bank::{Bank, BankDefaults, Mode, Position};
use serde_json::{json, Map, Value};
use std::f64::consts::TAU;
use std::fmt;

/// Upper limit of hearing: modes at or above it are dropped.
pub const MAX_AUDIBLE_HZ: f64 = 20_000.0;

/// Default cap on the number of modes of one bank (plates and membranes have thousands below
/// 20 kHz; the lowest 300 carry the character and most of the energy).
pub const DEFAULT_MAX_MODES: usize = 300;

/// Gains smaller than this, relative to the largest, are set to exactly zero: they are rounding
/// noise at nodes (`sin(2 pi)` is 2.4e-16, not 0).
const GAIN_FLOOR: f64 = 1e-12;

/// Which modes a shape yields.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeLimits {
    /// Modes at or above this frequency in Hz are dropped.
    pub max_freq_hz: f64,
    /// At most this many modes are kept, the lowest in frequency.
    pub max_modes: usize,
}

impl Default for ModeLimits {
    fn default() -> Self {
        Self {
            max_freq_hz: MAX_AUDIBLE_HZ,
            max_modes: DEFAULT_MAX_MODES,
        }
    }
}

/// Why a shape could not produce modes.
#[derive(Debug, Clone, PartialEq)]
pub enum ShapeError {
    /// A dimension or parameter is out of range.
    BadParameter {
        /// Name of the parameter, e.g. `length_m`.
        name: &'static str,
        /// The offending value.
        value: f64,
        /// What was expected.
        reason: String,
    },
    /// A strike position does not fit the shape.
    BadPosition {
        /// Index of the position.
        index: usize,
        /// Name of the position.
        name: String,
        /// What was expected.
        reason: String,
    },
    /// No parameter value gives the requested pitch.
    CannotTune {
        /// Why.
        reason: String,
    },
    /// No mode lies below the frequency limit.
    NoModes {
        /// The limit in Hz.
        max_freq_hz: f64,
    },
    /// The object's lowest mode lies below the lowest frequency a bank's modes may have.
    BelowFloor {
        /// The lowest mode in Hz.
        lowest_hz: f64,
        /// The floor in Hz.
        min_freq_hz: f64,
    },
}

impl fmt::Display for ShapeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadParameter {
                name,
                value,
                reason,
            } => write!(f, "{name} = {value}: {reason}"),
            Self::BadPosition {
                index,
                name,
                reason,
            } => write!(f, "positions[{index}] (\"{name}\"): {reason}"),
            Self::CannotTune { reason } => write!(f, "cannot tune: {reason}"),
            Self::NoModes { max_freq_hz } => write!(
                f,
                "no mode below {max_freq_hz} Hz: the object is too small or too stiff to sound \
                 within it"
            ),
            Self::BelowFloor {
                lowest_hz,
                min_freq_hz,
            } => write!(
                f,
                "the object's lowest mode would be at {} Hz, below the \
                 {min_freq_hz} Hz a bank's modes start at: make it smaller, thicker, stiffer or \
                 tighter, or tune it higher (--tune-hz, --root-note)",
                if *lowest_hz >= 0.01 {
                    format!("{lowest_hz:.3}")
                } else {
                    format!("{lowest_hz:.1e}")
                }
            ),
        }
    }
}

impl std::error::Error for ShapeError {}

/// A mode before damping and gains: its frequency and its unit-mean-square shape at each
/// position.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ShapedMode {
    /// Frequency in Hz.
    pub freq_hz: f64,
    /// Mode shape at each strike position.
    pub shape: Vec<f64>,
}

/// `Ok` when `thickness` (named `name`) is at most a fifth of `span` (what `what` is measured
/// against): thicker, the object is a block and the thin-object theory of its modes fails.
pub(crate) fn check_thin(
    name: &'static str,
    thickness: f64,
    span: f64,
    what: &str,
) -> Result<(), ShapeError> {
    if thickness <= 0.2 * span {
        Ok(())
    } else {
        Err(ShapeError::BadParameter {
            name,
            value: thickness,
            reason: format!(
                "more than a fifth of the {what} ({span:.4} m): the object is too thick for the \
                 thin-object theory its modes come from"
            ),
        })
    }
}

/// `Ok` when `value` is a positive finite number.
pub(crate) fn check_positive(name: &'static str, value: f64) -> Result<(), ShapeError> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(ShapeError::BadParameter {
            name,
            value,
            reason: "expected a positive finite number".to_string(),
        })
    }
}

/// Damping and gains for shaped modes: keeps the lowest modes within the limits, sets
/// `decay = material.decay_per_s(f)` and `gain = Psi(p) / omega` (seed 000 eq. 3.11), scaled so
/// that the largest gain is 1.
pub(crate) fn finish_modes(
    mut shaped: Vec<ShapedMode>,
    material: &Material,
    limits: &ModeLimits,
) -> Result<Vec<Mode>, ShapeError> {
    let min_hz = crate::bank::validate::MODE_FREQ_HZ.min;
    let lowest_hz = shaped
        .iter()
        .map(|m| m.freq_hz)
        .fold(f64::INFINITY, f64::min);
    if lowest_hz < min_hz {
        return Err(ShapeError::BelowFloor {
            lowest_hz,
            min_freq_hz: min_hz,
        });
    }
    shaped.retain(|mode| mode.freq_hz >= min_hz && mode.freq_hz < limits.max_freq_hz);
    shaped.sort_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
    shaped.truncate(limits.max_modes);
    if shaped.is_empty() {
        return Err(ShapeError::NoModes {
            max_freq_hz: limits.max_freq_hz,
        });
    }
    let mut modes: Vec<Mode> = shaped
        .into_iter()
        .map(|mode| {
            let omega = TAU * mode.freq_hz;
            Mode {
                freq_hz: mode.freq_hz,
                decay_per_s: material.decay_per_s(mode.freq_hz),
                gains: mode.shape.iter().map(|psi| psi / omega).collect(),
            }
        })
        .collect();
    let peak = modes
        .iter()
        .flat_map(|mode| mode.gains.iter())
        .fold(0.0f64, |peak, gain| peak.max(gain.abs()));
    if peak > 0.0 {
        for gain in modes.iter_mut().flat_map(|mode| mode.gains.iter_mut()) {
            *gain /= peak;
            if gain.abs() < GAIN_FLOOR {
                *gain = 0.0; // also turns -0.0 into 0.0
            }
        }
    }
    Ok(modes)
}

/// A complete bank for `shape` made of `material`, struck at `positions`.
///
/// `description` may be empty, in which case the shape's [`Shape::summary`] is used. The bank's
/// `root_hz` is [`Shape::root_hz`]; its default mallet hardness suits the object. The position
/// nearest [`Shape::typical_strike`] comes first, since a bank is played at its first position
/// unless told otherwise (and is normalised there); the others keep their order.
pub fn build_bank(
    name: &str,
    description: &str,
    shape: &Shape,
    material: &Material,
    positions: &[Position],
    limits: &ModeLimits,
) -> Result<Bank, ShapeError> {
    let positions = &nearest_first(positions, &shape.typical_strike());
    let modes = shape.modes(material, positions, limits)?;

    let mut source = Map::new();
    source.insert("kind".into(), json!("analytic"));
    source.insert("shape".into(), json!(shape.kind()));
    source.insert("material".into(), json!(material.name));
    source.insert("dimensions_m".into(), Value::Object(shape.dimensions_m()));
    source.extend(shape.parameters(material));
    source.insert("loss_factor".into(), json!(material.loss_factor));
    source.insert("air_damping_per_s".into(), json!(AIR_DAMPING_PER_S));

    let mut bank = Bank::new(name, positions.to_vec());
    bank.description = if description.is_empty() {
        shape.summary(material)
    } else {
        description.to_string()
    };
    bank.author = "Modal Resonator".to_string();
    bank.license = "CC0-1.0".to_string();
    bank.source = Some(source);
    bank.root_hz = Some(shape.root_hz(material));
    bank.modes = modes;
    bank.defaults = Some(BankDefaults {
        hardness_ms: Some(shape.default_hardness_ms(material)),
        ..BankDefaults::default()
    });
    Ok(bank)
}

/// `positions` with the one nearest `coords` moved to the front.
fn nearest_first(positions: &[Position], coords: &[f64]) -> Vec<Position> {
    let distance = |p: &Position| -> f64 {
        p.coords
            .iter()
            .zip(coords)
            .map(|(a, b)| (a - b) * (a - b))
            .sum()
    };
    let mut ordered = positions.to_vec();
    if let Some(nearest) = (0..positions.len())
        .min_by(|&a, &b| distance(&positions[a]).total_cmp(&distance(&positions[b])))
    {
        let first = ordered.remove(nearest);
        ordered.insert(0, first);
    }
    ordered
}

#[cfg(test)]
mod tests;
