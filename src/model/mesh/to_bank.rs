//! From a meshed solid's modes to a bank: strike points on the surface, and each mode's gain
//! at them.

use serde_json::{json, Map, Value};

use super::surface::{norm, sub, Surface};
use super::{MeshError, MeshModes, MeshSettings};
use crate::model::materials::AIR_DAMPING_PER_S;
use crate::model::shapes::{finish_modes, solid_contact_ms, ModeLimits, ShapeError, ShapedMode};
use crate::model::{Bank, BankDefaults, Position};

/// Strike points are stored to the micrometre: this many steps per metre.
const COORD_STEPS_PER_M: f64 = 1e6;

/// At most this many points are candidates when spreading strike points over a surface.
const MAX_CANDIDATES: usize = 20_000;

/// A strike point as asked for: a name and a place near the surface, in metres.
#[derive(Debug, Clone, PartialEq)]
pub struct StrikeRequest {
    /// Display name, e.g. "rim".
    pub name: String,
    /// Where, in metres (moved onto the nearest point of the surface).
    pub point_m: [f64; 3],
}

/// A strike point on the surface.
#[derive(Debug, Clone, PartialEq)]
pub struct StrikePoint {
    /// Display name.
    pub name: String,
    /// The point of the surface, in metres.
    pub point_m: [f64; 3],
    /// The surface's outward unit normal there: the direction of the strike's impulse.
    pub normal: [f64; 3],
}

/// `requests` moved onto the surface.
pub fn strike_points(surface: &Surface, requests: &[StrikeRequest]) -> Vec<StrikePoint> {
    requests
        .iter()
        .map(|r| {
            let (point_m, normal) = surface.nearest(r.point_m);
            StrikePoint {
                name: r.name.clone(),
                point_m,
                normal,
            }
        })
        .collect()
}

/// `count` strike points spread over the surface: the first the farthest from its centre (a
/// rim, a tip, an end: where objects are usually struck), each next the farthest from those
/// already chosen. Named `p1`, `p2`, ...
pub fn spread_strike_points(surface: &Surface, count: usize) -> Vec<StrikePoint> {
    let stride = surface.triangles.len().div_ceil(MAX_CANDIDATES).max(1);
    let candidates: Vec<[f64; 3]> = (0..surface.triangles.len())
        .step_by(stride)
        .map(|t| {
            let [a, b, c] = surface.corners(t);
            [0, 1, 2].map(|k| (a[k] + b[k] + c[k]) / 3.0)
        })
        .collect();
    let (lo, hi) = surface.bounds();
    let centre = [0, 1, 2].map(|k| 0.5 * (lo[k] + hi[k]));
    let mut nearest_chosen: Vec<f64> = candidates.iter().map(|&p| norm(sub(p, centre))).collect();
    let mut requests = Vec::new();
    for k in 0..count.min(candidates.len()) {
        let (best, _) =
            nearest_chosen
                .iter()
                .enumerate()
                .fold((0, f64::NEG_INFINITY), |(bi, bd), (i, &d)| {
                    if d > bd {
                        (i, d)
                    } else {
                        (bi, bd)
                    }
                });
        let chosen = candidates[best];
        requests.push(StrikeRequest {
            name: format!("p{}", k + 1),
            point_m: chosen,
        });
        let first = k == 0;
        for (d, &p) in nearest_chosen.iter_mut().zip(&candidates) {
            let to_chosen = norm(sub(p, chosen));
            *d = if first { to_chosen } else { d.min(to_chosen) };
        }
    }
    strike_points(surface, &requests)
}

/// What a meshed bank records of how it was made.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshSource {
    /// The mesh file's name, without its folder.
    pub file_name: String,
    /// SHA-256 of the mesh file's bytes, in hex.
    pub sha256: String,
    /// Factor that took the file's units to metres.
    pub scale: f64,
}

/// A bank of `modes`, struck at `points` (the first is the default strike), in the order of the
/// points.
pub fn bank_from_modes(
    name: &str,
    modes: &MeshModes,
    settings: &MeshSettings,
    points: &[StrikePoint],
    limits: &ModeLimits,
    source: &MeshSource,
) -> Result<Bank, MeshError> {
    if points.is_empty() {
        return Err(MeshError::BadSetting {
            name: "positions",
            reason: "expected at least one strike point".to_string(),
        });
    }
    let along: Vec<Vec<f64>> = points
        .iter()
        .map(|p| modes.displacement_along(p.point_m, p.normal))
        .collect();
    let shaped = modes
        .freqs_hz
        .iter()
        .enumerate()
        .map(|(m, &freq_hz)| ShapedMode {
            freq_hz,
            shape: along.iter().map(|a| a[m]).collect(),
        })
        .collect();
    let material = &settings.material;
    let bank_modes = finish_modes(shaped, material, limits).map_err(|e| match e {
        ShapeError::NoModes { max_freq_hz } => MeshError::NoModes {
            max_freq_hz,
            lowest_hz: modes.freqs_hz[0],
            size_m: modes.longest_side_m(),
        },
        ShapeError::BelowFloor { lowest_hz, .. } => MeshError::BelowFloor {
            lowest_hz,
            size_m: modes.longest_side_m(),
        },
        other => MeshError::BadSetting {
            name: "mesh",
            reason: other.to_string(),
        },
    })?;
    let positions = points
        .iter()
        .map(|p| Position {
            name: p.name.clone(),
            coords: p
                .point_m
                // Divided, not multiplied by 1e-6, so 0.084 stays 0.084.
                .map(|x| (x * COORD_STEPS_PER_M).round() / COORD_STEPS_PER_M)
                .to_vec(),
        })
        .collect();
    let mut bank = Bank::new(name, positions);
    bank.description = format!(
        "{} object from the mesh {}: {} modes by finite elements.",
        material.display_name,
        source.file_name,
        bank_modes.len()
    );
    bank.author = "Modal Resonator".to_string();
    bank.license = "CC0-1.0".to_string();
    bank.modes = bank_modes;
    bank.root_hz = Some(bank.effective_root_hz());
    bank.source = Some(source_record(modes, settings, source));
    bank.defaults = Some(BankDefaults {
        hardness_ms: Some(solid_contact_ms(material.class)),
        ..BankDefaults::default()
    });
    Ok(bank)
}

/// The bank's `source`: the mesh, the material, the solver and the element counts.
fn source_record(
    modes: &MeshModes,
    settings: &MeshSettings,
    source: &MeshSource,
) -> Map<String, Value> {
    let material = &settings.material;
    let stats = &modes.stats;
    let mut record = Map::new();
    record.insert("kind".into(), json!("mesh"));
    record.insert("mesh".into(), json!(source.file_name));
    record.insert("mesh_sha256".into(), json!(source.sha256));
    record.insert("scale".into(), json!(source.scale));
    record.insert("material".into(), json!(material.name));
    record.insert("density_kg_m3".into(), json!(material.density_kg_m3));
    record.insert(
        "youngs_modulus_pa".into(),
        json!(material.youngs_modulus_pa),
    );
    record.insert("poisson_ratio".into(), json!(material.poisson_ratio));
    record.insert("loss_factor".into(), json!(material.loss_factor));
    record.insert("air_damping_per_s".into(), json!(AIR_DAMPING_PER_S));
    record.insert(
        "solver".into(),
        json!("voxel bricks with incompatible modes, shift-invert Lanczos on sparse Cholesky"),
    );
    record.insert("elements".into(), json!(stats.elements));
    record.insert(
        "voxel_mm".into(),
        json!(modes.voxels.size_m.map(|s| (s * 1e7).round() / 1e4)),
    );
    record.insert("degrees_of_freedom".into(), json!(stats.dofs));
    record.insert("modes_sought".into(), json!(settings.modes));
    record.insert(
        "clamped".into(),
        json!(settings
            .clamps
            .iter()
            .map(|c| format!("{c:?}"))
            .collect::<Vec<_>>()),
    );
    record.insert("rigid_modes".into(), json!(stats.rigid_modes));
    record
}
