//! Why a mesh could not be made into modes, and the advice on its unit that a size far from
//! any instrument's calls for.

use std::fmt;

use super::read;
use super::surface::Surface;
use crate::bank::validate::MODE_FREQ_HZ;

/// An object larger than this (its bounding box's longest side) is probably in the wrong unit:
/// a millimetre file read as metres.
const LARGEST_LIKELY_M: f64 = 10.0;

/// An object smaller than this is probably in the wrong unit.
const SMALLEST_LIKELY_M: f64 = 1e-3;

/// Why a mesh could not be made into modes.
#[derive(Debug, Clone, PartialEq)]
pub enum MeshError {
    /// The file cannot be read as a mesh.
    Syntax {
        /// Line (OBJ, ASCII STL) or triangle (binary STL), from 1.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Neither text nor a binary STL of the size its header gives.
    BinarySize {
        /// The triangles the header gives (`None`: too short for a header).
        triangles: Option<usize>,
        /// The size those take, in bytes.
        expected_bytes: usize,
        /// The file's size, in bytes.
        found_bytes: usize,
    },
    /// No triangles.
    Empty,
    /// A face refers to a vertex that does not exist.
    BadIndex {
        /// Face index, from 0.
        face: usize,
        /// The vertex index it names.
        vertex: usize,
        /// Number of vertices.
        count: usize,
    },
    /// A triangle without area.
    Degenerate {
        /// Face index.
        face: usize,
        /// Its vertices.
        vertices: [u32; 3],
    },
    /// An edge with a triangle on one side only: the surface has a hole.
    Open {
        /// The face with the edge.
        face: usize,
        /// The edge's vertices.
        edge: [u32; 2],
    },
    /// An edge shared by more than two triangles.
    NonManifold {
        /// The faces sharing it.
        faces: Vec<usize>,
        /// The edge's vertices.
        edge: [u32; 2],
    },
    /// Two neighbouring triangles facing opposite ways.
    Inconsistent {
        /// The two faces.
        faces: [usize; 2],
        /// Their shared edge.
        edge: [u32; 2],
    },
    /// The triangles face inward.
    InsideOut {
        /// The signed volume, negative.
        volume_m3: f64,
    },
    /// The surface is closed but encloses (almost) nothing: it is folded flat.
    NoVolume {
        /// The enclosed volume.
        volume_m3: f64,
    },
    /// More triangles, cells or elements than can be solved.
    TooLarge {
        /// What there are too many of.
        what: &'static str,
        /// How many.
        count: usize,
        /// The limit.
        limit: usize,
    },
    /// No voxel centre falls inside the surface.
    TooThin {
        /// Voxel edge in metres.
        voxel_m: f64,
    },
    /// The voxels fall apart into several pieces.
    Pieces {
        /// How many.
        pieces: usize,
        /// Voxel edge in metres.
        voxel_m: f64,
    },
    /// A setting is out of range.
    BadSetting {
        /// Its name.
        name: &'static str,
        /// What was expected.
        reason: String,
    },
    /// The solve would hold more memory than allowed.
    TooMuchMemory {
        /// The estimate, in bytes.
        needed_bytes: usize,
        /// The limit, in bytes.
        limit_bytes: usize,
    },
    /// The eigensolver failed.
    Solver(String),
    /// The lowest elastic mode lies under the lowest frequency a bank's modes may have.
    BelowFloor {
        /// The lowest mode in Hz.
        lowest_hz: f64,
        /// The longest side of the object's bounding box in metres.
        size_m: f64,
    },
    /// No elastic mode lies below the frequency limit.
    NoModes {
        /// The limit in Hz.
        max_freq_hz: f64,
        /// The lowest mode found, in Hz.
        lowest_hz: f64,
        /// The longest side of the object's bounding box in metres.
        size_m: f64,
    },
}

impl fmt::Display for MeshError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Syntax { line, message } => write!(f, "line {line}: {message}"),
            Self::BinarySize {
                triangles,
                expected_bytes,
                found_bytes,
            } => f.write_str(&read::binary_size_message(
                *triangles,
                *expected_bytes,
                *found_bytes,
            )),
            Self::Empty => write!(f, "the mesh has no faces"),
            Self::BadIndex {
                face,
                vertex,
                count,
            } => write!(
                f,
                "face {face} names vertex {vertex}, but there are only {count} vertices"
            ),
            Self::Degenerate { face, vertices } => write!(
                f,
                "face {face} (vertices {vertices:?}) has no area: remove degenerate triangles"
            ),
            Self::Open { face, edge } => write!(
                f,
                "the surface is not closed: edge {edge:?} of face {face} borders no other face \
                 (a hole); a solid needs a watertight surface"
            ),
            Self::NonManifold { faces, edge } => write!(
                f,
                "the surface is not manifold: edge {edge:?} is shared by {} faces {faces:?}, \
                 expected 2",
                faces.len()
            ),
            Self::Inconsistent { faces, edge } => write!(
                f,
                "faces {} and {} face opposite ways across edge {edge:?}: orient every face \
                 counter-clockwise seen from outside",
                faces[0], faces[1]
            ),
            Self::InsideOut { volume_m3 } => write!(
                f,
                "the surface is inside-out (its faces point inward, signed volume {volume_m3:.3e} \
                 m^3): flip the normals"
            ),
            Self::NoVolume { volume_m3 } => write!(
                f,
                "the surface encloses no volume ({volume_m3:.3e} m^3): it is folded flat, or \
                 its units are far too small (see --scale)"
            ),
            Self::TooLarge { .. }
            | Self::TooThin { .. }
            | Self::Pieces { .. }
            | Self::BadSetting { .. }
            | Self::TooMuchMemory { .. }
            | Self::Solver(..)
            | Self::BelowFloor { .. }
            | Self::NoModes { .. } => self.fmt_solving(f),
        }
    }
}

impl MeshError {
    /// The message of an error met filling, assembling or solving the solid (those of its
    /// surface are written by `fmt`, which sends only these here).
    fn fmt_solving(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TooLarge { what, count, limit } => write!(
                f,
                "too large: {count} {what}, at most {limit}; use fewer elements or a coarser mesh"
            ),
            Self::TooThin { voxel_m } => write!(
                f,
                "no voxel of {:.3} mm fits inside the surface: the object is thinner than a voxel; \
                 use more elements",
                voxel_m * 1e3
            ),
            Self::Pieces { pieces, voxel_m } => write!(
                f,
                "at voxels of {:.3} mm the object falls apart into {pieces} pieces: a wall or \
                 a joint is thinner than a voxel (or the mesh holds separate objects); use more \
                 elements",
                voxel_m * 1e3
            ),
            Self::BadSetting { name, reason } => write!(f, "{name}: {reason}"),
            Self::TooMuchMemory {
                needed_bytes,
                limit_bytes,
            } => write!(
                f,
                "the solve would hold about {:.2} GiB, more than the {:.2} GiB allowed; use \
                 fewer elements or modes",
                *needed_bytes as f64 / GIB,
                *limit_bytes as f64 / GIB
            ),
            Self::Solver(reason) => write!(f, "the eigensolver failed: {reason}"),
            Self::BelowFloor { lowest_hz, size_m } => write!(
                f,
                "lowest mode {lowest_hz:.3} Hz: under the {} Hz floor a bank's modes start at; {}",
                MODE_FREQ_HZ.min,
                size_advice(*size_m, "too large, too soft or too loosely held")
            ),
            Self::NoModes {
                max_freq_hz,
                lowest_hz,
                size_m,
            } => write!(
                f,
                "no mode below {max_freq_hz} Hz: the lowest is {lowest_hz:.0} Hz; {}",
                size_advice(*size_m, "too small or too stiff")
            ),
            surface => unreachable!("{surface:?} is written by fmt"),
        }
    }
}

impl std::error::Error for MeshError {}

/// Bytes in a GiB, for messages.
const GIB: f64 = (1u64 << 30) as f64;

/// What to try when an object whose bounding box's longest side is `size_m` (metres, once
/// scaled) is so large or so small that its file is probably in another unit, naming its size;
/// `None` when its size is likely.
pub fn scale_hint(size_m: f64) -> Option<String> {
    if size_m > LARGEST_LIKELY_M {
        Some(format!(
            "the object is {} across: is the file in millimetres? try --scale 0.001",
            length(size_m)
        ))
    } else if size_m < SMALLEST_LIKELY_M {
        Some(format!(
            "the object is {} across: is --scale right? (1 for a file in metres, 0.001 in \
             millimetres)",
            length(size_m)
        ))
    } else {
        None
    }
}

/// Why an object whose bounding box's longest side is `size_m` does not sound: its unit
/// ([`scale_hint`]), or else it is `what` (too large, too small...) to sound.
fn size_advice(size_m: f64, what: &str) -> String {
    scale_hint(size_m)
        .unwrap_or_else(|| format!("the object ({} across) is {what} to sound", length(size_m)))
}

/// A warning when `surface` (in metres) is so large or so small that its file is probably in
/// another unit, naming its bounding box.
pub fn unit_warning(surface: &Surface) -> Option<String> {
    let (lo, hi) = surface.bounds();
    let sides = [0, 1, 2].map(|a| hi[a] - lo[a]);
    let longest = sides.iter().fold(0.0f64, |a, &b| a.max(b));
    scale_hint(longest).map(|hint| {
        let [x, y, z] = sides.map(length);
        format!("{hint} (its bounding box is {x} x {y} x {z})")
    })
}

/// A length in metres to 4 significant digits, in metres from 1 m, else in millimetres.
fn length(m: f64) -> String {
    let (value, unit) = if m >= 1.0 { (m, "m") } else { (m * 1e3, "mm") };
    let digits = if value > 0.0 {
        (3 - value.log10().floor() as i32).clamp(0, 12) as usize
    } else {
        0
    };
    let text = format!("{value:.digits$}");
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        &text
    };
    format!("{text} {unit}")
}
