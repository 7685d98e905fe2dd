//! A meshed bank combined with a recording of the object struck at one of its points (seed 000
//! sections 6.2.2-6.2.3): the recording gives the modes' true frequencies, decays and levels at
//! that point, the mesh how each mode's level changes from point to point.
//!
//! The recording's modes (fitted by [`crate::model::fit`]) are paired with the mesh's: first a
//! common frequency scale (a mesh's material constants are rarely exact) from the strongest
//! modes, then each recorded mode, strongest first, with the unpaired mesh mode nearest it in
//! frequency among those the recorded point can excite, within a tolerance; pairs that cross in
//! frequency order are undone. A paired mode keeps the recording's frequency, decay and gain at
//! the recorded point, and the mesh's gain ratio to that point everywhere else. A recorded mode
//! left unpaired keeps its recorded gain at every point (the "minimum impulse response" of seed
//! 000 section 6.2.3). A mesh mode silent at the recorded point, which the recording could not
//! have heard, is kept at the mesh's frequency times the scale, at the level the pairs set.

use crate::model::{Bank, Mode};

/// Most a paired recorded mode may lie from its mesh mode, after the common scale, as a ratio.
const PAIR_TOLERANCE: f64 = 0.03;

/// A mesh mode is excited at a point when its gain there is within this many dB of its largest.
const EXCITED_DB: f64 = -30.0;

/// The recorded modes whose frequency ratios to mesh modes propose a scale: the strongest few.
const SCALE_PROPOSERS: usize = 6;

/// The common scale lies within these bounds.
const SCALE_RANGE: (f64, f64) = (0.5, 2.0);

/// What the combination did.
#[derive(Debug, Clone, PartialEq)]
pub struct MatchReport {
    /// The recording's frequencies over the mesh's, for the pairs.
    pub frequency_scale: f64,
    /// Recorded modes paired with mesh modes.
    pub paired: usize,
    /// Recorded modes left unpaired (recorded gain at every point).
    pub unpaired_recorded: usize,
    /// Mesh modes kept because the recorded point cannot excite them.
    pub kept_from_mesh: usize,
}

/// Largest absolute gain of a mode over its positions.
fn largest(mode: &Mode) -> f64 {
    mode.gains.iter().fold(0.0f64, |a, g| a.max(g.abs()))
}

/// Whether mesh mode `mode` is excited at position `at`.
fn excited(mode: &Mode, at: usize) -> bool {
    mode.gains[at].abs() >= largest(mode) * 10f64.powf(EXCITED_DB / 20.0) && largest(mode) > 0.0
}

/// The scale `recorded / mesh` under which the most recorded strength finds a mesh mode.
fn frequency_scale(mesh: &Bank, recorded: &[Mode], at: usize) -> f64 {
    let mut strongest: Vec<&Mode> = recorded.iter().collect();
    strongest.sort_by(|a, b| largest(b).total_cmp(&largest(a)));
    let audible: Vec<f64> = mesh
        .modes
        .iter()
        .filter(|m| excited(m, at))
        .map(|m| m.freq_hz)
        .collect();
    let score = |scale: f64| -> f64 {
        recorded
            .iter()
            .filter(|r| {
                audible
                    .iter()
                    .any(|f| (r.freq_hz / (scale * f)).ln().abs() < PAIR_TOLERANCE.ln_1p())
            })
            .map(largest)
            .sum()
    };
    let mut best: (f64, f64) = (score(1.0), 1.0);
    for r in strongest.iter().take(SCALE_PROPOSERS) {
        for f in &audible {
            let scale = r.freq_hz / f;
            if !(SCALE_RANGE.0..=SCALE_RANGE.1).contains(&scale) {
                continue;
            }
            let s = score(scale);
            let closer = (s - best.0).abs() < 1e-12 && scale.ln().abs() < best.1.ln().abs();
            if s > best.0 + 1e-12 || closer {
                best = (s, scale);
            }
        }
    }
    best.1
}

/// Pairs `(recorded index, mesh index)`: strongest recorded first, nearest excited mesh mode
/// within the tolerance, then pairs out of frequency order undone (the weaker of two).
fn pairs(mesh: &Bank, recorded: &[Mode], at: usize, scale: f64) -> Vec<(usize, usize)> {
    let mut order: Vec<usize> = (0..recorded.len()).collect();
    order.sort_by(|&a, &b| largest(&recorded[b]).total_cmp(&largest(&recorded[a])));
    let mut taken = vec![false; mesh.modes.len()];
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for k in order {
        let f = recorded[k].freq_hz;
        let nearest = (0..mesh.modes.len())
            .filter(|&j| !taken[j] && excited(&mesh.modes[j], at))
            .map(|j| (j, (f / (scale * mesh.modes[j].freq_hz)).ln().abs()))
            .filter(|&(_, d)| d < PAIR_TOLERANCE.ln_1p())
            .min_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((j, _)) = nearest {
            // Undo the pairing if it crosses a stronger one in frequency order.
            let crosses = pairs.iter().any(|&(k2, j2)| {
                (recorded[k2].freq_hz < f) != (mesh.modes[j2].freq_hz < mesh.modes[j].freq_hz)
            });
            if !crosses {
                taken[j] = true;
                pairs.push((k, j));
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

/// `mesh` combined with `recorded`, modes fitted from a recording of the object struck at the
/// mesh bank's position `at` (each with one gain). The positions are the mesh bank's.
pub fn combine_with_recording(mesh: &Bank, recorded: &[Mode], at: usize) -> (Bank, MatchReport) {
    let positions = mesh.positions.len();
    let scale = frequency_scale(mesh, recorded, at);
    let pairs = pairs(mesh, recorded, at, scale);
    let floor = 10f64.powf(EXCITED_DB / 20.0);
    let mut modes = Vec::new();
    let mut levels = Vec::new();
    for &(k, j) in &pairs {
        let (r, m) = (&recorded[k], &mesh.modes[j]);
        let at_point = m.gains[at];
        // Never divide by less than the excitation floor: a point near a node of the mode.
        let reference = at_point.signum() * at_point.abs().max(floor * largest(m));
        let gains = (0..positions)
            .map(|p| {
                if p == at {
                    r.gains[0]
                } else {
                    r.gains[0] * m.gains[p] / reference
                }
            })
            .collect();
        levels.push(r.gains[0].abs() / at_point.abs());
        modes.push(Mode {
            freq_hz: r.freq_hz,
            decay_per_s: r.decay_per_s,
            gains,
        });
    }
    let paired_recorded: Vec<usize> = pairs.iter().map(|&(k, _)| k).collect();
    let unpaired: Vec<&Mode> = (0..recorded.len())
        .filter(|k| !paired_recorded.contains(k))
        .map(|k| &recorded[k])
        .collect();
    for r in &unpaired {
        modes.push(Mode {
            freq_hz: r.freq_hz,
            decay_per_s: r.decay_per_s,
            gains: vec![r.gains[0]; positions],
        });
    }
    levels.sort_by(f64::total_cmp);
    let level = levels.get(levels.len() / 2).copied().unwrap_or(0.0);
    let mut kept = 0;
    let paired_mesh: Vec<usize> = pairs.iter().map(|&(_, j)| j).collect();
    for (j, m) in mesh.modes.iter().enumerate() {
        if paired_mesh.contains(&j) || excited(m, at) || level == 0.0 {
            continue;
        }
        kept += 1;
        modes.push(Mode {
            freq_hz: m.freq_hz * scale,
            decay_per_s: m.decay_per_s * scale,
            gains: m.gains.iter().map(|g| g * level).collect(),
        });
    }
    modes.sort_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
    let mut bank = mesh.clone();
    bank.modes = modes;
    bank.root_hz = None;
    bank.root_hz = Some(bank.effective_root_hz());
    let report = MatchReport {
        frequency_scale: scale,
        paired: pairs.len(),
        unpaired_recorded: unpaired.len(),
        kept_from_mesh: kept,
    };
    (bank, report)
}
