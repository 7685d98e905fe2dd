//! From a meshed solid's modes to a bank: strike points on the surface, and each mode's gain
//! at them.

use serde_json::{json, Map, Value};

use super::strike::StrikePoint;
use super::{MeshError, MeshModes, MeshSettings};
use crate::authoring::materials::AIR_DAMPING_PER_S;
use crate::authoring::shapes::{
    finish_modes, solid_contact_ms, ModeLimits, ShapeError, ShapedMode,
};
use crate::bank::{Bank, BankDefaults, Position};

/// Strike points are stored to the micrometre: this many steps per metre.
const COORD_STEPS_PER_M: f64 = 1e6;

/// The bank's root is the lowest mode its default strike (the first point) excites within
/// this many dB of the strike's strongest mode, as [`Bank::effective_root_hz`] judges a bank's
/// modes over all its positions.
const ROOT_WITHIN_DB: f64 = 6.0;

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
    bank.root_hz = Some(default_strike_root_hz(&bank));
    bank.source = Some(source_record(modes, settings, source));
    bank.defaults = Some(BankDefaults {
        hardness_ms: Some(solid_contact_ms(material.class)),
        ..BankDefaults::default()
    });
    Ok(bank)
}

/// The lowest mode the bank's first position excites within [`ROOT_WITHIN_DB`] of its
/// strongest there: the pitch its default strike sounds.
fn default_strike_root_hz(bank: &Bank) -> f64 {
    let at_first = |m: &crate::bank::Mode| m.gains.first().map_or(0.0, |g| g.abs());
    let strongest = bank.modes.iter().map(at_first).fold(0.0, f64::max);
    let floor = strongest * 10f64.powf(-ROOT_WITHIN_DB / 20.0);
    bank.modes
        .iter()
        .filter(|m| strongest > 0.0 && at_first(m) >= floor)
        .map(|m| m.freq_hz)
        .reduce(f64::min)
        .unwrap_or_else(|| bank.effective_root_hz())
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
