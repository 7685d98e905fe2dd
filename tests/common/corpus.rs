//! The fitting corpus: real recordings of single strikes on struck objects, decoded from three
//! Debian packages (freepats' GUS patches, Sonic Pi's FLAC samples and the samples of the
//! FluidR3 General MIDI SoundFont), each pinned by a checksum of its decoded samples.
//!
//! Some recordings stop while the object still rings: sampled instruments whose data ends at
//! their loop, and one-shots trimmed short. They are marked [`Ending::Ringing`]; a fitter must
//! not read their last frames as the noise floor.
//!
//! `cargo bench --bench fit` decodes and checks them all, and with `FIT_CORPUS_DIR` writes them as
//! WAV files for `modal-resonator fit`.

use std::path::{Path, PathBuf};

use modal_resonator::authoring::fit::Recording;

use super::decode::{read_flac, read_gus_patch};
use super::sf2::SoundFont;

/// Where [`extract`] writes the WAV files unless told otherwise.
pub const DEFAULT_EXTRACT_DIR: &str = "target/fit-corpus";

/// Highest level, in dB relative to the peak, of the last [`TAIL_S`] of a recording that has
/// died away: above it the object is still ringing when the file stops.
pub const RINGING_TAIL_DB: f64 = -45.0;
/// Length of the end of a recording whose level tells whether it has died away, in seconds.
pub const TAIL_S: f64 = 0.02;

/// A Debian package the corpus reads, with the licence of the recordings taken from it.
pub struct Package {
    /// Debian package name, for `apt-get install`.
    pub name: &'static str,
    /// Folder the package installs its files in.
    pub dir: &'static str,
    /// SPDX licence of the recordings, from the package's copyright file.
    pub license: &'static str,
}

/// freepats: GUS patches, GPL-2.0 or later (`/usr/share/doc/freepats/copyright`).
pub const FREEPATS: Package = Package {
    name: "freepats",
    dir: "/usr/share/midi/freepats",
    license: "GPL-2.0-or-later",
};

/// Sonic Pi's samples: each file taken here is listed as CC0 in
/// `/usr/share/doc/sonic-pi-samples/copyright` (from freesound.org).
pub const SONIC_PI: Package = Package {
    name: "sonic-pi-samples",
    dir: "/usr/share/sonic-pi/samples",
    license: "CC0-1.0",
};

/// The FluidR3 General MIDI SoundFont by Frank Wen, MIT
/// (`/usr/share/doc/fluid-soundfont-gm/copyright`).
pub const FLUID: Package = Package {
    name: "fluid-soundfont-gm",
    dir: "/usr/share/sounds/sf2",
    license: "MIT",
};

/// Which recording of a file to take.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sample {
    /// The sample at this index of a GUS patch.
    Patch(usize),
    /// The whole FLAC file, its channels averaged.
    Flac,
    /// The sample of this name in a SoundFont (the left one of a stereo pair).
    SoundFont(&'static str),
}

/// How a recording ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Ending {
    /// The sound has died away: the last [`TAIL_S`] lie at least 45 dB under the peak.
    Decayed,
    /// The file stops while the object still rings (cut at a loop, or trimmed).
    Ringing,
}

use Ending::{Decayed, Ringing};

/// One recording of the corpus.
pub struct Entry {
    /// Short unique name, also the WAV file's name.
    pub slug: &'static str,
    /// What kind of object is struck.
    pub kind: &'static str,
    /// The package the file comes from, and so its licence.
    pub package: &'static Package,
    /// The file, relative to the package's folder.
    pub file: &'static str,
    /// Which recording of the file.
    pub sample: Sample,
    /// Whether the file stops before the sound has died.
    pub ending: Ending,
    /// FNV-1a 64 of the decoded samples' f32 bits ([`fnv1a64`]).
    pub checksum: u64,
}

/// A sample of a freepats patch.
const fn patch(
    slug: &'static str,
    kind: &'static str,
    file: &'static str,
    index: usize,
    ending: Ending,
    checksum: u64,
) -> Entry {
    Entry {
        slug,
        kind,
        package: &FREEPATS,
        file,
        sample: Sample::Patch(index),
        ending,
        checksum,
    }
}

/// A Sonic Pi FLAC file.
const fn flac(
    slug: &'static str,
    kind: &'static str,
    file: &'static str,
    ending: Ending,
    checksum: u64,
) -> Entry {
    Entry {
        slug,
        kind,
        package: &SONIC_PI,
        file,
        sample: Sample::Flac,
        ending,
        checksum,
    }
}

/// A sample of the FluidR3 SoundFont.
const fn fluid(
    slug: &'static str,
    kind: &'static str,
    name: &'static str,
    ending: Ending,
    checksum: u64,
) -> Entry {
    Entry {
        slug,
        kind,
        package: &FLUID,
        file: "FluidR3_GM.sf2",
        sample: Sample::SoundFont(name),
        ending,
        checksum,
    }
}

/// Every recording. Pitched instruments are taken at several notes across their range.
// One entry a line, so the table reads as one.
#[rustfmt::skip]
pub const CORPUS: &[Entry] = &[
    patch("celesta-cs5-freepats", "celesta", "Tone_000/008_Celesta.pat", 0, Decayed, 0x6fe46e70052ceb9f),
    patch("celesta-a6-freepats", "celesta", "Tone_000/008_Celesta.pat", 1, Decayed, 0x4fc2dae6edfe7827),
    patch("glockenspiel-gs5-freepats", "glockenspiel", "Tone_000/009_Glockenspiel.pat", 0, Ringing, 0x3e5a6abeca76682c),
    patch("glockenspiel-c6-freepats", "glockenspiel", "Tone_000/009_Glockenspiel.pat", 1, Ringing, 0x279228d10373af34),
    patch("glockenspiel-e7-freepats", "glockenspiel", "Tone_000/009_Glockenspiel.pat", 3, Ringing, 0xcfaff229bb3a8ab1),
    patch("glockenspiel-b7-freepats", "glockenspiel", "Tone_000/009_Glockenspiel.pat", 4, Ringing, 0xbc85c7d431f3d2b4),
    patch("marimba-cs3-freepats", "marimba", "Tone_000/013_Xylophone.pat", 0, Decayed, 0xe42bfea0c7a9ce9b),
    patch("marimba-c4-freepats", "marimba", "Tone_000/013_Xylophone.pat", 3, Decayed, 0x1ed9ea5dcafd3b99),
    patch("xylophone-c5-freepats", "xylophone", "Tone_000/013_Xylophone.pat", 4, Decayed, 0x05e78fb91277f769),
    patch("xylophone-e7-freepats", "xylophone", "Tone_000/013_Xylophone.pat", 10, Decayed, 0xe9eea1af9563c4dc),
    patch("tubular-bell-f5-freepats", "tubular bell", "Tone_000/014_Tubular_Bells.pat", 0, Decayed, 0x9b6770b037aef643),
    patch("timpani-freepats", "timpani", "Tone_000/047_Timpani.pat", 0, Ringing, 0x080d682eaa5e09e0),
    patch("steel-drum-c4-freepats", "steel drum", "Tone_000/114_Steel_Drums.pat", 1, Ringing, 0x4b5d7ccc5f4f6467),
    patch("steel-drum-c5-freepats", "steel drum", "Tone_000/114_Steel_Drums.pat", 3, Decayed, 0xddbd94b42e81639a),
    patch("wood-block-freepats", "wood block", "Tone_000/115_Wood_Block.pat", 0, Ringing, 0xb5986811955cb5ff),
    patch("metronome-bell-freepats", "bell", "Drum_000/034_Metronome_Bell.pat", 0, Ringing, 0xc95d5da3459c51c4),
    patch("tom-low-freepats", "tom", "Drum_000/041_Tom_Low_2.pat", 0, Decayed, 0xbc6ad8d384e2f3d7),
    patch("tom-high-freepats", "tom", "Drum_000/050_Tom_High_1.pat", 0, Decayed, 0xa920cdf89a6fc378),
    patch("ride-bell-freepats", "cymbal", "Drum_000/053_Cymbal_Ride_Bell.pat", 0, Decayed, 0x2b4075678a94aef9),
    patch("cowbell-freepats", "cowbell", "Drum_000/056_Cow_Bell.pat", 0, Ringing, 0x58e3882d5fbcac9a),
    patch("agogo-high-freepats", "agogo", "Drum_000/067_Agogo_High.pat", 0, Ringing, 0x6415eecb84b2bb6d),
    patch("claves-freepats", "claves", "Drum_000/075_Claves.pat", 0, Decayed, 0x1597493340891ba7),
    patch("triangle-freepats", "triangle", "Drum_000/081_Triangle_2_Open.pat", 0, Ringing, 0xbec4784e3c0ae036),
    flac("hand-bell-sonic-pi", "bell", "perc_bell.flac", Decayed, 0x9250eeec23710c31),
    flac("cowbell-sonic-pi", "cowbell", "drum_cowbell.flac", Ringing, 0xcaa95e19164b4a3f),
    flac("tom-hi-sonic-pi", "tom", "drum_tom_hi_hard.flac", Decayed, 0x830073b84f45b11f),
    flac("tom-mid-sonic-pi", "tom", "drum_tom_mid_soft.flac", Decayed, 0xc2d3ece97795626e),
    flac("tom-lo-sonic-pi", "tom", "drum_tom_lo_hard.flac", Decayed, 0xc2c680c4422f4cd3),
    flac("tabla-tun-sonic-pi", "tabla", "tabla_tun1.flac", Decayed, 0x92c1f83a72860cb5),
    flac("splash-cymbal-sonic-pi", "cymbal", "drum_splash_soft.flac", Decayed, 0x0eca0d7c4c1f9af0),
    fluid("tinkle-bell-fluid", "bell", "tinker bell", Decayed, 0xfbf3e66618acd8ed),
    fluid("glockenspiel-g7-fluid", "glockenspiel", "Glocken G7", Ringing, 0x7ce4dbe7da65a518),
    fluid("glockenspiel-c9-fluid", "glockenspiel", "Glocken C9", Ringing, 0xa3bd53a6170ca81c),
    fluid("celesta-fs3-fluid", "celesta", "Celesta F# 3(L)", Ringing, 0xb87168ae2e3c6c9e),
    fluid("celesta-c6-fluid", "celesta", "Celesta C 6(L)", Ringing, 0x21198cc73c7718b3),
    fluid("music-box-gs3-fluid", "music box", "Music Box G#3", Ringing, 0xcd3b85c7d36e133a),
    fluid("music-box-c5-fluid", "music box", "Music Box C5", Ringing, 0x4d1fe917f3c7858f),
    fluid("music-box-e7-fluid", "music box", "Music Box E7", Ringing, 0xd15d01d27d05529c),
    fluid("vibraphone-a4-fluid", "vibraphone", "Vibraphone A4(L)", Ringing, 0x61277b214214a38c),
    fluid("vibraphone-a6-fluid", "vibraphone", "Vibraphone A6(L)", Ringing, 0xb3f094b18fe3e157),
    fluid("marimba-c5-fluid", "marimba", "Marimba C 5(L)", Decayed, 0xe3c009260e09c079),
    fluid("marimba-c7-fluid", "marimba", "Marimba C 7(L)", Decayed, 0xbe2b39458a028c21),
    fluid("xylophone-c5-fluid", "xylophone", "Xylophone C 5(L)", Decayed, 0xa29bba1592ffa18a),
    fluid("xylophone-c7-fluid", "xylophone", "Xylophone C 7(L)", Decayed, 0x316368f168a0e561),
    fluid("tubular-bell-c7-fluid", "tubular bell", "Tubular Bells C7(L)", Ringing, 0x43c999ebb016ede2),
    fluid("timpani-fluid", "timpani", "Timpani 1(L)", Decayed, 0x4d56720b8194a894),
    fluid("agogo-low-fluid", "agogo", "Low Agogo(L)", Decayed, 0xf658d86d7d17a01e),
    fluid("steel-drum-fs5-fluid", "steel drum", "Steel Drum F# 5(L)", Decayed, 0x7187d4198f3169b5),
    fluid("steel-drum-c6-fluid", "steel drum", "Steel Drum C 6(L)", Decayed, 0x935421c6fce8515c),
    fluid("wood-block-high-fluid", "wood block", "High Woodblock(L)", Decayed, 0xb8632882663a97dc),
    fluid("cowbell-fluid", "cowbell", "Cow Bell(L)", Decayed, 0xf79ef21ed1b1363b),
    fluid("triangle-fluid", "triangle", "Triangle", Ringing, 0x20f0455f9e7a9f3b),
    fluid("metronome-bell-fluid", "bell", "Metronome Bell(L)", Ringing, 0x753f7f4dacd7844a),
    fluid("claves-fluid", "claves", "Clave(L)", Decayed, 0xa598b12b3fefbedb),
    fluid("tom-floor-fluid", "tom", "Tom Floor(L)", Decayed, 0xbe8649e1fa192db7),
    fluid("tom-hi-fluid", "tom", "Tom Hi(L)", Decayed, 0x1f7361de4cf8d0e6),
    fluid("bell-ride-fluid", "cymbal", "BellRide(L)", Decayed, 0x3e3cd9f185cd5b63),
];

/// FNV-1a 64 over the little-endian bits of `samples`.
pub fn fnv1a64(samples: &[f32]) -> u64 {
    const OFFSET_BASIS: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    samples
        .iter()
        .flat_map(|s| s.to_bits().to_le_bytes())
        .fold(OFFSET_BASIS, |h, b| (h ^ u64::from(b)).wrapping_mul(PRIME))
}

/// Level in dB, relative to the peak, of the RMS of the last [`TAIL_S`] of `samples`.
pub fn tail_level_db(samples: &[f32], sample_rate_hz: u32) -> f64 {
    let n = ((TAIL_S * f64::from(sample_rate_hz)) as usize).clamp(1, samples.len().max(1));
    let tail = &samples[samples.len().saturating_sub(n)..];
    let power = tail.iter().map(|&v| f64::from(v).powi(2)).sum::<f64>() / n as f64;
    let peak = samples
        .iter()
        .fold(0.0f64, |a, &v| a.max(f64::from(v).abs()));
    10.0 * (power.max(1e-30)).log10() - 20.0 * peak.max(1e-15).log10()
}

impl Entry {
    /// Where the package installs the file.
    pub fn path(&self) -> PathBuf {
        Path::new(self.package.dir).join(self.file)
    }

    /// The recording as decoded, named after the slug, without checking it.
    pub fn decode(&self) -> Result<Recording, String> {
        let path = self.path();
        if !path.exists() {
            return Err(format!(
                "{}: {} is missing: install the Debian package {} (apt-get install {})",
                self.slug,
                path.display(),
                self.package.name,
                self.package.name
            ));
        }
        Ok(match self.sample {
            Sample::Patch(index) => read_gus_patch(&path, index, self.slug),
            Sample::Flac => read_flac(&path, self.slug),
            Sample::SoundFont(name) => {
                let font = SoundFont::open(&path).map_err(|e| format!("{}: {e}", self.slug))?;
                let (points, header) = font
                    .read_sample(name)
                    .map_err(|e| format!("{}: {e}", self.slug))?;
                let samples = points.iter().map(|&p| f32::from(p) / 32768.0).collect();
                Recording::new(self.slug, samples, header.sample_rate_hz)
            }
        })
    }

    /// The recording, checked against its pinned checksum and its ending.
    pub fn load(&self) -> Result<Recording, String> {
        let recording = self.decode()?;
        let checksum = fnv1a64(&recording.samples);
        if checksum != self.checksum {
            return Err(format!(
                "{}: {} ({:?}) decodes to checksum {checksum:#018x}, expected {:#018x}: the file \
                 differs from the one the corpus was pinned on (Debian package {})",
                self.slug,
                self.path().display(),
                self.sample,
                self.checksum,
                self.package.name
            ));
        }
        let tail_db = tail_level_db(&recording.samples, recording.sample_rate_hz);
        let ringing = tail_db > RINGING_TAIL_DB;
        if ringing != (self.ending == Ringing) {
            return Err(format!(
                "{}: its last {} s lie {tail_db:.1} dB from the peak, but it is marked {:?}",
                self.slug, TAIL_S, self.ending
            ));
        }
        Ok(recording)
    }
}

/// The entries named in `only` (every entry when empty), or an error naming an unknown slug.
pub fn select(only: &[String]) -> Result<Vec<&'static Entry>, String> {
    if only.is_empty() {
        return Ok(CORPUS.iter().collect());
    }
    only.iter()
        .map(|slug| {
            CORPUS.iter().find(|e| e.slug == slug).ok_or_else(|| {
                let known: Vec<&str> = CORPUS.iter().map(|e| e.slug).collect();
                format!(
                    "no corpus recording \"{slug}\"; known: {}",
                    known.join(", ")
                )
            })
        })
        .collect()
}

/// Loads every recording (checked) and writes each as a WAV file in `dir`: see
/// [`extract_entries`].
pub fn extract(dir: &Path) -> Result<Vec<Recording>, String> {
    extract_entries(&select(&[])?, dir)
}

/// Loads `entries` (checked) and writes each as a mono 32-bit float WAV file named after its
/// slug in `dir`, which is created if needed; returns the recordings in the same order.
pub fn extract_entries(entries: &[&Entry], dir: &Path) -> Result<Vec<Recording>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    entries
        .iter()
        .map(|entry| {
            let recording = entry.load()?;
            let path = dir.join(format!("{}.wav", entry.slug));
            write_wav(&recording, &path).map_err(|e| format!("{}: {e}", path.display()))?;
            Ok(recording)
        })
        .collect()
}

/// Writes `recording` as a mono 32-bit float WAV file.
fn write_wav(recording: &Recording, path: &Path) -> Result<(), hound::Error> {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: recording.sample_rate_hz,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    let mut writer = hound::WavWriter::create(path, spec)?;
    for &s in &recording.samples {
        writer.write_sample(s)?;
    }
    writer.finalize()
}
