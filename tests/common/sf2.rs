//! Samples read by name out of a SoundFont 2 file (the RIFF `sfbk` form): the 16-bit PCM of the
//! `smpl` chunk in the `sdta` list, cut by the sample headers of the `shdr` chunk in the `pdta`
//! list (SoundFont 2.04 specification, sections 6.2 and 7.10). Only the headers are read whole;
//! each sample is read where it lies, so a 150 MB font costs a few reads.

use std::fs::File;
use std::io::{self, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// Bytes of one sample header record in `shdr`.
const SAMPLE_HEADER_BYTES: usize = 46;
/// Bytes of the name at the start of a sample header, NUL-padded.
const NAME_BYTES: usize = 20;
/// Bytes of a RIFF chunk header: a four-character code and a little-endian size.
const CHUNK_HEADER_BYTES: u64 = 8;

/// One sample header: where a sample lies in `smpl` and how it loops.
#[derive(Debug, Clone, PartialEq)]
pub struct SampleHeader {
    /// The sample's name, as instruments and tools show it.
    pub name: String,
    /// First sample point, counted from the start of `smpl`.
    pub start: u32,
    /// One past the last sample point.
    pub end: u32,
    /// First point of the loop, counted from the start of `smpl`.
    pub start_loop: u32,
    /// One past the last point of the loop.
    pub end_loop: u32,
    /// Sample rate in Hz.
    pub sample_rate_hz: u32,
    /// MIDI key the sample was recorded at.
    pub original_pitch: u8,
    /// Correction of that pitch, in cents.
    pub pitch_correction: i8,
    /// Index of the other channel's header, for a stereo pair.
    pub sample_link: u16,
    /// 1 mono, 2 right, 4 left, 8 linked; 0x8000 and above for ROM samples.
    pub sample_type: u16,
}

/// An open SoundFont: its sample headers and where its sample data lies.
pub struct SoundFont {
    /// The file, for reading samples and naming it in errors.
    path: PathBuf,
    /// Byte offset of the first sample point of `smpl` in the file.
    smpl_offset: u64,
    /// Sample points in `smpl`.
    smpl_points: u64,
    /// Every sample header, the terminal "EOS" record dropped.
    headers: Vec<SampleHeader>,
}

/// An error about `path`'s contents.
fn invalid(path: &Path, message: impl std::fmt::Display) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!("{}: {message}", path.display()),
    )
}

/// Reads a chunk header at the file's position: its code and size in bytes.
fn chunk_header(file: &mut File) -> io::Result<([u8; 4], u64)> {
    let mut b = [0u8; 8];
    file.read_exact(&mut b)?;
    let size = u32::from_le_bytes([b[4], b[5], b[6], b[7]]);
    Ok(([b[0], b[1], b[2], b[3]], u64::from(size)))
}

impl SoundFont {
    /// Opens the SoundFont at `path` and reads its sample headers.
    pub fn open(path: &Path) -> io::Result<Self> {
        let mut file = File::open(path)
            .map_err(|e| io::Error::new(e.kind(), format!("{}: {e}", path.display())))?;
        let (riff, riff_size) = chunk_header(&mut file)?;
        let mut form = [0u8; 4];
        file.read_exact(&mut form)?;
        if &riff != b"RIFF" || &form != b"sfbk" {
            return Err(invalid(path, "not a SoundFont 2 file (no RIFF sfbk form)"));
        }
        let riff_end = CHUNK_HEADER_BYTES + riff_size;
        let (mut smpl, mut shdr) = (None, None);
        let mut at = CHUNK_HEADER_BYTES + 4;
        while at + CHUNK_HEADER_BYTES <= riff_end {
            file.seek(SeekFrom::Start(at))?;
            let (id, size) = chunk_header(&mut file)?;
            if &id == b"LIST" {
                // The list's own chunks follow its four-character type.
                let list_end = at + CHUNK_HEADER_BYTES + size;
                let mut sub = at + CHUNK_HEADER_BYTES + 4;
                while sub + CHUNK_HEADER_BYTES <= list_end {
                    file.seek(SeekFrom::Start(sub))?;
                    let (sub_id, sub_size) = chunk_header(&mut file)?;
                    let data = (sub + CHUNK_HEADER_BYTES, sub_size);
                    match &sub_id {
                        b"smpl" => smpl = Some(data),
                        b"shdr" => shdr = Some(data),
                        _ => {}
                    }
                    // Chunks are padded to an even size.
                    sub += CHUNK_HEADER_BYTES + sub_size + (sub_size & 1);
                }
            }
            at += CHUNK_HEADER_BYTES + size + (size & 1);
        }
        let (smpl_offset, smpl_bytes) =
            smpl.ok_or_else(|| invalid(path, "no smpl chunk in the sdta list"))?;
        let (shdr_offset, shdr_bytes) =
            shdr.ok_or_else(|| invalid(path, "no shdr chunk in the pdta list"))?;
        file.seek(SeekFrom::Start(shdr_offset))?;
        let mut records = vec![0u8; shdr_bytes as usize];
        file.read_exact(&mut records)?;
        let mut headers: Vec<SampleHeader> = records
            .chunks_exact(SAMPLE_HEADER_BYTES)
            .map(parse_header)
            .collect();
        // The last record only marks the end of the list.
        headers.pop();
        Ok(Self {
            path: path.to_path_buf(),
            smpl_offset,
            smpl_points: smpl_bytes / 2,
            headers,
        })
    }

    /// Every sample header in the font.
    pub fn headers(&self) -> &[SampleHeader] {
        &self.headers
    }

    /// The header of the sample called `name`.
    pub fn header(&self, name: &str) -> Option<&SampleHeader> {
        self.headers.iter().find(|h| h.name == name)
    }

    /// The points of the sample called `name`, from its start to its end (past its loop, so a
    /// sample made to loop stops there), and its header.
    pub fn read_sample(&self, name: &str) -> io::Result<(Vec<i16>, &SampleHeader)> {
        let header = self
            .header(name)
            .ok_or_else(|| invalid(&self.path, format!("no sample named \"{name}\"")))?;
        if header.start >= header.end || u64::from(header.end) > self.smpl_points {
            return Err(invalid(
                &self.path,
                format!(
                    "sample \"{name}\" spans points {} to {}, outside the {} of smpl",
                    header.start, header.end, self.smpl_points
                ),
            ));
        }
        let mut file = File::open(&self.path)?;
        file.seek(SeekFrom::Start(
            self.smpl_offset + 2 * u64::from(header.start),
        ))?;
        let mut bytes = vec![0u8; 2 * (header.end - header.start) as usize];
        file.read_exact(&mut bytes)?;
        let points = bytes
            .chunks_exact(2)
            .map(|b| i16::from_le_bytes([b[0], b[1]]))
            .collect();
        Ok((points, header))
    }
}

/// One 46-byte `shdr` record.
fn parse_header(r: &[u8]) -> SampleHeader {
    let u32_at = |o: usize| u32::from_le_bytes([r[o], r[o + 1], r[o + 2], r[o + 3]]);
    let name_end = r[..NAME_BYTES]
        .iter()
        .position(|&b| b == 0)
        .unwrap_or(NAME_BYTES);
    SampleHeader {
        name: String::from_utf8_lossy(&r[..name_end]).into_owned(),
        start: u32_at(20),
        end: u32_at(24),
        start_loop: u32_at(28),
        end_loop: u32_at(32),
        sample_rate_hz: u32_at(36),
        original_pitch: r[40],
        pitch_correction: r[41] as i8,
        sample_link: u16::from_le_bytes([r[42], r[43]]),
        sample_type: u16::from_le_bytes([r[44], r[45]]),
    }
}
