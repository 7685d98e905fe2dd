//! Where the strike pad writes the names of the bank's positions: near each mark, and never over
//! another name, a mark, or the pad's edge, whatever the pad's size.

use egui::{pos2, Pos2, Rect, Vec2};

/// Gap between a position's mark and its name, in points.
const GAP: f32 = 6.0;
/// Half the side of the square a position's mark takes, in points.
pub const MARK_RADIUS: f32 = 4.0;
/// Rows of names on each side of a line (below and above), and on a plane above and below a
/// mark: with two each side, four names on a line always find a row.
const ROWS: usize = 2;
/// Space between two rows of names, in points, so they never touch.
const ROW_SPACING: f32 = 1.0;

/// Room a line needs above and below itself for its rows of names `row_height` high, in
/// points.
pub fn line_room(row_height: f32) -> f32 {
    GAP + ROWS as f32 * (row_height + ROW_SPACING)
}

/// Where each name goes: `sizes[k]` is the size of the name of the position marked at `marks[k]`.
/// Each name takes the first place, in order, that stays inside `bounds` and touches no name
/// placed before it and no mark: below its mark, above it, beside it (on a plane), then a row
/// further out below and above. A name with no room left is `None` (the pad names that position
/// when the pointer is over it).
pub fn place(marks: &[Pos2], sizes: &[Vec2], bounds: Rect, plane: bool) -> Vec<Option<Rect>> {
    let mark_rects: Vec<Rect> = marks
        .iter()
        .map(|&p| Rect::from_center_size(p, Vec2::splat(2.0 * MARK_RADIUS)))
        .collect();
    let mut placed: Vec<Rect> = Vec::with_capacity(marks.len());
    marks
        .iter()
        .zip(sizes)
        .map(|(&mark, &size)| {
            let free = |r: &Rect| {
                bounds.contains_rect(*r)
                    && !placed.iter().chain(&mark_rects).any(|o| o.intersects(*r))
            };
            let spot = candidates(mark, size, bounds, plane).find(free);
            placed.extend(spot);
            spot
        })
        .collect()
}

/// The places to try for a name of `size` at `mark`, in order of preference, each moved
/// sideways to lie within `bounds` where it can.
fn candidates(mark: Pos2, size: Vec2, bounds: Rect, plane: bool) -> impl Iterator<Item = Rect> {
    let centred = move |top: f32| {
        // Not `clamp`: a name wider than the bounds has no valid range (and is then refused).
        let left = (mark.x - size.x / 2.0)
            .min(bounds.right() - size.x)
            .max(bounds.left());
        Rect::from_min_size(pos2(left, top), size)
    };
    let row = move |i: usize, below: bool| {
        let offset = GAP + i as f32 * (size.y + ROW_SPACING);
        if below {
            centred(mark.y + offset)
        } else {
            centred(mark.y - offset - size.y)
        }
    };
    let beside = move |right: bool| {
        let left = if right {
            mark.x + MARK_RADIUS + GAP
        } else {
            mark.x - MARK_RADIUS - GAP - size.x
        };
        Rect::from_min_size(pos2(left, mark.y - size.y / 2.0), size)
    };
    let near = [row(0, true), row(0, false)];
    let sides = plane.then(|| [beside(true), beside(false)]);
    let far = (1..ROWS).flat_map(move |i| [row(i, true), row(i, false)]);
    near.into_iter()
        .chain(sides.into_iter().flatten())
        .chain(far)
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::vec2;

    /// Four names too wide to sit side by side on a short line each find a row of their own.
    #[test]
    fn crowded_names_on_a_line_take_rows_and_never_touch() {
        let bounds = Rect::from_min_max(pos2(0.0, 0.0), pos2(120.0, 80.0));
        let marks = [30.0, 40.0, 50.0, 60.0].map(|x| pos2(x, 40.0));
        let sizes = [vec2(70.0, 12.0); 4];
        let placed = place(&marks, &sizes, bounds, false);
        let rects: Vec<Rect> = placed
            .iter()
            .map(|r| r.expect("every name placed"))
            .collect();
        for (i, a) in rects.iter().enumerate() {
            assert!(bounds.contains_rect(*a), "name {i} at {a:?}");
            for (j, b) in rects.iter().enumerate().skip(i + 1) {
                assert!(!a.intersects(*b), "names {i} {a:?} and {j} {b:?}");
            }
        }
    }

    /// A name with no room is left out rather than drawn over another.
    #[test]
    fn a_name_with_no_room_is_left_out() {
        let bounds = Rect::from_min_max(pos2(0.0, 0.0), pos2(60.0, 30.0));
        let marks = [pos2(30.0, 15.0); 3];
        let placed = place(&marks, &[vec2(50.0, 8.0); 3], bounds, false);
        assert_eq!(
            placed.iter().filter(|r| r.is_some()).count(),
            2,
            "{placed:?}"
        );
    }
}
