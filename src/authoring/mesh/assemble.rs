//! The whole object's stiffness and mass: every solid voxel's brick, assembled into sparse
//! symmetric matrices over the grid's corners, less the clamped ones.

use super::element::{BrickMatrices, BRICK_DOFS};
use super::voxel::Voxels;

/// The assembled system: stiffness `K` and mass `M` on one sparsity pattern, lower triangles in
/// compressed columns (the factorisation and the products read only those).
#[derive(Debug, Clone)]
pub struct System {
    /// Number of free degrees of freedom (rows and columns).
    pub dofs: usize,
    /// Start of each column's entries in `rows`, `stiffness` and `mass`; `dofs + 1` values.
    pub col_ptr: Vec<usize>,
    /// Row of each entry, ascending within a column, never above the diagonal.
    pub rows: Vec<usize>,
    /// Stiffness entries in N/m.
    pub stiffness: Vec<f64>,
    /// Mass entries in kg.
    pub mass: Vec<f64>,
    /// Degree of freedom of each grid corner's x displacement (y and z follow it), or `None`
    /// for a corner of no solid voxel or a clamped one. Corners in the grid's order: x fastest,
    /// over `dims + 1` per axis.
    pub corner_dof: Vec<Option<usize>>,
}

impl System {
    /// `y = M x` for the symmetric mass matrix stored as its lower triangle.
    pub fn mass_times(&self, x: &[f64], y: &mut [f64]) {
        y.fill(0.0);
        for col in 0..self.dofs {
            let xc = x[col];
            let mut acc = 0.0;
            for p in self.col_ptr[col]..self.col_ptr[col + 1] {
                let (row, m) = (self.rows[p], self.mass[p]);
                y[row] += m * xc;
                if row != col {
                    acc += m * x[row];
                }
            }
            y[col] += acc;
        }
    }

    /// Number of stored entries (lower triangle).
    pub fn entries(&self) -> usize {
        self.rows.len()
    }
}

/// The assembled system of the solid `voxels`, each a `brick`, with the grid corners for which
/// `clamped(position_m)` holds left out.
pub fn assemble(
    voxels: &Voxels,
    brick: &BrickMatrices,
    clamped: impl FnMut([f64; 3]) -> bool,
) -> System {
    let (corner_dof, dofs) = number_corners(voxels, clamped);
    let entries = brick_entries(voxels, brick, &corner_dof);
    let (col_ptr, rows, stiffness, mass) = compress(entries, dofs);
    System {
        dofs,
        col_ptr,
        rows,
        stiffness,
        mass,
        corner_dof,
    }
}

/// Index of grid corner `(i, j, k)` in a grid of `dims` voxels.
fn corner_index(dims: [usize; 3], i: usize, j: usize, k: usize) -> usize {
    i + (dims[0] + 1) * (j + (dims[1] + 1) * k)
}

/// The first degree of freedom of each corner of a solid voxel that is not clamped, and their
/// count.
fn number_corners(
    voxels: &Voxels,
    mut clamped: impl FnMut([f64; 3]) -> bool,
) -> (Vec<Option<usize>>, usize) {
    let [nx, ny, nz] = voxels.dims;
    let (cx, cy) = (nx + 1, ny + 1);
    let mut corner_dof = vec![None; cx * cy * (nz + 1)];
    let mut used = vec![false; corner_dof.len()];
    for (v, _) in voxels.solid.iter().enumerate().filter(|(_, &s)| s) {
        let [i, j, k] = voxels.cell(v);
        for c in 0..8 {
            used[corner_index(voxels.dims, i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1))] = true;
        }
    }
    let mut dofs = 0;
    for (index, dof) in corner_dof.iter_mut().enumerate() {
        if !used[index] {
            continue;
        }
        let cell = [index % cx, (index / cx) % cy, index / (cx * cy)];
        let p = [0, 1, 2].map(|a| voxels.origin_m[a] + cell[a] as f64 * voxels.size_m[a]);
        if !clamped(p) {
            *dof = Some(dofs);
            dofs += 3;
        }
    }
    (corner_dof, dofs)
}

/// Every brick's lower-triangle entries as `(column, row, stiffness, mass)`, unmerged.
fn brick_entries(
    voxels: &Voxels,
    brick: &BrickMatrices,
    corner_dof: &[Option<usize>],
) -> Vec<(u32, u32, f64, f64)> {
    let mut entries = Vec::new();
    for (v, _) in voxels.solid.iter().enumerate().filter(|(_, &s)| s) {
        let [i, j, k] = voxels.cell(v);
        let mut local = [None; BRICK_DOFS];
        for c in 0..8 {
            let corner = corner_index(voxels.dims, i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1));
            if let Some(first) = corner_dof[corner] {
                for axis in 0..3 {
                    local[3 * c + axis] = Some(first + axis);
                }
            }
        }
        for (a, row) in local.iter().enumerate() {
            let Some(row) = *row else { continue };
            for (b, col) in local.iter().enumerate() {
                let Some(col) = *col else { continue };
                if row < col {
                    continue;
                }
                let mass = if a % 3 == b % 3 {
                    brick.mass[a / 3][b / 3]
                } else {
                    0.0
                };
                entries.push((col as u32, row as u32, brick.stiffness[a][b], mass));
            }
        }
    }
    entries
}

/// Compressed columns (column starts, rows, stiffness, mass) of `entries`, those at the same
/// place summed.
#[allow(clippy::type_complexity)]
fn compress(
    mut entries: Vec<(u32, u32, f64, f64)>,
    dofs: usize,
) -> (Vec<usize>, Vec<usize>, Vec<f64>, Vec<f64>) {
    entries.sort_unstable_by_key(|&(col, row, _, _)| (col, row));
    let mut col_ptr = vec![0usize; dofs + 1];
    let mut rows = Vec::new();
    let mut stiffness: Vec<f64> = Vec::new();
    let mut mass: Vec<f64> = Vec::new();
    let mut last = None;
    for (col, row, k, m) in entries {
        if last == Some((col, row)) {
            *stiffness.last_mut().expect("an entry") += k;
            *mass.last_mut().expect("an entry") += m;
        } else {
            rows.push(row as usize);
            stiffness.push(k);
            mass.push(m);
            col_ptr[col as usize + 1] += 1;
            last = Some((col, row));
        }
    }
    for col in 0..dofs {
        col_ptr[col + 1] += col_ptr[col];
    }
    (col_ptr, rows, stiffness, mass)
}
