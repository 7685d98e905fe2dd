//! A closed triangle surface: the object's boundary as read from a file, checked, and the
//! geometry the rest of the pipeline asks of it (volume, nearest point, normal).

use std::collections::HashMap;

use super::MeshError;

/// At most this many triangles are read: a finer surface adds nothing a voxel grid of a few
/// hundred thousand elements can resolve, and costs memory and time.
pub const MAX_TRIANGLES: usize = 5_000_000;

/// A triangle surface in metres.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Surface {
    /// Vertex positions in metres.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles as vertex indices, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// `a - b`.
pub(super) fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `a . b`.
pub(super) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// `a x b`.
pub(super) fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// `|a|`.
pub(super) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

impl Surface {
    /// The corners of triangle `t`.
    pub fn corners(&self, t: usize) -> [[f64; 3]; 3] {
        self.triangles[t].map(|v| self.vertices[v as usize])
    }

    /// Lowest and highest corner of the axis-aligned box around the surface.
    /// Vertices no triangle uses (common in exported files) are not part of the surface.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        let used = self
            .triangles
            .iter()
            .flatten()
            .filter_map(|&v| self.vertices.get(v as usize));
        for v in used {
            for axis in 0..3 {
                lo[axis] = lo[axis].min(v[axis]);
                hi[axis] = hi[axis].max(v[axis]);
            }
        }
        (lo, hi)
    }

    /// Length of the bounding box's diagonal in metres.
    pub fn diagonal_m(&self) -> f64 {
        let (lo, hi) = self.bounds();
        norm(sub(hi, lo))
    }

    /// Enclosed volume in cubic metres, signed: negative when the triangles face inward
    /// (divergence theorem over the triangles).
    pub fn signed_volume_m3(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                dot(a, cross(b, c)) / 6.0
            })
            .sum()
    }

    /// Scales every vertex by `factor` (units to metres).
    pub fn scale(&mut self, factor: f64) {
        for v in &mut self.vertices {
            *v = v.map(|x| x * factor);
        }
    }

    /// Checks that the surface bounds a solid: not empty, no degenerate triangle, every edge
    /// shared by exactly two triangles that run along it in opposite directions (closed,
    /// manifold, consistently oriented), and facing outward.
    pub fn check(&self) -> Result<(), MeshError> {
        if self.triangles.is_empty() {
            return Err(MeshError::Empty);
        }
        if self.triangles.len() > MAX_TRIANGLES {
            return Err(MeshError::TooLarge {
                what: "triangles",
                count: self.triangles.len(),
                limit: MAX_TRIANGLES,
            });
        }
        let scale = self.diagonal_m();
        if !scale.is_finite() {
            return Err(MeshError::BadSetting {
                name: "scale",
                reason: "the mesh's coordinates overflow once scaled to metres".to_string(),
            });
        }
        let mut edges: HashMap<(u32, u32), Vec<(usize, bool)>> = HashMap::new();
        for (t, tri) in self.triangles.iter().enumerate() {
            if let Some(&v) = tri.iter().find(|&&v| v as usize >= self.vertices.len()) {
                return Err(MeshError::BadIndex {
                    face: t,
                    vertex: v as usize,
                    count: self.vertices.len(),
                });
            }
            let [a, b, c] = self.corners(t);
            let area = 0.5 * norm(cross(sub(b, a), sub(c, a)));
            if area.is_nan() || area <= 1e-12 * scale * scale {
                return Err(MeshError::Degenerate {
                    face: t,
                    vertices: *tri,
                });
            }
            for k in 0..3 {
                let (from, to) = (tri[k], tri[(k + 1) % 3]);
                let key = (from.min(to), from.max(to));
                edges.entry(key).or_default().push((t, from < to));
            }
        }
        let mut sorted: Vec<_> = edges.into_iter().collect();
        sorted.sort_unstable_by_key(|(key, _)| *key);
        for ((a, b), uses) in sorted {
            match uses.as_slice() {
                [(face, _)] => {
                    return Err(MeshError::Open {
                        face: *face,
                        edge: [a, b],
                    })
                }
                [(first, da), (second, db)] if da == db => {
                    return Err(MeshError::Inconsistent {
                        faces: [*first, *second],
                        edge: [a, b],
                    })
                }
                [_, _] => {}
                more => {
                    return Err(MeshError::NonManifold {
                        faces: more.iter().map(|(f, _)| *f).collect(),
                        edge: [a, b],
                    })
                }
            }
        }
        let volume = self.signed_volume_m3();
        if volume < 0.0 {
            return Err(MeshError::InsideOut { volume_m3: volume });
        }
        // A closed surface folded flat (two sheets back to back) encloses nothing.
        if volume <= 1e-9 * scale.powi(3) {
            return Err(MeshError::NoVolume { volume_m3: volume });
        }
        Ok(())
    }

    /// The point of the surface nearest `p`, and the outward unit normal of its triangle.
    pub fn nearest(&self, p: [f64; 3]) -> ([f64; 3], [f64; 3]) {
        let mut best = (f64::INFINITY, p, [0.0, 0.0, 1.0]);
        for t in 0..self.triangles.len() {
            let [a, b, c] = self.corners(t);
            let q = closest_on_triangle(p, a, b, c);
            let d = norm(sub(p, q));
            if d < best.0 {
                let n = cross(sub(b, a), sub(c, a));
                let len = norm(n);
                best = (d, q, n.map(|x| x / len));
            }
        }
        (best.1, best.2)
    }
}

/// The point of triangle `abc` nearest `p` (Ericson, Real-Time Collision Detection, 5.1.5).
fn closest_on_triangle(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> [f64; 3] {
    let along =
        |o: [f64; 3], d: [f64; 3], t: f64| [o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]];
    let (ab, ac, ap) = (sub(b, a), sub(c, a), sub(p, a));
    let (d1, d2) = (dot(ab, ap), dot(ac, ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = sub(p, b);
    let (d3, d4) = (dot(ab, bp), dot(ac, bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return along(a, ab, d1 / (d1 - d3));
    }
    let cp = sub(p, c);
    let (d5, d6) = (dot(ab, cp), dot(ac, cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return along(a, ac, d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return along(b, sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    [
        a[0] + ab[0] * v + ac[0] * w,
        a[1] + ab[1] * v + ac[1] * w,
        a[2] + ab[2] * v + ac[2] * w,
    ]
}
