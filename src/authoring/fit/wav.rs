//! Reading a recording from a WAV file: mono as it is, stereo mixed to mono, anything else refused.

use std::path::Path;

use hound::{SampleFormat, WavReader};

use super::{FitError, Recording};

/// Reads the WAV file at `path` as the recording of the strike position `name`.
///
/// Integer samples are scaled so full scale is 1; float samples are taken as they are. A stereo
/// file is mixed to mono (the mean of the channels) and the recording carries a note saying so,
/// since modes out of phase between the microphones partly cancel in the mix. More channels are
/// an error.
pub fn read_wav_recording(path: &Path, name: &str) -> Result<Recording, FitError> {
    let not_wav = |error: hound::Error| match error {
        hound::Error::IoError(source) => FitError::Io {
            path: path.to_path_buf(),
            source,
        },
        other => FitError::NotWav {
            path: path.to_path_buf(),
            message: other.to_string(),
        },
    };
    let mut reader = WavReader::open(path).map_err(not_wav)?;
    let spec = reader.spec();
    let origin = format!("{} ({name})", path.display());
    if !(1..=2).contains(&spec.channels) {
        return Err(FitError::Channels {
            name: origin,
            channels: spec.channels,
        });
    }
    let interleaved: Vec<f32> = match spec.sample_format {
        SampleFormat::Float => reader
            .samples::<f32>()
            .collect::<Result<_, _>>()
            .map_err(not_wav)?,
        SampleFormat::Int => {
            let full_scale = (1u64 << (spec.bits_per_sample.clamp(1, 32) - 1)) as f32;
            reader
                .samples::<i32>()
                .map(|s| s.map(|v| v as f32 / full_scale))
                .collect::<Result<_, _>>()
                .map_err(not_wav)?
        }
    };
    let channels = spec.channels as usize;
    let samples: Vec<f32> = interleaved
        .chunks_exact(channels)
        .map(|frame| frame.iter().sum::<f32>() / channels as f32)
        .collect();
    let mut notes = Vec::new();
    if channels == 2 {
        notes.push(
            "stereo: the two channels were mixed to mono; a mode out of phase between them is \
             weakened in the mix"
                .to_string(),
        );
    }
    Ok(Recording {
        name: name.to_string(),
        samples,
        sample_rate_hz: spec.sample_rate,
        notes,
        origin,
    })
}
