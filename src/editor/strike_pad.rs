//! The strike pad: the object as a line (1-D banks) or a plane (2-D banks), 0 to 1 along each
//! axis, with the bank's positions where they lie on it (and, faint, where symmetry repeats them)
//! and the strike point. Pressing strikes the object there (auditions without MIDI) and holds the note
//! until released; dragging moves the strike position parameters.

mod labels;

use egui::{pos2, vec2, Color32, CornerRadius, FontId, Painter, Pos2, Rect, Response, Sense};
use egui::{Slider, Stroke, Ui, Vec2};
use nice_plug::prelude::ParamSetter;

use super::style;
use super::Audition;
use super::Host;
use crate::engine::{PositionMap, StrikeAxis};
use crate::params::ModalParams;

/// Velocity of pad strikes until the player sets another.
const DEFAULT_VELOCITY: f32 = 0.8;
/// Room around the pad's drawing area, in points.
const INSET: f32 = 12.0;
/// Size of the positions' names, in points.
const NAME_SIZE: f32 = 10.0;
/// Space between a line's outermost rows of names and the pad's edges, in points.
const EDGE_CLEARANCE: f32 = 2.0;
/// How near a position's mark the pointer must be for the pad to name it, in points.
const HOVER_RADIUS: f32 = 8.0;

/// The pad's own state.
#[derive(Debug, Clone)]
pub struct StrikePad {
    /// Velocity of pad strikes, 0 to 1.
    pub velocity: f32,
    /// Whether a pad strike is held (the pointer is down on the pad).
    held: bool,
    /// The whole pad in the last frame.
    rect: Rect,
    /// The area positions map to (0 to 1 on each axis) in the last frame.
    area: Rect,
    /// The names written on the pad in the last frame, with where.
    labels: Vec<(String, Rect)>,
}

impl Default for StrikePad {
    fn default() -> Self {
        Self {
            velocity: DEFAULT_VELOCITY,
            held: false,
            rect: Rect::NOTHING,
            area: Rect::NOTHING,
            labels: Vec::new(),
        }
    }
}

/// Where the pad lies on screen in one frame.
#[derive(Clone, Copy)]
struct PadGeometry {
    /// The whole pad.
    rect: Rect,
    /// The area positions map to (0 to 1 on each axis; y up).
    area: Rect,
    /// Whether the object is a plane (else a line).
    two_d: bool,
}

impl PadGeometry {
    /// The screen point of position `(x, y)`.
    fn to_screen(self, x: f32, y: f32) -> Pos2 {
        let area = self.area;
        if self.two_d {
            pos2(
                area.left() + area.width() * x,
                area.bottom() - area.height() * y,
            )
        } else {
            pos2(area.left() + area.width() * x, area.center().y)
        }
    }

    /// The position under screen point `p`, clamped to the object (0 to 1 on each axis).
    fn position_at(self, p: Pos2) -> (f32, f32) {
        let area = self.area;
        let x = ((p.x - area.left()) / area.width()).clamp(0.0, 1.0);
        let y = ((area.bottom() - p.y) / area.height()).clamp(0.0, 1.0);
        (x, y)
    }
}

impl StrikePad {
    /// The area positions map to (0 to 1 on each axis; y up) in the last frame.
    pub fn area(&self) -> Rect {
        self.area
    }

    /// The whole pad in the last frame.
    pub fn rect(&self) -> Rect {
        self.rect
    }

    /// The positions' names written in the last frame, with where (a name with no room is
    /// left out and shown on hover).
    pub fn labels(&self) -> &[(String, Rect)] {
        &self.labels
    }

    /// Forgets a held strike (the window closed under the pointer); returns whether one was.
    pub fn forget_hold(&mut self) -> bool {
        std::mem::take(&mut self.held)
    }

    /// Draws the pad in at most `size` and handles the pointer. `names` are the positions' names.
    pub fn show(
        &mut self,
        ui: &mut Ui,
        size: Vec2,
        positions: &PositionMap,
        names: &[String],
        host: &Host,
    ) {
        let two_d = positions.dims() == 2;
        let font = FontId::proportional(NAME_SIZE);
        let row_height = ui.ctx().fonts_mut(|f| f.row_height(&font));
        let size = if two_d {
            let side = size.x.min(size.y - 24.0).max(60.0);
            vec2(side, side)
        } else {
            // The line in the middle, with its rows of names above and below, clear of the edges.
            vec2(
                size.x,
                2.0 * (labels::line_room(row_height) + EDGE_CLEARANCE),
            )
        };
        let (rect, response) = ui.allocate_exact_size(size, Sense::click_and_drag());
        // A line leaves room beside its ends for the names of positions there.
        let area = if two_d {
            rect.shrink(INSET)
        } else {
            rect.shrink2(vec2(3.0 * INSET, INSET))
        };
        (self.rect, self.area) = (rect, area);
        let pad = PadGeometry { rect, area, two_d };
        self.handle_pointer(ui, &response, pad, host);

        let painter = ui.painter_at(rect);
        let marks: Vec<Pos2> = positions
            .coords()
            .iter()
            .map(|c| pad.to_screen(c[0] as f32, c[1] as f32))
            .collect();
        paint_object(&painter, pad, positions, &marks);
        self.paint_names(&painter, pad, &marks, names, &font);
        self.paint_strike(&painter, pad, host.params);

        let named = response.hover_pos().and_then(|p| {
            let near = marks.iter().position(|m| m.distance(p) <= HOVER_RADIUS)?;
            names.get(near)
        });
        let hint = "Press to strike here (held until released); drag to move";
        match named {
            Some(name) => response.on_hover_text(format!("{name}\n{hint}")),
            None => response.on_hover_text(hint),
        };
        ui.add(
            Slider::new(&mut self.velocity, 0.05..=1.0)
                .text("strike velocity")
                .fixed_decimals(2),
        );
    }

    /// Press: strike there; drag: move the strike point; release: end the note.
    fn handle_pointer(&mut self, ui: &Ui, response: &Response, pad: PadGeometry, host: &Host) {
        let Host {
            params,
            setter,
            shared,
        } = *host;
        let two_d = pad.two_d;
        let position = |p: Pos2| {
            let (x, y) = pad.position_at(p);
            (
                x,
                if two_d {
                    y
                } else {
                    params.strike.strike_y.value()
                },
            )
        };
        let (pressed, down) = ui.input(|i| (i.pointer.primary_pressed(), i.pointer.primary_down()));
        let pointer = ui.input(|i| i.pointer.interact_pos());
        if pressed && response.contains_pointer() {
            if let Some(p) = pointer {
                let (x, y) = position(p);
                setter.begin_set_parameter(&params.strike.strike_x);
                if two_d {
                    setter.begin_set_parameter(&params.strike.strike_y);
                }
                set_position(params, setter, x, y, two_d);
                shared.request(Audition::Strike {
                    x,
                    y,
                    velocity: self.velocity,
                });
                self.held = true;
            }
        } else if self.held && down {
            if let Some(p) = pointer {
                let (x, y) = position(p);
                set_position(params, setter, x, y, two_d);
            }
        }
        if self.held && !down {
            self.held = false;
            shared.request(Audition::Release);
            setter.end_set_parameter(&params.strike.strike_x);
            if two_d {
                setter.end_set_parameter(&params.strike.strike_y);
            }
        }
    }

    /// Writes the positions' names where [`labels::place`] finds them room, and keeps where.
    fn paint_names(
        &mut self,
        painter: &Painter,
        pad: PadGeometry,
        marks: &[Pos2],
        names: &[String],
        font: &FontId,
    ) {
        let galleys: Vec<_> = names
            .iter()
            .take(marks.len())
            .map(|name| painter.layout_no_wrap(name.clone(), font.clone(), style::LABEL))
            .collect();
        let sizes: Vec<Vec2> = galleys.iter().map(|g| g.size()).collect();
        let spots = labels::place(&marks[..galleys.len()], &sizes, pad.rect, pad.two_d);
        self.labels.clear();
        for ((galley, spot), name) in galleys.into_iter().zip(spots).zip(names) {
            if let Some(spot) = spot {
                painter.galley(spot.min, galley, style::LABEL);
                self.labels.push((name.clone(), spot));
            }
        }
    }

    /// The strike point: a ring and a cross, filled while a pad strike is held.
    fn paint_strike(&self, painter: &Painter, pad: PadGeometry, params: &ModalParams) {
        let strike = pad.to_screen(
            params.strike.strike_x.value(),
            params.strike.strike_y.value(),
        );
        let colour = style::STRIKE;
        painter.circle_stroke(strike, 7.0, Stroke::new(2.0, colour));
        painter.line_segment(
            [strike - vec2(10.0, 0.0), strike + vec2(10.0, 0.0)],
            (1.0, colour),
        );
        painter.line_segment(
            [strike - vec2(0.0, 10.0), strike + vec2(0.0, 10.0)],
            (1.0, colour),
        );
        if self.held {
            painter.circle_filled(strike, 4.0, colour);
        }
    }
}

/// The object (a line or a square) and its positions' marks, with faint marks where a mirrored
/// axis repeats them.
fn paint_object(painter: &Painter, pad: PadGeometry, positions: &PositionMap, marks: &[Pos2]) {
    painter.rect_filled(pad.rect, CornerRadius::same(4), style::PLOT_BG);
    let area = pad.area;
    if pad.two_d {
        painter.rect_stroke(
            area,
            CornerRadius::ZERO,
            Stroke::new(1.0, style::GRID),
            egui::StrokeKind::Middle,
        );
    } else {
        painter.hline(
            area.x_range(),
            area.center().y,
            Stroke::new(2.0, style::GRID),
        );
    }
    let [mirror_x, mirror_y] = positions.axes().map(|a| a == StrikeAxis::Mirrored);
    for c in positions.coords() {
        let (x, y) = (c[0] as f32, c[1] as f32);
        let images = [
            (mirror_x && x < 0.5, 1.0 - x, y),
            (mirror_y && y < 0.5, x, 1.0 - y),
            (mirror_x && mirror_y && x < 0.5 && y < 0.5, 1.0 - x, 1.0 - y),
        ];
        for (shown, ix, iy) in images {
            if shown {
                let faint: (f32, Color32) = (1.0, style::POSITION);
                painter.circle_stroke(pad.to_screen(ix, iy), 3.5, faint);
            }
        }
    }
    for &mark in marks {
        painter.circle_filled(mark, labels::MARK_RADIUS, style::POSITION);
    }
}

/// Sets the strike position parameters (y only on 2-D banks).
fn set_position(params: &ModalParams, setter: &ParamSetter, x: f32, y: f32, two_d: bool) {
    setter.set_parameter(&params.strike.strike_x, x);
    if two_d {
        setter.set_parameter(&params.strike.strike_y, y);
    }
}
