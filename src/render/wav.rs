//! Stereo WAV files, written atomically.

use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::path::{Path, PathBuf};

use hound::{SampleFormat, WavSpec, WavWriter};

use super::{RenderError, Rendered};
use tempfile::NamedTempFile;

use crate::model::staged::{destination, temp_beside};

/// Sample format of a WAV file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BitDepth {
    /// 16-bit integers.
    Int16,
    /// 24-bit integers.
    #[default]
    Int24,
    /// 32-bit IEEE floats, unclipped.
    Float32,
}

impl BitDepth {
    /// Every depth.
    pub const ALL: [BitDepth; 3] = [BitDepth::Int16, BitDepth::Int24, BitDepth::Float32];

    /// Bits per sample.
    pub fn bits(self) -> u16 {
        match self {
            BitDepth::Int16 => 16,
            BitDepth::Int24 => 24,
            BitDepth::Float32 => 32,
        }
    }

    /// The depth with `bits` bits per sample (16 and 24 are integers, 32 is float).
    pub fn from_bits(bits: u16) -> Option<Self> {
        Self::ALL.into_iter().find(|d| d.bits() == bits)
    }

    /// The smallest level a file of this depth holds, as a share of full scale: one step of an
    /// integer file; for float, where far smaller values are held, -140 dBFS (under 24-bit's
    /// step), taken as silence.
    pub fn least_level(self) -> f32 {
        match self {
            BitDepth::Int16 => 1.0 / 32_768.0,
            BitDepth::Int24 => 1.0 / 8_388_608.0,
            BitDepth::Float32 => 1e-7,
        }
    }

    /// Short description, such as "24-bit" or "32-bit float".
    pub fn name(self) -> &'static str {
        match self {
            BitDepth::Int16 => "16-bit",
            BitDepth::Int24 => "24-bit",
            BitDepth::Float32 => "32-bit float",
        }
    }
}

/// Converts a sample in -1..1 to a `bits`-bit integer: scaled by `2^(bits-1)` (so -1 maps to the
/// most negative code), rounded to nearest, clipped to the range. Not a number maps to 0.
pub fn to_int_sample(x: f32, bits: u16) -> i32 {
    let full_scale = (1i64 << (bits - 1)) as f64;
    let v = (x as f64 * full_scale).round();
    if v.is_nan() {
        0
    } else {
        v.clamp(-full_scale, full_scale - 1.0) as i32
    }
}

/// Writes `rendered` as a stereo WAV file at `path` with `bit_depth` and a sample rate of
/// `sample_rate_hz` (normally `rendered.sample_rate_hz`), as [`WavFile`] writes it.
pub fn write_wav(
    path: impl AsRef<Path>,
    rendered: &Rendered,
    bit_depth: BitDepth,
    sample_rate_hz: u32,
) -> Result<(), RenderError> {
    let mut file = WavFile::create(path, bit_depth, sample_rate_hz)?;
    file.write(&rendered.left, &rendered.right)?;
    file.finish()
}

/// A stereo WAV file written a piece at a time, as a render goes, so that memory does not grow
/// with its length. Integer depths round and clip (see [`to_int_sample`]); floats are written as
/// they are, non-finite values as 0.
///
/// Atomic: the samples go to a temporary file in the destination directory, renamed into place
/// by [`WavFile::finish`], so on any failure (or when dropped unfinished) neither a partial file
/// nor the temporary file is left behind, and an existing file at `path` is untouched. The
/// destination is where `path` leads ([`destination`]): a symbolic link's target is replaced, an
/// existing file keeps its permissions, and a directory, device, named pipe or socket is refused.
pub struct WavFile {
    /// The path asked for, for messages.
    path: PathBuf,
    /// Where the file goes.
    destination: PathBuf,
    /// The temporary file; dropping it removes it.
    temp: NamedTempFile,
    writer: WavWriter<BufWriter<File>>,
    bit_depth: BitDepth,
}

impl WavFile {
    /// Starts a WAV file for `path`, checking the destination first.
    pub fn create(
        path: impl AsRef<Path>,
        bit_depth: BitDepth,
        sample_rate_hz: u32,
    ) -> Result<Self, RenderError> {
        let path = path.as_ref().to_path_buf();
        let destination = destination(&path).map_err(|source| RenderError::Io {
            path: path.clone(),
            source,
        })?;
        let opened = temp_beside(&destination, ".modal-resonator-", ".wav.tmp")
            .and_then(|temp| temp.as_file().try_clone().map(|file| (temp, file)));
        let (temp, file) = opened.map_err(|source| RenderError::Io {
            path: path.clone(),
            source,
        })?;
        let writer = WavWriter::new(BufWriter::new(file), spec(bit_depth, sample_rate_hz))
            .map_err(|source| RenderError::Wav {
                path: path.clone(),
                source,
            })?;
        Ok(Self {
            path,
            destination: destination.path,
            temp,
            writer,
            bit_depth,
        })
    }

    /// Appends stereo samples (`left` and `right` of one length).
    pub fn write(&mut self, left: &[f32], right: &[f32]) -> Result<(), RenderError> {
        write_samples(&mut self.writer, left, right, self.bit_depth).map_err(|source| {
            RenderError::Wav {
                path: self.path.clone(),
                source,
            }
        })
    }

    /// Completes the header, writes the file to disk and puts it in place.
    pub fn finish(self) -> Result<(), RenderError> {
        let Self {
            path,
            destination,
            temp,
            writer,
            ..
        } = self;
        let io_error = |source| RenderError::Io {
            path: path.clone(),
            source,
        };
        writer.finalize().map_err(|source| RenderError::Wav {
            path: path.clone(),
            source,
        })?;
        temp.as_file().sync_all().map_err(io_error)?;
        temp.persist(&destination).map_err(|e| io_error(e.error))?;
        Ok(())
    }
}

/// `rendered` as the bytes of a WAV file, as [`write_wav`] writes it: for a stream (standard
/// output) that cannot seek back to fill in the header.
pub fn wav_bytes(
    rendered: &Rendered,
    bit_depth: BitDepth,
    sample_rate_hz: u32,
) -> hound::Result<Vec<u8>> {
    let mut bytes = std::io::Cursor::new(Vec::new());
    encode(&mut bytes, rendered, bit_depth, sample_rate_hz)?;
    Ok(bytes.into_inner())
}

/// The header of a stereo WAV file.
fn spec(bit_depth: BitDepth, sample_rate_hz: u32) -> WavSpec {
    WavSpec {
        channels: 2,
        sample_rate: sample_rate_hz,
        bits_per_sample: bit_depth.bits(),
        sample_format: match bit_depth {
            BitDepth::Float32 => SampleFormat::Float,
            _ => SampleFormat::Int,
        },
    }
}

/// Encodes `rendered` as a stereo WAV file into `out`.
fn encode<W: Write + Seek>(
    out: W,
    rendered: &Rendered,
    bit_depth: BitDepth,
    sample_rate_hz: u32,
) -> hound::Result<()> {
    let mut writer = WavWriter::new(out, spec(bit_depth, sample_rate_hz))?;
    write_samples(&mut writer, &rendered.left, &rendered.right, bit_depth)?;
    writer.finalize()
}

fn write_samples<W: Write + Seek>(
    writer: &mut WavWriter<W>,
    left: &[f32],
    right: &[f32],
    bit_depth: BitDepth,
) -> hound::Result<()> {
    let frames = left.iter().zip(right);
    match bit_depth {
        BitDepth::Float32 => {
            for (&l, &r) in frames {
                writer.write_sample(if l.is_finite() { l } else { 0.0 })?;
                writer.write_sample(if r.is_finite() { r } else { 0.0 })?;
            }
        }
        BitDepth::Int16 => {
            for (&l, &r) in frames {
                writer.write_sample(to_int_sample(l, 16) as i16)?;
                writer.write_sample(to_int_sample(r, 16) as i16)?;
            }
        }
        BitDepth::Int24 => {
            for (&l, &r) in frames {
                writer.write_sample(to_int_sample(l, 24))?;
                writer.write_sample(to_int_sample(r, 24))?;
            }
        }
    }
    Ok(())
}
