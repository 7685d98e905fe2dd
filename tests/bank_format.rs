//! The bank file format: a good bank loads and survives a save unchanged; each kind of broken bank
//! gives its own error, naming the JSON path and what was expected; the committed JSON Schema
//! matches the Rust types.
//!
//! Broken banks live in `tests/data/bad/`, one problem each; the large ones are built here.

use std::fs;
use std::path::{Path, PathBuf};

use modal_resonator::bank::io::{bank_to_json, BankErrorKind};
use modal_resonator::bank::schema::bank_schema_json;
use modal_resonator::bank::validate::{validate_bank, MAX_REPORTED_PROBLEMS};
use modal_resonator::bank::{
    load_bank_file, parse_bank_str, save_bank_file, Bank, BankDefaults, BankError, Mode, Position,
    MAX_BANK_FILE_BYTES, MAX_JSON_VALUES,
};
use serde_json::{json, Value};

/// A bank using every field of the format.
const GOOD_BANK: &str = r#"{
  "format": "modal-bank",
  "version": 1,
  "name": "Steel bar, 30 cm",
  "description": "A free-free steel bar struck with a hard mallet.",
  "author": "Modal Resonator tests",
  "license": "CC0-1.0",
  "source": {"kind": "analytic", "shape": "free-free bar", "length_m": 0.3, "notes": [1, "two"]},
  "root_hz": 523.25,
  "positions": [
    {"name": "end", "coords": [0.0]},
    {"name": "middle", "coords": [0.5]}
  ],
  "modes": [
    {"freq_hz": 523.25, "decay_per_s": 1.2, "gains": [1.0, 0.05]},
    {"freq_hz": 1442.4, "decay_per_s": 3.3, "gains": [-0.6, 0.0]},
    {"freq_hz": 2827.6, "decay_per_s": 6.5, "gains": [0.45, -0.4]}
  ],
  "defaults": {
    "material_q": 800,
    "damping_tilt": 0.5,
    "hardness_ms": 0.4,
    "strike_position": 0.0,
    "key_tracking_pct": 100,
    "exciter": "mallet",
    "roughness": 0.5,
    "rolling_radius_mm": 20,
    "contact_speed_m_per_s": 0.5,
    "contact_force": 0.7
  }
}
"#;

fn bad_file(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/bad")
        .join(name)
}

fn load_bad(name: &str) -> BankError {
    match load_bank_file(&bad_file(name)) {
        Ok(bank) => panic!("{name} loaded, but it is broken: {bank:?}"),
        Err(error) => error,
    }
}

fn parse_bad(text: &str) -> BankError {
    match parse_bank_str(text, "test.json") {
        Ok(bank) => panic!("a broken bank parsed: {bank:?}"),
        Err(error) => error,
    }
}

/// Asserts that `error` reports a problem at exactly `path` whose message contains `needle`.
fn assert_problem(error: &BankError, path: &str, needle: &str) {
    assert_eq!(error.kind(), BankErrorKind::Invalid, "{error}");
    let found = error
        .problems()
        .iter()
        .any(|problem| problem.path == path && problem.message.contains(needle));
    assert!(
        found,
        "expected a problem at `{path}` containing {needle:?}; the error was:\n{error}"
    );
}

/// Asserts that `error` is the only problem, at `path`, with a message containing `needle`.
fn assert_only_problem(error: &BankError, path: &str, needle: &str) {
    assert_problem(error, path, needle);
    assert_eq!(error.problems().len(), 1, "{error}");
}

/// Asserts a syntax error on `line` whose message contains `needle`.
fn assert_syntax_error(error: &BankError, line: usize, needle: &str) {
    match error.kind() {
        BankErrorKind::Syntax { line: found, .. } => assert_eq!(found, line, "{error}"),
        kind => panic!("expected a syntax error, got {kind:?}: {error}"),
    }
    assert!(
        error.to_string().contains(needle),
        "expected {needle:?} in:\n{error}"
    );
}

/// A valid bank with `num_positions` positions and `num_modes` modes, as JSON.
fn generated_bank(num_positions: usize, num_modes: usize) -> Value {
    let positions: Vec<Value> = (0..num_positions)
        .map(|i| json!({"name": format!("p{i}"), "coords": [i as f64 / 64.0]}))
        .collect();
    let modes: Vec<Value> = (0..num_modes)
        .map(|i| {
            let gains = vec![0.5; num_positions];
            json!({"freq_hz": 100.0 + i as f64, "decay_per_s": 1.0, "gains": gains})
        })
        .collect();
    json!({
        "format": "modal-bank",
        "version": 1,
        "name": "Generated",
        "positions": positions,
        "modes": modes,
    })
}

#[test]
fn good_bank_loads() {
    let bank = parse_bank_str(GOOD_BANK, "good.json").unwrap_or_else(|error| panic!("{error}"));
    assert_eq!(bank.name, "Steel bar, 30 cm");
    assert_eq!(bank.license, "CC0-1.0");
    assert_eq!(bank.root_hz, Some(523.25));
    assert_eq!(bank.num_positions(), 2);
    assert_eq!(bank.positions[1].name, "middle");
    assert_eq!(bank.positions[1].coords, [0.5]);
    assert_eq!(bank.modes.len(), 3);
    assert_eq!(bank.modes[1].freq_hz, 1442.4);
    assert_eq!(bank.modes[1].gains, [-0.6, 0.0]);
    let source = bank.source.as_ref().expect("source");
    assert_eq!(source["kind"], "analytic");
    let defaults = bank.defaults.as_ref().expect("defaults");
    assert_eq!(defaults.material_q, Some(800.0));
    assert_eq!(defaults.key_tracking_pct, Some(100.0));
    assert!(validate_bank(&bank).is_empty());
}

#[test]
fn readme_example_loads() {
    let readme =
        fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/README.md"))
            .expect("presets/README.md");
    let example = readme
        .split("## Example")
        .nth(1)
        .and_then(|section| section.split("```json").nth(1))
        .and_then(|block| block.split("```").next())
        .expect("a ```json block under \"## Example\" in presets/README.md");
    parse_bank_str(example, "presets/README.md").unwrap_or_else(|error| panic!("{error}"));
}

#[test]
fn optional_fields_may_be_absent_or_null() {
    let minimal = r#"{"format": "modal-bank", "version": 1, "name": "Minimal",
        "positions": [{"name": "here", "coords": [0.1, 0.2]}],
        "modes": [{"freq_hz": 1e6, "decay_per_s": 0, "gains": [-1e6]}]}"#;
    let bank = parse_bank_str(minimal, "minimal.json").unwrap_or_else(|error| panic!("{error}"));
    assert_eq!(bank.description, "");
    assert_eq!(
        (bank.source, bank.root_hz, bank.defaults),
        (None, None, None)
    );

    let nulls = r#"{"format": "modal-bank", "version": 1, "name": "Nulls", "source": null,
        "root_hz": null, "defaults": {"material_q": null},
        "positions": [{"name": "here", "coords": [0]}],
        "modes": [{"freq_hz": 1, "decay_per_s": 1, "gains": [1]}]}"#;
    let bank = parse_bank_str(nulls, "nulls.json").unwrap_or_else(|error| panic!("{error}"));
    assert_eq!(bank.defaults, Some(BankDefaults::default()));
}

#[test]
fn wrong_types_name_the_expected_type() {
    let error = load_bad("wrong-types.json");
    assert_problem(&error, "name", "expected a string, found a number (42)");
    assert_problem(&error, "description", "expected a string, found an array");
    assert_problem(
        &error,
        "source",
        "expected an object, found a string (\"analytic\")",
    );
    assert_problem(
        &error,
        "root_hz",
        "expected a number, found a string (\"440\")",
    );
    assert_problem(
        &error,
        "modes[0].freq_hz",
        "expected a number, found a string",
    );
    assert_problem(
        &error,
        "modes[0].gains",
        "expected an array, found a number (1.0)",
    );
    assert_problem(
        &error,
        "modes[1].decay_per_s",
        "expected a number, found null",
    );
    assert_problem(
        &error,
        "modes[1].gains[0]",
        "expected a number, found a boolean (true)",
    );
    assert_problem(
        &error,
        "defaults.material_q",
        "expected a number, found a string",
    );
    assert_eq!(error.problems().len(), 9, "{error}");
}

#[test]
fn nan_literal_is_a_syntax_error_with_its_position() {
    let error = load_bad("nan-literal.json");
    assert_syntax_error(
        &error,
        7,
        "found NaN, which JSON does not allow: every number must be finite",
    );
    assert!(
        error.to_string().contains("nan-literal.json:7:37: "),
        "{error}"
    );
    for literal in ["nan", "-Infinity", "inf"] {
        let text = GOOD_BANK.replace(
            "\"decay_per_s\": 3.3",
            &format!("\"decay_per_s\": {literal}"),
        );
        assert_syntax_error(
            &parse_bad(&text),
            16,
            &format!("found {literal}, which JSON does not allow"),
        );
    }
}

#[test]
fn negative_frequency() {
    let error = load_bad("negative-frequency.json");
    assert_only_problem(
        &error,
        "modes[1].freq_hz",
        "found -440, expected a number from 1 to 1000000 Hz",
    );
}

#[test]
fn zero_frequency() {
    let error = load_bad("zero-frequency.json");
    assert_only_problem(
        &error,
        "modes[0].freq_hz",
        "found 0, expected a number from 1 to",
    );
}

#[test]
fn ragged_gains() {
    let error = load_bad("ragged-gains.json");
    assert_only_problem(
        &error,
        "modes[3].gains",
        "found 2 values, expected 3 (one per position)",
    );
}

#[test]
fn number_too_large_for_f64() {
    let error = load_bad("huge-number-1e400.json");
    assert_syntax_error(&error, 7, "the number 1e400 is out of range");
}

#[test]
fn numbers_beyond_the_limits() {
    let error = load_bad("huge-number-1e300.json");
    assert_problem(
        &error,
        "modes[0].freq_hz",
        "found 1e300, expected a number from 1 to",
    );
    assert_problem(
        &error,
        "modes[0].decay_per_s",
        "found 1e300, expected a number from 0 to 1000000 per second",
    );
    assert_problem(
        &error,
        "modes[0].gains[0]",
        "found -1e300, expected a number from -1000000 to 1000000",
    );
    assert_eq!(error.problems().len(), 3, "{error}");
}

#[test]
fn truncated_file() {
    let error = load_bad("truncated.json");
    assert_syntax_error(&error, 8, "the file looks truncated");
    let error = parse_bad("");
    assert_syntax_error(&error, 1, "the file is empty");
}

#[test]
fn version_from_a_newer_build() {
    let error = load_bad("version-2.json");
    // Its other fields may be valid in version 2: only the version is reported.
    assert_only_problem(
        &error,
        "version",
        "found 2: this bank was made by a newer version of Modal Resonator; this build reads version 1",
    );
}

#[test]
fn version_zero() {
    let error = load_bad("version-0.json");
    assert_only_problem(&error, "version", "found 0, expected 1");
}

#[test]
fn version_as_a_string() {
    let error = load_bad("version-string.json");
    assert_only_problem(
        &error,
        "version",
        "expected an integer, found a string (\"1\")",
    );
}

#[test]
fn version_not_an_integer() {
    for version in ["1.5", "1.0", "-1"] {
        let text = GOOD_BANK.replace("\"version\": 1,", &format!("\"version\": {version},"));
        let error = parse_bad(&text);
        assert_only_problem(&error, "version", "expected the integer 1");
    }
}

#[test]
fn wrong_format_name() {
    let error = load_bad("wrong-format.json");
    assert_only_problem(
        &error,
        "format",
        "found \"modal_bank\", expected \"modal-bank\"",
    );
}

#[test]
fn unknown_field_suggests_the_closest_name() {
    let error = load_bad("unknown-field.json");
    assert_problem(
        &error,
        "modes[0].freq",
        "unknown field; did you mean \"freq_hz\"?",
    );
    assert_problem(
        &error,
        "modes[0].freq_hz",
        "missing; expected a number from 1 to",
    );
    assert_eq!(error.problems().len(), 2, "{error}");
}

#[test]
fn unknown_fields_everywhere_but_source() {
    let mut bank: Value = serde_json::from_str(GOOD_BANK).unwrap();
    bank["nmae"] = json!("typo");
    bank["colour"] = json!("red");
    bank["positions"][0]["coord"] = json!([0.0]);
    bank["modes"][2]["Decay"] = json!(1.0);
    bank["modes"][2]["frequency"] = json!(1.0);
    bank["defaults"]["tilt"] = json!(1.0);
    bank["defaults"]["weird key"] = json!(1.0);
    bank["source"]["anything"] = json!({"goes": ["here"]});
    let error = parse_bad(&bank.to_string());
    assert_problem(&error, "nmae", "did you mean \"name\"?");
    assert_problem(
        &error,
        "colour",
        "unknown field; the known fields here are \"format\", \"version\"",
    );
    assert_problem(&error, "positions[0].coord", "did you mean \"coords\"?");
    assert_problem(&error, "modes[2].Decay", "did you mean \"decay_per_s\"?");
    assert_problem(&error, "modes[2].frequency", "did you mean \"freq_hz\"?");
    assert_problem(&error, "defaults.tilt", "did you mean \"damping_tilt\"?");
    assert_problem(&error, "defaults[\"weird key\"]", "unknown field");
    assert_eq!(error.problems().len(), 7, "{error}");
}

#[test]
fn no_modes() {
    let error = load_bad("no-modes.json");
    assert_only_problem(&error, "modes", "found 0 modes, expected from 1 to 65536");
}

#[test]
fn too_many_modes() {
    // The parser stops at the first mode too many, with where it is.
    let text = generated_bank(1, 65_537)
        .to_string()
        .replace("},{", "},\n{");
    let error = parse_bad(&text);
    assert_syntax_error(&error, 65_537, "more than 65536 modes");
    parse_bank_str(&generated_bank(1, 65_536).to_string(), "max.json")
        .unwrap_or_else(|error| panic!("{error}"));
}

#[test]
fn too_many_positions() {
    let error = parse_bad(&generated_bank(65, 2).to_string());
    assert_only_problem(
        &error,
        "positions",
        "found 65 positions, expected from 1 to 64",
    );
    parse_bank_str(&generated_bank(64, 2).to_string(), "max.json")
        .unwrap_or_else(|error| panic!("{error}"));
}

#[test]
fn no_positions() {
    let error = parse_bad(&generated_bank(0, 2).to_string());
    // Gains cannot match zero positions: only the cause is reported.
    assert_only_problem(
        &error,
        "positions",
        "found 0 positions, expected from 1 to 64",
    );
}

#[test]
fn mixed_one_and_two_dimensional_coords() {
    let error = load_bad("mixed-dimensions.json");
    assert_only_problem(
        &error,
        "positions[1].coords",
        "found 2 coordinates, expected 1 like positions[0]",
    );
}

#[test]
fn four_dimensional_coords() {
    let error = load_bad("coords-4d.json");
    assert_only_problem(
        &error,
        "positions[0].coords",
        "found 4 coordinates, expected 1 (a point along a line), 2 (a point on a surface) or 3 \
         (a point in space)",
    );
}

#[test]
fn points_in_space_are_positions() {
    let text = r#"{
        "format": "modal-bank", "version": 1, "name": "Cup",
        "positions": [{"name": "rim", "coords": [0.04, 0.0, 0.09]},
                      {"name": "base", "coords": [0.0, 0.0, 0.0]}],
        "modes": [{"freq_hz": 1200, "decay_per_s": 2.0, "gains": [1.0, 0.2]}]
    }"#;
    let bank = modal_resonator::bank::parse_bank_str(text, "cup.json").expect("a 3-D bank loads");
    assert_eq!(bank.positions[0].coords, vec![0.04, 0.0, 0.09]);
}

#[test]
fn duplicate_position_names() {
    let error = load_bad("duplicate-position-names.json");
    assert_only_problem(
        &error,
        "positions[2].name",
        "\"end\" is already the name of positions[0]; position names must be unique",
    );
}

#[test]
fn duplicate_keys_are_a_syntax_error() {
    let text = "{\"format\": \"modal-bank\",\n \"version\": 1,\n \"version\": 1}";
    let error = parse_bad(text);
    assert_syntax_error(&error, 3, "duplicate field \"version\"");
}

#[test]
fn every_problem_in_a_file_is_reported_in_order() {
    let error = load_bad("many-problems.json");
    let found: Vec<(&str, &str)> = error
        .problems()
        .iter()
        .map(|problem| (problem.path.as_str(), problem.message.as_str()))
        .collect();
    let expected_paths = [
        "name",
        "root_hz",
        "positions[1].weight",
        "modes[0].decay_per_s",
        "modes[1].freq_hz",
        "modes[1].gains",
        "modes[2].freq_hz",
        "defaults.material_q",
        "defaults.hardness_ms",
        "defaults.brightness",
    ];
    let paths: Vec<&str> = found.iter().map(|(path, _)| *path).collect();
    assert_eq!(paths, expected_paths, "{error}");
    assert_problem(&error, "name", "found \"\", expected a name");
    assert_problem(
        &error,
        "root_hz",
        "found -1, expected a number greater than 0",
    );
    assert_problem(
        &error,
        "modes[0].decay_per_s",
        "found -1, expected a number from 0 to",
    );
    assert_problem(&error, "modes[1].freq_hz", "found 2000000, expected");
    assert_problem(
        &error,
        "modes[1].gains",
        "found 1 value, expected 2 (one per position)",
    );
    assert_problem(&error, "modes[2].freq_hz", "missing");
    assert_problem(
        &error,
        "defaults.material_q",
        "found 0, expected a number from 1 to 100000",
    );
    assert_problem(
        &error,
        "defaults.hardness_ms",
        "found 50, expected a number from 0.05 to 20 ms",
    );
    assert_problem(&error, "defaults.brightness", "unknown field");
}

#[test]
fn missing_fields_and_a_document_that_is_not_an_object() {
    let error = parse_bad(r#"{"format": "modal-bank", "version": 1}"#);
    assert_problem(&error, "name", "missing; expected a non-empty string");
    assert_problem(
        &error,
        "positions",
        "missing; expected an array of positions",
    );
    assert_problem(&error, "modes", "missing; expected an array of modes");
    assert_eq!(error.problems().len(), 3, "{error}");

    let error = parse_bad("[]");
    assert_only_problem(
        &error,
        "",
        "expected an object (a modal bank), found an empty array",
    );
}

#[test]
fn long_lists_of_problems_are_capped() {
    let mut bank = generated_bank(2, 1000);
    for mode in bank["modes"].as_array_mut().unwrap() {
        mode["freq_hz"] = json!(-1.0);
        mode["gains"] = json!([]);
    }
    let error = parse_bad(&bank.to_string());
    assert_eq!(error.problems().len(), MAX_REPORTED_PROBLEMS);
    assert_eq!(error.num_omitted(), 2000 - MAX_REPORTED_PROBLEMS);
    let text = error.to_string();
    assert_eq!(text.lines().count(), MAX_REPORTED_PROBLEMS + 1);
    assert!(
        text.ends_with("test.json: ... and 1900 more problems"),
        "{text}"
    );
}

#[test]
fn display_names_the_file_then_the_path_or_position() {
    let error = load_bad("negative-frequency.json");
    let file = bad_file("negative-frequency.json").display().to_string();
    assert_eq!(
        error.to_string(),
        format!("{file}: modes[1].freq_hz: found -440, expected a number from 1 to 1000000 Hz")
    );

    let error = parse_bad("{\n  \"format\": \"modal-bank\",\n  \"version\": 1,,\n}");
    assert_eq!(
        error.kind(),
        BankErrorKind::Syntax {
            line: 3,
            column: 16
        }
    );
    assert!(
        error
            .to_string()
            .starts_with("test.json:3:16: invalid JSON: "),
        "{error}"
    );

    // A line break inside a string is placed at the end of the line it breaks.
    let error = parse_bad("{\"name\": \"Bar\n\"}");
    let expected = "test.json:1:14: a line break or control character inside a string: \
                    is a closing quote missing?";
    assert_eq!(error.to_string(), expected);

    let error = load_bank_file(Path::new("/nonexistent/bank.json")).unwrap_err();
    assert_eq!(error.kind(), BankErrorKind::Io);
    assert!(
        error
            .to_string()
            .starts_with("/nonexistent/bank.json: cannot read: "),
        "{error}"
    );
    assert!(std::error::Error::source(&error).is_some());
}

#[test]
fn a_file_larger_than_any_bank_is_refused_before_it_is_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("huge.json");
    // Sparse: the size is what counts, and none of it is read.
    let file = fs::File::create(&path).unwrap();
    file.set_len(MAX_BANK_FILE_BYTES + 1).unwrap();
    let error = load_bank_file(&path).unwrap_err();
    assert_eq!(error.kind(), BankErrorKind::Io, "{error}");
    let expected = format!(
        "huge.json: cannot read: the file holds {} bytes, and a bank file is at most {} bytes",
        MAX_BANK_FILE_BYTES + 1,
        MAX_BANK_FILE_BYTES
    );
    assert!(error.to_string().contains(&expected), "{error}");

    // A file of the limit itself is read and parsed: here, a syntax error on its first byte.
    file.set_len(MAX_BANK_FILE_BYTES).unwrap();
    let error = load_bank_file(&path).unwrap_err();
    assert!(
        matches!(error.kind(), BankErrorKind::Syntax { .. }),
        "{error}"
    );
}

#[test]
fn a_document_of_more_values_than_any_bank_is_refused_while_parsing() {
    // Any JSON value counts: here a free-form `source` far larger than a whole bank.
    let mut bank = generated_bank(1, 2);
    let junk = format!("[{}0]", "0,\n".repeat(2 * MAX_JSON_VALUES));
    bank["source"] = json!({"kind": "junk", "data": "JUNK"});
    let text = serde_json::to_string_pretty(&bank)
        .unwrap()
        .replace("\"JUNK\"", &junk);
    let error = parse_bad(&text);
    let line = match error.kind() {
        BankErrorKind::Syntax { line, .. } => line,
        kind => panic!("expected a syntax error, got {kind:?}: {error}"),
    };
    assert!(
        error
            .to_string()
            .contains(&format!("more than {MAX_JSON_VALUES} values")),
        "{error}"
    );
    // It stops where the budget runs out (one value a line), not at the end of the document.
    assert!(line < MAX_JSON_VALUES + 100, "{error}");
}

#[test]
fn the_largest_bank_fits_both_limits() {
    // 65,536 modes at 64 positions, every number as long as this program writes any.
    let positions = (0..64)
        .map(|i| Position {
            name: format!("position {i}"),
            coords: vec![-1.2345678901234567e-100, 1.2345678901234567e-100],
        })
        .collect();
    let mut bank = Bank::new("Largest", positions);
    bank.modes = (0..65_536)
        .map(|i| Mode {
            freq_hz: 123_456.789_012_345_67 + i as f64 * 1e-9,
            decay_per_s: 1.234_567_890_123_456_7e-100,
            gains: vec![-1.234_567_890_123_456_7e-100; 64],
        })
        .collect();
    let text = bank_to_json(&bank);
    println!(
        "the largest bank: {} bytes of JSON, limit {MAX_BANK_FILE_BYTES}",
        text.len()
    );
    assert!((text.len() as u64) < MAX_BANK_FILE_BYTES);
    let loaded = parse_bank_str(&text, "largest.json").unwrap_or_else(|error| panic!("{error}"));
    assert_eq!(loaded.modes.len(), 65_536);
}

#[test]
fn text_that_is_not_utf8_reports_where() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("latin1.json");
    fs::write(&path, b"{\n  \"name\": \"Caf\xe9\"\n}").unwrap();
    let error = load_bank_file(&path).unwrap_err();
    assert_eq!(
        error.kind(),
        BankErrorKind::Syntax {
            line: 2,
            column: 15
        },
        "{error}"
    );
    assert!(error.to_string().contains("not UTF-8"), "{error}");
}

#[test]
fn byte_order_mark_is_accepted() {
    parse_bank_str(&format!("\u{feff}{GOOD_BANK}"), "bom.json")
        .unwrap_or_else(|error| panic!("{error}"));
}

/// A bank whose numbers are hard to print and read back exactly.
fn awkward_bank() -> Bank {
    let mut bank = Bank::new(
        "Awkward numbers \u{2014} \"quoted\"",
        vec![
            Position {
                name: "a".into(),
                coords: vec![0.1, 1.7976931348623157e308],
            },
            Position {
                name: "b".into(),
                coords: vec![5e-324, -0.0],
            },
        ],
    );
    bank.root_hz = Some(523.2511306011972);
    bank.modes = vec![
        Mode {
            freq_hz: 1.1,
            decay_per_s: 1e-300,
            gains: vec![523.2511306011972, -2.2250738585072014e-308],
        },
        Mode {
            freq_hz: 1.000_000_000_000_000_2,
            decay_per_s: 0.0,
            gains: vec![1.0 / 3.0, 999_999.999_999_999_9],
        },
    ];
    bank.source = Some(
        json!({"kind": "edited", "seed": 12345678901234567_u64, "x": 0.3})
            .as_object()
            .unwrap()
            .clone(),
    );
    bank.defaults = Some(BankDefaults {
        material_q: Some(1.0 / 7.0 * 7000.0),
        strike_position: Some(0.1 + 0.2),
        ..BankDefaults::default()
    });
    bank
}

#[test]
fn round_trip_is_lossless() {
    let bank = awkward_bank();
    assert!(
        validate_bank(&bank).is_empty(),
        "{:?}",
        validate_bank(&bank)
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("awkward.json");
    save_bank_file(&bank, &path).unwrap_or_else(|error| panic!("{error}"));
    let loaded = load_bank_file(&path).unwrap_or_else(|error| panic!("{error}"));
    assert_eq!(loaded, bank);
    save_bank_file(&loaded, &path).unwrap_or_else(|error| panic!("{error}"));
    assert_eq!(load_bank_file(&path).unwrap(), bank);

    let parsed = parse_bank_str(GOOD_BANK, "good.json").unwrap();
    let reparsed = parse_bank_str(&bank_to_json(&parsed), "saved.json").unwrap();
    assert_eq!(reparsed, parsed);
}

#[test]
fn saved_json_is_pretty_ordered_and_ends_with_a_newline() {
    let bank = parse_bank_str(GOOD_BANK, "good.json").unwrap();
    let json = bank_to_json(&bank);
    assert!(json.starts_with("{\n  \"format\": \"modal-bank\",\n  \"version\": 1,\n  \"name\": "));
    assert!(json.ends_with("}\n"));
    let order = [
        "\"description\"",
        "\"author\"",
        "\"license\"",
        "\"source\"",
        "\"root_hz\"",
        "\"positions\"",
        "\"modes\"",
        "\"defaults\"",
    ];
    let offsets: Vec<usize> = order.iter().map(|key| json.find(key).expect(key)).collect();
    assert!(offsets.windows(2).all(|pair| pair[0] < pair[1]), "{json}");
    // Fields that are absent stay absent.
    let minimal = Bank::new("Minimal", vec![]);
    let json = bank_to_json(&minimal);
    assert!(!json.contains("root_hz") && !json.contains("source") && !json.contains("defaults"));
}

#[test]
fn save_validates_and_leaves_nothing_behind_on_failure() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bank.json");
    let mut bank = awkward_bank();
    bank.modes[1].freq_hz = f64::NAN;
    bank.modes[0].gains.pop();
    let error = save_bank_file(&bank, &path).unwrap_err();
    assert_problem(
        &error,
        "modes[0].gains",
        "found 1 value, expected 2 (one per position)",
    );
    assert_problem(
        &error,
        "modes[1].freq_hz",
        "found NaN, expected a number from 1 to",
    );
    assert!(
        error
            .to_string()
            .starts_with(&format!("{}: ", path.display())),
        "{error}"
    );
    assert_eq!(
        fs::read_dir(dir.path()).unwrap().count(),
        0,
        "nothing written"
    );

    // A directory that does not exist: nothing is created.
    let error = save_bank_file(&awkward_bank(), &dir.path().join("missing/bank.json")).unwrap_err();
    assert_eq!(error.kind(), BankErrorKind::Io, "{error}");
    assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 0);

    // The target is a directory: the rename fails and the temporary file is removed.
    let target = dir.path().join("taken");
    fs::create_dir(&target).unwrap();
    fs::write(target.join("keep"), "x").unwrap();
    let error = save_bank_file(&awkward_bank(), &target).unwrap_err();
    assert_eq!(error.kind(), BankErrorKind::Io, "{error}");
    let names: Vec<_> = fs::read_dir(dir.path())
        .unwrap()
        .map(|entry| entry.unwrap().file_name())
        .collect();
    assert_eq!(names, ["taken"]);
}

#[test]
fn save_replaces_an_existing_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bank.json");
    fs::write(&path, "old contents").unwrap();
    let bank = parse_bank_str(GOOD_BANK, "good.json").unwrap();
    save_bank_file(&bank, &path).unwrap_or_else(|error| panic!("{error}"));
    assert_eq!(fs::read_to_string(&path).unwrap(), bank_to_json(&bank));
    let names: Vec<_> = fs::read_dir(dir.path())
        .unwrap()
        .map(|entry| entry.unwrap().file_name())
        .collect();
    assert_eq!(names, ["bank.json"], "no temporary file left");
}

#[test]
fn validate_bank_applies_the_same_rules_in_memory() {
    let mut bank = parse_bank_str(GOOD_BANK, "good.json").unwrap();
    bank.format = "modal-bank-v2".into();
    bank.version = 3;
    bank.name = " ".into();
    bank.root_hz = Some(f64::INFINITY);
    bank.positions.push(Position {
        name: "end".into(),
        coords: vec![0.0, f64::NAN],
    });
    bank.modes[2].decay_per_s = -0.5;
    bank.modes[2].gains[0] = 2e6;
    let problems = validate_bank(&bank);
    let paths: Vec<&str> = problems
        .iter()
        .map(|problem| problem.path.as_str())
        .collect();
    assert_eq!(
        paths,
        [
            "format",
            "version",
            "name",
            "root_hz",
            "positions[2].name",
            "positions[2].coords",
            "positions[2].coords[1]",
            "modes[0].gains",
            "modes[1].gains",
            "modes[2].decay_per_s",
            "modes[2].gains",
            "modes[2].gains[0]",
        ],
        "{problems:#?}"
    );
    assert!(problems[1]
        .message
        .contains("made by a newer version of Modal Resonator"));
    assert!(problems[3].message.contains("found infinity"));
    assert!(problems[6]
        .message
        .contains("found NaN, expected a finite number"));

    // Each default is checked against its own range.
    let bad_defaults = [
        (
            "material_q",
            BankDefaults {
                material_q: Some(0.5),
                ..Default::default()
            },
        ),
        (
            "damping_tilt",
            BankDefaults {
                damping_tilt: Some(2.5),
                ..Default::default()
            },
        ),
        (
            "hardness_ms",
            BankDefaults {
                hardness_ms: Some(0.01),
                ..Default::default()
            },
        ),
        (
            "strike_position",
            BankDefaults {
                strike_position: Some(1.5),
                ..Default::default()
            },
        ),
        (
            "key_tracking_pct",
            BankDefaults {
                key_tracking_pct: Some(-1.0),
                ..Default::default()
            },
        ),
        (
            "exciter",
            BankDefaults {
                exciter: Some("bow".into()),
                ..Default::default()
            },
        ),
        (
            "roughness",
            BankDefaults {
                roughness: Some(1.5),
                ..Default::default()
            },
        ),
        (
            "rolling_radius_mm",
            BankDefaults {
                rolling_radius_mm: Some(0.0),
                ..Default::default()
            },
        ),
        (
            "contact_speed_m_per_s",
            BankDefaults {
                contact_speed_m_per_s: Some(4.0),
                ..Default::default()
            },
        ),
        (
            "contact_force",
            BankDefaults {
                contact_force: Some(-0.1),
                ..Default::default()
            },
        ),
    ];
    for (name, defaults) in bad_defaults {
        let mut bank = parse_bank_str(GOOD_BANK, "good.json").unwrap();
        bank.defaults = Some(defaults);
        let problems = validate_bank(&bank);
        assert_eq!(problems.len(), 1, "{problems:?}");
        assert_eq!(problems[0].path, format!("defaults.{name}"));
    }
}

#[test]
fn no_input_panics_the_loader() {
    // Every node of a good bank replaced, in turn, by each kind of JSON value.
    let replacements = [
        json!(null),
        json!(true),
        json!(-1),
        json!(1e300),
        json!("x"),
        json!([]),
        json!([[1, 2], {}]),
        json!({}),
        json!({"name": 1}),
    ];
    let good: Value = serde_json::from_str(GOOD_BANK).unwrap();
    let mut pointers = Vec::new();
    collect_pointers(&good, String::new(), &mut pointers);
    for pointer in &pointers {
        for replacement in &replacements {
            let mut bank = good.clone();
            *bank.pointer_mut(pointer).unwrap() = replacement.clone();
            let _ = parse_bank_str(&bank.to_string(), "mutated.json");
        }
    }
    // Every prefix of a good bank is truncated, hence an error.
    for (end, _) in GOOD_BANK.trim_end().char_indices() {
        let error = parse_bad(&GOOD_BANK[..end]);
        assert!(
            matches!(error.kind(), BankErrorKind::Syntax { .. }),
            "{error}"
        );
    }
    // Deep nesting is refused, not a stack overflow.
    let deep = format!("{}{}", "[".repeat(100_000), "]".repeat(100_000));
    let error = parse_bad(&deep);
    assert!(
        matches!(error.kind(), BankErrorKind::Syntax { .. }),
        "{error}"
    );
}

/// JSON pointers to every node below the root of `value`.
fn collect_pointers(value: &Value, pointer: String, out: &mut Vec<String>) {
    let children: Vec<(String, &Value)> = match value {
        Value::Array(values) => values
            .iter()
            .enumerate()
            .map(|(i, v)| (i.to_string(), v))
            .collect(),
        Value::Object(map) => map
            .iter()
            .map(|(k, v)| (k.replace('~', "~0").replace('/', "~1"), v))
            .collect(),
        _ => Vec::new(),
    };
    for (key, child) in children {
        let child_pointer = format!("{pointer}/{key}");
        out.push(child_pointer.clone());
        collect_pointers(child, child_pointer, out);
    }
}

/// The committed schema is the one the types generate. To regenerate it after changing the types:
/// `UPDATE_SCHEMA=1 cargo test --test bank_format`.
#[test]
fn committed_schema_matches_the_types() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("presets/modal-bank.schema.json");
    let generated = bank_schema_json();
    if std::env::var_os("UPDATE_SCHEMA").is_some() {
        fs::write(&path, &generated).expect("write presets/modal-bank.schema.json");
    }
    let committed = fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} is out of date with the Rust types; regenerate it with \
         `UPDATE_SCHEMA=1 cargo test --test bank_format` and commit it",
        path.display()
    );
}

/// The validator knows exactly the fields the types have: the good bank uses every field the
/// schema lists, and loads.
#[test]
fn validator_and_types_agree_on_the_fields() {
    let schema: Value = serde_json::from_str(&bank_schema_json()).unwrap();
    let good: Value = serde_json::from_str(GOOD_BANK).unwrap();
    let keys = |value: &Value| -> Vec<String> {
        let mut keys: Vec<String> = value.as_object().unwrap().keys().cloned().collect();
        keys.sort();
        keys
    };
    let definitions = &schema["$defs"];
    let cases = [
        (&schema["properties"], &good),
        (
            &definitions["Position"]["properties"],
            &good["positions"][0],
        ),
        (&definitions["Mode"]["properties"], &good["modes"][0]),
        (
            &definitions["BankDefaults"]["properties"],
            &good["defaults"],
        ),
    ];
    for (properties, object) in cases {
        assert_eq!(keys(properties), keys(object));
    }
}

/// The schema's bounds are the validator's: every numeric range, list length and name list that
/// `presets/modal-bank.schema.json` states is the constant `bank::validate` checks, so an editor
/// that follows the schema and the program that loads the bank agree.
#[test]
fn schema_bounds_are_the_validators() {
    use modal_resonator::bank::validate::{
        NumberRange, DECAY_PER_S, DEFAULTS_RANGES, EXCITER_NAMES, FREQ_HZ, GAIN, MAX_COORDS,
        MAX_MODES, MAX_POSITIONS, MODE_FREQ_HZ,
    };
    let schema: Value = serde_json::from_str(&bank_schema_json()).unwrap();
    let defs = &schema["$defs"];
    let number = |v: &Value| v.as_f64();
    let check_range = |where_: &str, property: &Value, range: &NumberRange| {
        let (min_key, other_key) = if range.min_inclusive {
            ("minimum", "exclusiveMinimum")
        } else {
            ("exclusiveMinimum", "minimum")
        };
        assert_eq!(
            number(&property[min_key]),
            Some(range.min),
            "{where_}: schema {min_key} {} vs validator {range:?}",
            property[min_key]
        );
        assert!(property[other_key].is_null(), "{where_}: {property}");
        assert_eq!(
            number(&property["maximum"]),
            Some(range.max),
            "{where_}: schema maximum {} vs validator {range:?}",
            property["maximum"]
        );
    };
    check_range("root_hz", &schema["properties"]["root_hz"], &FREQ_HZ);
    let mode = &defs["Mode"]["properties"];
    check_range("modes[].freq_hz", &mode["freq_hz"], &MODE_FREQ_HZ);
    check_range("modes[].decay_per_s", &mode["decay_per_s"], &DECAY_PER_S);
    check_range("modes[].gains[]", &mode["gains"]["items"], &GAIN);
    let lengths = [
        (
            "positions",
            &schema["properties"]["positions"],
            MAX_POSITIONS,
        ),
        ("modes", &schema["properties"]["modes"], MAX_MODES),
        ("modes[].gains", &mode["gains"], MAX_POSITIONS),
        (
            "positions[].coords",
            &defs["Position"]["properties"]["coords"],
            MAX_COORDS,
        ),
    ];
    for (where_, property, max) in lengths {
        assert_eq!(property["minItems"].as_u64(), Some(1), "{where_}");
        assert_eq!(property["maxItems"].as_u64(), Some(max as u64), "{where_}");
    }
    let defaults = &defs["BankDefaults"]["properties"];
    let numeric: Vec<&str> = defaults
        .as_object()
        .unwrap()
        .iter()
        .filter(|(_, p)| p["type"][0] == "number")
        .map(|(name, _)| name.as_str())
        .collect();
    let ranged: Vec<&str> = DEFAULTS_RANGES.iter().map(|(name, _)| *name).collect();
    assert_eq!(numeric.len(), ranged.len(), "{numeric:?} vs {ranged:?}");
    for (name, range) in &DEFAULTS_RANGES {
        check_range(&format!("defaults.{name}"), &defaults[*name], range);
    }
    let exciters: Vec<&str> = defaults["exciter"]["enum"]
        .as_array()
        .expect("defaults.exciter lists its names")
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(exciters, EXCITER_NAMES);
}
