//! Editing the selected mode by typing or dragging numbers: frequency, T60 and gain at the strike
//! position; muting and soloing it.

use egui::{DragValue, Grid, RichText, Ui};

use super::session::BankSession;
use crate::bank::summary::note_name;
use crate::engine::PositionWeights;
use crate::units::{decay_to_t60_s, t60_to_decay};

/// Longest T60 an edit sets, in seconds (decay 0, ringing forever, stays as loaded).
const MAX_EDIT_T60_S: f64 = 1000.0;
/// Shortest T60 an edit sets, in seconds.
const MIN_EDIT_T60_S: f64 = 0.001;
/// Gain range of the gain field, in dB.
const GAIN_DB_RANGE: (f64, f64) = (-120.0, 60.0);

/// Draws the editor for mode `selected` of `session` (or a hint when none is).
pub fn show(
    ui: &mut Ui,
    session: &mut BankSession,
    selected: Option<usize>,
    weights: &PositionWeights,
) {
    let Some(i) = selected.filter(|&i| i < session.num_modes()) else {
        ui.label(RichText::new("Click a stem to select a mode.").weak());
        mutes_row(ui, session);
        return;
    };
    ui.label(RichText::new(format!("Mode {} of {}", i + 1, session.num_modes())).strong());
    Grid::new("mode editor")
        .num_columns(2)
        .spacing([8.0, 4.0])
        .show(ui, |ui| {
            frequency_rows(ui, session, i);
            t60_row(ui, session, i);
            gain_rows(ui, session, i, weights);
        });
    mute_solo_row(ui, session, i);
    mutes_row(ui, session);
}

/// Mode `i`'s frequency, to drag, and the note it is nearest.
fn frequency_rows(ui: &mut Ui, session: &mut BankSession, i: usize) {
    ui.label("Frequency");
    let mut freq_hz = session.bank().modes[i].freq_hz;
    let speed = (freq_hz * 0.002).max(0.01);
    let response = ui.add(
        DragValue::new(&mut freq_hz)
            .speed(speed)
            .range(1.0..=1e6)
            .max_decimals(3)
            .suffix(" Hz"),
    );
    if response.changed() {
        session.set_freq_hz(i, freq_hz);
    }
    ui.end_row();

    ui.label("Note");
    ui.label(note_name(session.bank().modes[i].freq_hz));
    ui.end_row();
}

/// Mode `i`'s T60, to drag; a mode that does not decay offers a finite one instead.
fn t60_row(ui: &mut Ui, session: &mut BankSession, i: usize) {
    ui.label("T60");
    let decay_per_s = session.bank().modes[i].decay_per_s;
    if decay_per_s > 0.0 {
        let mut t60_s = decay_to_t60_s(decay_per_s);
        let speed = (t60_s * 0.005).max(0.0005);
        let response = ui.add(
            DragValue::new(&mut t60_s)
                .speed(speed)
                .range(MIN_EDIT_T60_S..=MAX_EDIT_T60_S)
                .max_decimals(4)
                .suffix(" s"),
        );
        if response.changed() {
            session.set_decay_per_s(i, t60_to_decay(t60_s));
        }
    } else if ui
        .button("690 s (decay 0 plays at the engine's floor): set 10 s")
        .clicked()
    {
        session.set_decay_per_s(i, t60_to_decay(10.0));
    }
    ui.end_row();
}

/// Mode `i`'s gain where the strike is (`weights`), in dB to drag, and its polarity to flip.
fn gain_rows(ui: &mut Ui, session: &mut BankSession, i: usize, weights: &PositionWeights) {
    ui.label("Gain at strike");
    let gain = session.gain_at(i, weights);
    let mut gain_db = 20.0 * gain.abs().max(1e-9).log10();
    let response = ui.add(
        DragValue::new(&mut gain_db)
            .speed(0.1)
            .range(GAIN_DB_RANGE.0..=GAIN_DB_RANGE.1)
            .max_decimals(2)
            .suffix(" dB"),
    );
    if response.changed() {
        let sign = if gain < 0.0 { -1.0 } else { 1.0 };
        session.set_gain_at(i, weights, sign * 10f64.powf(gain_db / 20.0));
    }
    ui.end_row();

    ui.label("Polarity");
    let label = if gain < 0.0 {
        "inverted (−)"
    } else {
        "normal (+)"
    };
    if ui.button(label).on_hover_text("Flip the sign").clicked() {
        session.set_gain_at(i, weights, -gain);
        session.end_gesture();
    }
    ui.end_row();
}

/// Mute and solo buttons of mode `i`.
fn mute_solo_row(ui: &mut Ui, session: &mut BankSession, i: usize) {
    ui.horizontal(|ui| {
        if ui
            .selectable_label(session.is_muted(i), "Mute")
            .on_hover_text("Silence this mode (left out when saved)")
            .clicked()
        {
            session.toggle_mute(i);
        }
        if ui
            .selectable_label(session.is_soloed(i), "Solo")
            .on_hover_text("Hear only the soloed modes")
            .clicked()
        {
            session.toggle_solo(i);
        }
    });
}

/// How many modes are muted or soloed, and a button to clear them.
fn mutes_row(ui: &mut Ui, session: &mut BankSession) {
    if !session.has_mutes() {
        return;
    }
    let heard = (0..session.num_modes())
        .filter(|&i| session.is_audible(i))
        .count();
    ui.horizontal(|ui| {
        ui.label(format!("{heard} of {} modes heard", session.num_modes()));
        if ui.button("Clear mute/solo").clicked() {
            session.clear_mutes();
        }
    });
}
