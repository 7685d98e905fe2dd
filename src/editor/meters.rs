//! Meters: voices in use, modes computed against modes in the bank, output level and the audio
//! thread's load, from what the audio thread publishes.

use egui::{CornerRadius, Rect, Sense, Ui, Vec2};

use super::style;
use super::MeterReading;

/// Lowest level the output meter shows, in dBFS.
const FLOOR_DB: f32 = -60.0;
/// Highest level the output meter shows, in dBFS.
const CEILING_DB: f32 = 6.0;
/// How fast the level display falls, in dB per second (a peak meter's release).
const FALL_DB_PER_S: f32 = 24.0;
/// How long a peak is held, in seconds.
const HOLD_S: f32 = 1.5;
/// Time constant of the load display, in seconds.
const LOAD_SMOOTHING_S: f32 = 0.5;

/// The meters' display state: values smoothed for reading.
#[derive(Debug, Clone)]
pub struct Meters {
    /// The last reading.
    last: MeterReading,
    /// Output level shown, in dBFS.
    level_db: f32,
    /// Highest level of the last [`HOLD_S`], in dBFS.
    hold_db: f32,
    /// Seconds since `hold_db` was set.
    hold_age_s: f32,
    /// DSP load shown, 0 to 1 and beyond.
    load: f32,
}

impl Default for Meters {
    fn default() -> Self {
        Self {
            last: MeterReading::default(),
            level_db: FLOOR_DB,
            hold_db: FLOOR_DB,
            hold_age_s: 0.0,
            load: 0.0,
        }
    }
}

impl Meters {
    /// Takes a new reading, `dt_s` seconds after the last.
    pub fn update(&mut self, reading: MeterReading, dt_s: f32) {
        let dt_s = dt_s.clamp(0.0, 1.0);
        let db = 20.0 * reading.peak.max(1e-9).log10();
        self.level_db = db.max(self.level_db - FALL_DB_PER_S * dt_s).max(FLOOR_DB);
        self.hold_age_s += dt_s;
        if db >= self.hold_db || self.hold_age_s > HOLD_S {
            self.hold_db = db.max(FLOOR_DB);
            self.hold_age_s = 0.0;
        }
        let k = 1.0 - (-dt_s / LOAD_SMOOTHING_S).exp();
        self.load += (reading.dsp_load - self.load) * k;
        self.load = self.load.max(reading.dsp_load * 0.5);
        self.last = reading;
    }

    /// The last reading.
    pub fn reading(&self) -> MeterReading {
        self.last
    }

    /// Draws the meters in a row; `polyphony` is the voice limit.
    pub fn show(&self, ui: &mut Ui, polyphony: u32) {
        let r = self.last;
        ui.horizontal(|ui| {
            ui.label("Voices");
            bar(ui, r.voices as f32 / polyphony.max(1) as f32, false);
            ui.label(format!("{} / {polyphony}", r.voices));
            ui.separator();
            ui.label("Modes");
            let per_voice = r.live_modes as f32 / r.voices.max(1) as f32;
            bar(ui, per_voice / r.bank_modes.max(1) as f32, false);
            let pruned = if r.pruned_modes > 0 {
                format!(" · {} pruned", r.pruned_modes)
            } else {
                String::new()
            };
            ui.label(format!(
                "{} live{pruned} · {} computed · bank {}",
                r.live_modes, r.computed_modes, r.bank_modes
            ))
            .on_hover_text(
                "Live: modes sounding over all voices. Pruned: live modes switched off by \
                 perceptual pruning or the mode budget, their state carried without computing \
                 them. Computed: modes the resonators advance per sample (live modes not pruned, \
                 plus padding to whole SIMD rows). The bar compares one voice's live modes with \
                 the bank's",
            );
            ui.separator();
            ui.label("Output");
            let t = (self.level_db - FLOOR_DB) / (CEILING_DB - FLOOR_DB);
            let hold = (self.hold_db - FLOOR_DB) / (CEILING_DB - FLOOR_DB);
            level_bar(ui, t, hold, self.hold_db > 0.0);
            ui.label(if self.hold_db <= FLOOR_DB {
                "-inf dBFS".to_string()
            } else {
                format!("{:.1} dBFS", self.hold_db)
            });
            ui.separator();
            ui.label("DSP load");
            bar(ui, self.load, self.load > 0.8);
            ui.label(format!("{:.1} %", self.load * 100.0))
                .on_hover_text("Time spent processing a block over the block's duration");
        });
    }
}

/// Size of a meter bar, in points.
const BAR: Vec2 = Vec2::new(90.0, 12.0);

/// A horizontal bar filled to `t` (0 to 1).
fn bar(ui: &mut Ui, t: f32, hot: bool) {
    let (rect, _) = ui.allocate_exact_size(BAR, Sense::hover());
    bar_at(ui, rect, t, hot);
}

/// The output level bar: level `t`, a hold mark at `hold` (0 to 1), red when it clipped.
fn level_bar(ui: &mut Ui, t: f32, hold: f32, clipped: bool) {
    let (rect, _) = ui.allocate_exact_size(BAR, Sense::hover());
    bar_at(ui, rect, t, false);
    let x = rect.left() + rect.width() * hold.clamp(0.0, 1.0);
    let colour = if clipped {
        style::METER_HOT
    } else {
        style::LABEL
    };
    ui.painter().vline(x, rect.y_range(), (2.0, colour));
    // 0 dBFS.
    let zero = rect.left() + rect.width() * (-FLOOR_DB / (CEILING_DB - FLOOR_DB));
    ui.painter().vline(zero, rect.y_range(), (1.0, style::GRID));
}

/// A bar in `rect` filled to `t` (0 to 1), red when `hot`.
fn bar_at(ui: &Ui, rect: Rect, t: f32, hot: bool) {
    let painter = ui.painter();
    painter.rect_filled(rect, CornerRadius::same(2), style::PLOT_BG);
    let mut fill = rect;
    fill.set_width(rect.width() * t.clamp(0.0, 1.0));
    let colour = if hot { style::METER_HOT } else { style::METER };
    painter.rect_filled(fill, CornerRadius::same(2), colour);
}
