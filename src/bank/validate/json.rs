//! The JSON walker: checks a parsed document's shape (the type of every value, missing and unknown
//! fields) and applies the rules of the parent module to each value it finds.
//!
//! It copes with any JSON value anywhere. When it reports nothing, the document deserializes into
//! a [`Bank`](crate::bank::Bank), and the typed walker would report nothing either.

use serde_json::{Map, Value};

use super::{
    check_count, check_format, check_gains_len, check_name, check_number, check_version, quote,
    JsonPath, NumberRange, Problems, SameDimension, UniqueNames, COORD, DECAY_PER_S,
    DEFAULTS_RANGES, EXCITER_NAMES, FREQ_HZ, GAIN, MAX_MODES, MAX_POSITIONS, MODE_FREQ_HZ,
};
use crate::bank::format::FORMAT_VERSION;

/// Fields of a bank, in the order of [`Bank`](crate::bank::Bank).
const BANK_FIELDS: &[&str] = &[
    "format",
    "version",
    "name",
    "description",
    "author",
    "license",
    "source",
    "root_hz",
    "positions",
    "modes",
    "defaults",
];

/// Fields of a strike position.
const POSITION_FIELDS: &[&str] = &["name", "coords"];

/// Fields of a mode.
const MODE_FIELDS: &[&str] = &["freq_hz", "decay_per_s", "gains"];

/// Checks a whole document, reporting every problem in the order of the fields of the Rust types
/// (unknown fields last in each object).
pub(crate) fn check_document(doc: &Value, problems: &mut Problems) {
    let root = JsonPath::Root;
    let Some(bank) = object(doc, &root, "an object (a modal bank)", problems) else {
        return;
    };

    let path = root.field("format");
    if let Some(format) = required(bank, "format", &path, "the string \"modal-bank\"", problems)
        .and_then(|value| string(value, &path, problems))
    {
        problems.check(&path, check_format(format));
    }

    let path = root.field("version");
    let expected_version = format!("the integer {FORMAT_VERSION}");
    if let Some(version) = required(bank, "version", &path, &expected_version, problems)
        .and_then(|value| version(value, &path, problems))
    {
        problems.check(&path, check_version(version));
        if version > u64::from(FORMAT_VERSION) {
            // A newer format may differ anywhere: checking the rest against version 1 would
            // bury the one message that matters.
            return;
        }
    }

    let path = root.field("name");
    if let Some(name) = required(bank, "name", &path, "a non-empty string", problems)
        .and_then(|value| string(value, &path, problems))
    {
        problems.check(&path, check_name(name));
    }
    for field in ["description", "author", "license"] {
        if let Some(value) = bank.get(field) {
            string(value, &root.field(field), problems);
        }
    }
    if let Some(source) = optional(bank, "source") {
        // Free-form: only its being an object is checked.
        object(source, &root.field("source"), "an object", problems);
    }
    check_number_field(
        bank,
        &root,
        "root_hz",
        &FREQ_HZ,
        Presence::Optional,
        problems,
    );

    let num_positions = check_positions(bank, &root, problems);
    check_modes(bank, &root, num_positions, problems);
    check_defaults(bank, &root, problems);
    check_unknown_fields(bank, &root, BANK_FIELDS, problems);
}

/// Checks `positions` and returns how many there are, or 0 when that is unknown.
fn check_positions(
    bank: &Map<String, Value>,
    root: &JsonPath<'_>,
    problems: &mut Problems,
) -> usize {
    let path = root.field("positions");
    let expected = "an array of positions, each {\"name\": ..., \"coords\": [...]}";
    let Some(positions) = required(bank, "positions", &path, expected, problems)
        .and_then(|v| array(v, &path, problems))
    else {
        return 0;
    };
    problems.check(
        &path,
        check_count(positions.len(), MAX_POSITIONS, "positions"),
    );

    let mut names = UniqueNames::default();
    let mut dimensions = SameDimension::default();
    for (i, position) in positions.iter().enumerate() {
        let path = path.index(i);
        let Some(position) = object(
            position,
            &path,
            "an object with a name and coords",
            problems,
        ) else {
            continue;
        };
        let name_path = path.field("name");
        if let Some(name) = required(position, "name", &name_path, "a non-empty string", problems)
            .and_then(|value| string(value, &name_path, problems))
        {
            problems.check(&name_path, check_name(name));
            problems.check(&name_path, names.check(i, name));
        }
        let coords_path = path.field("coords");
        let expected = "an array of 1 or 2 numbers";
        if let Some(coords) = required(position, "coords", &coords_path, expected, problems)
            .and_then(|value| array(value, &coords_path, problems))
        {
            problems.check(&coords_path, dimensions.check(i, coords.len()));
            check_numbers(coords, &coords_path, &COORD, problems);
        }
        check_unknown_fields(position, &path, POSITION_FIELDS, problems);
    }
    positions.len()
}

/// Checks `modes`; `num_positions` is how many gains each needs (0 when unknown: not checked).
fn check_modes(
    bank: &Map<String, Value>,
    root: &JsonPath<'_>,
    num_positions: usize,
    problems: &mut Problems,
) {
    let path = root.field("modes");
    let expected =
        "an array of modes, each {\"freq_hz\": ..., \"decay_per_s\": ..., \"gains\": [...]}";
    let Some(modes) =
        required(bank, "modes", &path, expected, problems).and_then(|v| array(v, &path, problems))
    else {
        return;
    };
    problems.check(&path, check_count(modes.len(), MAX_MODES, "modes"));

    for (i, mode) in modes.iter().enumerate() {
        let path = path.index(i);
        let expected = "an object with freq_hz, decay_per_s and gains";
        let Some(mode) = object(mode, &path, expected, problems) else {
            continue;
        };
        check_number_field(
            mode,
            &path,
            "freq_hz",
            &MODE_FREQ_HZ,
            Presence::Required,
            problems,
        );
        check_number_field(
            mode,
            &path,
            "decay_per_s",
            &DECAY_PER_S,
            Presence::Required,
            problems,
        );
        let gains_path = path.field("gains");
        let expected = "an array of numbers, one per position";
        if let Some(gains) = required(mode, "gains", &gains_path, expected, problems)
            .and_then(|value| array(value, &gains_path, problems))
        {
            problems.check(&gains_path, check_gains_len(gains.len(), num_positions));
            check_numbers(gains, &gains_path, &GAIN, problems);
        }
        check_unknown_fields(mode, &path, MODE_FIELDS, problems);
    }
}

fn check_defaults(bank: &Map<String, Value>, root: &JsonPath<'_>, problems: &mut Problems) {
    let path = root.field("defaults");
    let Some(defaults) = optional(bank, "defaults")
        .and_then(|value| object(value, &path, "an object of parameter defaults", problems))
    else {
        return;
    };
    for (name, range) in &DEFAULTS_RANGES {
        check_number_field(defaults, &path, name, range, Presence::Optional, problems);
    }
    let exciter_path = path.field("exciter");
    if let Some(exciter) =
        optional(defaults, "exciter").and_then(|value| string(value, &exciter_path, problems))
    {
        if !EXCITER_NAMES.contains(&exciter) {
            problems.report(
                &exciter_path,
                format!(
                    "expected one of {}, found \"{exciter}\"",
                    EXCITER_NAMES.join(", ")
                ),
            );
        }
    }
    let mut known: Vec<&str> = DEFAULTS_RANGES.iter().map(|(name, _)| *name).collect();
    known.push("exciter");
    check_unknown_fields(defaults, &path, &known, problems);
}

/// Whether a field must be present.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Presence {
    Required,
    /// May be absent or null.
    Optional,
}

/// Checks the number field `name` of the object at `parent` against `range`.
fn check_number_field(
    object: &Map<String, Value>,
    parent: &JsonPath<'_>,
    name: &str,
    range: &NumberRange,
    presence: Presence,
    problems: &mut Problems,
) {
    let path = parent.field(name);
    let value = match presence {
        Presence::Required => required(object, name, &path, &range.describe(), problems),
        Presence::Optional => optional(object, name),
    };
    if let Some(x) = value.and_then(|value| number(value, &path, problems)) {
        problems.check(&path, check_number(x, range));
    }
}

/// Checks that every element of the array at `path` is a number in `range`.
fn check_numbers(
    values: &[Value],
    path: &JsonPath<'_>,
    range: &NumberRange,
    problems: &mut Problems,
) {
    for (i, value) in values.iter().enumerate() {
        if let Value::Number(n) = value {
            // Only reports build a path, so the common case costs no allocation.
            if let Err(message) = check_number(as_f64(n), range) {
                problems.report(&path.index(i), message);
            }
        } else {
            problems.report(&path.index(i), expected("a number", value));
        }
    }
}

/// The value of the required field `name`, or None once reported missing.
fn required<'v>(
    object: &'v Map<String, Value>,
    name: &str,
    path: &JsonPath<'_>,
    what: &str,
    problems: &mut Problems,
) -> Option<&'v Value> {
    let value = object.get(name);
    if value.is_none() {
        problems.report(path, format!("missing; expected {what}"));
    }
    value
}

/// The value of the optional field `name`; None when absent or null, which mean the same.
fn optional<'v>(object: &'v Map<String, Value>, name: &str) -> Option<&'v Value> {
    object.get(name).filter(|value| !value.is_null())
}

fn object<'v>(
    value: &'v Value,
    path: &JsonPath<'_>,
    what: &str,
    problems: &mut Problems,
) -> Option<&'v Map<String, Value>> {
    match value {
        Value::Object(map) => Some(map),
        other => {
            problems.report(path, expected(what, other));
            None
        }
    }
}

fn array<'v>(
    value: &'v Value,
    path: &JsonPath<'_>,
    problems: &mut Problems,
) -> Option<&'v [Value]> {
    match value {
        Value::Array(values) => Some(values),
        other => {
            problems.report(path, expected("an array", other));
            None
        }
    }
}

fn string<'v>(value: &'v Value, path: &JsonPath<'_>, problems: &mut Problems) -> Option<&'v str> {
    match value {
        Value::String(text) => Some(text),
        other => {
            problems.report(path, expected("a string", other));
            None
        }
    }
}

fn number(value: &Value, path: &JsonPath<'_>, problems: &mut Problems) -> Option<f64> {
    match value {
        Value::Number(n) => Some(as_f64(n)),
        other => {
            problems.report(path, expected("a number", other));
            None
        }
    }
}

/// The format version: a non-negative integer, or None once reported.
fn version(value: &Value, path: &JsonPath<'_>, problems: &mut Problems) -> Option<u64> {
    match value {
        Value::Number(n) => {
            if n.as_u64().is_none() {
                let message = format!(
                    "found {n}, expected the integer {FORMAT_VERSION} (no sign, no decimal point)"
                );
                problems.report(path, message);
            }
            n.as_u64()
        }
        other => {
            problems.report(path, expected("an integer", other));
            None
        }
    }
}

fn as_f64(n: &serde_json::Number) -> f64 {
    // Without serde_json's arbitrary_precision every number is an i64, u64 or finite f64, and
    // as_f64 never fails; NaN would fail every range check if it ever did.
    n.as_f64().unwrap_or(f64::NAN)
}

/// Reports every field of `object` not in `known`, with the likeliest intended name.
fn check_unknown_fields(
    object: &Map<String, Value>,
    path: &JsonPath<'_>,
    known: &[&str],
    problems: &mut Problems,
) {
    for key in object.keys() {
        if !known.contains(&key.as_str()) {
            let message = match suggest(key, known) {
                Some(name) => format!("unknown field; did you mean {}?", quote(name)),
                None => {
                    let names: Vec<String> = known.iter().map(|name| quote(name)).collect();
                    format!(
                        "unknown field; the known fields here are {}",
                        names.join(", ")
                    )
                }
            };
            problems.report(&path.field(key), message);
        }
    }
}

/// The known field name closest to `unknown` by edit distance, if it is close enough to be the
/// likely intent: within 2 edits, or sharing a 3-letter prefix, or one containing the other.
fn suggest<'k>(unknown: &str, known: &[&'k str]) -> Option<&'k str> {
    /// Longer keys are not typos of a field name; comparing them would only cost time.
    const MAX_LEN: usize = 64;
    /// Edits within which any field name counts as a typo.
    const MAX_TYPO_EDITS: usize = 2;
    /// Shared leading characters that make a field name a plausible intent ("frequency").
    const MIN_PREFIX: usize = 3;

    if unknown.chars().count() > MAX_LEN {
        return None;
    }
    // "Freq-Hz" and "freq hz" both mean freq_hz.
    let unknown: String = unknown
        .chars()
        .map(|c| {
            if c == '-' || c == ' ' {
                '_'
            } else {
                c.to_ascii_lowercase()
            }
        })
        .collect();
    known
        .iter()
        .filter_map(|&name| {
            let distance = edit_distance(&unknown, name);
            let prefix = unknown
                .chars()
                .zip(name.chars())
                .take_while(|(a, b)| a == b)
                .count();
            let contains = unknown.len() >= MIN_PREFIX
                && (name.contains(unknown.as_str()) || unknown.contains(name));
            let plausible = distance <= MAX_TYPO_EDITS || prefix >= MIN_PREFIX || contains;
            plausible.then_some((distance, name))
        })
        // min_by_key keeps the first of equals: the earlier field in the type wins a tie.
        .min_by_key(|&(distance, _)| distance)
        .map(|(_, name)| name)
}

/// Levenshtein distance in characters: insertions, deletions and substitutions.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut previous: Vec<usize> = (0..=b.len()).collect();
    let mut current = vec![0; b.len() + 1];
    for (i, ca) in a.chars().enumerate() {
        current[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let substitution = previous[j] + usize::from(ca != cb);
            current[j + 1] = substitution.min(previous[j + 1] + 1).min(current[j] + 1);
        }
        std::mem::swap(&mut previous, &mut current);
    }
    previous[b.len()]
}

/// "expected a number, found a string ("440")".
fn expected(what: &str, found: &Value) -> String {
    format!("expected {what}, found {}", describe(found))
}

/// What a value is, in words, with its content when short.
fn describe(value: &Value) -> String {
    match value {
        Value::Null => "null".to_string(),
        Value::Bool(b) => format!("a boolean ({b})"),
        Value::Number(n) => format!("a number ({n})"),
        Value::String(text) => format!("a string ({})", quote(text)),
        Value::Array(values) if values.is_empty() => "an empty array".to_string(),
        Value::Array(_) => "an array".to_string(),
        Value::Object(_) => "an object".to_string(),
    }
}
