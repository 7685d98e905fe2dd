//! The mode view: every mode as a stem on a log-frequency axis, its height the mode's gain at the
//! strike position and its colour its T60, with the live level of sounding modes drawn over it.
//! Modes not heard (muted) are grey; modes dropped by truncation while the object sounds are
//! marked; modes switched off by perceptual pruning or the mode budget show their level hollow
//! (it is carried analytically, not computed). Hovering shows a mode's numbers; clicking selects it; dragging a stem moves its
//! frequency (sideways) and gain (up and down), finely with Shift, gain alone with Ctrl.

use egui::emath::GuiRounding;
use egui::{pos2, CornerRadius, Pos2, Rect, Response, Sense, Stroke, Ui, Vec2};

use super::session::BankSession;

mod plot;

use super::style;
use crate::bank::summary::note_name;
use crate::engine::PositionWeights;
use crate::units::decay_to_t60_s;
pub use plot::DB_SPAN;
use plot::{axes_for, cross, db_to_gain, draw_axes, draw_legend, gain_db, Axes, Mapping, MARGINS};

/// How near the pointer must be to a stem to hover or grab it, in points.
const PICK_DISTANCE: f32 = 8.0;
/// Drag speed with Shift held, relative to a normal drag.
const FINE_DRAG: f32 = 0.1;

/// What the view shows besides the bank.
pub struct ViewInput<'a> {
    /// The strike position's blend of the bank's positions.
    pub weights: PositionWeights,
    /// Live energy `|z|^2` of each mode by index in the bank (`None`: sounding nowhere), when
    /// the plugin plays this very bank.
    pub energy: Option<&'a [Option<f32>]>,
    /// Whether each mode (by index in the bank) is switched off by pruning or the budget, with
    /// `energy`.
    pub pruned: Option<&'a [bool]>,
    /// Whether any voice sounds now.
    pub sounding: bool,
}

/// A stem being dragged.
#[derive(Debug, Clone, Copy)]
struct Drag {
    /// The mode, by index in the bank.
    mode: usize,
    /// Its log2 frequency when the drag began.
    log2_hz: f64,
    /// Its gain in dB when the drag began (clamped to the axis).
    gain_db: f64,
    /// The sign of its gain.
    sign: f64,
    /// The pointer's travel so far, scaled for fine moves.
    travel: Vec2,
    /// Where the pointer was in the last frame.
    last_pos: Pos2,
    /// The scales when the drag began.
    axes: Axes,
}

/// The mode view's own state.
#[derive(Debug, Clone)]
pub struct ModeView {
    /// The selected mode, by index in the bank.
    pub selected: Option<usize>,
    /// The mode under the pointer in the last frame.
    hovered: Option<usize>,
    /// The stem being dragged.
    drag: Option<Drag>,
    /// Stems drawn in the last frame.
    stems_drawn: usize,
    /// Live levels drawn in the last frame.
    live_drawn: usize,
    /// Truncation marks drawn in the last frame.
    truncated_drawn: usize,
    /// Live levels of pruned modes drawn in the last frame.
    pruned_drawn: usize,
    /// Where each stem's head was drawn in the last frame, by index in the bank.
    heads: Vec<Pos2>,
    /// The plotting area in the last frame.
    plot: Rect,
}

impl Default for ModeView {
    fn default() -> Self {
        Self {
            selected: None,
            hovered: None,
            drag: None,
            stems_drawn: 0,
            live_drawn: 0,
            truncated_drawn: 0,
            pruned_drawn: 0,
            heads: Vec::new(),
            plot: Rect::NOTHING,
        }
    }
}

impl ModeView {
    /// The mode under the pointer in the last frame.
    pub fn hovered(&self) -> Option<usize> {
        self.hovered
    }

    /// How many stems the last frame drew.
    pub fn stems_drawn(&self) -> usize {
        self.stems_drawn
    }

    /// How many live levels and truncation marks the last frame drew.
    pub fn marks_drawn(&self) -> (usize, usize) {
        (self.live_drawn, self.truncated_drawn)
    }

    /// How many of the live levels the last frame drew were of pruned modes.
    pub fn pruned_drawn(&self) -> usize {
        self.pruned_drawn
    }

    /// Where the last frame drew mode `i`'s stem head.
    pub fn head(&self, i: usize) -> Option<Pos2> {
        self.heads.get(i).copied()
    }

    /// The plotting area in the last frame.
    pub fn plot_rect(&self) -> Rect {
        self.plot
    }

    /// Forgets selection and drag (a new bank).
    pub fn reset(&mut self) {
        self.selected = None;
        self.hovered = None;
        self.drag = None;
    }

    /// Draws the view in `size` and handles the pointer.
    pub fn show(&mut self, ui: &mut Ui, size: Vec2, session: &mut BankSession, input: &ViewInput) {
        let (rect, response) = ui.allocate_exact_size(size, Sense::click_and_drag());
        let (ml, mr, mt, mb) = MARGINS;
        let plot = Rect::from_min_max(
            pos2(rect.left() + ml, rect.top() + mt),
            pos2(rect.right() - mr, rect.bottom() - mb),
        );
        if plot.width() < 10.0 || plot.height() < 10.0 {
            return;
        }
        let axes = self
            .drag
            .map_or_else(|| axes_for(session, input), |d| d.axes);
        let map = Mapping { plot, axes };

        let hovered = response
            .hover_pos()
            .and_then(|p| nearest_stem(session, input, &map, p));
        self.handle_pointer(ui, &response, hovered, session, input, &map);
        self.hovered = hovered;

        let painter = ui.painter_at(rect);
        draw_axes(&painter, &map, ui.pixels_per_point());
        self.plot = plot;
        self.draw_stems(ui, &map, session, input);
        draw_legend(&painter, rect);
        if let Some(i) = self.hovered.filter(|_| self.drag.is_none()) {
            let text = describe(session, input, i);
            response.on_hover_text_at_pointer(text);
        }
    }

    fn handle_pointer(
        &mut self,
        ui: &Ui,
        response: &Response,
        hovered: Option<usize>,
        session: &mut BankSession,
        input: &ViewInput,
        map: &Mapping,
    ) {
        if response.clicked() {
            self.selected = hovered;
        }
        if response.drag_started() {
            // From where the button went down: the pointer moved a little before egui called
            // it a drag.
            let origin = ui.input(|i| i.pointer.press_origin());
            let grabbed = origin.and_then(|p| nearest_stem(session, input, map, p));
            if let (Some(i), Some(origin)) = (grabbed.or(hovered).or(self.selected), origin) {
                let gain = session.gain_at(i, &input.weights);
                self.selected = Some(i);
                self.drag = Some(Drag {
                    mode: i,
                    log2_hz: session.bank().modes[i].freq_hz.log2(),
                    gain_db: gain_db(gain).max(map.axes.top_db - DB_SPAN),
                    sign: if gain < 0.0 { -1.0 } else { 1.0 },
                    travel: Vec2::ZERO,
                    last_pos: origin,
                    axes: map.axes,
                });
            }
        }
        if let Some(drag) = self.drag.as_mut() {
            if response.dragged() {
                let (fine, gain_only) =
                    ui.input(|i| (i.modifiers.shift, i.modifiers.command || i.modifiers.ctrl));
                let pos = response.interact_pointer_pos().unwrap_or(drag.last_pos);
                let delta = (pos - drag.last_pos) * if fine { FINE_DRAG } else { 1.0 };
                drag.last_pos = pos;
                drag.travel += delta;
                let octaves = drag.travel.x as f64 / map.px_per_octave();
                let db = -drag.travel.y as f64 / map.px_per_db();
                if !gain_only && drag.travel.x != 0.0 {
                    session.set_freq_hz(drag.mode, (drag.log2_hz + octaves).exp2());
                }
                if drag.travel.y != 0.0 {
                    let gain = drag.sign * db_to_gain(drag.gain_db + db);
                    session.set_gain_at(drag.mode, &input.weights, gain);
                }
            }
            if response.drag_stopped() || !response.dragged() && !response.drag_started() {
                self.drag = None;
                session.end_gesture();
            }
        }
    }

    /// Draws every mode's stem and live level, counting what it drew.
    fn draw_stems(&mut self, ui: &Ui, map: &Mapping, session: &BankSession, input: &ViewInput) {
        let painter = ui.painter_at(map.plot);
        let ppp = ui.pixels_per_point();
        let bottom = map.plot.bottom();
        let mut selected = None;
        self.heads.clear();
        (self.stems_drawn, self.live_drawn, self.truncated_drawn) = (0, 0, 0);
        self.pruned_drawn = 0;
        for (i, mode) in session.bank().modes.iter().enumerate() {
            let x = map.x(mode.freq_hz).round_to_pixel_center(ppp);
            let gain = session.gain_at(i, &input.weights);
            // A stem at least 2 points tall, so modes below the axis still show.
            let y = map.y(gain_db(gain)).min(bottom - 2.0);
            let live = input.energy.map(|e| e.get(i).copied().flatten());
            if let Some(Some(energy)) = live {
                let level_y = map.y(map.axes.top_db + 10.0 * (energy.max(1e-30) as f64).log10());
                let bar = Rect::from_min_max(pos2(x - 3.0, level_y), pos2(x + 3.0, bottom));
                if is_pruned(input, i) {
                    painter.rect_stroke(
                        bar,
                        CornerRadius::ZERO,
                        Stroke::new(1.0, style::PRUNED),
                        egui::StrokeKind::Inside,
                    );
                    self.pruned_drawn += 1;
                } else {
                    painter.rect_filled(bar, CornerRadius::ZERO, style::LIVE.gamma_multiply(0.55));
                }
                self.live_drawn += 1;
            }
            let colour = if !session.is_audible(i) {
                style::MUTED
            } else {
                style::t60_colour(decay_to_t60_s(mode.decay_per_s))
            };
            painter.line_segment([pos2(x, bottom), pos2(x, y)], Stroke::new(2.0, colour));
            painter.circle_filled(pos2(x, y), 2.5, colour);
            let truncated = input.sounding && session.is_audible(i) && live == Some(None);
            if truncated {
                cross(&painter, pos2(x, bottom - 5.0), 3.5, style::TRUNCATED);
                self.truncated_drawn += 1;
            }
            if session.is_soloed(i) {
                painter.circle_stroke(pos2(x, y), 5.0, Stroke::new(1.5, style::LIVE));
            }
            if self.selected == Some(i) {
                selected = Some(pos2(x, y));
            }
            self.heads.push(pos2(x, y));
            self.stems_drawn += 1;
        }
        if let Some(head) = selected {
            painter.line_segment(
                [pos2(head.x, bottom), head],
                Stroke::new(2.0, style::SELECTED),
            );
            painter.circle_stroke(head, 6.0, Stroke::new(2.0, style::SELECTED));
        }
    }
}

/// The mode whose stem is nearest `p` sideways, within [`PICK_DISTANCE`]; the stronger of two
/// at the same place.
fn nearest_stem(session: &BankSession, input: &ViewInput, map: &Mapping, p: Pos2) -> Option<usize> {
    if !map.plot.expand(PICK_DISTANCE).contains(p) {
        return None;
    }
    let mut best: Option<(usize, f32, f64)> = None;
    for (i, mode) in session.bank().modes.iter().enumerate() {
        let dx = (map.x(mode.freq_hz) - p.x).abs();
        if dx > PICK_DISTANCE {
            continue;
        }
        let strength = session.gain_at(i, &input.weights).abs();
        let better = match best {
            None => true,
            Some((_, bdx, bs)) => dx + 0.5 < bdx || ((dx - bdx).abs() <= 0.5 && strength > bs),
        };
        if better {
            best = Some((i, dx, strength));
        }
    }
    best.map(|(i, _, _)| i)
}

/// Whether mode `i` is switched off by pruning or the budget, as published.
fn is_pruned(input: &ViewInput, i: usize) -> bool {
    input
        .pruned
        .is_some_and(|p| p.get(i).copied().unwrap_or(false))
}

/// What hovering over mode `i` tells.
fn describe(session: &BankSession, input: &ViewInput, i: usize) -> String {
    let mode = &session.bank().modes[i];
    let gain = session.gain_at(i, &input.weights);
    let t60 = if mode.decay_per_s > 0.0 {
        format!("{:.3} s", decay_to_t60_s(mode.decay_per_s))
    } else {
        "infinite".to_string()
    };
    let mut text = format!(
        "Mode {} of {}\n{:.2} Hz  {}\nT60 {t60} (decay {:.3} /s)\nGain at strike {:+.1} dB ({:.4})",
        i + 1,
        session.num_modes(),
        mode.freq_hz,
        note_name(mode.freq_hz),
        mode.decay_per_s,
        gain_db(gain),
        gain,
    );
    match input.energy.map(|e| e.get(i).copied().flatten()) {
        Some(Some(e)) => {
            let db = 10.0 * (e.max(1e-30) as f64).log10();
            text.push_str(&format!("\nLevel now {db:.1} dB"));
            if is_pruned(input, i) {
                text.push_str(
                    "\nPruned: masked or below the threshold of hearing, not computed \
                     (its level is carried, and it comes back in phase)",
                );
            }
        }
        Some(None) if input.sounding && session.is_audible(i) => {
            text.push_str("\nTruncated: below the threshold now")
        }
        _ => {}
    }
    if !session.is_audible(i) {
        text.push_str("\nMuted");
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bank::factory::factory_bank;

    #[test]
    fn hovering_tells_a_pruned_mode_from_a_computed_and_a_truncated_one() {
        let bank = factory_bank("steel-plate").unwrap();
        let session = BankSession::new(bank, "test", 1);
        let n = session.num_modes();
        let mut energy = vec![Some(1e-4f32); n];
        energy[2] = None;
        let mut pruned = vec![false; n];
        pruned[1] = true;
        let input = ViewInput {
            weights: PositionWeights::single(0),
            energy: Some(&energy),
            pruned: Some(&pruned),
            sounding: true,
        };
        let computed = describe(&session, &input, 0);
        assert!(computed.contains("Level now -40.0 dB"), "{computed}");
        assert!(!computed.contains("Pruned"), "{computed}");
        let switched_off = describe(&session, &input, 1);
        assert!(
            switched_off.contains("Level now -40.0 dB"),
            "{switched_off}"
        );
        assert!(switched_off.contains("Pruned"), "{switched_off}");
        let truncated = describe(&session, &input, 2);
        assert!(truncated.contains("Truncated"), "{truncated}");
        assert!(!truncated.contains("Pruned"), "{truncated}");
    }
}
