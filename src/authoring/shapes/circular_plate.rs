//! The thin circular Kirchhoff plate, free or clamped at its edge: a flat gong or cymbal, a disc
//! of glass, a clamped diaphragm.
//!
//! Frequencies `f = lambda^2 / (2 pi a^2) sqrt(D / (rho h))`, flexural rigidity
//! `D = E h^3 / (12 (1 - nu^2))`, radius `a`. Mode `(n, s)` has `n` nodal diameters and `s` nodal
//! circles (besides a clamped rim) and the shape
//! `W = [J_n(lambda r / a) + C I_n(lambda r / a)] cos(n theta)`, with `lambda` the roots of the
//! frequency equation set by the edge (A. W. Leissa, *Vibration of Plates*, NASA SP-160, 1969,
//! ch. 2, eqs. 2.12 and 2.15; Fletcher & Rossing ch. 3):
//!
//! - clamped, `W = dW/dr = 0`: `J_n(l) I_n'(l) - I_n(l) J_n'(l) = 0`, whatever `nu`;
//! - free, no bending moment and no Kirchhoff shear at the rim:
//!   `m_J v_I - m_I v_J = 0` with `m_F = l^2 F'' + nu (l F' - n^2 F)` and
//!   `v_F = -+ l^3 F' + (1 - nu) n^2 (F - l F')` (minus for `J`, plus for `I`), which depends on
//!   Poisson's ratio. The rigid-body motions of a free plate (`lambda = 0`) are not sounds and
//!   are left out.
//!
//! The roots are found numerically here and checked against Leissa's tables 2.1 (clamped) and
//! 2.3 (free, `nu = 0.33`) in the tests. Shapes are normalised to unit mean square over the plate
//! numerically. A cymbal's curvature and centre mount, and a gong's turned-down rim, shift and
//! split these modes: a flat free disc is their starting point, not a model of either.
//!
//! Positions are `(x, y)` in fractions of the radius from the centre, as for the membrane.

use super::bessel::{bessel_i_scaled_upto, bessel_j_upto, roots_by_scan};
use super::disc::{unit_mean_square_scale, DiscPoints};
use super::membrane::DISC_STRIKE;
use super::objects::{Dimension, ObjectKind, ObjectOption};
use super::positions::{plane_coords, position};
use super::shape::{mm, Object};
use super::{check_thin, ModeLimits, Shape, ShapeError, ShapedMode};
use crate::authoring::materials::{self, Material};
use crate::bank::Position;
use serde_json::{json, Map, Value};
use std::f64::consts::TAU;

/// `circular-plate` on the command line.
pub static CIRCULAR_PLATE: ObjectKind = ObjectKind {
    name: "circular-plate",
    about: "thin disc, free or clamped at its rim (--edge): gong, cymbal, saucer",
    dimensions: &[
        (Dimension::Radius, "m", 0.15),
        (Dimension::Thickness, "m", 0.002),
    ],
    options: &[ObjectOption::Edge],
    default_material: &materials::BRASS,
    build: |spec| {
        Shape::CircularPlate(CircularPlate {
            radius_m: spec.value(Dimension::Radius),
            thickness_m: spec.value(Dimension::Thickness),
            edge: spec.edge.unwrap_or(PlateEdge::Free),
        })
    },
};

/// How the rim of a circular plate is held.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlateEdge {
    /// Nothing holds the rim (a gong or cymbal hung or held at a point near the centre).
    Free,
    /// The rim cannot move or turn (a diaphragm held in a ring).
    Clamped,
}

impl PlateEdge {
    /// Both edges, for listing.
    pub const ALL: [PlateEdge; 2] = [PlateEdge::Free, PlateEdge::Clamped];

    /// Lowercase name, as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Free => "free",
            Self::Clamped => "clamped",
        }
    }

    /// The edge called `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|edge| edge.name().eq_ignore_ascii_case(name.trim()))
    }
}

/// Step of the scan for roots in `lambda`: roots of one order are about pi apart.
const ROOT_SCAN_STEP: f64 = 0.1;

/// Smallest `lambda` scanned: below the lowest elastic mode of either edge (2.29 for a free
/// plate, 3.20 clamped) and clear of the free plate's rigid-body root at 0.
const MIN_LAMBDA: f64 = 0.5;

/// No root of order `n` lies below `n / 2` (the lowest, free `(n, 0)`, sit near `n + 0.7`);
/// starting there keeps `J_n` far from underflow.
const LOWEST_ROOT_OVER_ORDER: f64 = 0.5;

/// First bound of the search in `lambda`, grown by half until enough modes are found.
const FIRST_LAMBDA_BOUND: f64 = 12.0;

/// Intervals of Simpson's rule for the mean square of a shape along the radius: the shapes
/// wiggle with period `2 pi / lambda`, at least 0.15 of the radius for 300 modes.
const NORM_STEPS: usize = 400;

/// A flat plate of uniform thickness with a circular outline, free or clamped at its rim.
/// Positions: `(x, y)` in fractions of the radius from the centre.
#[derive(Debug, Clone, PartialEq)]
pub struct CircularPlate {
    /// Radius in m.
    pub radius_m: f64,
    /// Thickness in m.
    pub thickness_m: f64,
    /// How the rim is held.
    pub edge: PlateEdge,
}

/// `[F(l), F'(l)]` of the two radial solutions at `l`, for order `n`: `J_n`, and `I_n` scaled by
/// `e^-l` (a common positive factor, which changes no root and no ratio).
fn radial_values(n: usize, l: f64) -> ([f64; 2], [f64; 2]) {
    let j = bessel_j_upto(n + 1, l);
    let i = bessel_i_scaled_upto(n + 1, l);
    let order = n as f64;
    // A&S 9.1.27 and 9.6.26: J_n' = (n / x) J_n - J_(n+1), I_n' = (n / x) I_n + I_(n+1).
    let j_prime = order / l * j[n] - j[n + 1];
    let i_prime = order / l * i[n] + i[n + 1];
    ([j[n], j_prime], [i[n], i_prime])
}

/// The two boundary conditions at the rim applied to each radial solution: `([J row], [I row])`,
/// each `[condition 1, condition 2]`. A root is where the 2x2 determinant vanishes.
fn edge_conditions(edge: PlateEdge, nu: f64, n: usize, l: f64) -> ([f64; 2], [f64; 2]) {
    let ([j, jp], [i, ip]) = radial_values(n, l);
    match edge {
        PlateEdge::Clamped => ([j, jp], [i, ip]),
        PlateEdge::Free => {
            let n2 = (n * n) as f64;
            let (l2, l3) = (l * l, l * l * l);
            // Bessel's equations give l^2 J'' = -l J' - (l^2 - n^2) J and
            // l^2 I'' = -l I' + (l^2 + n^2) I; with them, m_F and v_F of the module notes.
            let moment_j = -(l2 * j + (1.0 - nu) * (l * jp - n2 * j));
            let moment_i = l2 * i - (1.0 - nu) * (l * ip - n2 * i);
            let shear_j = -(l3 * jp + (1.0 - nu) * n2 * (l * jp - j));
            let shear_i = l3 * ip - (1.0 - nu) * n2 * (l * ip - i);
            ([moment_j, shear_j], [moment_i, shear_i])
        }
    }
}

/// The determinant of the edge conditions, divided by positive factors that keep it of order 1.
fn frequency_equation(edge: PlateEdge, nu: f64, n: usize, l: f64) -> f64 {
    let (a, b) = edge_conditions(edge, nu, n, l);
    let scale = a[0].hypot(a[1]) * b[0].hypot(b[1]);
    (a[0] * b[1] - a[1] * b[0]) / scale
}

/// The roots `lambda` of order `n` up to `max_lambda`, ascending.
pub fn plate_roots(edge: PlateEdge, nu: f64, n: usize, max_lambda: f64) -> Vec<f64> {
    let from = MIN_LAMBDA.max(LOWEST_ROOT_OVER_ORDER * n as f64);
    if from >= max_lambda {
        return Vec::new();
    }
    roots_by_scan(
        |l| frequency_equation(edge, nu, n, l),
        from,
        max_lambda,
        ROOT_SCAN_STEP,
    )
}

/// The radial shape `J_n(l r) + C I_n(l r)` of the mode with root `l`, not normalised.
fn radial_shape(edge: PlateEdge, nu: f64, n: usize, l: f64) -> impl Fn(f64) -> f64 {
    let (a, b) = edge_conditions(edge, nu, n, l);
    // C from both conditions at once, by least squares: at a root they agree, and this stays
    // well conditioned whichever of the two is near zero. C multiplies e^-l I_n.
    let c = -(a[0] * b[0] + a[1] * b[1]) / (b[0] * b[0] + b[1] * b[1]);
    move |r: f64| {
        let x = l * r;
        let j = bessel_j_upto(n, x)[n];
        // C multiplies e^-l I_n(l r) = [e^-(l r) I_n(l r)] e^(l r - l).
        let i = bessel_i_scaled_upto(n, x)[n] * (x - l).exp();
        j + c * i
    }
}

/// `int_0^1 f(r) r dr` by Simpson's rule.
fn radial_integral(f: impl Fn(f64) -> f64) -> f64 {
    let h = 1.0 / NORM_STEPS as f64;
    let sum: f64 = (0..=NORM_STEPS)
        .map(|k| {
            let weight = match k {
                0 => 1.0,
                k if k == NORM_STEPS => 1.0,
                k if k % 2 == 1 => 4.0,
                _ => 2.0,
            };
            let r = k as f64 * h;
            weight * f(r) * r
        })
        .sum();
    sum * h / 3.0
}

impl CircularPlate {
    /// `sqrt(D / (rho h))` in m^2/s, with `D = E h^3 / (12 (1 - nu^2))`.
    pub fn bending_constant_m2_per_s(&self, material: &Material) -> f64 {
        let h = self.thickness_m;
        let nu = material.poisson_ratio;
        let rigidity = material.youngs_modulus_pa * h.powi(3) / (12.0 * (1.0 - nu * nu));
        (rigidity / (material.density_kg_m3 * h)).sqrt()
    }

    /// Frequency in Hz of the mode with root `lambda`.
    pub fn freq_hz_of_root(&self, material: &Material, lambda: f64) -> f64 {
        lambda * lambda / (TAU * self.radius_m * self.radius_m)
            * self.bending_constant_m2_per_s(material)
    }

    /// `lambda` of the lowest mode: `(2, 0)` for a free plate, `(0, 0)` for a clamped one.
    pub fn lowest_root(&self, material: &Material) -> f64 {
        let nu = material.poisson_ratio;
        let order = match self.edge {
            PlateEdge::Free => 2,
            PlateEdge::Clamped => 0,
        };
        plate_roots(self.edge, nu, order, FIRST_LAMBDA_BOUND)[0]
    }

    /// Fundamental in Hz.
    pub fn fundamental_hz(&self, material: &Material) -> f64 {
        self.freq_hz_of_root(material, self.lowest_root(material))
    }

    /// The plate with its radius changed (thickness kept) so that the fundamental is `root_hz`
    /// (`f ~ 1 / a^2`).
    pub fn tuned_to(&self, material: &Material, root_hz: f64) -> Self {
        let scale = (self.fundamental_hz(material) / root_hz).sqrt();
        Self {
            radius_m: self.radius_m * scale,
            ..self.clone()
        }
    }

    /// The lowest modes within the limits, shapes (unit mean square over the plate) at `coords`.
    pub(super) fn shaped_modes(
        &self,
        material: &Material,
        coords: &[[f64; 2]],
        limits: &ModeLimits,
    ) -> Vec<ShapedMode> {
        let nu = material.poisson_ratio;
        let points = DiscPoints::new(coords);
        // lambda of the frequency limit. Every root below the current bound is found, so once
        // there are enough of them the lowest ones are the lowest of all.
        let lambda_limit = (limits.max_freq_hz * TAU * self.radius_m * self.radius_m
            / self.bending_constant_m2_per_s(material))
        .sqrt();
        let mut bound = FIRST_LAMBDA_BOUND.min(lambda_limit);
        let mut roots = loop {
            let mut roots: Vec<(usize, f64)> = Vec::new();
            let mut count = 0;
            for n in 0.. {
                if LOWEST_ROOT_OVER_ORDER * n as f64 >= bound {
                    break;
                }
                for l in plate_roots(self.edge, nu, n, bound) {
                    roots.push((n, l));
                    count += points.modes_per_root(n);
                }
            }
            if count >= limits.max_modes || bound >= lambda_limit {
                break roots;
            }
            bound = (bound * 1.5).min(lambda_limit);
        };
        // Only the lowest are kept (finish_modes truncates): skip shaping the rest.
        roots.sort_by(|a, b| a.1.total_cmp(&b.1));
        roots.truncate(limits.max_modes);

        let mut modes = Vec::new();
        for (n, l) in roots {
            let radial = radial_shape(self.edge, nu, n, l);
            let scale = unit_mean_square_scale(n, radial_integral(|r| radial(r).powi(2)));
            points.push_modes(&mut modes, self.freq_hz_of_root(material, l), n, |r| {
                scale * radial(r)
            });
        }
        modes
    }
}

impl Object for CircularPlate {
    fn display_kind(&self) -> &'static str {
        match self.edge {
            PlateEdge::Free => "free circular plate",
            PlateEdge::Clamped => "clamped circular plate",
        }
    }

    fn validate(&self) -> Result<(), ShapeError> {
        super::check_positive("radius_m", self.radius_m)?;
        super::check_positive("thickness_m", self.thickness_m)
    }

    fn check_proportions(&self) -> Result<(), ShapeError> {
        check_thin(
            "thickness_m",
            self.thickness_m,
            2.0 * self.radius_m,
            "diameter",
        )
    }

    fn root_hz(&self, material: &Material) -> f64 {
        self.fundamental_hz(material)
    }

    fn tuned(&self, material: &Material, root_hz: f64) -> Result<Shape, ShapeError> {
        Ok(self.tuned_to(material, root_hz).into())
    }

    fn modes_at(
        &self,
        material: &Material,
        positions: &[Position],
        limits: &ModeLimits,
    ) -> Result<Vec<ShapedMode>, ShapeError> {
        Ok(self.shaped_modes(material, &plane_coords(positions, true)?, limits))
    }

    fn default_positions(&self) -> Vec<Position> {
        vec![
            position("centre", &[0.0, 0.0]),
            position("third radius", &[0.33, 0.0]),
            position("two-thirds radius", &DISC_STRIKE),
            position("near rim", &[0.9, 0.0]),
        ]
    }

    fn typical_strike(&self) -> Vec<f64> {
        DISC_STRIKE.to_vec()
    }

    fn dimensions_m(&self) -> Vec<(&'static str, f64)> {
        vec![("radius", self.radius_m), ("thickness", self.thickness_m)]
    }

    fn parameters(&self, _material: &Material) -> Map<String, Value> {
        let mut map = Map::new();
        map.insert("edge".into(), json!(self.edge.name()));
        map
    }

    fn size(&self) -> String {
        format!(
            "{} mm radius, {} mm thick",
            mm(self.radius_m),
            mm(self.thickness_m)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(n, s, lambda^2)`: nodal diameters, nodal circles, tabulated value.
    type Table = [(usize, usize, f64)];

    /// Asserts the `(n, s)` roots against `table` within `rel_tol`.
    fn assert_table(edge: PlateEdge, nu: f64, table: &Table, rel_tol: f64) {
        for &(n, s, want) in table {
            // A free plate's (0, 0) and (1, 0) are rigid-body motions, which have no root.
            let index = if edge == PlateEdge::Free && n < 2 {
                s - 1
            } else {
                s
            };
            let roots = plate_roots(edge, nu, n, 12.0);
            let got = roots[index] * roots[index];
            assert!(
                (got / want - 1.0).abs() < rel_tol,
                "{edge:?} ({n}, {s}): lambda^2 {got:.4} vs {want} tabulated"
            );
        }
    }

    #[test]
    fn clamped_roots_match_leissa_table_2_1() {
        // Leissa, Vibration of Plates (NASA SP-160, 1969), table 2.1: exact to the figures
        // given, and independent of Poisson's ratio.
        let table = [
            (0, 0, 10.2158),
            (1, 0, 21.260),
            (2, 0, 34.877),
            (0, 1, 39.771),
            (3, 0, 51.030),
            (1, 1, 60.829),
            (4, 0, 69.666),
            (2, 1, 84.583),
            (0, 2, 89.104),
            (5, 0, 90.739),
        ];
        for nu in [0.2, 0.3, 0.45] {
            assert_table(PlateEdge::Clamped, nu, &table, 2e-5);
        }
    }

    #[test]
    fn free_roots_match_leissa_table_2_3() {
        // Leissa table 2.3, free edge, nu = 0.33. The table compiles early solutions to three or
        // four figures (some by approximate methods); the exact roots of the frequency equation
        // lie within 0.4% of them.
        let table = [
            (2, 0, 5.253),
            (0, 1, 9.084),
            (3, 0, 12.23),
            (1, 1, 20.52),
            (4, 0, 21.6),
            (5, 0, 33.1),
            (2, 1, 35.25),
            (0, 2, 38.55),
            (3, 1, 52.91),
            (1, 2, 59.86),
        ];
        assert_table(PlateEdge::Free, 0.33, &table, 4e-3);
        // Poisson's ratio moves the free plate's modes, most of all the edge modes (n, 0).
        let stiff_edge = plate_roots(PlateEdge::Free, 0.3, 2, 5.0)[0];
        let soft_edge = plate_roots(PlateEdge::Free, 0.33, 2, 5.0)[0];
        assert!(stiff_edge > soft_edge, "{stiff_edge} vs {soft_edge}");
    }

    /// `[R(1), R'(1), R''(1), R'''(1)]` of the radial shape by central differences.
    fn rim_derivatives(edge: PlateEdge, nu: f64, n: usize, l: f64) -> [f64; 4] {
        let radial = radial_shape(edge, nu, n, l);
        let h = 1e-3;
        let f = |k: f64| radial(1.0 + k * h);
        [
            f(0.0),
            (f(1.0) - f(-1.0)) / (2.0 * h),
            (f(1.0) - 2.0 * f(0.0) + f(-1.0)) / (h * h),
            (f(2.0) - 2.0 * f(1.0) + 2.0 * f(-1.0) - f(-2.0)) / (2.0 * h * h * h),
        ]
    }

    #[test]
    fn shapes_meet_their_edge_conditions() {
        let nu = 0.3;
        for n in [0, 1, 2, 5] {
            for &l in plate_roots(PlateEdge::Clamped, nu, n, 12.0).iter().take(3) {
                let [w, slope, curvature, _] = rim_derivatives(PlateEdge::Clamped, nu, n, l);
                let size = curvature.abs();
                assert!(w.abs() < 1e-9 * size, "clamped ({n}, {l}): W(a) = {w}");
                assert!(
                    slope.abs() < 1e-5 * size,
                    "clamped ({n}, {l}): W'(a) = {slope}"
                );
            }
            for &l in plate_roots(PlateEdge::Free, nu, n, 12.0).iter().take(3) {
                let [w, d1, d2, d3] = rim_derivatives(PlateEdge::Free, nu, n, l);
                let n2 = (n * n) as f64;
                // M_r ~ W'' + nu (W' - n^2 W) and, with the Laplacian's derivative written out,
                // V_r ~ W''' + W'' - (1 + (2 - nu) n^2) W' + (3 - nu) n^2 W, at r = a = 1.
                let moment = d2 + nu * (d1 - n2 * w);
                let shear = d3 + d2 - (1.0 + (2.0 - nu) * n2) * d1 + (3.0 - nu) * n2 * w;
                let size = d2.abs().max(w.abs() * l * l);
                assert!(
                    moment.abs() < 1e-4 * size,
                    "free ({n}, {l}): moment {moment} vs {size}"
                );
                assert!(
                    shear.abs() < 1e-3 * size * l,
                    "free ({n}, {l}): shear {shear} vs {}",
                    size * l
                );
            }
        }
    }

    #[test]
    fn shapes_of_one_order_are_orthogonal() {
        // Modes of the same order n are orthogonal over the disc (weight r).
        for edge in PlateEdge::ALL {
            for n in [0, 3] {
                let roots = plate_roots(edge, 0.3, n, 16.0);
                let a = radial_shape(edge, 0.3, n, roots[0]);
                let b = radial_shape(edge, 0.3, n, roots[1]);
                let cross = radial_integral(|r| a(r) * b(r));
                let norms =
                    (radial_integral(|r| a(r).powi(2)) * radial_integral(|r| b(r).powi(2))).sqrt();
                assert!(
                    cross.abs() < 1e-6 * norms,
                    "{edge:?} order {n}: cross {cross} vs {norms}"
                );
            }
        }
    }
}
