//! Strike positions: making them, and checking their coordinates before a shape reads them.

use super::ShapeError;
use crate::bank::Position;

/// A position called `name` at `coords`.
pub(super) fn position(name: &str, coords: &[f64]) -> Position {
    Position {
        name: name.to_string(),
        coords: coords.to_vec(),
    }
}

/// Where a rectangle (a plate, a frame drum) is usually struck: off-centre, away from the
/// nodal lines of the low modes.
pub(super) const RECTANGLE_STRIKE: [f64; 2] = [0.38, 0.42];

/// Positions on a rectangle, from its centre out to a corner.
pub(super) fn rectangle_positions() -> Vec<Position> {
    vec![
        position("centre", &[0.5, 0.5]),
        position("off-centre", &RECTANGLE_STRIKE),
        position("near edge", &[0.5, 0.1]),
        position("near corner", &[0.1, 0.12]),
    ]
}

/// The error for `position`, number `index` in its list.
fn bad_position(index: usize, position: &Position, reason: String) -> ShapeError {
    ShapeError::BadPosition {
        index,
        name: position.name.clone(),
        reason,
    }
}

/// The single coordinate of each position, each within [0, 1].
pub(super) fn line_coords(positions: &[Position]) -> Result<Vec<f64>, ShapeError> {
    positions
        .iter()
        .enumerate()
        .map(|(index, p)| match p.coords[..] {
            [x] if (0.0..=1.0).contains(&x) => Ok(x),
            _ => Err(bad_position(
                index,
                p,
                format!("expected one coordinate in [0, 1], got {:?}", p.coords),
            )),
        })
        .collect()
}

/// The two coordinates of each position: within the unit disc if `disc`, else the unit square.
pub(super) fn plane_coords(
    positions: &[Position],
    disc: bool,
) -> Result<Vec<[f64; 2]>, ShapeError> {
    positions
        .iter()
        .enumerate()
        .map(|(index, p)| {
            let inside = |x: f64, y: f64| {
                if disc {
                    x.hypot(y) <= 1.0
                } else {
                    (0.0..=1.0).contains(&x) && (0.0..=1.0).contains(&y)
                }
            };
            match p.coords[..] {
                [x, y] if inside(x, y) => Ok([x, y]),
                _ => Err(bad_position(
                    index,
                    p,
                    format!(
                        "expected two coordinates {}, got {:?}",
                        if disc {
                            "(x, y) within the unit disc"
                        } else {
                            "in [0, 1]"
                        },
                        p.coords
                    ),
                )),
            }
        })
        .collect()
}
