//! How many rigid motions a solid keeps once clamped: the count of zero-frequency modes the
//! solver must leave out, from the geometry of what holds it rather than from a frequency floor
//! (a floor mistakes the real, very low modes of a large or soft object for rigid motions).
//!
//! A rigid motion moves each point `x` by `a + w x x` (a translation `a` and a rotation `w`:
//! six freedoms). Each point held still asks `a + w x x = 0`. Held points all at one place
//! remove the three translations and leave the three rotations about it; held points on one
//! line leave the rotation about that line; held points not on one line leave nothing.

use faer::{Mat, Side};

use super::surface::sub;

/// Rigid motions of a free solid: three translations, three rotations.
pub const FREE_RIGID_MOTIONS: usize = 6;

/// Held points closer than this share of the object's size to a single place (or to a single
/// line) count as at it: rounding in the coordinates, not a lever that resists rotation.
const SAME_PLACE_SHARE: f64 = 1e-9;

/// The rigid motions left to a solid of size `size_m` (its bounding box's diagonal) when the
/// points `held_m` are held still: 6 with none, 3 when all lie at one place, 1 when all lie on
/// one line, 0 otherwise.
pub fn rigid_motions_left(held_m: &[[f64; 3]], size_m: f64) -> usize {
    if held_m.is_empty() {
        return FREE_RIGID_MOTIONS;
    }
    let count = held_m.len() as f64;
    let mut mean = [0.0; 3];
    for p in held_m {
        for a in 0..3 {
            mean[a] += p[a] / count;
        }
    }
    // The spread of the points about their mean: its eigenvalues are the squared extents along
    // the principal axes, summed over the points.
    let mut spread = Mat::<f64>::zeros(3, 3);
    for p in held_m {
        let d = sub(*p, mean);
        for i in 0..3 {
            for j in 0..3 {
                spread[(i, j)] += d[i] * d[j];
            }
        }
    }
    let extents = spread
        .self_adjoint_eigenvalues(Side::Lower)
        .unwrap_or_else(|_| vec![0.0; 3]);
    let floor = count * (SAME_PLACE_SHARE * size_m).powi(2);
    match extents.iter().filter(|&&e| e > floor).count() {
        0 => 3,
        1 => 1,
        _ => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn held_points_leave_the_motions_their_geometry_allows() {
        let size = 0.3;
        assert_eq!(rigid_motions_left(&[], size), 6);
        assert_eq!(rigid_motions_left(&[[0.1, 0.0, 0.0]], size), 3);
        // The same vertex given twice is still one place.
        assert_eq!(
            rigid_motions_left(&[[0.1, 0.0, 0.0], [0.1, 0.0, 0.0]], size),
            3
        );
        assert_eq!(
            rigid_motions_left(&[[0.0, 0.0, 0.0], [0.3, 0.03, 0.0]], size),
            1
        );
        // Three on one line turn about it; a fourth off the line holds it.
        let line = [[0.0, 0.0, 0.0], [0.1, 0.01, 0.0], [0.3, 0.03, 0.0]];
        assert_eq!(rigid_motions_left(&line, size), 1);
        let mut held = line.to_vec();
        held.push([0.0, 0.0, 0.01]);
        assert_eq!(rigid_motions_left(&held, size), 0);
    }
}
