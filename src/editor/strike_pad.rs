//! The strike pad: the object as a line (1-D banks) or a plane (2-D banks), 0 to 1 along each
//! axis, with the bank's positions where they lie on it (and, faint, where symmetry repeats them)
//! and the strike point. Pressing strikes the object there (auditions without MIDI) and holds the note
//! until released; dragging moves the strike position parameters.

use egui::{pos2, vec2, Align2, CornerRadius, FontId, Pos2, Rect, Sense, Slider, Stroke, Ui, Vec2};
use nice_plug::prelude::ParamSetter;

use super::app::Host;
use super::style;
use super::Audition;
use crate::engine::{PositionMap, StrikeAxis};
use crate::params::ModalParams;

/// Velocity of pad strikes until the player sets another.
const DEFAULT_VELOCITY: f32 = 0.8;
/// Height of the 1-D pad, in points.
const LINE_HEIGHT: f32 = 64.0;
/// Room around the pad's drawing area, in points.
const INSET: f32 = 12.0;

/// The pad's own state.
#[derive(Debug, Clone)]
pub struct StrikePad {
    /// Velocity of pad strikes, 0 to 1.
    pub velocity: f32,
    /// Whether a pad strike is held (the pointer is down on the pad).
    held: bool,
    /// The area positions map to (0 to 1 on each axis) in the last frame.
    area: Rect,
}

impl Default for StrikePad {
    fn default() -> Self {
        Self {
            velocity: DEFAULT_VELOCITY,
            held: false,
            area: Rect::NOTHING,
        }
    }
}

impl StrikePad {
    /// The area positions map to (0 to 1 on each axis; y up) in the last frame.
    pub fn area(&self) -> Rect {
        self.area
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
        let Host {
            params,
            setter,
            shared,
        } = *host;
        let two_d = positions.dims() == 2;
        let size = if two_d {
            let side = size.x.min(size.y - 24.0).max(60.0);
            vec2(side, side)
        } else {
            vec2(size.x, LINE_HEIGHT)
        };
        let (rect, response) = ui.allocate_exact_size(size, Sense::click_and_drag());
        // Room for the names of the end positions of a line.
        let area = if two_d {
            rect.shrink(INSET)
        } else {
            rect.shrink2(vec2(3.0 * INSET, INSET))
        };
        self.area = area;
        let to_screen = |x: f32, y: f32| {
            if two_d {
                pos2(
                    area.left() + area.width() * x,
                    area.bottom() - area.height() * y,
                )
            } else {
                pos2(area.left() + area.width() * x, area.center().y)
            }
        };
        let from_screen = |p: Pos2| {
            let x = ((p.x - area.left()) / area.width()).clamp(0.0, 1.0);
            let y = ((area.bottom() - p.y) / area.height()).clamp(0.0, 1.0);
            (
                x,
                if two_d {
                    y
                } else {
                    params.strike.strike_y.value()
                },
            )
        };

        // Press: strike there; drag: move the strike point; release: end the note.
        let (pressed, down) = ui.input(|i| (i.pointer.primary_pressed(), i.pointer.primary_down()));
        if pressed && response.contains_pointer() {
            if let Some(p) = ui.input(|i| i.pointer.interact_pos()) {
                let (x, y) = from_screen(p);
                setter.begin_set_parameter(&params.strike.strike_x);
                if two_d {
                    setter.begin_set_parameter(&params.strike.strike_y);
                }
                self.set_position(params, setter, x, y, two_d);
                shared.request(Audition::Strike {
                    x,
                    y,
                    velocity: self.velocity,
                });
                self.held = true;
            }
        } else if self.held && down {
            if let Some(p) = ui.input(|i| i.pointer.interact_pos()) {
                let (x, y) = from_screen(p);
                self.set_position(params, setter, x, y, two_d);
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

        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, CornerRadius::same(4), style::PLOT_BG);
        let font = FontId::proportional(10.0);
        if two_d {
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
        // Where a mirrored axis repeats the measured positions, they are drawn again, faint.
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
                    painter.circle_stroke(to_screen(ix, iy), 3.5, (1.0, style::POSITION));
                }
            }
        }
        for (k, c) in positions.coords().iter().enumerate() {
            let p = to_screen(c[0] as f32, c[1] as f32);
            painter.circle_filled(p, 4.0, style::POSITION);
            if let Some(name) = names.get(k) {
                let (offset, align) = if two_d || k % 2 == 0 {
                    (vec2(0.0, 7.0), Align2::CENTER_TOP)
                } else {
                    (vec2(0.0, -7.0), Align2::CENTER_BOTTOM)
                };
                painter.text(p + offset, align, name, font.clone(), style::LABEL);
            }
        }
        let strike = to_screen(
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
        response.on_hover_text("Press to strike here (held until released); drag to move");
        ui.add(
            Slider::new(&mut self.velocity, 0.05..=1.0)
                .text("strike velocity")
                .fixed_decimals(2),
        );
    }

    /// Sets the strike position parameters (y only on 2-D banks).
    fn set_position(
        &self,
        params: &ModalParams,
        setter: &ParamSetter,
        x: f32,
        y: f32,
        two_d: bool,
    ) {
        setter.set_parameter(&params.strike.strike_x, x);
        if two_d {
            setter.set_parameter(&params.strike.strike_y, y);
        }
    }
}
