//! Reading and writing banks as JSON files.
//!
//! Loading goes text -> `serde_json::Value` (a syntax error stops here, with its line and column)
//! -> the JSON walker of [`validate`](super::validate), which collects every problem with its path
//! -> the typed [`Bank`], only when there are none. Saving validates first and replaces the file
//! atomically.

use std::cell::Cell;
use std::fmt;
use std::fs;
use std::io::{self, Read};
use std::path::Path;

use serde::de::{self, DeserializeSeed, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use serde_json::{Map, Value};

use super::format::Bank;
use super::staged::StagedFile;
use super::validate::{self, Problem, Problems, MAX_MODES, MAX_POSITIONS, MAX_REPORTED_PROBLEMS};

/// Why a bank could not be loaded or saved. `Display` prints one line per problem, each starting
/// with the file: `FILE: PATH: message`, or `FILE:LINE:COLUMN: message` for a syntax error.
#[derive(Debug)]
pub struct BankError {
    /// The file, or whatever the text came from.
    origin: String,
    /// Which stage failed.
    kind: BankErrorKind,
    /// What is wrong: never empty.
    problems: Vec<Problem>,
    /// Problems found beyond those kept in `problems`.
    omitted: usize,
    /// The I/O error, for [`std::error::Error::source`].
    io_error: Option<io::Error>,
}

/// The stage at which loading or saving a bank failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BankErrorKind {
    /// The file could not be read or written.
    Io,
    /// The text is not JSON (or not UTF-8); `line` and `column` count from 1.
    Syntax {
        /// Line of the error.
        line: usize,
        /// Column of the error, in bytes; 0 when the line is empty.
        column: usize,
    },
    /// The JSON is not a valid bank: see [`BankError::problems`].
    Invalid,
}

impl BankError {
    /// The file, or whatever the text came from.
    pub fn origin(&self) -> &str {
        &self.origin
    }

    /// Which stage failed.
    pub fn kind(&self) -> BankErrorKind {
        self.kind
    }

    /// What is wrong, at most [`MAX_REPORTED_PROBLEMS`] entries; one entry, with an empty path,
    /// for I/O and syntax errors.
    pub fn problems(&self) -> &[Problem] {
        &self.problems
    }

    /// How many more problems were found than [`problems`](Self::problems) holds.
    pub fn num_omitted(&self) -> usize {
        self.omitted
    }

    fn io(origin: &str, what: &str, error: io::Error) -> Self {
        Self {
            origin: origin.to_string(),
            kind: BankErrorKind::Io,
            problems: vec![Problem {
                path: String::new(),
                message: format!("{what}: {error}"),
            }],
            omitted: 0,
            io_error: Some(error),
        }
    }

    fn syntax(origin: &str, line: usize, column: usize, message: String) -> Self {
        Self {
            origin: origin.to_string(),
            kind: BankErrorKind::Syntax { line, column },
            problems: vec![Problem {
                path: String::new(),
                message,
            }],
            omitted: 0,
            io_error: None,
        }
    }

    fn invalid(origin: &str, problems: Problems) -> Self {
        let (problems, omitted) = problems.into_parts();
        Self {
            origin: origin.to_string(),
            kind: BankErrorKind::Invalid,
            problems,
            omitted,
            io_error: None,
        }
    }
}

impl fmt::Display for BankError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let origin = &self.origin;
        for (i, problem) in self.problems.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            match self.kind {
                BankErrorKind::Syntax { line, column } => {
                    write!(f, "{origin}:{line}:{column}: {}", problem.message)?;
                }
                BankErrorKind::Io | BankErrorKind::Invalid => write!(f, "{origin}: {problem}")?,
            }
        }
        if self.omitted > 0 {
            let problems = if self.omitted == 1 {
                "problem"
            } else {
                "problems"
            };
            write!(f, "\n{origin}: ... and {} more {problems}", self.omitted)?;
        }
        Ok(())
    }
}

impl std::error::Error for BankError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.io_error
            .as_ref()
            .map(|error| error as &(dyn std::error::Error + 'static))
    }
}

/// Parses and validates a bank from JSON text. `origin` names the text in messages (a file
/// name, "clipboard", ...). Reports every problem found, up to [`MAX_REPORTED_PROBLEMS`].
pub fn parse_bank_str(text: &str, origin: &str) -> Result<Bank, BankError> {
    // Some editors start UTF-8 files with a byte-order mark; it is not part of the JSON.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let value = parse_json(text).map_err(|error| {
        let message = describe_syntax_error(text, &error);
        let (line, column) = error_position(text, error.line(), error.column());
        BankError::syntax(origin, line, column, message)
    })?;

    let mut problems = Problems::new(MAX_REPORTED_PROBLEMS);
    validate::check_document(&value, &mut problems);
    if !problems.is_empty() {
        return Err(BankError::invalid(origin, problems));
    }
    Bank::deserialize(value).map_err(|error| {
        // The walker accepts only what deserializes; reaching this is a bug in the walker,
        // still reported rather than panicking on a user's file.
        let mut problems = Problems::new(1);
        let message = format!("not a valid bank ({error}); please report this file as a bug");
        problems.report(&validate::JsonPath::Root, message);
        BankError::invalid(origin, problems)
    })
}

/// Reads, parses and validates the bank file at `path`.
pub fn load_bank_file(path: &Path) -> Result<Bank, BankError> {
    let origin = path.display().to_string();
    let bytes = read_limited(path).map_err(|error| BankError::io(&origin, "cannot read", error))?;
    match String::from_utf8(bytes) {
        Ok(text) => parse_bank_str(&text, &origin),
        Err(error) => {
            let valid = &error.as_bytes()[..error.utf8_error().valid_up_to()];
            let line = 1 + valid.iter().filter(|&&b| b == b'\n').count();
            let column = 1 + valid.iter().rev().take_while(|&&b| b != b'\n').count();
            let message = "not UTF-8 text: save the file as UTF-8".to_string();
            Err(BankError::syntax(&origin, line, column, message))
        }
    }
}

/// The bytes of the file at `path`, or an error of kind [`io::ErrorKind::FileTooLarge`] naming
/// the limit when it holds more than [`MAX_BANK_FILE_BYTES`] (checked before reading, and while
/// reading for files whose size is not known in advance, such as pipes).
fn read_limited(path: &Path) -> io::Result<Vec<u8>> {
    let too_large = |size: Option<u64>| {
        let found = match size {
            Some(size) => format!("the file holds {size} bytes"),
            None => format!("the file holds more than {MAX_BANK_FILE_BYTES} bytes"),
        };
        let message = format!(
            "{found}, and a bank file is at most {MAX_BANK_FILE_BYTES} bytes (256 MiB; the \
             largest bank, {MAX_MODES} modes at {MAX_POSITIONS} positions, takes about 150 MB)"
        );
        io::Error::new(io::ErrorKind::FileTooLarge, message)
    };
    let file = fs::File::open(path)?;
    let size = file.metadata()?.len();
    if size > MAX_BANK_FILE_BYTES {
        return Err(too_large(Some(size)));
    }
    let mut bytes = Vec::with_capacity(usize::try_from(size).unwrap_or(0));
    file.take(MAX_BANK_FILE_BYTES + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_BANK_FILE_BYTES {
        return Err(too_large(None));
    }
    Ok(bytes)
}

/// Validates `bank` and writes it to `path` as [`bank_to_json`] does. The file is replaced
/// atomically: the JSON goes to a temporary file in the same directory, which is then renamed
/// over `path`; on any failure `path` is left as it was and the temporary file is removed.
pub fn save_bank_file(bank: &Bank, path: &Path) -> Result<(), BankError> {
    stage_bank_file(bank, path)?
        .commit()
        .map_err(|error| BankError::io(&path.display().to_string(), "cannot replace", error))
}

/// Validates `bank` and writes its JSON to a temporary file beside `path`, to replace `path`
/// when committed ([`save_bank_file`] in two steps, for commands writing several files).
pub fn stage_bank_file(bank: &Bank, path: &Path) -> Result<StagedFile, BankError> {
    let origin = path.display().to_string();
    let mut problems = Problems::new(MAX_REPORTED_PROBLEMS);
    validate::check_bank(bank, &mut problems);
    if !problems.is_empty() {
        return Err(BankError::invalid(&origin, problems));
    }
    StagedFile::write(path, "modal-bank", bank_to_json(bank).as_bytes())
        .map_err(|error| BankError::io(&origin, "cannot write", error))
}

/// The bank as pretty-printed JSON: fields in the order of the Rust types, each float printed with
/// the fewest digits that read back to the same value, and a final newline.
pub fn bank_to_json(bank: &Bank) -> String {
    // Serializing a Bank cannot fail: every map key is a string, and serde_json writes any f64
    // (a non-finite one as null, which validation rejects before saving).
    let mut json = serde_json::to_string_pretty(bank).expect("a Bank always serializes to JSON");
    json.push('\n');
    json
}

/// Parses JSON text into a tree, rejecting duplicate keys, which `serde_json::Value` would
/// silently resolve to the last one.
fn parse_json(text: &str) -> Result<Value, serde_json::Error> {
    let mut deserializer = serde_json::Deserializer::from_str(text);
    let budget = Cell::new(MAX_JSON_VALUES);
    let value = StrictValue::document(&budget).deserialize(&mut deserializer)?;
    deserializer.end()?;
    Ok(value)
}

/// Largest bank file read: well above the largest bank the format allows as this program writes
/// it ([`MAX_MODES`] modes of [`MAX_POSITIONS`] full-precision gains, about 150 MB), so that a file
/// far too large for any bank is refused before it is read.
pub const MAX_BANK_FILE_BYTES: u64 = 256 << 20;

/// Most JSON values (numbers, strings, arrays, objects...) a bank document may hold: every mode of
/// the largest bank with room for a few more fields each, plus as many again as one mode count for
/// names and a free-form `source`. Parsing stops at the first value beyond, so a document far
/// larger than any bank never grows into a tree many times its size.
pub const MAX_JSON_VALUES: usize = MAX_MODES * (MAX_POSITIONS + 8) + MAX_MODES;

/// Builds a `serde_json::Value` like its own `Deserialize`, but fails on a duplicate key, on a
/// `modes` array longer than [`MAX_MODES`] and on a document of more than [`MAX_JSON_VALUES`]
/// values; the deserializer adds the line and column.
#[derive(Clone, Copy)]
struct StrictValue<'a> {
    /// Values that may still be read in the whole document.
    budget: &'a Cell<usize>,
    /// Whether this value is the top-level `modes` field.
    is_modes: bool,
    /// Objects around this value: 0 for the document itself.
    depth: usize,
}

impl<'a> StrictValue<'a> {
    fn document(budget: &'a Cell<usize>) -> Self {
        Self {
            budget,
            is_modes: false,
            depth: 0,
        }
    }

    /// A value inside this one (an array element, or the field `key` of an object).
    fn child(self, key: Option<&str>) -> Self {
        Self {
            budget: self.budget,
            is_modes: self.depth == 0 && key == Some("modes"),
            depth: self.depth + 1,
        }
    }

    /// Counts one value against the document's budget.
    fn spend<E: de::Error>(self) -> Result<(), E> {
        match self.budget.get().checked_sub(1) {
            Some(left) => {
                self.budget.set(left);
                Ok(())
            }
            None => Err(E::custom(format!(
                "the document holds more than {MAX_JSON_VALUES} values, far more than a bank of \
                 {MAX_MODES} modes at {MAX_POSITIONS} positions; the rest was not read"
            ))),
        }
    }
}

impl<'de> DeserializeSeed<'de> for StrictValue<'_> {
    type Value = Value;

    fn deserialize<D: de::Deserializer<'de>>(self, deserializer: D) -> Result<Value, D::Error> {
        deserializer.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for StrictValue<'_> {
    type Value = Value;

    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("any JSON value")
    }

    fn visit_bool<E: de::Error>(self, b: bool) -> Result<Value, E> {
        self.spend()?;
        Ok(Value::Bool(b))
    }

    fn visit_i64<E: de::Error>(self, n: i64) -> Result<Value, E> {
        self.spend()?;
        Ok(Value::from(n))
    }

    fn visit_u64<E: de::Error>(self, n: u64) -> Result<Value, E> {
        self.spend()?;
        Ok(Value::from(n))
    }

    fn visit_f64<E: de::Error>(self, x: f64) -> Result<Value, E> {
        self.spend()?;
        // The parser yields finite numbers only (it rejects overflow); Value::from maps any
        // other to null, which validation rejects.
        Ok(Value::from(x))
    }

    fn visit_str<E: de::Error>(self, text: &str) -> Result<Value, E> {
        self.spend()?;
        Ok(Value::String(text.to_string()))
    }

    fn visit_string<E: de::Error>(self, text: String) -> Result<Value, E> {
        self.spend()?;
        Ok(Value::String(text))
    }

    fn visit_unit<E: de::Error>(self) -> Result<Value, E> {
        self.spend()?;
        Ok(Value::Null)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        self.spend()?;
        let mut values = Vec::new();
        while let Some(value) = seq.next_element_seed(self.child(None))? {
            if self.is_modes && values.len() == MAX_MODES {
                return Err(de::Error::custom(format!(
                    "more than {MAX_MODES} modes, the most a bank may have; the rest was not read"
                )));
            }
            values.push(value);
        }
        Ok(Value::Array(values))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        self.spend()?;
        let mut object = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            if object.contains_key(&key) {
                return Err(de::Error::custom(format!(
                    "duplicate field {}: each field may appear once per object",
                    Value::from(key)
                )));
            }
            let value = map.next_value_seed(self.child(Some(&key)))?;
            object.insert(key, value);
        }
        Ok(Value::Object(object))
    }
}

/// A serde_json syntax error in words a person can act on, without its position (the caller
/// prints that).
fn describe_syntax_error(text: &str, error: &serde_json::Error) -> String {
    let full = error.to_string();
    let suffix = format!(" at line {} column {}", error.line(), error.column());
    let raw = full.strip_suffix(&suffix).unwrap_or(&full);
    let token = token_at(text, error.line(), error.column());

    if error.is_eof() {
        if text.trim().is_empty() {
            return "the file is empty; expected a JSON object (a modal bank)".to_string();
        }
        let inside = match raw.strip_prefix("EOF while parsing ") {
            Some("a list") => "an array",
            Some(what) => what,
            None => "the document",
        };
        return format!("the text ends in the middle of {inside}: the file looks truncated");
    }
    if error.classify() == serde_json::error::Category::Data {
        // A message of the strict parser's own, already in words.
        return raw.to_string();
    }
    let lower = token.to_ascii_lowercase();
    let unsigned = lower.trim_start_matches(['-', '+']);
    if matches!(unsigned, "nan" | "inf" | "infinity") {
        return format!("found {token}, which JSON does not allow: every number must be finite");
    }
    match raw {
        "number out of range" => format!(
            "the number {token} is out of range: numbers must be within about \
             +-1.8e308 (a 64-bit float)"
        ),
        "control character (\\u0000-\\u001F) found while parsing a string" => {
            "a line break or control character inside a string: is a closing quote missing?"
                .to_string()
        }
        "trailing characters" => "unexpected text after the end of the JSON document".to_string(),
        "recursion limit exceeded" => "nested too deeply (more than 128 levels)".to_string(),
        _ if token.is_empty() => format!("invalid JSON: {raw}"),
        _ => format!("invalid JSON: {raw} (near {token:?})"),
    }
}

/// serde_json's error position, except that an error at a line break (column 0 of the next
/// line) is put at the end of the line it breaks, where the reader's eye is.
fn error_position(text: &str, line: usize, column: usize) -> (usize, usize) {
    if column == 0 && line > 1 {
        if let Some(previous) = text.split('\n').nth(line - 2) {
            return (line - 1, previous.len() + 1);
        }
    }
    (line, column)
}

/// The word or number around serde_json's error position (a 1-based byte column, pointing at the
/// last byte read), or "" when there is none.
fn token_at(text: &str, line: usize, column: usize) -> &str {
    fn is_token_byte(b: u8) -> bool {
        b.is_ascii_alphanumeric() || matches!(b, b'+' | b'-' | b'.')
    }
    let Some(line_text) = text.split('\n').nth(line.saturating_sub(1)) else {
        return "";
    };
    let bytes = line_text.as_bytes();
    let Some(at) = column.checked_sub(1).filter(|&at| at < bytes.len()) else {
        return "";
    };
    if !is_token_byte(bytes[at]) {
        return "";
    }
    let start = bytes[..at]
        .iter()
        .rposition(|&b| !is_token_byte(b))
        .map_or(0, |i| i + 1);
    let end = bytes[at..]
        .iter()
        .position(|&b| !is_token_byte(b))
        .map_or(bytes.len(), |i| at + i);
    // The token is ASCII, so its bounds are character boundaries.
    line_text.get(start..end).unwrap_or("")
}
