//! The solid as voxels: cubes of one size on a regular grid, each inside the surface or not
//! (seed 000 section 3.2.3).
//!
//! A voxel is solid when its centre is inside the closed surface, found by casting a ray along z
//! through each column of centres and counting the surface crossings below each centre.
//!
//! The grid spans the surface's bounding box exactly, with a whole number of voxels along each
//! axis: a voxel is then a box near the asked size rather than a cube, and an object's extent
//! along each axis (a plate's thickness above all) is kept exactly, not rounded to a voxel.

use super::surface::Surface;
use super::MeshError;

/// At most this many solid voxels: the factorisation's memory grows faster than the count, and
/// 200,000 bricks already take minutes.
pub const MAX_ELEMENTS: usize = 200_000;

/// At most this many cells in the grid's bounding box (solid or not).
const MAX_CELLS: usize = 50_000_000;

/// Offsets of the rays from the column centres, in voxels: irrational, so a ray never passes
/// exactly through a vertex or an edge of a surface drawn on round numbers.
const RAY_OFFSET: [f64; 2] = [1.234_567_9e-6, 2.718_281_8e-6];

/// A grid of cubes, solid or empty.
#[derive(Debug, Clone, PartialEq)]
pub struct Voxels {
    /// Lowest corner of the grid in metres.
    pub origin_m: [f64; 3],
    /// Edges of a voxel along x, y and z in metres.
    pub size_m: [f64; 3],
    /// Voxels along x, y and z.
    pub dims: [usize; 3],
    /// Whether each voxel is solid, x fastest, then y, then z.
    pub solid: Vec<bool>,
}

impl Voxels {
    /// Index in [`Voxels::solid`] of voxel `(i, j, k)`.
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        i + self.dims[0] * (j + self.dims[1] * k)
    }

    /// Number of solid voxels.
    pub fn count(&self) -> usize {
        self.solid.iter().filter(|&&s| s).count()
    }

    /// Grid coordinates `(i, j, k)` of voxel `index`.
    pub fn cell(&self, index: usize) -> [usize; 3] {
        let [nx, ny, _] = self.dims;
        [index % nx, (index / nx) % ny, index / (nx * ny)]
    }

    /// Lowest corner of voxel `(i, j, k)` in metres.
    pub fn corner_m(&self, cell: [usize; 3]) -> [f64; 3] {
        [0, 1, 2].map(|a| self.origin_m[a] + cell[a] as f64 * self.size_m[a])
    }

    /// The solid voxel whose centre is nearest `p`.
    pub fn nearest_solid(&self, p: [f64; 3]) -> Option<[usize; 3]> {
        let mut best: Option<(f64, usize)> = None;
        for (index, _) in self.solid.iter().enumerate().filter(|(_, &s)| s) {
            let corner = self.corner_m(self.cell(index));
            let d: f64 = (0..3)
                .map(|a| (corner[a] + 0.5 * self.size_m[a] - p[a]).powi(2))
                .sum();
            if best.is_none_or(|(b, _)| d < b) {
                best = Some((d, index));
            }
        }
        best.map(|(_, index)| self.cell(index))
    }

    /// Number of separate pieces: solid voxels joined through shared faces.
    pub fn pieces(&self) -> usize {
        let mut seen = vec![false; self.solid.len()];
        let mut pieces = 0;
        let mut stack = Vec::new();
        for start in 0..self.solid.len() {
            if !self.solid[start] || seen[start] {
                continue;
            }
            pieces += 1;
            seen[start] = true;
            stack.push(start);
            while let Some(index) = stack.pop() {
                let cell = self.cell(index);
                for axis in 0..3 {
                    for step in [-1i64, 1] {
                        let mut next = cell.map(|c| c as i64);
                        next[axis] += step;
                        if next[axis] < 0 || next[axis] >= self.dims[axis] as i64 {
                            continue;
                        }
                        let n = self.index(next[0] as usize, next[1] as usize, next[2] as usize);
                        if self.solid[n] && !seen[n] {
                            seen[n] = true;
                            stack.push(n);
                        }
                    }
                }
            }
        }
        pieces
    }
}

/// The voxels of edges near `size_m` inside `surface` (which must have passed
/// [`Surface::check`]).
pub fn voxelize(surface: &Surface, size_m: f64) -> Result<Voxels, MeshError> {
    let (lo, hi) = surface.bounds();
    let mut dims = [0usize; 3];
    let mut sizes = [0.0; 3];
    for axis in 0..3 {
        let span = hi[axis] - lo[axis];
        let n = (span / size_m).round().max(1.0);
        if n > MAX_CELLS as f64 {
            return Err(too_many_cells(n as usize));
        }
        dims[axis] = n as usize;
        sizes[axis] = span / n;
    }
    let cells = dims[0].saturating_mul(dims[1]).saturating_mul(dims[2]);
    if cells > MAX_CELLS {
        return Err(too_many_cells(cells));
    }
    let (origin_m, size_m) = (lo, sizes);
    let columns = crossings_by_column(surface, origin_m, size_m, dims);
    let mut solid = vec![false; cells];
    for (column, zs) in columns.iter().enumerate() {
        let (i, j) = (column % dims[0], column / dims[0]);
        // Pairs of crossings bound the inside.
        for pair in zs.chunks_exact(2) {
            let from = ((pair[0] - origin_m[2]) / size_m[2] - 0.5).ceil().max(0.0) as usize;
            let to = ((pair[1] - origin_m[2]) / size_m[2] - 0.5).floor();
            if to < 0.0 {
                continue;
            }
            for k in from..=(to as usize).min(dims[2] - 1) {
                solid[i + dims[0] * (j + dims[1] * k)] = true;
            }
        }
    }
    let voxels = Voxels {
        origin_m,
        size_m,
        dims,
        solid,
    };
    let count = voxels.count();
    if count == 0 {
        return Err(MeshError::TooThin { voxel_m: size_m[2] });
    }
    if count > MAX_ELEMENTS {
        return Err(MeshError::TooLarge {
            what: "elements",
            count,
            limit: MAX_ELEMENTS,
        });
    }
    Ok(voxels)
}

/// The error for a grid of `cells` cells.
fn too_many_cells(cells: usize) -> MeshError {
    MeshError::TooLarge {
        what: "grid cells",
        count: cells,
        limit: MAX_CELLS,
    }
}

/// For each column of voxel centres (x fastest), the sorted heights at which its ray crosses the
/// surface.
fn crossings_by_column(
    surface: &Surface,
    origin_m: [f64; 3],
    size_m: [f64; 3],
    dims: [usize; 3],
) -> Vec<Vec<f64>> {
    let ray =
        |axis: usize, n: usize| origin_m[axis] + (n as f64 + 0.5 + RAY_OFFSET[axis]) * size_m[axis];
    let mut columns: Vec<Vec<f64>> = vec![Vec::new(); dims[0] * dims[1]];
    for t in 0..surface.triangles.len() {
        let [a, b, c] = surface.corners(t);
        // Twice the signed area of the triangle seen from above.
        let area = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        if area == 0.0 {
            continue; // edge-on to the rays
        }
        let range = |axis: usize| {
            let lo = a[axis].min(b[axis]).min(c[axis]);
            let hi = a[axis].max(b[axis]).max(c[axis]);
            let first = ((lo - origin_m[axis]) / size_m[axis] - 0.5 - RAY_OFFSET[axis]).ceil();
            let last = ((hi - origin_m[axis]) / size_m[axis] - 0.5 - RAY_OFFSET[axis]).floor();
            let first = first.max(0.0) as usize;
            let last = last.min(dims[axis] as f64 - 1.0);
            (first, last)
        };
        let ((i0, i1), (j0, j1)) = (range(0), range(1));
        if i1 < i0 as f64 || j1 < j0 as f64 {
            continue;
        }
        for j in j0..=j1 as usize {
            for i in i0..=i1 as usize {
                let (x, y) = (ray(0, i), ray(1, j));
                // Barycentric weights of (x, y) in the projected triangle.
                let wa = ((b[0] - x) * (c[1] - y) - (c[0] - x) * (b[1] - y)) / area;
                let wb = ((c[0] - x) * (a[1] - y) - (a[0] - x) * (c[1] - y)) / area;
                let wc = 1.0 - wa - wb;
                if wa >= 0.0 && wb >= 0.0 && wc >= 0.0 {
                    columns[i + dims[0] * j].push(wa * a[2] + wb * b[2] + wc * c[2]);
                }
            }
        }
    }
    for zs in &mut columns {
        zs.sort_by(f64::total_cmp);
    }
    columns
}
