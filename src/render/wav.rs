//! Stereo WAV files, written atomically.

use std::fs::File;
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use super::{RenderError, Rendered};
use tempfile::NamedTempFile;

use crate::bank::staged::{destination, temp_beside};

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
/// they are, non-finite values as 0. A file whose data passes 4 GiB, which a RIFF header's 32-bit
/// sizes cannot hold, is written as RF64 (see [`WavEncoder`]).
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
    /// The samples' way into the temporary file.
    encoder: WavEncoder<BufWriter<File>>,
}

impl WavFile {
    /// Starts a WAV file for `path`, checking the destination first.
    pub fn create(
        path: impl AsRef<Path>,
        bit_depth: BitDepth,
        sample_rate_hz: u32,
    ) -> Result<Self, RenderError> {
        let path = path.as_ref().to_path_buf();
        let io_error = |source| RenderError::Io {
            path: path.clone(),
            source,
        };
        let destination = destination(&path).map_err(io_error)?;
        let (temp, file) = temp_beside(&destination, ".modal-resonator-", ".wav.tmp")
            .and_then(|temp| temp.as_file().try_clone().map(|file| (temp, file)))
            .map_err(io_error)?;
        let encoder =
            WavEncoder::new(BufWriter::new(file), bit_depth, sample_rate_hz).map_err(|source| {
                RenderError::Wav {
                    path: path.clone(),
                    source,
                }
            })?;
        Ok(Self {
            path,
            destination: destination.path,
            temp,
            encoder,
        })
    }

    /// Writes the file as RF64 once its data passes `bytes` rather than 4 GiB: for tests, which
    /// cannot write 4 GiB.
    #[doc(hidden)]
    pub fn with_rf64_above(mut self, bytes: u64) -> Self {
        self.encoder.rf64_above_bytes = bytes;
        self
    }

    /// Appends stereo samples (`left` and `right` of one length).
    pub fn write(&mut self, left: &[f32], right: &[f32]) -> Result<(), RenderError> {
        self.encoder
            .write(left, right)
            .map_err(|source| RenderError::Wav {
                path: self.path.clone(),
                source,
            })
    }

    /// Completes the header, writes the file to disk and puts it in place.
    pub fn finish(self) -> Result<(), RenderError> {
        let Self {
            path,
            destination,
            temp,
            encoder,
        } = self;
        let io_error = |source| RenderError::Io {
            path: path.clone(),
            source,
        };
        encoder
            .finish()
            .and_then(|mut out| out.flush())
            .map_err(|source| RenderError::Wav {
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
) -> io::Result<Vec<u8>> {
    let mut encoder = WavEncoder::new(io::Cursor::new(Vec::new()), bit_depth, sample_rate_hz)?;
    encoder.write(&rendered.left, &rendered.right)?;
    Ok(encoder.finish()?.into_inner())
}

/// A RIFF header's largest size: files whose sizes pass it are written as RF64.
const RIFF_MAX_BYTES: u64 = u32::MAX as u64;

/// Bytes of the `JUNK` chunk's body reserved after `WAVE`: the size of the `ds64` chunk's body
/// that replaces it in an RF64 file (three 64-bit sizes and an empty table's length).
const DS64_BODY_BYTES: usize = 28;

/// Stereo WAV encoding into a seekable writer: a canonical RIFF WAVE file, with a `JUNK` chunk
/// reserved after the `WAVE` tag which, when the data passes the 32-bit sizes of RIFF, becomes
/// the `ds64` chunk of an RF64 file (EBU Tech 3306, the BWF-compatible layout that Pro Tools,
/// Reaper, Audacity and libsndfile read): the `RIFF` tag becomes `RF64`, the 32-bit sizes
/// read 0xFFFFFFFF and the true sizes are in `ds64`. A file that fits stays a plain WAV that
/// every reader opens (a `JUNK` chunk is skipped by all of them). 16-bit files carry a PCM
/// format chunk, 24-bit and float ones WAVE_FORMAT_EXTENSIBLE, as the format asks above 16
/// bits.
pub struct WavEncoder<W: Write + Seek> {
    /// Where the bytes go.
    out: W,
    /// Sample format.
    bit_depth: BitDepth,
    /// Bytes of sample data written so far.
    data_bytes: u64,
    /// Offset of the data chunk's size field.
    data_size_at: u64,
    /// Data larger than this makes the file RF64 (4 GiB less the header, unless a test says
    /// otherwise).
    rf64_above_bytes: u64,
}

impl<W: Write + Seek> WavEncoder<W> {
    /// Writes the header of a stereo file into `out`, up to the start of the samples.
    pub fn new(mut out: W, bit_depth: BitDepth, sample_rate_hz: u32) -> io::Result<Self> {
        let header = header(bit_depth, sample_rate_hz);
        out.write_all(&header)?;
        Ok(Self {
            out,
            bit_depth,
            data_bytes: 0,
            data_size_at: header.len() as u64 - 4,
            rf64_above_bytes: RIFF_MAX_BYTES - header.len() as u64,
        })
    }

    /// Appends stereo samples (`left` and `right` of one length).
    pub fn write(&mut self, left: &[f32], right: &[f32]) -> io::Result<()> {
        debug_assert_eq!(left.len(), right.len());
        let bytes = usize::from(self.bit_depth.bits() / 8);
        let mut frame = [0u8; 8];
        for (&l, &r) in left.iter().zip(right) {
            for (k, x) in [l, r].into_iter().enumerate() {
                let at = &mut frame[k * bytes..(k + 1) * bytes];
                match self.bit_depth {
                    BitDepth::Float32 => {
                        at.copy_from_slice(&(if x.is_finite() { x } else { 0.0 }).to_le_bytes())
                    }
                    depth => {
                        at.copy_from_slice(&to_int_sample(x, depth.bits()).to_le_bytes()[..bytes])
                    }
                }
            }
            self.out.write_all(&frame[..2 * bytes])?;
        }
        self.data_bytes += (2 * bytes * left.len()) as u64;
        Ok(())
    }

    /// Fills in the sizes (as RF64 if the data passed the limit) and gives the writer back.
    pub fn finish(mut self) -> io::Result<W> {
        let end = self.data_size_at + 4 + self.data_bytes;
        // A data chunk of odd size is padded to an even one; stereo frames never are odd.
        let riff_bytes = end - 8;
        if self.data_bytes > self.rf64_above_bytes {
            let frames = self.data_bytes / u64::from(self.bit_depth.bits() / 4);
            let mut ds64 = Vec::with_capacity(8 + DS64_BODY_BYTES);
            ds64.extend(b"ds64");
            ds64.extend((DS64_BODY_BYTES as u32).to_le_bytes());
            ds64.extend(riff_bytes.to_le_bytes());
            ds64.extend(self.data_bytes.to_le_bytes());
            ds64.extend(frames.to_le_bytes());
            ds64.extend(0u32.to_le_bytes());
            self.out.seek(SeekFrom::Start(0))?;
            self.out.write_all(b"RF64")?;
            self.out.write_all(&u32::MAX.to_le_bytes())?;
            self.out.seek(SeekFrom::Start(12))?;
            self.out.write_all(&ds64)?;
            self.out.seek(SeekFrom::Start(self.data_size_at))?;
            self.out.write_all(&u32::MAX.to_le_bytes())?;
        } else {
            self.out.seek(SeekFrom::Start(4))?;
            self.out.write_all(&(riff_bytes as u32).to_le_bytes())?;
            self.out.seek(SeekFrom::Start(self.data_size_at))?;
            self.out
                .write_all(&(self.data_bytes as u32).to_le_bytes())?;
        }
        self.out.seek(SeekFrom::Start(end))?;
        Ok(self.out)
    }
}

/// GUID tail shared by the KSDATAFORMAT subtypes (after the format tag's two bytes).
const SUBTYPE_TAIL: [u8; 14] = [
    0x00, 0x00, 0x00, 0x00, 0x10, 0x00, 0x80, 0x00, 0x00, 0xaa, 0x00, 0x38, 0x9b, 0x71,
];

/// The bytes of a stereo file's header, from `RIFF` to the data chunk's (empty) size.
fn header(bit_depth: BitDepth, sample_rate_hz: u32) -> Vec<u8> {
    let bits = bit_depth.bits();
    let block_align = 2 * (bits / 8);
    // WAVE_FORMAT_PCM 1, WAVE_FORMAT_IEEE_FLOAT 3.
    let tag: u16 = if bit_depth == BitDepth::Float32 { 3 } else { 1 };
    let mut h = Vec::with_capacity(80);
    h.extend(b"RIFF");
    h.extend(0u32.to_le_bytes());
    h.extend(b"WAVE");
    h.extend(b"JUNK");
    h.extend((DS64_BODY_BYTES as u32).to_le_bytes());
    h.extend([0u8; DS64_BODY_BYTES]);
    h.extend(b"fmt ");
    let extensible = bits > 16;
    h.extend(if extensible { 40u32 } else { 16u32 }.to_le_bytes());
    h.extend(if extensible { 0xfffe } else { tag }.to_le_bytes());
    h.extend(2u16.to_le_bytes());
    h.extend(sample_rate_hz.to_le_bytes());
    h.extend((sample_rate_hz * u32::from(block_align)).to_le_bytes());
    h.extend(block_align.to_le_bytes());
    h.extend(bits.to_le_bytes());
    if extensible {
        // cbSize, valid bits, the channel mask (front left and right), the subtype GUID.
        h.extend(22u16.to_le_bytes());
        h.extend(bits.to_le_bytes());
        h.extend(3u32.to_le_bytes());
        h.extend(tag.to_le_bytes());
        h.extend(SUBTYPE_TAIL);
    }
    h.extend(b"data");
    h.extend(0u32.to_le_bytes());
    h
}
