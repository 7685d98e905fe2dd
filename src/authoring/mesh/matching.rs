//! A meshed bank combined with a recording of the object struck at one of its points (seed 000
//! sections 6.2.2-6.2.3): the recording gives the modes' true frequencies, decays and levels at
//! that point, the mesh how each mode's level changes from point to point.
//!
//! The recording's modes (fitted by [`crate::authoring::fit`]) are paired with the mesh's: first a
//! common frequency scale (a mesh's material constants are rarely exact) from the strongest
//! modes, then each recorded mode, strongest first, with the unpaired mesh mode nearest it in
//! frequency among those the recorded point can excite, within a tolerance; pairs that cross in
//! frequency order are undone. A second pass pairs again around a ratio that drifts with
//! frequency, fitted to the first pass's pairs, and is kept if it pairs at least as many. A paired mode keeps the recording's frequency, decay and gain at
//! the recorded point, and the mesh's gain ratio to that point everywhere else. A recorded mode
//! left unpaired keeps its recorded gain at every point (the "minimum impulse response" of seed
//! 000 section 6.2.3). A mesh mode silent at the recorded point, which the recording could not
//! have heard, is kept at the mesh's frequency times the scale, at the level the pairs set.

use crate::authoring::fit::{fit_bank_with_progress, FitError, FitOptions, Recording};
use crate::bank::{Bank, Mode};

/// Most a paired recorded mode may lie from its mesh mode, after the common scale, as a ratio.
const PAIR_TOLERANCE: f64 = 0.03;

/// A mesh mode is excited at a point when its gain there is within this many dB of its largest.
const EXCITED_DB: f64 = -30.0;

/// A mesh mode whose gains all lie below this (-120 dB of a meshed bank's largest gain, which
/// is 1) is silent at the bank's points: a bar's twisting modes on its centre line, where the
/// solver's rounding leaves gains of 1e-9 whose relative sizes mean nothing.
const SILENT_GAIN: f64 = 1e-6;

/// A pair whose log frequency ratio lies farther than this from the fitted line is a chance
/// pairing (about 1 %).
const LINE_OUTLIER: f64 = 0.01;

/// The recorded modes whose frequency ratios to mesh modes propose a scale: the strongest few.
const SCALE_PROPOSERS: usize = 6;

/// The common scale lies within these bounds.
const SCALE_RANGE: (f64, f64) = (0.5, 2.0);

/// What the combination did.
#[derive(Debug, Clone, PartialEq)]
pub struct MatchReport {
    /// The recording's frequencies over the mesh's at the mesh's lowest mode.
    pub frequency_scale: f64,
    /// How that ratio's logarithm changes per octave (0 when it is one constant).
    pub scale_per_octave: f64,
    /// Recorded modes paired with mesh modes.
    pub paired: usize,
    /// Recorded modes left unpaired (recorded gain at every point).
    pub unpaired_recorded: usize,
    /// Mesh modes kept because the recorded point cannot excite them.
    pub kept_from_mesh: usize,
    /// Mesh modes the recorded point excites that the recording lacks, left out.
    pub dropped_from_mesh: usize,
}

/// Largest absolute gain of a mode over its positions.
fn largest(mode: &Mode) -> f64 {
    mode.gains.iter().fold(0.0f64, |a, g| a.max(g.abs()))
}

/// Whether mesh mode `mode` is excited at position `at`: not when it is silent at every point
/// (its gains, at most [`SILENT_GAIN`] of the bank's largest, are rounding, not motion).
fn excited(mode: &Mode, at: usize) -> bool {
    mode.gains[at].abs() >= largest(mode) * 10f64.powf(EXCITED_DB / 20.0)
        && largest(mode) > SILENT_GAIN
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

/// The recorded-to-mesh frequency ratio as a function of the mesh mode's frequency: a straight
/// line in logarithms, `ln s = intercept + slope ln f` (a constant first; then fitted to the
/// pairs, since a mesh's error grows with frequency: a voxel grid's stiffness, a missing
/// detail).
#[derive(Debug, Clone, Copy, PartialEq)]
struct ScaleLine {
    /// `ln s` at 1 Hz.
    intercept: f64,
    /// Change of `ln s` per unit of `ln f`.
    slope: f64,
}

impl ScaleLine {
    /// The same ratio at every frequency.
    fn constant(scale: f64) -> Self {
        Self {
            intercept: scale.ln(),
            slope: 0.0,
        }
    }

    /// The ratio for a mesh mode at `freq_hz`.
    fn scale(self, freq_hz: f64) -> f64 {
        (self.intercept + self.slope * freq_hz.ln()).exp()
    }

    /// The least-squares line through the pairs' log ratios, the pair farthest from it dropped
    /// and the line fitted again while that pair is more than [`LINE_OUTLIER`] off (a chance
    /// pairing within the first pass's wide tolerance); `None` for fewer than three pairs.
    fn fit(mesh: &Bank, recorded: &[Mode], pairs: &[(usize, usize)]) -> Option<Self> {
        let mut points: Vec<(f64, f64)> = pairs
            .iter()
            .map(|&(k, j)| {
                let f = mesh.modes[j].freq_hz;
                (f.ln(), (recorded[k].freq_hz / f).ln())
            })
            .collect();
        loop {
            let line = Self::least_squares(&points)?;
            let residual = |&(x, y): &(f64, f64)| (y - line.intercept - line.slope * x).abs();
            let worst = (0..points.len())
                .max_by(|&a, &b| residual(&points[a]).total_cmp(&residual(&points[b])))?;
            if residual(&points[worst]) <= LINE_OUTLIER || points.len() <= 3 {
                return Some(line);
            }
            points.remove(worst);
        }
    }

    /// The least-squares line through `(ln f, ln s)` points; `None` for fewer than three.
    fn least_squares(points: &[(f64, f64)]) -> Option<Self> {
        if points.len() < 3 {
            return None;
        }
        let n = points.len() as f64;
        let (mx, my) = points
            .iter()
            .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
        let sxx: f64 = points.iter().map(|(x, _)| (x - mx).powi(2)).sum();
        let sxy: f64 = points.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
        let slope = if sxx > 0.0 { sxy / sxx } else { 0.0 };
        Some(Self {
            intercept: my - slope * mx,
            slope,
        })
    }
}

/// Pairs `(recorded index, mesh index)`: strongest recorded first, nearest excited mesh mode
/// within the tolerance of the ratio `line` predicts, then pairs out of frequency order undone
/// (the weaker of two).
fn pairs(mesh: &Bank, recorded: &[Mode], at: usize, line: ScaleLine) -> Vec<(usize, usize)> {
    let mut order: Vec<usize> = (0..recorded.len()).collect();
    order.sort_by(|&a, &b| largest(&recorded[b]).total_cmp(&largest(&recorded[a])));
    let mut taken = vec![false; mesh.modes.len()];
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    for k in order {
        let f = recorded[k].freq_hz;
        let nearest = (0..mesh.modes.len())
            .filter(|&j| !taken[j] && excited(&mesh.modes[j], at))
            .map(|j| {
                let mesh_hz = mesh.modes[j].freq_hz;
                (j, (f / (line.scale(mesh_hz) * mesh_hz)).ln().abs())
            })
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

/// `bank` matched to `recording` of the object struck at the bank's position `at`: the
/// recording fitted ([`fit_bank_with_progress`], reporting its progress from 0 to 1), its modes
/// combined with the bank's ([`combine_with_recording`]), and what was done written into the
/// bank: `source.matched_recording` (the recording's file name `file_name`, the position and the
/// [`MatchReport`]) and a sentence of the description.
pub fn match_recording(
    bank: &Bank,
    recording: &Recording,
    at: usize,
    file_name: &str,
    progress: impl FnMut(f64),
) -> Result<(Bank, MatchReport), FitError> {
    let options = FitOptions {
        name: bank.name.clone(),
        ..FitOptions::default()
    };
    let fitted = fit_bank_with_progress(std::slice::from_ref(recording), &options, progress)?.bank;
    let (mut combined, report) = combine_with_recording(bank, &fitted.modes, at);
    let name = &bank.positions[at].name;
    if let Some(source) = combined.source.as_mut() {
        source.insert(
            "matched_recording".into(),
            serde_json::json!({
                "file": file_name,
                "position": name,
                "frequency_scale": report.frequency_scale,
                "scale_change_per_octave": report.scale_per_octave,
                "paired_modes": report.paired,
                "unpaired_recorded_modes": report.unpaired_recorded,
                "mesh_modes_kept": report.kept_from_mesh,
                "mesh_modes_dropped": report.dropped_from_mesh,
            }),
        );
    }
    combined.description = format!(
        "{} Matched to a recording struck at \"{name}\": {} modes paired (mesh frequencies x \
         {:.4} at the lowest), {} recorded modes unpaired, {} mesh modes the recording could not \
         hear kept, {} it should have heard left out.",
        combined.description,
        report.paired,
        report.frequency_scale,
        report.unpaired_recorded,
        report.kept_from_mesh,
        report.dropped_from_mesh
    );
    Ok((combined, report))
}

/// `mesh` combined with `recorded`, modes fitted from a recording of the object struck at the
/// mesh bank's position `at` (each with one gain). The positions are the mesh bank's.
pub fn combine_with_recording(mesh: &Bank, recorded: &[Mode], at: usize) -> (Bank, MatchReport) {
    let (line, pairs) = best_pairs(mesh, recorded, at);
    let (mut modes, levels) = paired_modes(mesh, recorded, at, &pairs);
    let paired_recorded: Vec<usize> = pairs.iter().map(|&(k, _)| k).collect();
    let unpaired: Vec<&Mode> = (0..recorded.len())
        .filter(|k| !paired_recorded.contains(k))
        .map(|k| &recorded[k])
        .collect();
    let positions = mesh.positions.len();
    for r in &unpaired {
        modes.push(Mode {
            freq_hz: r.freq_hz,
            decay_per_s: r.decay_per_s,
            gains: vec![r.gains[0]; positions],
        });
    }
    let (unheard, dropped) = unheard_mesh_modes(mesh, at, &pairs, line, levels);
    let kept = unheard.len();
    modes.extend(unheard);
    modes.sort_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
    let mut bank = mesh.clone();
    bank.modes = modes;
    bank.root_hz = None;
    bank.root_hz = Some(bank.effective_root_hz());
    let lowest_hz = mesh
        .modes
        .iter()
        .map(|m| m.freq_hz)
        .fold(f64::INFINITY, f64::min);
    let report = MatchReport {
        frequency_scale: line.scale(lowest_hz),
        scale_per_octave: line.slope * std::f64::consts::LN_2,
        paired: pairs.len(),
        unpaired_recorded: unpaired.len(),
        kept_from_mesh: kept,
        dropped_from_mesh: dropped,
    };
    (bank, report)
}

/// The pairs (recorded mode, mesh mode) of the better of two passes, with the frequency ratio
/// they were paired around: one constant scale, then a ratio drifting with frequency fitted to
/// the first pass's pairs, kept if it pairs at least as many.
fn best_pairs(mesh: &Bank, recorded: &[Mode], at: usize) -> (ScaleLine, Vec<(usize, usize)>) {
    let constant = ScaleLine::constant(frequency_scale(mesh, recorded, at));
    let first = pairs(mesh, recorded, at, constant);
    if let Some(line) = ScaleLine::fit(mesh, recorded, &first) {
        let second = pairs(mesh, recorded, at, line);
        if second.len() >= first.len() {
            return (line, second);
        }
    }
    (constant, first)
}

/// The paired modes: the recording's frequency, decay and gain at the recorded point `at`, the
/// mesh's gain ratio to that point elsewhere; and for each pair the recorded level over the
/// mesh's at the point.
fn paired_modes(
    mesh: &Bank,
    recorded: &[Mode],
    at: usize,
    pairs: &[(usize, usize)],
) -> (Vec<Mode>, Vec<f64>) {
    let floor = 10f64.powf(EXCITED_DB / 20.0);
    let mut modes = Vec::with_capacity(pairs.len());
    let mut levels = Vec::with_capacity(pairs.len());
    for &(k, j) in pairs {
        let (r, m) = (&recorded[k], &mesh.modes[j]);
        let at_point = m.gains[at];
        // Never divide by less than the excitation floor: a point near a node of the mode.
        let reference = at_point.signum() * at_point.abs().max(floor * largest(m));
        let gains = (0..mesh.positions.len())
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
    (modes, levels)
}

/// The unpaired mesh modes the recorded point `at` cannot excite, which the recording could not
/// have heard: kept at the mesh's frequency times the scale `line`, at the median of the pairs'
/// `levels`. Also how many unpaired mesh modes the point does excite, left out (the recording
/// should hold them, and does not).
fn unheard_mesh_modes(
    mesh: &Bank,
    at: usize,
    pairs: &[(usize, usize)],
    line: ScaleLine,
    mut levels: Vec<f64>,
) -> (Vec<Mode>, usize) {
    levels.sort_by(f64::total_cmp);
    let level = levels.get(levels.len() / 2).copied().unwrap_or(0.0);
    let paired_mesh: Vec<usize> = pairs.iter().map(|&(_, j)| j).collect();
    let mut kept = Vec::new();
    let mut dropped = 0;
    for (j, m) in mesh.modes.iter().enumerate() {
        if paired_mesh.contains(&j) {
            continue;
        }
        if excited(m, at) || level == 0.0 {
            dropped += 1;
            continue;
        }
        let s = line.scale(m.freq_hz);
        kept.push(Mode {
            freq_hz: m.freq_hz * s,
            decay_per_s: m.decay_per_s * s,
            gains: m.gains.iter().map(|g| g * level).collect(),
        });
    }
    (kept, dropped)
}
