//! Reading surfaces: Wavefront OBJ and STL (ASCII and binary), and writing OBJ.
//!
//! Hand-written rather than `tobj` and `stl_io` for their errors: `tobj` names only a kind
//! ("face parse error", "face vertex index out of bounds"), with no line, face or word; `stl_io`
//! quotes the bad line of an ASCII STL but not its number, and a binary STL cut short is a bare
//! end of file, without the triangles its header promised or the bytes it holds.

use std::collections::HashMap;
use std::fmt::Write as _;

use super::surface::Surface;
use super::MeshError;

/// A surface read from `bytes`, the contents of a file named `name` (its extension, `.obj` or
/// `.stl`, chooses the reader; anything else is tried as OBJ unless it looks like STL).
pub fn parse_surface(name: &str, bytes: &[u8]) -> Result<Surface, MeshError> {
    let lower = name.to_ascii_lowercase();
    let stl = lower.ends_with(".stl")
        || (!lower.ends_with(".obj") && (bytes.starts_with(b"solid") || is_binary_stl(bytes)));
    if stl {
        if is_binary_stl(bytes) {
            return parse_binary_stl(bytes);
        }
        // Text holds no NUL; a binary STL's header and counts almost always do.
        let binary = bytes.contains(&0) || std::str::from_utf8(bytes).is_err();
        if let Some(error) = binary.then(|| binary_stl_size(bytes)).flatten() {
            return Err(error);
        }
        parse_ascii_stl(text(bytes)?)
    } else {
        parse_obj(text(bytes)?)
    }
}

/// `bytes` as UTF-8 text.
fn text(bytes: &[u8]) -> Result<&str, MeshError> {
    std::str::from_utf8(bytes).map_err(|e| MeshError::Syntax {
        line: 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count(),
        message: "not text (and not a binary STL)".to_string(),
    })
}

/// What is wrong with `bytes`, neither text nor a binary STL of the size its header gives
/// (too short, as a copy or download cut off leaves it, or too long); `None` when they look like
/// an ASCII STL (`solid` and a `facet` at the start) with a stray byte that is not UTF-8.
fn binary_stl_size(bytes: &[u8]) -> Option<MeshError> {
    let start = &bytes[..bytes.len().min(512)];
    if start.starts_with(b"solid") && start.windows(5).any(|w| w == b"facet") {
        return None;
    }
    let count = (bytes.len() >= BINARY_STL_HEADER)
        .then(|| u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize);
    Some(MeshError::BinarySize {
        triangles: count,
        expected_bytes: BINARY_STL_HEADER + BINARY_STL_TRIANGLE * count.unwrap_or(0),
        found_bytes: bytes.len(),
    })
}

/// What [`MeshError::BinarySize`] says: a file of `found_bytes`, where a binary STL of the
/// `triangles` its header gives (`None`: too short for a header) takes `expected_bytes`.
pub(super) fn binary_size_message(
    triangles: Option<usize>,
    expected_bytes: usize,
    found_bytes: usize,
) -> String {
    let Some(count) = triangles else {
        return format!(
            "not text, and {found_bytes} bytes are too few for a binary STL, whose header alone \
             takes {expected_bytes}: the file is truncated"
        );
    };
    let given = format!(
        "a binary STL whose header gives {count} triangles ({expected_bytes} bytes) but the file \
         has {found_bytes} bytes"
    );
    if found_bytes < expected_bytes {
        let whole = found_bytes.saturating_sub(BINARY_STL_HEADER) / BINARY_STL_TRIANGLE;
        format!("{given} ({whole} whole triangles): it is truncated")
    } else {
        format!(
            "{given}, {} more: its count or its end is damaged",
            found_bytes - expected_bytes
        )
    }
}

/// Bytes of a binary STL's header: 80 free bytes and the triangle count.
pub(super) const BINARY_STL_HEADER: usize = 84;

/// Bytes of each triangle of a binary STL: a normal, three corners and an attribute.
pub(super) const BINARY_STL_TRIANGLE: usize = 50;

/// Whether `bytes` are a binary STL: an 80-byte header, a triangle count, and 50 bytes for each.
fn is_binary_stl(bytes: &[u8]) -> bool {
    if bytes.len() < BINARY_STL_HEADER {
        return false;
    }
    let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
    bytes.len() == BINARY_STL_HEADER + BINARY_STL_TRIANGLE * count
}

/// A number parsed from `word` on line `line`.
fn number(word: Option<&str>, line: usize, what: &str) -> Result<f64, MeshError> {
    let word = word.ok_or_else(|| MeshError::Syntax {
        line,
        message: format!("missing {what}"),
    })?;
    match word.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(MeshError::Syntax {
            line,
            message: format!("{what} \"{word}\" is not a finite number"),
        }),
    }
}

/// A Wavefront OBJ: `v x y z` vertices and `f` faces (polygons split into fans; `v/vt/vn`
/// references and negative, relative indices accepted). Other statements are ignored.
fn parse_obj(text: &str) -> Result<Surface, MeshError> {
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let mut words = raw.split_whitespace();
        match words.next() {
            Some("v") => {
                let mut v = [0.0; 3];
                for (axis, value) in v.iter_mut().enumerate() {
                    *value = number(words.next(), line, ["x", "y", "z"][axis])?;
                }
                vertices.push(v);
            }
            Some("f") => {
                let mut face = Vec::new();
                for word in words {
                    let first = word.split('/').next().unwrap_or("");
                    let i: i64 = first.parse().map_err(|_| MeshError::Syntax {
                        line,
                        message: format!("vertex reference \"{word}\" is not an index"),
                    })?;
                    let resolved = if i < 0 {
                        vertices.len() as i64 + i
                    } else {
                        i - 1
                    };
                    if resolved < 0 || resolved >= vertices.len() as i64 {
                        return Err(MeshError::Syntax {
                            line,
                            message: format!(
                                "vertex {i} does not exist ({} vertices so far)",
                                vertices.len()
                            ),
                        });
                    }
                    face.push(resolved as u32);
                }
                if face.len() < 3 {
                    return Err(MeshError::Syntax {
                        line,
                        message: format!("a face needs at least 3 vertices, found {}", face.len()),
                    });
                }
                for k in 1..face.len() - 1 {
                    triangles.push([face[0], face[k], face[k + 1]]);
                }
            }
            _ => {}
        }
        if triangles.len() > super::surface::MAX_TRIANGLES {
            break;
        }
    }
    Ok(Surface {
        vertices,
        triangles,
    })
}

/// An ASCII STL: `facet ... outer loop vertex x y z (3 times) endloop endfacet`.
fn parse_ascii_stl(text: &str) -> Result<Surface, MeshError> {
    let mut welder = Welder::default();
    let mut corners = Vec::with_capacity(3);
    for (index, raw) in text.lines().enumerate() {
        let line = index + 1;
        let mut words = raw.split_whitespace();
        match words.next() {
            Some("vertex") => {
                let mut v = [0.0; 3];
                for (axis, value) in v.iter_mut().enumerate() {
                    *value = number(words.next(), line, ["x", "y", "z"][axis])?;
                }
                corners.push(v);
            }
            Some("endloop") => {
                if corners.len() != 3 {
                    return Err(MeshError::Syntax {
                        line,
                        message: format!("a facet needs 3 vertices, found {}", corners.len()),
                    });
                }
                welder.triangle([corners[0], corners[1], corners[2]]);
                corners.clear();
            }
            _ => {}
        }
        if welder.surface.triangles.len() > super::surface::MAX_TRIANGLES {
            break;
        }
    }
    Ok(welder.surface)
}

/// A binary STL: per triangle a normal (ignored), three corners as little-endian f32, and two
/// attribute bytes.
fn parse_binary_stl(bytes: &[u8]) -> Result<Surface, MeshError> {
    let count = (bytes.len() - BINARY_STL_HEADER) / BINARY_STL_TRIANGLE;
    if count > super::surface::MAX_TRIANGLES {
        return Err(MeshError::TooLarge {
            what: "triangles",
            count,
            limit: super::surface::MAX_TRIANGLES,
        });
    }
    let mut welder = Welder::default();
    for t in 0..count {
        let at = BINARY_STL_HEADER + BINARY_STL_TRIANGLE * t;
        let record = &bytes[at..at + BINARY_STL_TRIANGLE];
        let value = |k: usize| {
            let at = 12 + 4 * k;
            f32::from_le_bytes([record[at], record[at + 1], record[at + 2], record[at + 3]]) as f64
        };
        let corners = [0, 1, 2].map(|c| [value(3 * c), value(3 * c + 1), value(3 * c + 2)]);
        if corners.iter().flatten().any(|v| !v.is_finite()) {
            return Err(MeshError::Syntax {
                line: t + 1,
                message: format!("triangle {t} has a coordinate that is not a finite number"),
            });
        }
        welder.triangle(corners);
    }
    Ok(welder.surface)
}

/// Joins the corners STL repeats for each triangle into shared vertices (equal coordinates).
#[derive(Default)]
struct Welder {
    /// The surface so far.
    surface: Surface,
    /// Vertex index of each distinct corner, by the bits of its coordinates.
    index: HashMap<[u64; 3], u32>,
}

impl Welder {
    /// Adds a triangle by its corners.
    fn triangle(&mut self, corners: [[f64; 3]; 3]) {
        let tri = corners.map(|c| {
            // +0.0 and -0.0 are the same place.
            let key = c.map(|x| (x + 0.0).to_bits());
            *self.index.entry(key).or_insert_with(|| {
                self.surface.vertices.push(c);
                (self.surface.vertices.len() - 1) as u32
            })
        });
        self.surface.triangles.push(tri);
    }
}

/// The surface as a Wavefront OBJ, coordinates in metres, with `comment` on top.
pub fn write_obj(surface: &Surface, comment: &str) -> String {
    let mut out = String::new();
    for line in comment.lines() {
        let _ = writeln!(out, "# {line}");
    }
    for v in &surface.vertices {
        let _ = writeln!(out, "v {} {} {}", v[0], v[1], v[2]);
    }
    for t in &surface.triangles {
        let _ = writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    out
}
