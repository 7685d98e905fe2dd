//! Strike points on the surface: asked for by place, or spread over it where the object's
//! lowest modes move most, so that the default strikes sound the object's pitch.
//!
//! Spreading by distance alone (the farthest points from the centre and from each other) lands
//! on ends, corners and edges: on a bar, its end faces and narrow sides, where the first bending
//! mode barely moves along the normal (14 to 41 dB down), and the bank then sounds a mode 18
//! semitones above the bar's fundamental. A strike excites a mode by the mode's motion along the
//! surface normal at the point (seed 000 eq. 3.11), so the points are chosen by that motion.

use super::surface::{cross, norm, sub, Surface};
use super::MeshModes;

/// Places on the surface considered when spreading strike points: enough to find each low
/// mode's largest motion within a few per cent of the object's size.
const CANDIDATES: usize = 4000;

/// The lowest modes the spread points are chosen to excite: the fundamental and the first
/// overtones, which set a struck object's pitch and colour.
const SPREAD_MODES: usize = 8;

/// The first point (the default strike) moves in the lowest mode at least this share of that
/// mode's largest normal motion over the surface (-1 dB).
const FIRST_WITHIN: f64 = 0.89;

/// Weight of a candidate's whole motion next to what it adds beyond the points already chosen:
/// once every low mode is excited somewhere, later points still go where the object moves.
const WHOLE_SHARE: f64 = 0.1;

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

/// The names of `count` spread strike points: `p1`, `p2`, ...
pub fn spread_names(count: usize) -> Vec<String> {
    (1..=count).map(|k| format!("p{k}")).collect()
}

/// `count` strike points spread over the surface of the solid whose `modes` these are, chosen
/// by each of the lowest modes' normal motion relative to its largest over the surface, the
/// k-th lowest weighing 1/k. The first (the default strike) is where the lowest mode moves
/// within 1 dB of its largest, and the most of the others with it; each next adds the most
/// motion beyond that of the points already chosen (a mode counts at the largest share any
/// chosen point gives it), plus a tenth of its whole motion, scaled down within
/// `diagonal / count` of a chosen point. Named `p1`, `p2`, ...
pub fn spread_strike_points(
    surface: &Surface,
    modes: &MeshModes,
    count: usize,
) -> Vec<StrikePoint> {
    let candidates = surface_samples(surface, CANDIDATES);
    let levels = relative_motion(modes, &candidates);
    let weighted = |c: usize| -> f64 {
        levels[c]
            .iter()
            .enumerate()
            .map(|(m, l)| l / (m + 1) as f64)
            .sum()
    };
    let first = (0..candidates.len())
        .filter(|&c| levels[c].first().is_some_and(|&l| l >= FIRST_WITHIN))
        .max_by(|&a, &b| weighted(a).total_cmp(&weighted(b)));
    let Some(first) = first else {
        return Vec::new();
    };
    let spacing = surface.diagonal_m() / count.max(1) as f64;
    let mut chosen = vec![first];
    let mut reached = levels[first].clone();
    let mut nearest_m: Vec<f64> = candidates
        .iter()
        .map(|(p, _)| norm(sub(*p, candidates[first].0)))
        .collect();
    while chosen.len() < count {
        let score = |c: usize| -> f64 {
            let added: f64 = levels[c]
                .iter()
                .zip(&reached)
                .enumerate()
                .map(|(m, (l, r))| (l - r).max(0.0) / (m + 1) as f64)
                .sum();
            (nearest_m[c] / spacing).min(1.0) * (added + WHOLE_SHARE * weighted(c))
        };
        let best = (0..candidates.len()).max_by(|&a, &b| score(a).total_cmp(&score(b)));
        let Some(best) = best.filter(|&b| score(b) > 0.0) else {
            break;
        };
        chosen.push(best);
        for (r, l) in reached.iter_mut().zip(&levels[best]) {
            *r = r.max(*l);
        }
        for (d, (p, _)) in nearest_m.iter_mut().zip(&candidates) {
            *d = d.min(norm(sub(*p, candidates[best].0)));
        }
    }
    chosen
        .iter()
        .zip(spread_names(chosen.len()))
        .map(|(&c, name)| StrikePoint {
            name,
            point_m: candidates[c].0,
            normal: candidates[c].1,
        })
        .collect()
}

/// Each candidate's normal motion in each of the lowest [`SPREAD_MODES`] modes, as a share of
/// that mode's largest over the candidates (0 to 1).
fn relative_motion(modes: &MeshModes, candidates: &[([f64; 3], [f64; 3])]) -> Vec<Vec<f64>> {
    let wanted = modes.freqs_hz.len().min(SPREAD_MODES);
    let mut levels: Vec<Vec<f64>> = candidates
        .iter()
        .map(|&(p, n)| {
            let mut motion = modes.displacement_along(p, n);
            motion.truncate(wanted);
            motion.iter().map(|x| x.abs()).collect()
        })
        .collect();
    for m in 0..wanted {
        let largest = levels.iter().map(|l| l[m]).fold(0.0, f64::max);
        if largest > 0.0 {
            for l in &mut levels {
                l[m] /= largest;
            }
        }
    }
    levels
}

/// About `target` places spread evenly over the surface, each with its triangle's outward unit
/// normal: the centres of the equal pieces a triangle larger than `area / target` is cut into
/// (n^2 of them, n along each edge), and among smaller triangles one centre per `area / target`
/// of them.
fn surface_samples(surface: &Surface, target: usize) -> Vec<([f64; 3], [f64; 3])> {
    let areas: Vec<f64> = (0..surface.triangles.len())
        .map(|t| {
            let [a, b, c] = surface.corners(t);
            0.5 * norm(cross(sub(b, a), sub(c, a)))
        })
        .collect();
    let piece = areas.iter().sum::<f64>() / target.max(1) as f64;
    let mut samples = Vec::new();
    let mut carried = 0.0;
    for (t, &area) in areas.iter().enumerate() {
        let [a, b, c] = surface.corners(t);
        let n = cross(sub(b, a), sub(c, a)).map(|x| x / (2.0 * area));
        let at = |u: f64, v: f64| [0, 1, 2].map(|k| a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]));
        let pieces = area / piece;
        if pieces < 1.0 {
            carried += pieces;
            if carried >= 1.0 {
                carried -= 1.0;
                samples.push((at(1.0 / 3.0, 1.0 / 3.0), n));
            }
            continue;
        }
        let cuts = pieces.sqrt().ceil() as usize;
        let step = 1.0 / cuts as f64;
        for i in 0..cuts {
            for j in 0..cuts - i {
                let (u, v) = (i as f64 * step, j as f64 * step);
                samples.push((at(u + step / 3.0, v + step / 3.0), n));
                if i + j + 1 < cuts {
                    samples.push((at(u + 2.0 * step / 3.0, v + 2.0 * step / 3.0), n));
                }
            }
        }
    }
    samples
}
