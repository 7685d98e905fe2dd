//! A parameter slider whose every host gesture ends: one begins when the pointer goes down on
//! the slider and ends the first frame it is up again, whatever happened in between (a drag, a
//! click, a double-click reset), so hosts recording touch or latch automation see each edit
//! whole.
//!
//! Dragging moves the value by the distance dragged (the whole range over the slider's width, a
//! tenth of that with Shift held), not to the pointer, so grabbing a slider never makes the value
//! jump. Double-click or Ctrl-click resets to the default; clicking the value lets you type one
//! (Enter sets it, Escape leaves it).

use egui::{Id, Key, Rect, Response, Sense, Stroke, TextEdit, Ui, Vec2};
use nice_plug::prelude::{Param, ParamSetter};

/// Share of the range one point of drag moves with Shift held, against the slider's width.
const FINE_DRAG_DIVISOR: f32 = 10.0;

/// Where a gesture started and how far it has been dragged.
#[derive(Debug, Clone, Copy, Default)]
struct Gesture {
    /// The normalized value the drag counts from.
    start: f32,
    /// The pointer's x where the drag counts from, in points.
    from_x: f32,
    /// Whether Shift was held: switching it starts counting afresh, so the value never jumps.
    fine: bool,
}

/// The memory key of a control's rectangle, by parameter name.
fn rect_id(name: &str) -> Id {
    Id::unique(("parameter-control", name))
}

/// Where the control of the parameter named `name` was last drawn, in points.
pub fn control_rect(ctx: &egui::Context, name: &str) -> Option<Rect> {
    ctx.memory(|m| m.data.get_temp(rect_id(name)))
}

/// Draws a slider `width` points wide for `param`, with its value and unit beside it.
pub fn param_slider<P: Param>(ui: &mut Ui, param: &P, setter: &ParamSetter, width: f32) {
    let id = Id::unique(("parameter-slider", param.name()));
    ui.horizontal(|ui| {
        let height = ui.spacing().interact_size.y;
        let (rect, response) =
            ui.allocate_exact_size(Vec2::new(width, height), Sense::click_and_drag());
        ui.memory_mut(|m| m.data.insert_temp(rect_id(param.name()), rect));
        drive(ui, id, &response, param, setter, width);
        paint(ui, &response, param.modulated_normalized_value());
        value_field(ui, id, param, setter);
    });
}

/// Turns the pointer on the slider into one host gesture per press.
fn drive<P: Param>(
    ui: &Ui,
    id: Id,
    response: &Response,
    param: &P,
    setter: &ParamSetter,
    width: f32,
) {
    let gesture: Option<Gesture> = ui.memory(|m| m.data.get_temp(id));
    let down = response.is_pointer_button_down_on();
    let (command, fine) = ui.input(|i| (i.modifiers.command, i.modifiers.shift));
    let pointer_x = ui.input(|i| i.pointer.interact_pos()).map_or(0.0, |p| p.x);
    let restart = |g: &mut Gesture| {
        g.start = param.unmodulated_normalized_value();
        g.from_x = pointer_x;
        g.fine = fine;
    };
    match gesture {
        None if down => {
            setter.begin_set_parameter(param);
            if command {
                setter.set_parameter(param, param.default_plain_value());
            }
            let mut g = Gesture::default();
            restart(&mut g);
            ui.memory_mut(|m| m.data.insert_temp(id, g));
        }
        Some(mut g) if down => {
            if g.fine != fine {
                restart(&mut g);
            }
            let scale = if fine { FINE_DRAG_DIVISOR } else { 1.0 };
            let moved = (pointer_x - g.from_x) / (width.max(1.0) * scale);
            if !command {
                let value = param.preview_plain((g.start + moved).clamp(0.0, 1.0));
                if value != param.modulated_plain_value() {
                    setter.set_parameter(param, value);
                }
            }
            ui.memory_mut(|m| m.data.insert_temp(id, g));
        }
        Some(_) => {
            // Released: a double-click resets, inside the gesture its second press began.
            if response.double_clicked() {
                setter.set_parameter(param, param.default_plain_value());
            }
            setter.end_set_parameter(param);
            ui.memory_mut(|m| m.data.remove::<Gesture>(id));
        }
        None => {}
    }
}

/// Background, the filled share of the range, and a frame.
fn paint(ui: &Ui, response: &Response, normalized: f32) {
    let rect = response.rect;
    if !ui.is_rect_visible(rect) {
        return;
    }
    let visuals = ui.visuals();
    let painter = ui.painter();
    painter.rect_filled(rect, 0.0, visuals.widgets.inactive.bg_fill);
    let mut filled = rect;
    filled.set_width(rect.width() * normalized.clamp(0.0, 1.0));
    let fill = if response.hovered() || response.dragged() {
        visuals.selection.bg_fill.gamma_multiply(1.25)
    } else {
        visuals.selection.bg_fill
    };
    painter.rect_filled(filled, 0.0, fill);
    painter.rect_stroke(
        rect,
        0.0,
        Stroke::new(1.0, visuals.widgets.active.bg_fill),
        egui::StrokeKind::Inside,
    );
}

/// The value with its unit; clicked, a text field to type a new one.
fn value_field<P: Param>(ui: &mut Ui, id: Id, param: &P, setter: &ParamSetter) {
    let edit_id = id.with("typed");
    let typed: Option<String> = ui.memory(|m| m.data.get_temp(edit_id));
    match typed {
        Some(mut text) => {
            let response = ui.add(
                TextEdit::singleline(&mut text)
                    .id(edit_id)
                    .desired_width(90.0)
                    .font(egui::TextStyle::Monospace),
            );
            let (enter, escape) =
                ui.input(|i| (i.key_pressed(Key::Enter), i.key_pressed(Key::Escape)));
            if enter {
                if let Some(normalized) = param.string_to_normalized_value(&text) {
                    setter.begin_set_parameter(param);
                    setter.set_parameter(param, param.preview_plain(normalized));
                    setter.end_set_parameter(param);
                }
            }
            if enter || escape || response.lost_focus() {
                ui.memory_mut(|m| m.data.remove::<String>(edit_id));
            } else {
                ui.memory_mut(|m| {
                    m.data.insert_temp(edit_id, text);
                    m.request_focus(edit_id);
                });
            }
        }
        None => {
            let response = ui.add(
                egui::Label::new(param.to_string())
                    .sense(Sense::click())
                    .selectable(false),
            );
            if response.clicked() {
                ui.memory_mut(|m| {
                    m.data.insert_temp(edit_id, param.to_string());
                    m.request_focus(edit_id);
                });
            }
            response.on_hover_cursor(egui::CursorIcon::Text);
        }
    }
}
