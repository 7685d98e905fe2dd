//! The mode view's plot: its scales, the mapping between points and frequency or gain, the
//! grid, labels and legend.

use egui::emath::GuiRounding;
use egui::{pos2, vec2, Align2, Color32, CornerRadius, FontId, Pos2, Rect, Stroke};

use super::ViewInput;
use crate::editor::session::BankSession;
use crate::editor::style;

/// Decibels the gain axis spans, top to bottom (and the level axis).
pub const DB_SPAN: f64 = 72.0;
/// Gain axis grid step, in dB.
const DB_STEP: f64 = 12.0;
/// Octaves of room beside the lowest and highest mode.
const MARGIN_OCTAVES: f64 = 0.3;
/// Fewest octaves the frequency axis spans.
const MIN_OCTAVES: f64 = 2.0;
/// Room for the axes' labels, in points: left, right, top, bottom.
pub const MARGINS: (f32, f32, f32, f32) = (40.0, 44.0, 22.0, 18.0);
/// Frequencies labelled on the axis, in Hz.
const FREQ_LABELS: [f64; 13] = [
    10.0, 20.0, 50.0, 100.0, 200.0, 500.0, 1e3, 2e3, 5e3, 1e4, 2e4, 5e4, 1e5,
];

/// The plot's scales, fixed while a stem is dragged.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axes {
    /// Lowest and highest log2 frequency shown.
    pub log2_hz: (f64, f64),
    /// Gain at the top edge, in dB.
    pub top_db: f64,
}

/// Converts between the plot's coordinates and frequency and gain.
pub struct Mapping {
    /// The plotting area.
    pub plot: Rect,
    /// The scales.
    pub axes: Axes,
}

impl Mapping {
    pub fn x(&self, freq_hz: f64) -> f32 {
        let (lo, hi) = self.axes.log2_hz;
        let t = (freq_hz.max(1e-6).log2() - lo) / (hi - lo);
        self.plot.left() + self.plot.width() * t as f32
    }

    pub fn y(&self, db: f64) -> f32 {
        let t = ((self.axes.top_db - db) / DB_SPAN).clamp(0.0, 1.0);
        self.plot.top() + self.plot.height() * t as f32
    }

    pub fn px_per_octave(&self) -> f64 {
        let (lo, hi) = self.axes.log2_hz;
        self.plot.width() as f64 / (hi - lo)
    }

    pub fn px_per_db(&self) -> f64 {
        self.plot.height() as f64 / DB_SPAN
    }
}

/// `20 log10 |gain|`, or -infinity for 0.
pub fn gain_db(gain: f64) -> f64 {
    20.0 * gain.abs().log10()
}

pub fn db_to_gain(db: f64) -> f64 {
    10f64.powf(db / 20.0)
}

/// Scales that show every mode: a margin around the frequencies, the strongest gain near the top.
pub fn axes_for(session: &BankSession, input: &ViewInput) -> Axes {
    let modes = &session.bank().modes;
    let (mut lo, mut hi) = modes.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), m| {
        (lo.min(m.freq_hz), hi.max(m.freq_hz))
    });
    if !(lo.is_finite() && hi > 0.0) {
        (lo, hi) = (100.0, 1000.0);
    }
    let (mut lo, mut hi) = (lo.log2() - MARGIN_OCTAVES, hi.log2() + MARGIN_OCTAVES);
    if hi - lo < MIN_OCTAVES {
        let mid = 0.5 * (lo + hi);
        (lo, hi) = (mid - MIN_OCTAVES / 2.0, mid + MIN_OCTAVES / 2.0);
    }
    let loudest = (0..modes.len())
        .map(|i| gain_db(session.gain_at(i, &input.weights)))
        .filter(|db| db.is_finite())
        .fold(f64::NEG_INFINITY, f64::max);
    let top_db = if loudest.is_finite() {
        (loudest / 6.0).ceil() * 6.0
    } else {
        0.0
    };
    Axes {
        log2_hz: (lo, hi),
        top_db,
    }
}

/// Grid lines and labels of both axes.
pub fn draw_axes(painter: &egui::Painter, map: &Mapping, ppp: f32) {
    let plot = map.plot;
    painter.rect_filled(plot, CornerRadius::same(2), style::PLOT_BG);
    let font = FontId::proportional(10.0);
    for hz in FREQ_LABELS {
        let x = map.x(hz);
        if x < plot.left() || x > plot.right() {
            continue;
        }
        let x = x.round_to_pixel_center(ppp);
        painter.vline(x, plot.y_range(), Stroke::new(1.0, style::GRID));
        let label = if hz >= 1000.0 {
            format!("{}k", hz / 1000.0)
        } else {
            format!("{hz}")
        };
        painter.text(
            pos2(x, plot.bottom() + 2.0),
            Align2::CENTER_TOP,
            label,
            font.clone(),
            style::LABEL,
        );
    }
    let mut db = map.axes.top_db;
    while db >= map.axes.top_db - DB_SPAN - 1e-9 {
        let y = map.y(db).round_to_pixel_center(ppp);
        painter.hline(plot.x_range(), y, Stroke::new(1.0, style::GRID));
        painter.text(
            pos2(plot.left() - 4.0, y),
            Align2::RIGHT_CENTER,
            format!("{:.0}", db + 0.0),
            font.clone(),
            style::LABEL,
        );
        let level = db - map.axes.top_db;
        painter.text(
            pos2(plot.right() + 4.0, y),
            Align2::LEFT_CENTER,
            format!("{:.0}", level + 0.0),
            font.clone(),
            style::LIVE.gamma_multiply(0.8),
        );
        db -= DB_STEP;
    }
    painter.text(
        pos2(plot.left() - 4.0, plot.top() - 4.0),
        Align2::RIGHT_BOTTOM,
        "gain dB",
        font.clone(),
        style::LABEL,
    );
    painter.text(
        pos2(plot.right() + 4.0, plot.top() - 4.0),
        Align2::LEFT_BOTTOM,
        "level dB",
        font,
        style::LIVE.gamma_multiply(0.8),
    );
}

/// The key to the colours, along the top edge.
pub fn draw_legend(painter: &egui::Painter, rect: Rect) {
    let font = FontId::proportional(10.0);
    let mut x = rect.left() + MARGINS.0;
    let y = rect.top() + 4.0;
    let items: [(&str, Color32); 6] = [
        ("T60 short", style::SHORT_T60),
        ("long", style::LONG_T60),
        ("live level", style::LIVE),
        ("pruned", style::PRUNED),
        ("muted", style::MUTED),
        ("× truncated", style::TRUNCATED),
    ];
    for (label, colour) in items {
        painter.rect_filled(
            Rect::from_min_size(pos2(x, y + 2.0), vec2(8.0, 8.0)),
            CornerRadius::same(1),
            colour,
        );
        let galley = painter.layout_no_wrap(label.to_string(), font.clone(), style::LABEL);
        let width = galley.size().x;
        painter.galley(pos2(x + 11.0, y), galley, style::LABEL);
        x += width + 22.0;
    }
}

/// A small × centred on `c`.
pub fn cross(painter: &egui::Painter, c: Pos2, r: f32, colour: Color32) {
    let stroke = Stroke::new(1.5, colour);
    painter.line_segment([c + vec2(-r, -r), c + vec2(r, r)], stroke);
    painter.line_segment([c + vec2(-r, r), c + vec2(r, -r)], stroke);
}
