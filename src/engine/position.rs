//! Strike positions between the measured ones: which gain columns to blend, and how much.

/// At most this many positions are blended (a triangle on 2-D banks).
pub const MAX_BLEND: usize = 3;

/// Weights of up to three gain columns for one strike point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PositionWeights {
    /// Column indices; entries past `count` are unused.
    pub index: [usize; MAX_BLEND],
    /// Weights summing to 1; entries past `count` are zero.
    pub weight: [f32; MAX_BLEND],
    /// Number of columns used.
    pub count: usize,
}

impl PositionWeights {
    /// All weight on column `k`.
    pub fn single(k: usize) -> Self {
        Self {
            index: [k, 0, 0],
            weight: [1.0, 0.0, 0.0],
            count: 1,
        }
    }
}

/// The bank's positions as places on the object, and how a strike position (0 to 1 on each
/// axis) finds them.
///
/// A strike position is a place on the object: on an axis whose coordinates all lie in 0 to 1
/// (fractions of the object's length or width, as every factory bank gives them), 0.5 is the
/// middle of the object whatever span the positions cover, and when they all lie in its first
/// half (a bar measured from its end to its centre) the object is taken to mirror about its
/// middle, so 0.75 sounds as 0.25. An axis in other units is stretched over 0 to 1 from its
/// lowest to its highest position; one on which every position agrees is not an axis the
/// strike can move along.
#[derive(Debug, Clone)]
pub struct PositionMap {
    /// Each position's place on the unit interval or square (second value 0.5 on 1-D banks).
    coords: Vec<[f64; 2]>,
    /// 1 or 2.
    dims: usize,
    /// Per axis, what it is to a strike.
    axes: [StrikeAxis; 2],
}

/// How a strike position maps onto one axis of a bank's positions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StrikeAxis {
    /// Coordinates are fractions of the object: a strike lands where it says.
    Object,
    /// As [`StrikeAxis::Object`], with every position in the first half: a strike beyond the middle
    /// lands at its mirror image.
    Mirrored,
    /// Coordinates in other units, stretched from the lowest position (0) to the highest (1).
    Stretched {
        /// Lowest coordinate.
        lo: f64,
        /// Highest coordinate.
        hi: f64,
    },
    /// Every position agrees on this axis (or the bank has no such axis): a strike cannot move
    /// along it.
    Fixed,
}

impl StrikeAxis {
    /// Where strike position `s` (0 to 1) lands on this axis, in the units of
    /// [`PositionMap::coords`].
    fn place(self, s: f64) -> f64 {
        match self {
            StrikeAxis::Mirrored => s.min(1.0 - s),
            StrikeAxis::Fixed => 0.5,
            StrikeAxis::Object | StrikeAxis::Stretched { .. } => s,
        }
    }
}

impl PositionMap {
    /// The map of positions with coordinates `coords` (each 1, 2 or 3 values): see
    /// [`PositionMap`]. Points in space (3 values: on the surface of a meshed object) are seen
    /// in the plane of their two widest spreads, each axis stretched over 0 to 1.
    pub fn new(coords: &[Vec<f64>]) -> Self {
        let spatial = coords.iter().any(|c| c.len() >= 3);
        let projected;
        let coords = if spatial {
            projected = project_onto_widest_plane(coords);
            &projected[..]
        } else {
            coords
        };
        let dims = coords
            .iter()
            .map(|c| c.len())
            .max()
            .unwrap_or(1)
            .clamp(1, 2);
        let mut out = vec![[0.5; 2]; coords.len()];
        let mut axes = [StrikeAxis::Fixed; 2];
        for axis in 0..dims {
            let values = coords.iter().map(|c| c.get(axis).copied().unwrap_or(0.0));
            let (lo, hi) = values
                .clone()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                    (lo.min(v), hi.max(v))
                });
            axes[axis] = if hi <= lo {
                StrikeAxis::Fixed
            } else if spatial {
                StrikeAxis::Stretched { lo, hi }
            } else if lo >= 0.0 && hi <= 0.5 {
                StrikeAxis::Mirrored
            } else if lo >= 0.0 && hi <= 1.0 {
                StrikeAxis::Object
            } else {
                StrikeAxis::Stretched { lo, hi }
            };
            for (o, v) in out.iter_mut().zip(values) {
                o[axis] = match axes[axis] {
                    StrikeAxis::Fixed => 0.5,
                    StrikeAxis::Object | StrikeAxis::Mirrored => v,
                    StrikeAxis::Stretched { lo, hi } => (v - lo) / (hi - lo),
                };
            }
        }
        Self {
            coords: out,
            dims,
            axes,
        }
    }

    /// What each axis is to a strike: x, then y.
    pub fn axes(&self) -> [StrikeAxis; 2] {
        self.axes
    }

    /// Whether a strike position along `axis` (0 for x, 1 for y) changes the sound.
    pub fn moves_along(&self, axis: usize) -> bool {
        self.axes[axis] != StrikeAxis::Fixed
    }

    /// The strike position of the same place on the object as `s` on `axis` meant before strike
    /// positions were places on the object (when 0 to 1 spanned the positions, lowest to
    /// highest), for bringing old settings forward.
    pub fn from_span_fraction(&self, axis: usize, s: f32) -> f32 {
        let s = s.clamp(0.0, 1.0) as f64;
        let (lo, hi) = self
            .coords
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
                (lo.min(c[axis]), hi.max(c[axis]))
            });
        match self.axes[axis] {
            StrikeAxis::Object | StrikeAxis::Mirrored if hi > lo => (lo + s * (hi - lo)) as f32,
            _ => s as f32,
        }
    }

    /// Number of coordinates per position.
    pub fn dims(&self) -> usize {
        self.dims
    }

    /// Each position's place on the unit interval or square, in the units of a strike position.
    pub fn coords(&self) -> &[[f64; 2]] {
        &self.coords
    }

    /// The blend of columns for a strike at `(x, y)`, places on the object (0 to 1; `y` ignored
    /// on 1-D banks), after the symmetry of each axis.
    ///
    /// 1-D: linear between the neighbours on either side, the end position beyond the ends.
    /// 2-D: barycentric within the triangle of the three nearest positions, clamped to its edges.
    pub fn weights(&self, x: f32, y: f32) -> PositionWeights {
        let p = [
            self.axes[0].place(x.clamp(0.0, 1.0) as f64),
            self.axes[1].place(y.clamp(0.0, 1.0) as f64),
        ];
        match (self.coords.len(), self.dims) {
            (0 | 1, _) => PositionWeights::single(0),
            (_, 1) => self.weights_1d(p[0]),
            (2, _) => self.weights_segment(0, 1, p),
            _ => self.weights_2d(p),
        }
    }

    fn weights_1d(&self, x: f64) -> PositionWeights {
        let mut below: Option<(usize, f64)> = None;
        let mut above: Option<(usize, f64)> = None;
        for (k, c) in self.coords.iter().enumerate() {
            let v = c[0];
            if v <= x && below.is_none_or(|(_, b)| v > b) {
                below = Some((k, v));
            }
            if v >= x && above.is_none_or(|(_, a)| v < a) {
                above = Some((k, v));
            }
        }
        match (below, above) {
            (Some((kb, vb)), Some((ka, va))) if ka != kb && va > vb => {
                let t = ((x - vb) / (va - vb)) as f32;
                Self::pair(kb, ka, t)
            }
            (Some((k, _)), _) | (None, Some((k, _))) => PositionWeights::single(k),
            (None, None) => PositionWeights::single(0),
        }
    }

    /// Weights `1 - t` on `a` and `t` on `b`.
    fn pair(a: usize, b: usize, t: f32) -> PositionWeights {
        PositionWeights {
            index: [a, b, 0],
            weight: [1.0 - t, t, 0.0],
            count: 2,
        }
    }

    /// Projection of `p` onto the segment between positions `a` and `b`.
    fn weights_segment(&self, a: usize, b: usize, p: [f64; 2]) -> PositionWeights {
        let (pa, pb) = (self.coords[a], self.coords[b]);
        let d = [pb[0] - pa[0], pb[1] - pa[1]];
        let len_sq = d[0] * d[0] + d[1] * d[1];
        if len_sq <= 1e-18 {
            return PositionWeights::single(a);
        }
        let t = (((p[0] - pa[0]) * d[0] + (p[1] - pa[1]) * d[1]) / len_sq).clamp(0.0, 1.0);
        Self::pair(a, b, t as f32)
    }

    fn weights_2d(&self, p: [f64; 2]) -> PositionWeights {
        let dist_sq = |k: usize| {
            let c = self.coords[k];
            (c[0] - p[0]).powi(2) + (c[1] - p[1]).powi(2)
        };
        // The three nearest positions, nearest first.
        let mut near = [usize::MAX; MAX_BLEND];
        for k in 0..self.coords.len() {
            let mut item = k;
            for slot in near.iter_mut() {
                if *slot == usize::MAX || dist_sq(item) < dist_sq(*slot) {
                    std::mem::swap(slot, &mut item);
                    if item == usize::MAX {
                        break;
                    }
                }
            }
        }
        let [a, b, c] = near;
        if dist_sq(a) <= 1e-18 {
            return PositionWeights::single(a);
        }
        let (pa, pb, pc) = (self.coords[a], self.coords[b], self.coords[c]);
        let det = (pb[1] - pc[1]) * (pa[0] - pc[0]) + (pc[0] - pb[0]) * (pa[1] - pc[1]);
        if det.abs() < 1e-12 {
            // Collinear: blend along the two nearest.
            return self.weights_segment(a, b, p);
        }
        let wa = ((pb[1] - pc[1]) * (p[0] - pc[0]) + (pc[0] - pb[0]) * (p[1] - pc[1])) / det;
        let wb = ((pc[1] - pa[1]) * (p[0] - pc[0]) + (pa[0] - pc[0]) * (p[1] - pc[1])) / det;
        let wc = 1.0 - wa - wb;
        let w = [wa.max(0.0), wb.max(0.0), wc.max(0.0)];
        let sum: f64 = w.iter().sum();
        if sum <= 0.0 {
            return PositionWeights::single(a);
        }
        PositionWeights {
            index: [a, b, c],
            weight: [
                (w[0] / sum) as f32,
                (w[1] / sum) as f32,
                (w[2] / sum) as f32,
            ],
            count: 3,
        }
    }
}

/// Points in space seen in the plane of their two widest spreads (the principal axes of their
/// scatter, the widest first), as 2-D coordinates from their mean; points on one line as 1-D
/// coordinates along it.
fn project_onto_widest_plane(coords: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let point = |c: &Vec<f64>| [0, 1, 2].map(|a| c.get(a).copied().unwrap_or(0.0));
    let n = coords.len().max(1) as f64;
    let mean = coords.iter().fold([0.0; 3], |m, c| {
        let p = point(c);
        [m[0] + p[0] / n, m[1] + p[1] / n, m[2] + p[2] / n]
    });
    let mut scatter = [[0.0; 3]; 3];
    for c in coords {
        let p = point(c);
        for i in 0..3 {
            for j in 0..3 {
                scatter[i][j] += (p[i] - mean[i]) * (p[j] - mean[j]);
            }
        }
    }
    let (values, vectors) = symmetric_eigen3(scatter);
    let mut order = [0, 1, 2];
    order.sort_by(|&a, &b| values[b].total_cmp(&values[a]));
    // Points on one line have no second axis (rounding must not make one up): a line.
    let axes = if values[order[1]] <= 1e-12 * values[order[0]] {
        1
    } else {
        2
    };
    coords
        .iter()
        .map(|c| {
            let p = point(c);
            order[..axes]
                .iter()
                .map(|&k| (0..3).map(|a| (p[a] - mean[a]) * vectors[a][k]).sum())
                .collect()
        })
        .collect()
}

/// Eigenvalues and eigenvectors (columns) of a symmetric 3 x 3 matrix, by Jacobi rotations.
fn symmetric_eigen3(mut a: [[f64; 3]; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..50 {
        let off = a[0][1].abs() + a[0][2].abs() + a[1][2].abs();
        let scale = a[0][0].abs() + a[1][1].abs() + a[2][2].abs();
        if off <= 1e-15 * scale || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = 0.5 * (a[q][q] - a[p][p]) / a[p][q];
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let (c, s) = (1.0 / (t * t + 1.0).sqrt(), t / (t * t + 1.0).sqrt());
            for row in a.iter_mut() {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (row_p, row_q) = (a[p], a[q]);
            for k in 0..3 {
                a[p][k] = c * row_p[k] - s * row_q[k];
                a[q][k] = s * row_p[k] + c * row_q[k];
            }
            for row in v.iter_mut() {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    ([a[0][0], a[1][1], a[2][2]], v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_dimension_interpolates_between_neighbours() {
        // In metres along a 2 m rod: stretched from the lowest position to the highest.
        let map = PositionMap::new(&[vec![1.0], vec![0.0], vec![0.5]]);
        let w = map.weights(0.25, 0.0); // halfway between coords 0.0 and 0.5
        assert_eq!(w.count, 2);
        assert_eq!((w.index[0], w.index[1]), (1, 2));
        assert!((w.weight[0] - 0.5).abs() < 1e-6 && (w.weight[1] - 0.5).abs() < 1e-6);
        assert_eq!(map.weights(1.0, 0.0), PositionWeights::single(0));
        assert_eq!(map.weights(0.0, 0.0), PositionWeights::single(1));
    }

    #[test]
    fn a_strike_position_is_a_place_on_the_object() {
        // A bar measured from its end (0) to its centre (0.5), as the factory bars are.
        let map = PositionMap::new(&[vec![0.4], vec![0.0], vec![0.25], vec![0.5]]);
        assert_eq!(map.axes()[0], StrikeAxis::Mirrored);
        // 0.5 is the middle of the bar, not the middle of the measured span.
        assert_eq!(map.weights(0.5, 0.0), PositionWeights::single(3));
        assert_eq!(map.weights(0.25, 0.0), PositionWeights::single(2));
        // The far half mirrors the near one.
        assert_eq!(map.weights(0.75, 0.0), PositionWeights::single(2));
        assert_eq!(map.weights(1.0, 0.0), PositionWeights::single(1));
        assert_eq!(map.weights(0.625, 0.0), map.weights(0.375, 0.0));
        // y is not an axis of a line.
        assert!(!map.moves_along(1));
        assert_eq!(map.weights(0.5, 0.9), map.weights(0.5, 0.1));

        // A bell measured from near its crown (0.25) to its rim (1): no mirror, and a strike
        // above the highest position lands there.
        let map = PositionMap::new(&[vec![0.875], vec![0.25], vec![0.5], vec![1.0]]);
        assert_eq!(map.axes()[0], StrikeAxis::Object);
        assert_eq!(map.weights(0.5, 0.0), PositionWeights::single(2));
        assert_eq!(map.weights(0.125, 0.0), PositionWeights::single(1));

        // A circular plate: radius along x, every position on one angle.
        let map = PositionMap::new(&[vec![0.625, 0.0], vec![0.0, 0.0], vec![0.875, 0.0]]);
        assert_eq!(map.axes(), [StrikeAxis::Object, StrikeAxis::Fixed]);
        assert_eq!(map.weights(0.625, 0.3), PositionWeights::single(0));
    }

    #[test]
    fn points_in_space_are_seen_in_their_widest_plane() {
        // Four points on a tilted square (side 0.1 m, in the plane z = y), and one off it.
        let map = PositionMap::new(&[
            vec![0.0, 0.0, 0.0],
            vec![0.1, 0.0, 0.0],
            vec![0.0, 0.07, 0.07],
            vec![0.1, 0.07, 0.07],
            vec![0.05, 0.035, 0.037],
        ]);
        assert_eq!(map.dims(), 2);
        assert!(map.moves_along(0) && map.moves_along(1));
        assert!(matches!(map.axes()[0], StrikeAxis::Stretched { .. }));
        // The square's corners land on the pad's corners, the fifth point in the middle.
        let mut corners: Vec<[i64; 2]> = map.coords()[..4]
            .iter()
            .map(|c| [c[0].round() as i64, c[1].round() as i64])
            .collect();
        corners.sort();
        assert_eq!(
            corners,
            vec![[0, 0], [0, 1], [1, 0], [1, 1]],
            "{:?}",
            map.coords()
        );
        // The fifth point, 2 mm off the plane, lands 1.4 mm along the 99 mm diagonal axis from
        // the middle.
        let middle = map.coords()[4];
        assert!(
            (middle[0] - 0.5).abs() < 0.02 && (middle[1] - 0.5).abs() < 0.02,
            "{middle:?}"
        );
        // A strike at a position's place plays that position (to the f32 of a strike position).
        for (k, c) in map.coords().iter().enumerate() {
            let w = map.weights(c[0] as f32, c[1] as f32);
            assert_eq!(w.index[0], k, "{w:?}");
            assert!(w.weight[0] > 0.9999, "{w:?}");
        }
    }

    #[test]
    fn points_in_space_on_one_line_have_one_axis() {
        // Along a slanted line: the strike moves along it, not across it.
        let map = PositionMap::new(&[
            vec![0.0, 0.0, 0.0],
            vec![0.1, 0.03, 0.07],
            vec![0.3, 0.09, 0.21],
        ]);
        assert_eq!(map.dims(), 1);
        assert!(map.moves_along(0));
        assert!(!map.moves_along(1));
        // The ends at the ends (which one at 0 is the axis's sign), the middle a third along.
        let x: Vec<f64> = map.coords().iter().map(|c| c[0]).collect();
        assert!((x[0] - x[2]).abs() > 1.0 - 1e-12, "{x:?}");
        assert!((x[1] - (2.0 * x[0] + x[2]) / 3.0).abs() < 1e-9, "{x:?}");
        let end = if x[2] > 0.5 { 1.0 } else { 0.0 };
        assert_eq!(map.weights(end, 0.3), PositionWeights::single(2));
        assert_eq!(map.weights(1.0 - end, 0.9), PositionWeights::single(0));
    }

    #[test]
    fn old_strike_positions_come_forward_to_the_same_place() {
        let bar = PositionMap::new(&[vec![0.4], vec![0.0], vec![0.25], vec![0.5]]);
        // 0.5 of the span from end to centre was the quarter point.
        assert_eq!(bar.from_span_fraction(0, 0.5), 0.25);
        assert_eq!(bar.from_span_fraction(0, 1.0), 0.5);
        let bell = PositionMap::new(&[vec![0.9], vec![0.2], vec![1.0]]);
        assert!((bell.from_span_fraction(0, 0.5) - 0.6).abs() < 1e-6);
        // Stretched axes meant the span already.
        let rod = PositionMap::new(&[vec![2.0], vec![0.0]]);
        assert_eq!(rod.from_span_fraction(0, 0.3), 0.3);
    }

    #[test]
    fn two_dimensions_hit_positions_exactly_and_blend_inside() {
        let map = PositionMap::new(&[
            vec![0.0, 0.0],
            vec![1.0, 0.0],
            vec![0.0, 1.0],
            vec![1.0, 1.0],
        ]);
        assert_eq!(map.weights(1.0, 1.0), PositionWeights::single(3));
        let w = map.weights(0.2, 0.2);
        let sum: f32 = w.weight.iter().sum();
        assert!((sum - 1.0).abs() < 1e-6);
        let mut at = [0.0f32; 4];
        for i in 0..w.count {
            at[w.index[i]] += w.weight[i];
        }
        assert!(at[0] > 0.5, "nearest corner dominates: {at:?}");
    }
}
