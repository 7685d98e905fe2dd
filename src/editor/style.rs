//! Colours and spacing shared by the editor's widgets.

use egui::{Color32, Context, Visuals};

/// Background of the plots.
pub const PLOT_BG: Color32 = Color32::from_rgb(18, 20, 26);
/// Grid lines.
pub const GRID: Color32 = Color32::from_rgb(44, 48, 58);
/// Axis labels.
pub const LABEL: Color32 = Color32::from_rgb(150, 156, 170);
/// Stems of the shortest-ringing modes.
pub const SHORT_T60: Color32 = Color32::from_rgb(70, 90, 190);
/// Stems of the longest-ringing modes.
pub const LONG_T60: Color32 = Color32::from_rgb(255, 196, 70);
/// Live energy over the stems.
pub const LIVE: Color32 = Color32::from_rgb(70, 230, 220);
/// Modes not heard (muted, or not soloed).
pub const MUTED: Color32 = Color32::from_rgb(85, 85, 92);
/// Modes dropped by truncation while the object sounds.
pub const TRUNCATED: Color32 = Color32::from_rgb(230, 90, 80);
/// Live levels of modes switched off by pruning (drawn hollow).
pub const PRUNED: Color32 = Color32::from_rgb(170, 140, 255);
/// The selected mode.
pub const SELECTED: Color32 = Color32::WHITE;
/// Strike positions of the bank.
pub const POSITION: Color32 = Color32::from_rgb(200, 200, 210);
/// The strike point.
pub const STRIKE: Color32 = Color32::from_rgb(255, 140, 60);
/// Error messages.
pub const ERROR: Color32 = Color32::from_rgb(255, 110, 100);
/// Messages that something worked.
pub const OK: Color32 = Color32::from_rgb(120, 210, 130);
/// Meter bars.
pub const METER: Color32 = Color32::from_rgb(90, 190, 120);
/// Meter bars near full scale.
pub const METER_HOT: Color32 = Color32::from_rgb(235, 80, 70);

/// Shortest T60 the stem colours tell apart, in seconds.
pub const T60_SHORT_S: f64 = 0.05;
/// Longest T60 the stem colours tell apart, in seconds.
pub const T60_LONG_S: f64 = 20.0;

/// Sets the editor's look on a new egui context.
pub fn apply(ctx: &Context) {
    let mut visuals = Visuals::dark();
    visuals.panel_fill = Color32::from_rgb(30, 33, 40);
    visuals.window_fill = visuals.panel_fill;
    ctx.set_visuals(visuals);
}

/// `a` to `b` by `t` (0 to 1), per channel.
pub fn mix(a: Color32, b: Color32, t: f32) -> Color32 {
    let t = t.clamp(0.0, 1.0);
    let m = |x: u8, y: u8| (x as f32 + (y as f32 - x as f32) * t).round() as u8;
    Color32::from_rgb(m(a.r(), b.r()), m(a.g(), b.g()), m(a.b(), b.b()))
}

/// The colour of a stem for a mode ringing `t60_s` seconds: log scale from [`T60_SHORT_S`] to
/// [`T60_LONG_S`].
pub fn t60_colour(t60_s: f64) -> Color32 {
    let t = if t60_s.is_finite() {
        (t60_s / T60_SHORT_S).max(1e-9).log10() / (T60_LONG_S / T60_SHORT_S).log10()
    } else {
        1.0
    };
    mix(SHORT_T60, LONG_T60, t as f32)
}
