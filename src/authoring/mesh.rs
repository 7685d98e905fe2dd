//! Banks from 3-D models: the modes of a solid bounded by a closed triangle surface, by finite
//! elements on voxels (seed 000 sections 3.2 and 3.2.3).
//!
//! The pipeline: the surface is checked ([`Surface::check`]), filled with cubes of one size
//! ([`voxel::voxelize`]), each cube an 8-node brick of linear elasticity with incompatible
//! bending modes ([`element`]); their stiffness and mass are assembled sparse ([`assemble`]),
//! and the lowest modes of `K phi = omega^2 M phi` come from shift-invert Lanczos on a sparse
//! Cholesky factorisation ([`lanczos`]). The rigid motions the clamps leave ([`rigid`]: six for a
//! free object) come out first, at zero, and are left out.
//! A mode's gain at a strike point is its mass-normalised shape along the surface normal there,
//! over `omega` (seed 000 eq. 3.11, as the analytic shapes do); decays come from the material.
//!
//! Voxels rather than tetrahedra: any closed surface fills without a mesher that can fail on
//! it, every element is the same box (its matrices are computed once), and the incompatible
//! modes keep a few bricks through a thin wall from locking in bending. The price is a
//! staircase at curved surfaces, which refining the grid removes.

pub mod assemble;
pub mod element;
pub mod error;
pub mod generate;
pub mod lanczos;
pub mod matching;
pub mod read;
pub mod rigid;
pub mod strike;
pub mod surface;
pub mod to_bank;
pub mod voxel;

use std::time::{Duration, Instant};

pub use error::{scale_hint, unit_warning, MeshError};
pub use lanczos::SolveStage;
pub use matching::{combine_with_recording, match_recording, MatchReport};
pub use read::{parse_surface, write_obj};
pub use strike::{spread_strike_points, strike_points, StrikePoint, StrikeRequest};
pub use surface::Surface;
pub use to_bank::{bank_from_modes, MeshSource};
pub use voxel::Voxels;

use crate::authoring::materials::Material;
use crate::bank::validate::MODE_FREQ_HZ;

/// Default number of solid voxels: 100 modes of it solve in seconds.
pub const DEFAULT_ELEMENTS: usize = 20_000;

/// Most modes one solve finds.
pub const MAX_MODES: usize = 500;

/// The Lanczos shift is `-(2 pi f)^2` with `f` this share of `c / D` (the material's rod wave
/// speed over the bounding box's diagonal): 20 Hz for the 300 mm steel bar. Below zero, so
/// `K - sigma M` is positive definite with the rigid motions' zeros; scaled with the object, so
/// its conditioning is the same at any size (stiffness over mass goes as 1 / size^2) and the
/// lowest modes of a large object (a 300 m bar's 0.57 Hz) lie well above it, apart from the
/// zeros, as the bar's 576 Hz does above 20 Hz.
const SHIFT_SHARE: f64 = 1.2e-3;

/// A motion left out as rigid whose frequency exceeds this share of the lowest mode kept is
/// not rigid: the clamps hold it only weakly (a pivot), and [`MeshModes::rigid_warning`] says so.
const RIGID_SHARE: f64 = 0.01;

/// At most this many bytes may a solve hold ([`solve_modes`]): a larger one is refused before
/// its numeric factorisation starts.
pub const DEFAULT_MAX_SOLVE_BYTES: usize = 8 << 30;

/// A region of the solid held still.
#[derive(Debug, Clone, PartialEq)]
pub enum Clamp {
    /// Everything at or below `at_m` along `axis` (0 = x, 1 = y, 2 = z).
    Below {
        /// The axis.
        axis: usize,
        /// The plane's coordinate in metres.
        at_m: f64,
    },
    /// Everything at or above `at_m` along `axis`.
    Above {
        /// The axis.
        axis: usize,
        /// The plane's coordinate in metres.
        at_m: f64,
    },
    /// The grid corners within one voxel of a point (a mesh vertex, say).
    Near {
        /// The point in metres.
        point_m: [f64; 3],
    },
}

impl Clamp {
    /// Whether a grid corner at `p` is held, for voxels of edge `voxel_m`.
    fn holds(&self, p: [f64; 3], voxel_m: f64) -> bool {
        let tolerance = 1e-6 * voxel_m;
        match *self {
            Self::Below { axis, at_m } => p[axis] <= at_m + tolerance,
            Self::Above { axis, at_m } => p[axis] >= at_m - tolerance,
            Self::Near { point_m } => surface::norm(surface::sub(p, point_m)) <= voxel_m,
        }
    }
}

/// How a surface is made into modes.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshSettings {
    /// What the solid is made of.
    pub material: Material,
    /// Number of voxels to aim for (the voxel edge is chosen from the volume).
    pub elements: usize,
    /// Regions held still; none for a free object.
    pub clamps: Vec<Clamp>,
    /// Number of vibration modes to find (the lowest).
    pub modes: usize,
}

/// How long each stage took and how large the problem was.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SolveStats {
    /// Solid voxels (elements).
    pub elements: usize,
    /// Longest edge of a voxel in metres.
    pub voxel_m: f64,
    /// Free degrees of freedom.
    pub dofs: usize,
    /// Stored entries of the stiffness matrix's lower triangle.
    pub matrix_entries: usize,
    /// Entries of the Cholesky factor.
    pub factor_entries: usize,
    /// Lanczos steps.
    pub steps: usize,
    /// Rigid motions the clamps leave (six for a free object), left out.
    pub rigid_modes: usize,
    /// The highest frequency among the motions left out as rigid, in Hz: near zero when they
    /// are rigid, higher when a clamp holds the object only at a pivot.
    pub rigid_max_hz: f64,
    /// Bytes the solve was expected to hold at its peak.
    pub memory_bytes: usize,
    /// Time to fill the surface with voxels.
    pub voxelising: Duration,
    /// Time to assemble the matrices.
    pub assembling: Duration,
    /// Time to factorise `K - sigma M`.
    pub factorising: Duration,
    /// Time of the Lanczos iterations and the mode shapes.
    pub iterating: Duration,
}

/// What the solver reports as it goes, for progress bars.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MeshStage {
    /// Filling the surface with voxels.
    Voxelising,
    /// Assembling stiffness and mass.
    Assembling {
        /// Elements.
        elements: usize,
    },
    /// The solver's own stages.
    Solving(SolveStage),
}

/// The vibration modes of a meshed solid.
#[derive(Debug, Clone)]
pub struct MeshModes {
    /// The voxels the modes live on.
    pub voxels: Voxels,
    /// Degree of freedom of each grid corner (see [`assemble::System::corner_dof`]).
    corner_dof: Vec<Option<usize>>,
    /// Frequencies in Hz, ascending, rigid motions left out.
    pub freqs_hz: Vec<f64>,
    /// Mass-normalised mode shapes over the free degrees of freedom, one per frequency.
    shapes: Vec<Vec<f64>>,
    /// Sizes and times.
    pub stats: SolveStats,
}

/// The lowest vibration modes of the solid bounded by `surface` (checked here), the solve
/// holding at most [`DEFAULT_MAX_SOLVE_BYTES`].
pub fn solve_modes(
    surface: &Surface,
    settings: &MeshSettings,
    progress: &mut dyn FnMut(MeshStage),
) -> Result<MeshModes, MeshError> {
    solve_modes_within(surface, settings, DEFAULT_MAX_SOLVE_BYTES, progress)
}

/// The modes of `surface` up to `max_hz`: solved for `settings.modes`, then again for twice as
/// many until one lies at or above `max_hz`, the solid has no more, or [`MAX_MODES`] are found
/// (then every mode found may lie below `max_hz`: see [`MeshModes::all_below`]).
/// `settings.modes` is left at the count last solved for.
pub fn solve_modes_up_to(
    surface: &Surface,
    settings: &mut MeshSettings,
    max_hz: f64,
    max_bytes: usize,
    progress: &mut dyn FnMut(MeshStage),
) -> Result<MeshModes, MeshError> {
    loop {
        let modes = solve_modes_within(surface, settings, max_bytes, progress)?;
        let exhausted = modes.freqs_hz.len() < settings.modes;
        if !modes.all_below(max_hz) || exhausted || settings.modes >= MAX_MODES {
            return Ok(modes);
        }
        settings.modes = (2 * settings.modes).min(MAX_MODES);
    }
}

/// The lowest vibration modes of the solid bounded by `surface` (checked here); a solve that
/// would hold more than `max_bytes` is refused before its numeric factorisation.
pub fn solve_modes_within(
    surface: &Surface,
    settings: &MeshSettings,
    max_bytes: usize,
    progress: &mut dyn FnMut(MeshStage),
) -> Result<MeshModes, MeshError> {
    surface.check()?;
    settings.check()?;
    let started = Instant::now();
    progress(MeshStage::Voxelising);
    let voxel_m = (surface.signed_volume_m3() / settings.elements as f64).cbrt();
    let voxels = voxel::voxelize(surface, voxel_m)?;
    let pieces = voxels.pieces();
    if pieces > 1 {
        return Err(MeshError::Pieces { pieces, voxel_m });
    }
    let mut stats = SolveStats {
        elements: voxels.count(),
        voxel_m: voxels.size_m.iter().fold(0.0, |a, &b| f64::max(a, b)),
        voxelising: started.elapsed(),
        ..SolveStats::default()
    };

    let started = Instant::now();
    progress(MeshStage::Assembling {
        elements: stats.elements,
    });
    let (system, rigid) = assemble_clamped(&voxels, settings, voxel_m);
    stats.dofs = system.dofs;
    stats.matrix_entries = system.entries();
    stats.rigid_modes = rigid;
    stats.assembling = started.elapsed();

    let started = Instant::now();
    let m = &settings.material;
    let shift_hz = SHIFT_SHARE * m.rod_wave_speed_m_per_s() / diagonal_m(&voxels);
    let pairs = lanczos::lowest_eigenpairs(
        &system,
        settings.modes + rigid,
        -(std::f64::consts::TAU * shift_hz).powi(2),
        max_bytes,
        &mut |stage| progress(MeshStage::Solving(stage)),
    )?;
    stats.factorising = pairs.factorising;
    stats.iterating = started.elapsed().saturating_sub(pairs.factorising);
    stats.factor_entries = pairs.factor_entries;
    stats.memory_bytes = pairs.memory_bytes;
    stats.steps = pairs.steps;

    let (freqs_hz, shapes, rigid_max_hz) = without_rigid_motions(pairs, rigid, settings.modes)?;
    stats.rigid_max_hz = rigid_max_hz;
    let modes = MeshModes {
        voxels,
        corner_dof: system.corner_dof,
        freqs_hz,
        shapes,
        stats,
    };
    if modes.freqs_hz[0] < MODE_FREQ_HZ.min {
        return Err(MeshError::BelowFloor {
            lowest_hz: modes.freqs_hz[0],
            size_m: modes.longest_side_m(),
        });
    }
    Ok(modes)
}

/// The system of `voxels` with the corners `settings.clamps` hold left out, and the number of
/// rigid motions those clamps leave ([`rigid::rigid_motions_left`]): a plane holds the grid
/// corners on its side, a point the corners within a voxel of it, as a pin at the point.
fn assemble_clamped(
    voxels: &Voxels,
    settings: &MeshSettings,
    voxel_m: f64,
) -> (assemble::System, usize) {
    let m = &settings.material;
    let brick = element::brick_matrices(
        voxels.size_m,
        m.density_kg_m3,
        m.youngs_modulus_pa,
        m.poisson_ratio,
    );
    let mut held_m = Vec::new();
    let mut pinned = vec![false; settings.clamps.len()];
    let system = assemble::assemble(voxels, &brick, |p| {
        let mut held = false;
        for (c, clamp) in settings.clamps.iter().enumerate() {
            if clamp.holds(p, voxel_m) {
                held = true;
                match clamp {
                    Clamp::Near { .. } => pinned[c] = true,
                    Clamp::Below { .. } | Clamp::Above { .. } => held_m.push(p),
                }
            }
        }
        held
    });
    for (clamp, _) in settings.clamps.iter().zip(&pinned).filter(|(_, &p)| p) {
        if let Clamp::Near { point_m } = clamp {
            held_m.push(*point_m);
        }
    }
    let rigid = rigid::rigid_motions_left(&held_m, diagonal_m(voxels));
    (system, rigid)
}

/// The diagonal of the voxel grid (the surface's bounding box) in metres.
fn diagonal_m(voxels: &Voxels) -> f64 {
    let sides = [0, 1, 2].map(|a| voxels.size_m[a] * voxels.dims[a] as f64);
    surface::norm(sides)
}

/// `Ok` when `elements` voxels may be asked for: checked before anything is read or computed,
/// as the solve's memory grows faster than the count.
pub fn check_elements(elements: usize) -> Result<(), MeshError> {
    if elements < 8 {
        return Err(MeshError::BadSetting {
            name: "elements",
            reason: format!("expected at least 8, found {elements}"),
        });
    }
    if elements > voxel::MAX_ELEMENTS {
        return Err(MeshError::TooLarge {
            what: "elements",
            count: elements,
            limit: voxel::MAX_ELEMENTS,
        });
    }
    Ok(())
}

impl MeshSettings {
    /// `Ok` when the settings can be solved.
    fn check(&self) -> Result<(), MeshError> {
        if !(1..=MAX_MODES).contains(&self.modes) {
            return Err(MeshError::BadSetting {
                name: "modes",
                reason: format!("expected 1 to {MAX_MODES}, found {}", self.modes),
            });
        }
        check_elements(self.elements)
    }
}

/// The `count` vibration modes of `pairs` after its `rigid` lowest (frequencies in Hz and
/// shapes), and the highest frequency among those left out (0 with none).
#[allow(clippy::type_complexity)]
fn without_rigid_motions(
    pairs: lanczos::Eigenpairs,
    rigid: usize,
    count: usize,
) -> Result<(Vec<f64>, Vec<Vec<f64>>, f64), MeshError> {
    let to_hz = |value: f64| value.max(0.0).sqrt() / std::f64::consts::TAU;
    if pairs.values.len() <= rigid {
        return Err(MeshError::Solver(format!(
            "{} eigenpairs found, none beyond the {rigid} rigid motions",
            pairs.values.len()
        )));
    }
    let rigid_max_hz = pairs.values[..rigid]
        .iter()
        .copied()
        .map(to_hz)
        .fold(0.0, f64::max);
    let freqs_hz = pairs.values[rigid..]
        .iter()
        .take(count)
        .copied()
        .map(to_hz)
        .collect();
    let shapes = pairs.vectors.into_iter().skip(rigid).take(count).collect();
    Ok((freqs_hz, shapes, rigid_max_hz))
}

impl MeshModes {
    /// The longest side of the voxel grid (the surface's bounding box) in metres.
    pub fn longest_side_m(&self) -> f64 {
        let v = &self.voxels;
        (0..3)
            .map(|a| v.size_m[a] * v.dims[a] as f64)
            .fold(0.0, f64::max)
    }

    /// Whether every mode found lies below `limit_hz` (none found counts as not).
    pub fn all_below(&self, limit_hz: f64) -> bool {
        self.freqs_hz.last().is_some_and(|&f| f < limit_hz)
    }

    /// A warning when the motions left out as rigid are not near zero (above 1 % of the lowest
    /// mode kept): what holds the object does so only at a pivot, whose motions about it ring at
    /// a low but real frequency.
    pub fn rigid_warning(&self) -> Option<String> {
        let s = &self.stats;
        let lowest = self.freqs_hz.first().copied().unwrap_or(0.0);
        (s.rigid_modes > 0 && s.rigid_max_hz > RIGID_SHARE * lowest).then(|| {
            format!(
                "the {} motions left out as rigid reach {:.2} Hz, more than {:.0} % of the lowest \
                 mode kept ({lowest:.2} Hz): they are not rigid; an object held only at a point \
                 or along a line turns about it at such a frequency (hold a patch: a plane, or \
                 vertices not on one line)",
                s.rigid_modes,
                s.rigid_max_hz,
                100.0 * RIGID_SHARE
            )
        })
    }

    /// Each mode's displacement at `point_m` (on or near the solid) along the unit vector
    /// `direction`, from the voxel nearest the point (trilinear between its corners).
    pub fn displacement_along(&self, point_m: [f64; 3], direction: [f64; 3]) -> Vec<f64> {
        let v = &self.voxels;
        let Some(cell) = v.nearest_solid(point_m) else {
            return vec![0.0; self.freqs_hz.len()];
        };
        let corner = v.corner_m(cell);
        let t = [0, 1, 2].map(|a| ((point_m[a] - corner[a]) / v.size_m[a]).clamp(0.0, 1.0));
        let (cx, cy) = (v.dims[0] + 1, v.dims[1] + 1);
        let mut weights: Vec<(usize, f64)> = Vec::with_capacity(8);
        for c in 0..8 {
            let offset = [c & 1, c >> 1 & 1, c >> 2 & 1];
            let index =
                (cell[0] + offset[0]) + cx * ((cell[1] + offset[1]) + cy * (cell[2] + offset[2]));
            let w: f64 = (0..3)
                .map(|a| if offset[a] == 1 { t[a] } else { 1.0 - t[a] })
                .product();
            if let Some(dof) = self.corner_dof[index] {
                weights.push((dof, w));
            }
        }
        self.shapes
            .iter()
            .map(|shape| {
                weights
                    .iter()
                    .map(|&(dof, w)| w * (0..3).map(|a| shape[dof + a] * direction[a]).sum::<f64>())
                    .sum()
            })
            .collect()
    }
}
