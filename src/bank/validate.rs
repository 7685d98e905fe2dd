//! The rules of bank format version 1, and [`validate_bank`] which applies them to a bank built in
//! code.
//!
//! Each rule is written once, here, as a function from plain values to a message saying what was
//! found and what was expected. Two walkers apply the rules and attach the JSON path: the one in
//! this file walks a typed [`Bank`]; the one in `validate/json.rs` walks a parsed document, which
//! can hold anything, and checks types, missing and unknown fields on the way.
//! `presets/README.md` lists the same rules for people.

mod json;

use std::collections::HashMap;
use std::fmt;

use super::format::{Bank, BankDefaults, FORMAT_NAME, FORMAT_VERSION};

pub(crate) use json::check_document;

/// Most strike positions a bank may have: enough for a fine grid on a plate, while a bank's gain
/// matrix stays small.
pub const MAX_POSITIONS: usize = 64;

/// Most modes a bank may have: far more than any voice renders, so authoring tools can keep a
/// generous set and let truncation and pruning choose.
pub const MAX_MODES: usize = 65_536;

/// Most coordinates of a strike position: along a line (1), on a surface (2) or in space (3).
pub const MAX_COORDS: usize = 3;

/// How many problems a [`BankError`](super::io::BankError) keeps: more than anyone reads, few
/// enough that a bank with every gain wrong cannot exhaust memory.
pub const MAX_REPORTED_PROBLEMS: usize = 100;

/// An interval a number must lie in. Every bound is finite or infinite; NaN never lies in any.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NumberRange {
    /// Lower bound.
    pub min: f64,
    /// Whether `min` itself is allowed.
    pub min_inclusive: bool,
    /// Upper bound, always allowed.
    pub max: f64,
    /// Unit appended to the bounds in messages, with its leading space (" Hz"), or "".
    pub unit: &'static str,
}

impl NumberRange {
    const fn closed(min: f64, max: f64, unit: &'static str) -> Self {
        Self {
            min,
            min_inclusive: true,
            max,
            unit,
        }
    }

    /// Whether `x` is finite and inside the range.
    pub fn contains(&self, x: f64) -> bool {
        let above_min = x > self.min || (self.min_inclusive && x == self.min);
        x.is_finite() && above_min && x <= self.max
    }

    /// The range in words: "a number greater than 0 and at most 1000000 Hz".
    pub fn describe(&self) -> String {
        let (min, max, unit) = (fmt_number(self.min), fmt_number(self.max), self.unit);
        if self.min == f64::NEG_INFINITY && self.max == f64::INFINITY {
            "a finite number".to_string()
        } else if self.min_inclusive {
            format!("a number from {min} to {max}{unit}")
        } else {
            format!("a number greater than {min} and at most {max}{unit}")
        }
    }
}

/// Root pitch (and the top of a mode's frequency): positive, and 1 MHz is far above any sample
/// rate's Nyquist frequency (such modes are dropped when rendering) while keeping `2 pi f` far
/// from overflow.
pub const FREQ_HZ: NumberRange = NumberRange {
    min: 0.0,
    min_inclusive: false,
    max: 1e6,
    unit: " Hz",
};

/// Mode frequency: from 1 Hz, where a default strike (measured over its first second to set
/// the bank's level) has reached its peak; below it a mode is a slow swell of near DC that a
/// level set at the strike cannot bound. The floor is at the bank's own pitch: keys far below
/// its root play a 1 Hz mode lower still. 1 MHz as for [`FREQ_HZ`].
pub const MODE_FREQ_HZ: NumberRange = NumberRange::closed(1.0, 1e6, " Hz");

/// Mode decay rate: the engine plays rates under its floor (0.01 per second, a T60 of 690 s) at
/// the floor; 1e6 per second dies within a sample at any audio rate.
pub const DECAY_PER_S: NumberRange = NumberRange::closed(0.0, 1e6, " per second");

/// Mode gain at one position: 1e6 (+120 dB) leaves room for any normalisation.
pub const GAIN: NumberRange = NumberRange::closed(-1e6, 1e6, "");

/// Position coordinates: any finite number, in a unit of the bank's choosing.
pub const COORD: NumberRange = NumberRange::closed(f64::NEG_INFINITY, f64::INFINITY, "");

/// Material Q: a bank's default, and the engine's control and host parameter.
pub const MATERIAL_Q: NumberRange = NumberRange::closed(1.0, 100_000.0, "");

/// Damping tilt: a bank's default, and the engine's control and host parameter.
pub const DAMPING_TILT: NumberRange = NumberRange::closed(-2.0, 2.0, "");

/// Mallet hardness (contact time) in ms: a bank's default, and the engine's control and host
/// parameter; every strike's contact time is held to it.
pub const HARDNESS_MS: NumberRange = NumberRange::closed(0.05, 20.0, " ms");

/// Roughness of a scraped or rolled surface, 0 (smooth) to 1: a bank's default, the engine's
/// control and the host parameter.
pub const ROUGHNESS: NumberRange = NumberRange::closed(0.0, 1.0, "");

/// Radius of a rolling object in mm, from a bead to a bowling ball.
pub const ROLLING_RADIUS_MM: NumberRange = NumberRange::closed(1.0, 200.0, " mm");

/// Speed of a scrape or roll in m/s, up to a quick stroke of the hand.
pub const CONTACT_SPEED_M_PER_S: NumberRange = NumberRange::closed(0.0, 3.0, " m/s");

/// Force of a scrape or roll at full velocity, 0 to 1.
pub const CONTACT_FORCE: NumberRange = NumberRange::closed(0.0, 1.0, "");

/// `defaults` fields and their ranges, which are those of the matching host parameters. The
/// typed walker lists the values of [`BankDefaults`](super::format::BankDefaults) in this order.
pub const DEFAULTS_RANGES: [(&str, NumberRange); 9] = [
    ("material_q", MATERIAL_Q),
    ("damping_tilt", DAMPING_TILT),
    ("hardness_ms", HARDNESS_MS),
    ("strike_position", NumberRange::closed(0.0, 1.0, "")),
    ("key_tracking_pct", NumberRange::closed(0.0, 100.0, "%")),
    ("roughness", ROUGHNESS),
    ("rolling_radius_mm", ROLLING_RADIUS_MM),
    ("contact_speed_m_per_s", CONTACT_SPEED_M_PER_S),
    ("contact_force", CONTACT_FORCE),
];

/// The exciters a bank's `defaults.exciter` may name (the engine's, by name).
pub const EXCITER_NAMES: [&str; 6] = ["impulse", "mallet", "noise", "scrape", "roll", "rub"];

/// One thing wrong with a bank.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Problem {
    /// Where: a JSON path such as `modes[12].decay_per_s`, or empty for the whole document.
    pub path: String,
    /// What was found and what was expected.
    pub message: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.path.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "{}: {}", self.path, self.message)
        }
    }
}

/// Checks `bank` against every rule of the format; an empty list means it can be saved and played.
///
/// This is for banks built in code: it reports every problem, where loading a file keeps the
/// first [`MAX_REPORTED_PROBLEMS`]. Paths are those the bank would have as JSON.
pub fn validate_bank(bank: &Bank) -> Vec<Problem> {
    let mut problems = Problems::new(usize::MAX);
    check_bank(bank, &mut problems);
    problems.list
}

/// The typed walker: every rule, applied to a [`Bank`].
pub(crate) fn check_bank(bank: &Bank, problems: &mut Problems) {
    let root = JsonPath::Root;
    problems.check(&root.field("format"), check_format(&bank.format));
    problems.check(
        &root.field("version"),
        check_version(u64::from(bank.version)),
    );
    problems.check(&root.field("name"), check_name(&bank.name));
    if let Some(root_hz) = bank.root_hz {
        problems.check(&root.field("root_hz"), check_number(root_hz, &FREQ_HZ));
    }
    check_positions(bank, &root.field("positions"), problems);
    check_modes(bank, &root.field("modes"), problems);
    if let Some(defaults) = &bank.defaults {
        check_defaults(defaults, &root.field("defaults"), problems);
    }
}

/// The positions, at `positions_path`: how many, their names (unique), their coordinates (as
/// many for each).
fn check_positions(bank: &Bank, positions_path: &JsonPath<'_>, problems: &mut Problems) {
    problems.check(
        positions_path,
        check_count(bank.positions.len(), MAX_POSITIONS, "positions"),
    );
    let mut names = UniqueNames::default();
    let mut dimensions = SameDimension::default();
    for (i, position) in bank.positions.iter().enumerate() {
        let path = positions_path.index(i);
        let name_path = path.field("name");
        problems.check(&name_path, check_name(&position.name));
        problems.check(&name_path, names.check(i, &position.name));
        let coords_path = path.field("coords");
        problems.check(&coords_path, dimensions.check(i, position.coords.len()));
        for (j, &coord) in position.coords.iter().enumerate() {
            problems.check(&coords_path.index(j), check_number(coord, &COORD));
        }
    }
}

/// The modes, at `modes_path`: how many, their numbers, and a gain for each position.
fn check_modes(bank: &Bank, modes_path: &JsonPath<'_>, problems: &mut Problems) {
    problems.check(
        modes_path,
        check_count(bank.modes.len(), MAX_MODES, "modes"),
    );
    for (i, mode) in bank.modes.iter().enumerate() {
        let path = modes_path.index(i);
        problems.check(
            &path.field("freq_hz"),
            check_number(mode.freq_hz, &MODE_FREQ_HZ),
        );
        problems.check(
            &path.field("decay_per_s"),
            check_number(mode.decay_per_s, &DECAY_PER_S),
        );
        let gains_path = path.field("gains");
        problems.check(
            &gains_path,
            check_gains_len(mode.gains.len(), bank.positions.len()),
        );
        for (j, &gain) in mode.gains.iter().enumerate() {
            problems.check(&gains_path.index(j), check_number(gain, &GAIN));
        }
    }
}

/// The defaults, at `path`: each number in its range, the exciter one the engine has.
fn check_defaults(defaults: &BankDefaults, path: &JsonPath<'_>, problems: &mut Problems) {
    let values = [
        defaults.material_q,
        defaults.damping_tilt,
        defaults.hardness_ms,
        defaults.strike_position,
        defaults.key_tracking_pct,
        defaults.roughness,
        defaults.rolling_radius_mm,
        defaults.contact_speed_m_per_s,
        defaults.contact_force,
    ];
    for ((name, range), value) in DEFAULTS_RANGES.iter().zip(values) {
        if let Some(value) = value {
            problems.check(&path.field(name), check_number(value, range));
        }
    }
    if let Some(exciter) = &defaults.exciter {
        if !EXCITER_NAMES.contains(&exciter.as_str()) {
            problems.check(
                &path.field("exciter"),
                Err(format!(
                    "expected one of {}, found \"{exciter}\"",
                    EXCITER_NAMES.join(", ")
                )),
            );
        }
    }
}

/// The problems found so far: the first `cap` of them, and how many there were in all.
#[derive(Debug)]
pub(crate) struct Problems {
    /// The problems kept, in the order found.
    list: Vec<Problem>,
    /// How many problems were reported, kept or not.
    total: usize,
    /// How many to keep.
    cap: usize,
}

impl Problems {
    pub(crate) fn new(cap: usize) -> Self {
        Self {
            list: Vec::new(),
            total: 0,
            cap,
        }
    }

    /// Records a problem at `path`.
    pub(crate) fn report(&mut self, path: &JsonPath<'_>, message: String) {
        self.total += 1;
        if self.list.len() < self.cap {
            self.list.push(Problem {
                path: path.to_string(),
                message,
            });
        }
    }

    /// Records the outcome of a rule: a problem at `path` when it failed.
    pub(crate) fn check(&mut self, path: &JsonPath<'_>, outcome: Result<(), String>) {
        if let Err(message) = outcome {
            self.report(path, message);
        }
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.total == 0
    }

    /// The problems kept, and how many more were found but not kept.
    pub(crate) fn into_parts(self) -> (Vec<Problem>, usize) {
        let omitted = self.total - self.list.len();
        (self.list, omitted)
    }
}

/// A JSON path built on the stack as a walker descends, turned into text only when a problem is
/// reported: `modes[12].decay_per_s`.
#[derive(Debug, Clone, Copy)]
pub(crate) enum JsonPath<'a> {
    /// The whole document.
    Root,
    /// A field of the object at the parent path.
    Field(&'a JsonPath<'a>, &'a str),
    /// An element of the array at the parent path.
    Index(&'a JsonPath<'a>, usize),
}

impl<'a> JsonPath<'a> {
    pub(crate) fn field(&'a self, name: &'a str) -> Self {
        Self::Field(self, name)
    }

    pub(crate) fn index(&'a self, i: usize) -> Self {
        Self::Index(self, i)
    }
}

impl fmt::Display for JsonPath<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Self::Root => Ok(()),
            Self::Field(parent, name) => {
                write!(f, "{parent}")?;
                let plain =
                    !name.is_empty() && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
                if !plain {
                    // A field name a reader could not tell from the path's own punctuation.
                    write!(f, "[{}]", quote(name))
                } else if matches!(parent, Self::Root) {
                    write!(f, "{name}")
                } else {
                    write!(f, ".{name}")
                }
            }
            Self::Index(parent, i) => write!(f, "{parent}[{i}]"),
        }
    }
}

fn check_format(found: &str) -> Result<(), String> {
    if found == FORMAT_NAME {
        Ok(())
    } else {
        Err(format!(
            "found {}, expected {}: this is not a modal bank, or the name is misspelt",
            quote(found),
            quote(FORMAT_NAME)
        ))
    }
}

fn check_version(found: u64) -> Result<(), String> {
    let known = u64::from(FORMAT_VERSION);
    if found == known {
        Ok(())
    } else if found > known {
        Err(format!(
            "found {found}: this bank was made by a newer version of Modal Resonator; \
             this build reads version {known}"
        ))
    } else {
        Err(format!(
            "found {found}, expected {known}: versions start at 1"
        ))
    }
}

fn check_name(found: &str) -> Result<(), String> {
    if found.trim().is_empty() {
        Err(format!(
            "found {}, expected a name with at least one visible character",
            quote(found)
        ))
    } else {
        Ok(())
    }
}

fn check_number(x: f64, range: &NumberRange) -> Result<(), String> {
    if range.contains(x) {
        Ok(())
    } else {
        Err(format!(
            "found {}, expected {}",
            fmt_number(x),
            range.describe()
        ))
    }
}

/// A list of `what` must have from 1 to `max` entries.
fn check_count(found: usize, max: usize, what: &str) -> Result<(), String> {
    if (1..=max).contains(&found) {
        Ok(())
    } else {
        Err(format!("found {found} {what}, expected from 1 to {max}"))
    }
}

fn check_gains_len(found: usize, num_positions: usize) -> Result<(), String> {
    // With no positions the `positions` problem says it all; a message per mode would be noise.
    if found == num_positions || num_positions == 0 {
        Ok(())
    } else {
        let values = if found == 1 { "value" } else { "values" };
        Err(format!(
            "found {found} {values}, expected {num_positions} (one per position)"
        ))
    }
}

/// Position names must be unique: remembers the names seen so far.
#[derive(Debug, Default)]
struct UniqueNames<'a> {
    /// Index of the first position with each name.
    first_index: HashMap<&'a str, usize>,
}

impl<'a> UniqueNames<'a> {
    fn check(&mut self, i: usize, name: &'a str) -> Result<(), String> {
        if name.trim().is_empty() {
            // Already reported as empty.
            return Ok(());
        }
        match self.first_index.get(name) {
            Some(&first) => Err(format!(
                "{} is already the name of positions[{first}]; position names must be unique",
                quote(name)
            )),
            None => {
                self.first_index.insert(name, i);
                Ok(())
            }
        }
    }
}

/// Positions must all have 1 or all have 2 coordinates: remembers the first valid dimension.
#[derive(Debug, Default)]
struct SameDimension {
    /// Dimension of the first position with 1 to 3 coordinates, and that position's index.
    first: Option<(usize, usize)>,
}

impl SameDimension {
    fn check(&mut self, i: usize, found: usize) -> Result<(), String> {
        if !(1..=MAX_COORDS).contains(&found) {
            return Err(format!(
                "found {}, expected 1 (a point along a line), 2 (a point on a surface) or 3 (a \
                 point in space)",
                coordinates(found)
            ));
        }
        match self.first {
            None => {
                self.first = Some((found, i));
                Ok(())
            }
            Some((expected, _)) if expected == found => Ok(()),
            Some((expected, first)) => Err(format!(
                "found {}, expected {expected} like positions[{first}]: \
                 all positions need the same number of coordinates",
                coordinates(found)
            )),
        }
    }
}

fn coordinates(n: usize) -> String {
    if n == 1 {
        "1 coordinate".to_string()
    } else {
        format!("{n} coordinates")
    }
}

/// A number as a person would write it: `523.25`, `-3`, `1e300`, `NaN`.
fn fmt_number(x: f64) -> String {
    if x.is_nan() {
        "NaN".to_string()
    } else if x.is_infinite() {
        if x > 0.0 { "infinity" } else { "-infinity" }.to_string()
    } else if x == 0.0 || (1e-5..1e16).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `text` as a JSON string, shortened when long so a message stays on one readable line.
fn quote(text: &str) -> String {
    /// Characters of a string shown in a message.
    const MAX_CHARS: usize = 40;
    if text.chars().count() <= MAX_CHARS {
        serde_json::Value::from(text).to_string()
    } else {
        let start: String = text.chars().take(MAX_CHARS).collect();
        format!("{}...", serde_json::Value::from(start))
    }
}
