//! One voxel as a finite element: the stiffness and mass matrices of an 8-node brick of linear
//! elasticity.
//!
//! A plain trilinear brick locks in bending (its edges cannot curve, so a bent bar of a few bricks
//! through its thickness is far too stiff). Each brick therefore carries the nine incompatible
//! modes of Wilson, Taylor, Doherty and Ghaboussi ("Incompatible displacement models", 1973):
//! `1 - xi^2`, `1 - eta^2`, `1 - zeta^2` for each displacement component, condensed out of the
//! element before assembly. On rectangular bricks, as voxels are, the element then represents
//! pure bending exactly. Every voxel of a mesh is the same box, so these matrices are computed once.

/// Degrees of freedom of a brick: three displacements at each of its eight corners.
pub const BRICK_DOFS: usize = 24;

/// Degrees of freedom of the incompatible modes, condensed out.
const BUBBLE_DOFS: usize = 9;

/// All the brick's degrees of freedom before condensation.
const FULL_DOFS: usize = BRICK_DOFS + BUBBLE_DOFS;

/// Gauss points of the 2-point rule on [-1, 1]: exact for the cubic integrands of a brick.
const GAUSS: [f64; 2] = [-0.577_350_269_189_625_8, 0.577_350_269_189_625_8];

/// A brick's matrices, degrees of freedom ordered corner by corner (x, y, z of corner 0, then of
/// corner 1, ...), corner `c` at offset `(c & 1, c >> 1 & 1, c >> 2 & 1)` of the brick.
#[derive(Debug, Clone)]
pub struct BrickMatrices {
    /// Stiffness in N/m, row-major 24 x 24.
    pub stiffness: [[f64; BRICK_DOFS]; BRICK_DOFS],
    /// Consistent mass in kg between corners, 8 x 8 (the same for each displacement component).
    pub mass: [[f64; 8]; 8],
}

/// Corner `c`'s natural coordinates, each -1 or 1.
fn corner(c: usize) -> [f64; 3] {
    [
        if c & 1 == 1 { 1.0 } else { -1.0 },
        if c & 2 == 2 { 1.0 } else { -1.0 },
        if c & 4 == 4 { 1.0 } else { -1.0 },
    ]
}

/// The matrices of a brick `size_m` (edge lengths along x, y, z) of an isotropic material.
pub fn brick_matrices(
    size_m: [f64; 3],
    density_kg_m3: f64,
    youngs_modulus_pa: f64,
    poisson_ratio: f64,
) -> BrickMatrices {
    let half = size_m.map(|s| 0.5 * s);
    let jacobian = half[0] * half[1] * half[2];
    let e = youngs_modulus_pa;
    let nu = poisson_ratio;
    let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));

    let mut full = vec![[0.0; FULL_DOFS]; FULL_DOFS];
    let mut mass = [[0.0; 8]; 8];
    for &xi in &GAUSS {
        for &eta in &GAUSS {
            for &zeta in &GAUSS {
                let point = [xi, eta, zeta];
                // Gradients in x, y, z of the 8 corner functions and the 3 bubbles.
                let mut grads = [[0.0; 3]; 11];
                let mut values = [0.0; 8];
                for (c, grad) in grads.iter_mut().take(8).enumerate() {
                    let n = corner(c);
                    let f = [
                        1.0 + n[0] * point[0],
                        1.0 + n[1] * point[1],
                        1.0 + n[2] * point[2],
                    ];
                    values[c] = 0.125 * f[0] * f[1] * f[2];
                    grad[0] = 0.125 * n[0] * f[1] * f[2] / half[0];
                    grad[1] = 0.125 * f[0] * n[1] * f[2] / half[1];
                    grad[2] = 0.125 * f[0] * f[1] * n[2] / half[2];
                }
                for axis in 0..3 {
                    grads[8 + axis][axis] = -2.0 * point[axis] / half[axis];
                }
                add_stiffness(&mut full, &grads, lambda, mu, jacobian);
                for a in 0..8 {
                    for b in 0..8 {
                        mass[a][b] += density_kg_m3 * values[a] * values[b] * jacobian;
                    }
                }
            }
        }
    }
    BrickMatrices {
        stiffness: condense(&full),
        mass,
    }
}

/// Adds `B^T D B * weight` at one Gauss point, for the displacement functions with gradients
/// `grads` (11 functions: the 8 corners, then the 3 bubbles), strains ordered
/// `xx, yy, zz, xy, yz, zx` (engineering shears).
fn add_stiffness(
    full: &mut [[f64; FULL_DOFS]],
    grads: &[[f64; 3]; 11],
    lambda: f64,
    mu: f64,
    weight: f64,
) {
    // Column `dof` of B: the strains of a unit value of that degree of freedom.
    let dof = |index: usize| -> (usize, usize) {
        if index < BRICK_DOFS {
            (index / 3, index % 3)
        } else {
            (8 + (index - BRICK_DOFS) / 3, (index - BRICK_DOFS) % 3)
        }
    };
    let strains = |index: usize| -> [f64; 6] {
        let (function, component) = dof(index);
        let g = grads[function];
        match component {
            0 => [g[0], 0.0, 0.0, g[1], 0.0, g[2]],
            1 => [0.0, g[1], 0.0, g[0], g[2], 0.0],
            _ => [0.0, 0.0, g[2], 0.0, g[1], g[0]],
        }
    };
    let columns: Vec<[f64; 6]> = (0..FULL_DOFS).map(strains).collect();
    for (a, ba) in columns.iter().enumerate() {
        // D * B column a (isotropic elasticity).
        let trace = ba[0] + ba[1] + ba[2];
        let stress = [
            lambda * trace + 2.0 * mu * ba[0],
            lambda * trace + 2.0 * mu * ba[1],
            lambda * trace + 2.0 * mu * ba[2],
            mu * ba[3],
            mu * ba[4],
            mu * ba[5],
        ];
        for (b, bb) in columns.iter().enumerate() {
            let dot: f64 = stress.iter().zip(bb).map(|(s, e)| s * e).sum();
            full[a][b] += dot * weight;
        }
    }
}

/// The 24 x 24 stiffness left when the bubbles are condensed out: `Kcc - Kcb Kbb^-1 Kbc`
/// (they are internal to the brick, so the assembled system never sees them).
fn condense(full: &[[f64; FULL_DOFS]]) -> [[f64; BRICK_DOFS]; BRICK_DOFS] {
    // Kbb^-1 Kbc by Gauss-Jordan elimination on the 9 x (9 + 24) block (Kbb is positive definite).
    let mut block = vec![[0.0; BUBBLE_DOFS + BRICK_DOFS]; BUBBLE_DOFS];
    for (i, row) in block.iter_mut().enumerate() {
        row[..BUBBLE_DOFS].copy_from_slice(&full[BRICK_DOFS + i][BRICK_DOFS..]);
        row[BUBBLE_DOFS..].copy_from_slice(&full[BRICK_DOFS + i][..BRICK_DOFS]);
    }
    for pivot in 0..BUBBLE_DOFS {
        let p = block[pivot][pivot];
        for value in block[pivot].iter_mut() {
            *value /= p;
        }
        let pivot_row = block[pivot];
        for (i, row) in block.iter_mut().enumerate() {
            if i != pivot {
                let factor = row[pivot];
                for (value, &above) in row.iter_mut().zip(&pivot_row) {
                    *value -= factor * above;
                }
            }
        }
    }
    let mut out = [[0.0; BRICK_DOFS]; BRICK_DOFS];
    for (a, row) in out.iter_mut().enumerate() {
        for (b, value) in row.iter_mut().enumerate() {
            let coupling: f64 = (0..BUBBLE_DOFS)
                .map(|k| full[a][BRICK_DOFS + k] * block[k][BUBBLE_DOFS + b])
                .sum();
            *value = full[a][b] - coupling;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn steel_brick(size: [f64; 3]) -> BrickMatrices {
        brick_matrices(size, 7850.0, 200e9, 0.3)
    }

    fn apply(k: &[[f64; BRICK_DOFS]; BRICK_DOFS], u: &[f64; BRICK_DOFS]) -> [f64; BRICK_DOFS] {
        let mut f = [0.0; BRICK_DOFS];
        for (fa, row) in f.iter_mut().zip(k) {
            *fa = row.iter().zip(u).map(|(k, u)| k * u).sum();
        }
        f
    }

    /// The displacement field `field(x, y, z)` at the corners of a brick of `size`.
    fn at_corners(size: [f64; 3], field: impl Fn([f64; 3]) -> [f64; 3]) -> [f64; BRICK_DOFS] {
        let mut u = [0.0; BRICK_DOFS];
        for c in 0..8 {
            let n = corner(c);
            let p = [
                0.5 * n[0] * size[0],
                0.5 * n[1] * size[1],
                0.5 * n[2] * size[2],
            ];
            u[3 * c..3 * c + 3].copy_from_slice(&field(p));
        }
        u
    }

    #[test]
    fn rigid_motions_take_no_force() {
        let size = [0.002, 0.003, 0.0015];
        let brick = steel_brick(size);
        let scale = brick.stiffness[0][0] * 1e-3;
        type Motion = fn([f64; 3]) -> [f64; 3];
        let motions: [Motion; 6] = [
            |_| [1e-3, 0.0, 0.0],
            |_| [0.0, 1e-3, 0.0],
            |_| [0.0, 0.0, 1e-3],
            |p| [-p[1], p[0], 0.0],
            |p| [0.0, -p[2], p[1]],
            |p| [p[2], 0.0, -p[0]],
        ];
        for (m, motion) in motions.iter().enumerate() {
            let f = apply(&brick.stiffness, &at_corners(size, motion));
            for (i, v) in f.iter().enumerate() {
                assert!(v.abs() < 1e-9 * scale, "motion {m}, dof {i}: force {v}");
            }
        }
    }

    #[test]
    fn stiffness_is_symmetric_and_mass_sums_to_the_brick() {
        let size = [0.002, 0.003, 0.0015];
        let brick = steel_brick(size);
        for a in 0..BRICK_DOFS {
            for b in 0..BRICK_DOFS {
                let (x, y) = (brick.stiffness[a][b], brick.stiffness[b][a]);
                assert!(
                    (x - y).abs() <= 1e-9 * x.abs().max(1.0),
                    "K[{a}][{b}] {x} vs {y}"
                );
            }
        }
        let total: f64 = brick.mass.iter().flatten().sum();
        let expected = 7850.0 * size[0] * size[1] * size[2];
        assert!(
            (total / expected - 1.0).abs() < 1e-12,
            "{total} vs {expected}"
        );
    }

    /// Pure bending of a beam along x, bent in the x-z plane: `u = -z x / R`, `w = x^2 / (2 R)`
    /// (plus the Poisson terms that leave the sides free). The incompatible modes let one brick
    /// store exactly the beam's bending energy `E I L / (2 R^2)`, which a trilinear brick
    /// overestimates by the factor `1 + (1-nu)/(1-2nu)...` of shear locking.
    #[test]
    fn one_brick_bends_with_the_beam_s_energy() {
        let size = [0.01, 0.002, 0.002];
        let (e, nu) = (200e9, 0.3);
        let brick = brick_matrices(size, 7850.0, e, nu);
        let radius = 1.0;
        let u = at_corners(size, |p| {
            let [x, y, z] = p;
            [
                -z * x / radius,
                nu * y * z / radius,
                (x * x + nu * (z * z - y * y)) / (2.0 * radius),
            ]
        });
        let f = apply(&brick.stiffness, &u);
        let energy: f64 = 0.5 * f.iter().zip(&u).map(|(f, u)| f * u).sum::<f64>();
        let inertia = size[1] * size[2].powi(3) / 12.0;
        let beam = e * inertia * size[0] / (2.0 * radius * radius);
        assert!(
            (energy / beam - 1.0).abs() < 1e-6,
            "bending energy {energy} J, beam theory {beam} J"
        );
    }
}
