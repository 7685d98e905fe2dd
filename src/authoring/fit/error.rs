//! Why a fit could not be made, in words a person can act on.

use std::fmt;
use std::path::PathBuf;

/// Why fitting failed. Every variant names the recording (its position name or file) and says
/// what to change.
#[derive(Debug)]
pub enum FitError {
    /// No recordings were given.
    NoRecordings,
    /// Two recordings share a position name.
    DuplicateName {
        /// The repeated name.
        name: String,
    },
    /// A position name is empty.
    EmptyName,
    /// An option is out of range.
    BadOption {
        /// What is wrong and what was expected.
        message: String,
    },
    /// A file could not be read.
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        source: std::io::Error,
    },
    /// A file is not a WAV file this tool reads.
    NotWav {
        /// The file.
        path: PathBuf,
        /// What the decoder said.
        message: String,
    },
    /// A recording has a channel count the tool does not accept.
    Channels {
        /// The recording.
        name: String,
        /// Channels found.
        channels: u16,
    },
    /// A sample rate too low to analyse.
    SampleRate {
        /// The recording.
        name: String,
        /// Rate found, in Hz.
        sample_rate_hz: u32,
    },
    /// A recording is silent, or holds nothing but noise.
    Silent {
        /// The recording.
        name: String,
        /// Why it counts as silent.
        detail: String,
    },
    /// Too little sound after the strike to measure decays.
    TooShort {
        /// The recording.
        name: String,
        /// Seconds of sound after the onset.
        found_s: f64,
        /// Seconds needed.
        needed_s: f64,
    },
    /// A recording clipped through much of its sound.
    Clipped {
        /// The recording.
        name: String,
        /// Fraction of the sound's samples clipped.
        fraction: f64,
    },
    /// No mode rose above the noise floor in any recording.
    NoModes {
        /// The noise floor used, in dBFS.
        noise_floor_db: f64,
    },
}

impl fmt::Display for FitError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FitError::NoRecordings => write!(f, "no recordings given: name at least one WAV file"),
            FitError::DuplicateName { name } => write!(
                f,
                "two recordings are named \"{name}\": give each strike position its own name \
                 (FILE.wav=NAME)"
            ),
            FitError::EmptyName => write!(
                f,
                "a recording has an empty position name: write FILE.wav=NAME with a visible name"
            ),
            FitError::BadOption { message } => write!(f, "{message}"),
            FitError::Io { path, source } => write!(f, "{}: cannot read: {source}", path.display()),
            FitError::NotWav { path, message } => write!(
                f,
                "{}: not a WAV file this tool reads ({message}); convert it to PCM or float WAV",
                path.display()
            ),
            FitError::Channels { name, channels } => write!(
                f,
                "{name}: {channels} channels; expected a mono or stereo recording (stereo is mixed \
                 to mono): export one channel or a stereo mix"
            ),
            FitError::SampleRate {
                name,
                sample_rate_hz,
            } => write!(
                f,
                "{name}: sample rate {sample_rate_hz} Hz is too low; record at 8000 Hz or more"
            ),
            FitError::Silent { name, detail } => write!(
                f,
                "{name}: {detail}; check the file holds the recording of a strike"
            ),
            FitError::Clipped { name, fraction } => write!(
                f,
                "{name}: clipped: {:.0}% of the sound after the strike is at full scale (at most \
                 {:.0}% can be fitted); record again with more headroom",
                100.0 * fraction,
                100.0 * super::warnings::MAX_CLIPPED_FRACTION
            ),
            FitError::TooShort {
                name,
                found_s,
                needed_s,
            } => write!(
                f,
                "{name}: only {found_s:.3} s of sound after the strike; at least {needed_s:.3} s \
                 is needed to measure decays: record longer after the strike"
            ),
            FitError::NoModes { noise_floor_db } => write!(
                f,
                "no mode rises clearly above the noise floor ({noise_floor_db:.1} dBFS) in any \
                 recording: lower --noise-floor-db, widen --min-hz/--max-hz, or record closer"
            ),
        }
    }
}

impl std::error::Error for FitError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            FitError::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}
