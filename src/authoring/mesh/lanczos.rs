//! The lowest modes of `K phi = lambda M phi`: shift-invert Lanczos with full
//! reorthogonalisation on a sparse Cholesky factorisation of `K - sigma M`.
//!
//! The operator `(K - sigma M)^-1 M` is symmetric in the `M` inner product and has eigenvalues
//! `theta = 1 / (lambda - sigma)`: the modes nearest above the shift become its largest, which
//! Lanczos finds first (Ericsson and Ruhe, "The spectral transformation Lanczos method", 1980).
//! With a shift below zero, `K - sigma M` is positive definite even for a free object, whose six
//! rigid motions (`lambda = 0`) come out first and are left out by the caller.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, LltRef, SymbolicCholesky};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{ColRef, Conj, MatMut, MatRef, Side};

use super::assemble::System;
use super::MeshError;

/// A Ritz pair is converged when its residual is below this share of its eigenvalue.
const TOLERANCE: f64 = 1e-9;

/// Lanczos steps taken before the first convergence check, beyond the modes asked for.
const EXTRA_STEPS: usize = 40;

/// Steps added between convergence checks.
const CHECK_EVERY: usize = 20;

/// At most this many Lanczos steps per mode asked for (plus [`EXTRA_STEPS`]): the 100 modes of
/// the bench converge in about 2.4 per mode. Past it, the Ritz pairs are taken as they are.
const MAX_STEPS_PER_MODE: usize = 4;

/// The Lanczos basis may take at most this many bytes.
pub const MAX_BASIS_BYTES: usize = 4 << 30;

/// What the solver reports as it goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SolveStage {
    /// Factorising `K - sigma M`, with its stored entries (lower triangle).
    Factorising,
    /// Lanczos steps taken so far, of a first estimate of those needed.
    Iterating {
        /// Steps taken.
        steps: usize,
        /// Steps expected.
        expected: usize,
    },
}

/// Eigenpairs from the bottom of the spectrum.
#[derive(Debug, Clone)]
pub struct Eigenpairs {
    /// Eigenvalues `omega^2` in (rad/s)^2, ascending.
    pub values: Vec<f64>,
    /// Eigenvectors, `M`-normalised (`phi^T M phi = 1`), one per value.
    pub vectors: Vec<Vec<f64>>,
    /// Lanczos steps taken.
    pub steps: usize,
    /// Non-zero entries of the Cholesky factor.
    pub factor_entries: usize,
    /// Bytes the solve was expected to hold at its peak (see `solve_bytes`).
    pub memory_bytes: usize,
    /// Time spent factorising.
    pub factorising: std::time::Duration,
}

/// The `count` lowest eigenpairs of `system` above `shift` (in (rad/s)^2; below every eigenvalue
/// wanted, and below zero for a free object), refused before the numeric factorisation when the
/// solve would hold more than `max_bytes`.
pub fn lowest_eigenpairs(
    system: &System,
    count: usize,
    shift: f64,
    max_bytes: usize,
    progress: &mut dyn FnMut(SolveStage),
) -> Result<Eigenpairs, MeshError> {
    let n = system.dofs;
    let count = count.min(n);
    if count == 0 {
        return Err(MeshError::Solver(
            "no degree of freedom is free".to_string(),
        ));
    }
    let max_steps = n.min(MAX_STEPS_PER_MODE * count + EXTRA_STEPS);
    let bytes = max_steps
        .saturating_mul(n)
        .saturating_mul(std::mem::size_of::<f64>());
    if bytes > MAX_BASIS_BYTES {
        return Err(MeshError::TooLarge {
            what: "bytes of Lanczos basis (elements times modes)",
            count: bytes,
            limit: MAX_BASIS_BYTES,
        });
    }
    progress(SolveStage::Factorising);
    let started = std::time::Instant::now();
    let symbolic = analyse(system)?;
    let memory_bytes = solve_bytes(system, &symbolic, count, max_steps);
    if memory_bytes > max_bytes {
        return Err(MeshError::TooMuchMemory {
            needed_bytes: memory_bytes,
            limit_bytes: max_bytes,
        });
    }
    let mut factor = Factor::new(system, symbolic, shift)?;
    let factor_entries = factor.values.len();
    let factorising = started.elapsed();

    let mut expected = (2 * count + EXTRA_STEPS).min(max_steps);
    let mut next_check = expected.min(count + EXTRA_STEPS);
    let mut lanczos = Lanczos::new(system, max_steps);
    loop {
        lanczos.step(system, &mut factor);
        let steps = lanczos.alpha.len();
        progress(SolveStage::Iterating { steps, expected });
        if steps >= next_check || steps == max_steps {
            let (alpha, beta) = (&lanczos.alpha, &lanczos.beta);
            if let Some((thetas, ritz)) = converged(alpha, beta, count, steps == max_steps)? {
                return Ok(Eigenpairs {
                    values: thetas.iter().map(|theta| shift + 1.0 / theta).collect(),
                    vectors: ritz_vectors(&lanczos.basis, n, &ritz),
                    steps,
                    factor_entries,
                    memory_bytes,
                    factorising,
                });
            }
            next_check = (steps + CHECK_EVERY).min(max_steps);
            expected = expected.max(next_check);
        }
    }
}

/// The symbolic Cholesky factorisation of the system's pattern (fill-reducing ordering and the
/// factor's structure): what the numeric factorisation will need is known from it.
fn analyse(system: &System) -> Result<SymbolicCholesky<usize>, MeshError> {
    let n = system.dofs;
    let pattern = SymbolicSparseColMatRef::new_checked(n, n, &system.col_ptr, None, &system.rows);
    factorize_symbolic_cholesky(pattern, Side::Lower, Default::default(), Default::default())
        .map_err(|e| MeshError::Solver(format!("the factor's structure: {e:?}")))
}

/// Bytes the solve holds at its peak: the system, the factor's values, and the larger of the
/// factorisation's own (the shifted matrix and faer's workspace) and the Lanczos iteration's
/// (a basis of `max_steps` vectors, `count` Ritz vectors, the tridiagonal matrix and its
/// eigenvectors). The voxels and the surface, held before, are left out: a few bytes per cell.
fn solve_bytes(
    system: &System,
    symbolic: &SymbolicCholesky<usize>,
    count: usize,
    max_steps: usize,
) -> usize {
    const F64: usize = std::mem::size_of::<f64>();
    let n = system.dofs;
    // K, M and the row indices per entry; column starts; each corner's degree of freedom.
    let held = system.entries() * 3 * F64 + (n + 1) * F64 + system.corner_dof.len() * 2 * F64;
    let factor = symbolic.len_val() * F64;
    let par = faer::get_global_parallelism();
    let factorising = system.entries() * F64
        + symbolic
            .factorize_numeric_llt_scratch::<f64>(par, Default::default())
            .unaligned_bytes_required();
    // The basis, the Ritz vectors, a few working vectors, and three m x m matrices (the
    // tridiagonal matrix, its eigenvectors and the eigensolver's workspace).
    let iterating = (max_steps + count + 8) * n * F64 + 3 * max_steps * max_steps * F64;
    held + factor + factorising.max(iterating)
}

/// The Cholesky factor of `K - sigma M`, with the workspace of a solve.
struct Factor {
    /// The structure, from [`analyse`].
    symbolic: SymbolicCholesky<usize>,
    /// The factor's entries.
    values: Vec<f64>,
    /// Workspace of one solve, kept between solves.
    scratch: MemBuffer,
}

impl Factor {
    /// Factorises `K - shift M` of `system` on the structure `symbolic`.
    fn new(
        system: &System,
        symbolic: SymbolicCholesky<usize>,
        shift: f64,
    ) -> Result<Self, MeshError> {
        let n = system.dofs;
        let shifted: Vec<f64> = system
            .stiffness
            .iter()
            .zip(&system.mass)
            .map(|(k, m)| k - shift * m)
            .collect();
        let pattern =
            SymbolicSparseColMatRef::new_checked(n, n, &system.col_ptr, None, &system.rows);
        let matrix = SparseColMatRef::new(pattern, &shifted);
        let par = faer::get_global_parallelism();
        let mut values = vec![0.0; symbolic.len_val()];
        let mut work =
            MemBuffer::new(symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()));
        symbolic
            .factorize_numeric_llt(
                &mut values,
                matrix,
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut work),
                Default::default(),
            )
            .map_err(|e| {
                // With a shift below zero K - sigma M is positive definite in exact arithmetic
                // (K is semi-definite, M definite): only rounding can break it.
                MeshError::Solver(format!(
                    "K - sigma M lost positive definiteness to rounding ({e:?}): the object's \
                     stiffest and softest motions lie too far apart for double precision (a \
                     wall far thinner than the object is large, or materials far apart)"
                ))
            })?;
        let scratch = MemBuffer::new(symbolic.solve_in_place_scratch::<f64>(1, par));
        Ok(Self {
            symbolic,
            values,
            scratch,
        })
    }

    /// `x = (K - sigma M)^-1 x`.
    fn solve_in_place(&mut self, x: &mut [f64]) {
        let n = x.len();
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(x, n, 1),
            faer::get_global_parallelism(),
            MemStack::new(&mut self.scratch),
        );
    }
}

/// The Lanczos recurrence's state: the basis so far, the tridiagonal matrix's diagonal and
/// off-diagonal, and the next (unnormalised) vector.
struct Lanczos {
    /// Length of a vector.
    n: usize,
    /// The `M`-orthonormal basis vectors, one after another.
    basis: Vec<f64>,
    /// Diagonal of the tridiagonal matrix.
    alpha: Vec<f64>,
    /// Its off-diagonal; the last is the norm of `w`.
    beta: Vec<f64>,
    /// The next vector before normalisation.
    w: Vec<f64>,
    /// `M w`.
    mw: Vec<f64>,
    /// State of the start vectors' generator.
    seed: u64,
}

impl Lanczos {
    /// A recurrence from a pseudo-random start, with room for `max_steps` steps (reserved, not
    /// touched: the basis never moves, so it never holds two copies of itself).
    fn new(system: &System, max_steps: usize) -> Self {
        let n = system.dofs;
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let w = random_vector(n, &mut seed);
        let mut mw = vec![0.0; n];
        system.mass_times(&w, &mut mw);
        Self {
            n,
            basis: Vec::with_capacity(n * max_steps),
            alpha: Vec::new(),
            beta: Vec::new(),
            w,
            mw,
            seed,
        }
    }

    /// One step: `w` normalised into the next basis vector `q` (a fresh start orthogonal to
    /// the basis if the last step broke down, `w` then lying in an invariant subspace), then
    /// `w = (K - sigma M)^-1 M q`, its component along `q` (alpha) and its norm once
    /// orthogonal to the whole basis (beta).
    fn step(&mut self, system: &System, factor: &mut Factor) {
        let n = self.n;
        let mut b = m_norm(&self.w, &self.mw);
        let scale = self.alpha.iter().fold(0.0f64, |s, a| s.max(a.abs()));
        if !self.alpha.is_empty() && b <= 1e-12 * scale {
            self.w = random_vector(n, &mut self.seed);
            orthogonalise(&self.basis, n, system, &mut self.w, &mut self.mw);
            b = m_norm(&self.w, &self.mw);
            *self.beta.last_mut().expect("a step") = 0.0;
        }
        let mq: Vec<f64> = self.mw.iter().map(|x| x / b).collect();
        self.basis.extend(self.w.iter().map(|x| x / b));
        self.w.copy_from_slice(&mq);
        factor.solve_in_place(&mut self.w);
        self.alpha
            .push(mq.iter().zip(&self.w).map(|(m, w)| m * w).sum());
        orthogonalise(&self.basis, n, system, &mut self.w, &mut self.mw);
        self.beta.push(m_norm(&self.w, &self.mw));
    }
}

/// `sqrt(w^T M w)` from `w` and `M w`.
fn m_norm(w: &[f64], mw: &[f64]) -> f64 {
    w.iter()
        .zip(mw)
        .map(|(a, b)| a * b)
        .sum::<f64>()
        .max(0.0)
        .sqrt()
}

/// A deterministic pseudo-random vector (xorshift), so solves repeat exactly.
fn random_vector(n: usize, seed: &mut u64) -> Vec<f64> {
    (0..n)
        .map(|_| {
            *seed ^= *seed << 13;
            *seed ^= *seed >> 7;
            *seed ^= *seed << 17;
            (*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        })
        .collect()
}

/// Removes from `w` its `M`-projection on every basis vector, twice (classical Gram-Schmidt
/// repeated: "twice is enough"), and leaves `M w` in `mw`.
fn orthogonalise(basis: &[f64], n: usize, system: &System, w: &mut [f64], mw: &mut [f64]) {
    let j = basis.len() / n;
    system.mass_times(w, mw);
    if j == 0 {
        return;
    }
    let q = MatRef::from_column_major_slice(basis, n, j);
    for _ in 0..2 {
        let c = q.transpose() * ColRef::from_slice(mw);
        let correction = q * &c;
        for (x, d) in w.iter_mut().zip(correction.iter()) {
            *x -= d;
        }
        system.mass_times(w, mw);
    }
}

/// The `count` largest Ritz values of the tridiagonal `(alpha, beta)` and their vectors in the
/// Lanczos basis, once all of them are converged (or `last`, when the basis is complete).
#[allow(clippy::type_complexity)]
fn converged(
    alpha: &[f64],
    beta: &[f64],
    count: usize,
    last: bool,
) -> Result<Option<(Vec<f64>, Vec<Vec<f64>>)>, MeshError> {
    let m = alpha.len();
    let t = faer::Mat::from_fn(m, m, |i, j| {
        if i == j {
            alpha[i]
        } else if i == j + 1 {
            beta[j]
        } else if j == i + 1 {
            beta[i]
        } else {
            0.0
        }
    });
    let eigen = t
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| MeshError::Solver(format!("tridiagonal eigenproblem failed: {e:?}")))?;
    let (values, vectors) = (eigen.S(), eigen.U());
    let residual_scale = beta[m - 1];
    let mut thetas = Vec::with_capacity(count);
    let mut ritz = Vec::with_capacity(count);
    // Ascending eigenvalues: the largest thetas are the lowest modes.
    for i in (0..m).rev().take(count) {
        let theta = values[i];
        let residual = (residual_scale * vectors[(m - 1, i)]).abs();
        if !last && residual > TOLERANCE * theta.abs() {
            return Ok(None);
        }
        thetas.push(theta);
        ritz.push((0..m).map(|k| vectors[(k, i)]).collect());
    }
    Ok(Some((thetas, ritz)))
}

/// `Q s` for each Ritz vector `s` in the basis `Q` (columns of length `n`).
fn ritz_vectors(basis: &[f64], n: usize, ritz: &[Vec<f64>]) -> Vec<Vec<f64>> {
    ritz.iter()
        .map(|s| {
            let mut x = vec![0.0; n];
            for (k, &sk) in s.iter().enumerate() {
                for (xi, qi) in x.iter_mut().zip(&basis[k * n..(k + 1) * n]) {
                    *xi += sk * qi;
                }
            }
            x
        })
        .collect()
}
