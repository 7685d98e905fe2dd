//! The modal bank, format version 1: plain data in natural units.
//!
//! `presets/README.md` documents the format for people; `presets/modal-bank.schema.json` is
//! generated from these types for editors.

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Value of the `format` field that marks a document as a modal bank.
pub const FORMAT_NAME: &str = "modal-bank";

/// The major format version this build reads and writes.
pub const FORMAT_VERSION: u32 = 1;

/// Highest mode frequency rendered, as a fraction of the sample rate: above it a mode aliases or
/// its pole crowds Nyquist (DESIGN.md). A bank's modes above it at a rate are left out there.
pub const MAX_FREQ_RATIO: f64 = 0.45;

/// Smallest decay rate played, in 1/s: a mode whose bank gives less (0 included) decays at this
/// rate, dying after about 690 seconds, so the recursion is strictly stable in `f32` and a
/// voice is eventually freed.
pub const MIN_DECAY_PER_S: f64 = 0.01;

/// A modal bank: how one object rings when struck at each of its measured positions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Bank {
    /// Always `"modal-bank"`.
    #[schemars(extend("const" = "modal-bank"))]
    pub format: String,
    /// Major format version; this build reads version 1.
    #[schemars(extend("const" = 1))]
    pub version: u32,
    /// Display name, for example "Steel bar, 30 cm".
    #[schemars(length(min = 1))]
    pub name: String,
    /// What the object is and how it sounds.
    #[serde(default)]
    pub description: String,
    /// Who made the bank.
    #[serde(default)]
    pub author: String,
    /// SPDX licence identifier of the bank data, for example "CC0-1.0".
    #[serde(default)]
    pub license: String,
    /// Free-form details of how the bank was made; `kind` names the method
    /// ("analytic", "fitted", "edited", ...).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source: Option<serde_json::Map<String, serde_json::Value>>,
    /// Pitch in Hz the bank sounds at size 1: the MIDI key with this equal-tempered pitch plays the
    /// bank as authored. When absent, the lowest of the strongest modes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(extend("exclusiveMinimum" = 0, "maximum" = 1_000_000))]
    pub root_hz: Option<f64>,
    /// The strike positions whose gains each mode lists, in order.
    #[schemars(length(min = 1, max = 64))]
    pub positions: Vec<Position>,
    /// The modes, in any order.
    #[schemars(length(min = 1, max = 65_536))]
    pub modes: Vec<Mode>,
    /// Parameter defaults that suit this bank.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub defaults: Option<BankDefaults>,
}

/// A strike position: where on the object the gains of column k were measured or computed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Position {
    /// Display name, for example "edge" or "centre".
    #[schemars(length(min = 1))]
    pub name: String,
    /// Coordinates on the object: one value (along a line), two (on a surface) or three (a
    /// point in space, on the surface of a meshed object, in metres), in any unit consistent
    /// within the bank (usually fractions of the object's length).
    #[schemars(length(min = 1, max = 3))]
    pub coords: Vec<f64>,
}

/// One mode of vibration.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Mode {
    /// Frequency in Hz at size 1, from 1 Hz.
    #[schemars(extend("minimum" = 1, "maximum" = 1_000_000))]
    pub freq_hz: f64,
    /// Exponential decay rate of the amplitude in 1/s (T60 = 3 ln 10 / decay).
    #[schemars(range(min = 0, max = 1_000_000))]
    pub decay_per_s: f64,
    /// Signed linear amplitude of the mode for a unit impulse at each position, one per position.
    #[schemars(length(min = 1, max = 64), inner(range(min = -1_000_000, max = 1_000_000)))]
    pub gains: Vec<f64>,
}

/// Parameter defaults a bank can carry. Every field is optional.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BankDefaults {
    /// Material quality factor Q (decays scale by the bank's own Q over this one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 1, max = 100_000))]
    pub material_q: Option<f64>,
    /// Damping tilt: decays scale by `(f / f_lowest) ^ tilt`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = -2, max = 2))]
    pub damping_tilt: Option<f64>,
    /// Mallet contact time in milliseconds (short = hard and bright).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0.05, max = 20))]
    pub hardness_ms: Option<f64>,
    /// Where the bank is struck by default: a place on the object, 0 to 1 along the first axis
    /// of its positions (see the presets README).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0, max = 1))]
    pub strike_position: Option<f64>,
    /// Key tracking in percent (0 = every key plays the bank's own pitch).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0, max = 100))]
    pub key_tracking_pct: Option<f64>,
    /// How the bank is played: a strike (`impulse`, `mallet`, `noise`) or a contact held with the
    /// note (`scrape`, `roll`, `rub`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(extend("enum" = ["impulse", "mallet", "noise", "scrape", "roll", "rub"]))]
    pub exciter: Option<String>,
    /// Roughness of a scraped or rolled surface and of a rolling object, 0 (smooth) to 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0, max = 1))]
    pub roughness: Option<f64>,
    /// Radius of a rolling object in mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 1, max = 200))]
    pub rolling_radius_mm: Option<f64>,
    /// Speed of a scrape or roll in m/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0, max = 3))]
    pub contact_speed_m_per_s: Option<f64>,
    /// Force of a scrape or roll at full velocity, 0 to 1.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schemars(range(min = 0, max = 1))]
    pub contact_force: Option<f64>,
}

impl Bank {
    /// A bank with no modes and the given positions, ready to be filled.
    pub fn new(name: impl Into<String>, positions: Vec<Position>) -> Self {
        Self {
            format: FORMAT_NAME.to_string(),
            version: FORMAT_VERSION,
            name: name.into(),
            description: String::new(),
            author: String::new(),
            license: String::new(),
            source: None,
            root_hz: None,
            positions,
            modes: Vec::new(),
            defaults: None,
        }
    }

    /// Number of strike positions (columns of the gain matrix).
    pub fn num_positions(&self) -> usize {
        self.positions.len()
    }
}

/// Modes within this many dB of the strongest count as "strongest" when choosing a default root.
const ROOT_STRENGTH_DB: f64 = 6.0;

impl Bank {
    /// The text `source` holds under `key`, if it holds text there.
    pub fn source_text(&self, key: &str) -> Option<&str> {
        self.source.as_ref()?.get(key)?.as_str()
    }

    /// The pitch the bank sounds at size 1: `root_hz` when given, else the lowest of the modes
    /// within 6 dB of the strongest (strength: largest gain over the positions).
    pub fn effective_root_hz(&self) -> f64 {
        if let Some(root) = self.root_hz {
            return root;
        }
        let strength = |m: &Mode| m.gains.iter().fold(0.0f64, |a, g| a.max(g.abs()));
        let strongest = self.modes.iter().map(strength).fold(0.0, f64::max);
        let floor = strongest * 10f64.powf(-ROOT_STRENGTH_DB / 20.0);
        self.modes
            .iter()
            .filter(|m| strength(m) >= floor)
            .map(|m| m.freq_hz)
            .fold(f64::INFINITY, f64::min)
            .min(1e6)
    }

    /// The bank's own quality factor: the median of `pi f / d` over its modes, with `d` at least
    /// `MIN_DECAY_PER_S` (the slowest decay the engine plays), or `None` for a bank without
    /// modes. Material Q scales decays relative to it: at this Q the bank sounds as authored.
    pub fn reference_q(&self) -> Option<f64> {
        let mut qs: Vec<f64> = self
            .modes
            .iter()
            .map(|m| std::f64::consts::PI * m.freq_hz / m.decay_per_s.max(MIN_DECAY_PER_S))
            .collect();
        if qs.is_empty() {
            return None;
        }
        qs.sort_by(f64::total_cmp);
        let mid = qs.len() / 2;
        Some(if qs.len() % 2 == 1 {
            qs[mid]
        } else {
            0.5 * (qs[mid - 1] + qs[mid])
        })
    }
}
