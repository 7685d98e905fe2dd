//! The flow between the plugin and the editor: following the bank the plugin saves, handing it
//! edited and loaded banks, taking the audio thread's meters, and resizing the window.

use std::sync::atomic::Ordering;

use egui::{pos2, vec2, Key, KeyboardShortcut, Modifiers, Rect, Sense, Ui, ViewportCommand};
use nice_plug::prelude::ParamSetter;
use nice_plug_egui::resizable_window::paint_resize_corner;

use super::EditorApp;
use crate::bank::factory::bank_from_state;
use crate::bank::io::bank_to_json;
use crate::editor::bank_browser::{apply_bank_defaults, Loaded};
use crate::editor::session::BankSession;
use crate::editor::{EDITOR_MIN_SIZE, METER_INTERVAL_S};

impl EditorApp {
    /// Follows the bank saved in the plugin when something else changed it (a host restoring
    /// state); a bank that cannot be read leaves the one shown.
    pub(super) fn sync_bank(&mut self) {
        let generation = self.params.bank.generation.load(Ordering::Acquire);
        if generation == self.session.generation() {
            return;
        }
        let json = self.params.bank.json_text();
        match bank_from_state(&json) {
            Ok(bank) => {
                self.session = BankSession::new(bank, "Plugin state", generation);
                self.view.reset();
                self.state_error = None;
            }
            Err(e) => {
                self.state_error = Some(e);
                self.session.set_generation(generation);
            }
        }
    }

    /// Plays `loaded` from now on, with its parameter defaults.
    pub(super) fn install(&mut self, loaded: Loaded, setter: &ParamSetter) {
        self.params.bank.replace(bank_to_json(&loaded.bank));
        let generation = self.params.bank.generation.load(Ordering::Acquire);
        apply_bank_defaults(&loaded.bank, &self.params, setter);
        self.session = BankSession::new(loaded.bank, loaded.origin, generation);
        self.view.reset();
        self.state_error = None;
    }

    /// Hands the edited bank to the plugin once an edit is complete.
    pub(super) fn push_bank(&mut self) {
        if let Some(bank) = self.session.take_push() {
            self.params.bank.replace(bank_to_json(&bank));
            let generation = self.params.bank.generation.load(Ordering::Acquire);
            self.session.set_generation(generation);
        }
    }

    /// Takes the audio thread's latest meters and mode energies.
    pub(super) fn read_meters(&mut self, ui: &Ui) {
        let now_s = ui.input(|i| i.time);
        let dt_s = self
            .last_time_s
            .map_or(METER_INTERVAL_S, |t| (now_s - t) as f32);
        self.last_time_s = Some(now_s);
        self.meters.update(self.shared.take_reading(), dt_s);

        let n = self.session.num_modes();
        let valid = self.shared.read_energies(
            self.session.generation(),
            &mut self.energies,
            &mut self.pruned,
        );
        self.energies_valid = valid && self.energies.len() == n;
        self.energy_by_mode.clear();
        self.energy_by_mode.resize(n, None);
        self.pruned_by_mode.clear();
        self.pruned_by_mode.resize(n, false);
        if self.energies_valid {
            for ((&i, e), &p) in self
                .session
                .order()
                .iter()
                .zip(&self.energies)
                .zip(&self.pruned)
            {
                self.energy_by_mode[i] = *e;
                self.pruned_by_mode[i] = p;
            }
        }
    }

    /// Undo and redo from the keyboard, unless a text field has the keys.
    pub(super) fn shortcuts(&mut self, ui: &mut Ui) {
        if ui.memory(|m| m.focused().is_some()) {
            return;
        }
        let redo = KeyboardShortcut::new(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
        let undo = KeyboardShortcut::new(Modifiers::COMMAND, Key::Z);
        if ui.input_mut(|i| i.consume_shortcut(&redo)) {
            self.session.redo();
        } else if ui.input_mut(|i| i.consume_shortcut(&undo)) {
            self.session.undo();
        }
    }
}

/// A corner that resizes the window by dragging, for hosts whose windows have no frame of their
/// own to drag.
pub(super) fn resize_corner(ui: &mut Ui) {
    let screen = ui.ctx().content_rect();
    let size = vec2(16.0, 16.0);
    let rect = Rect::from_min_size(pos2(screen.right(), screen.bottom()) - size, size);
    let response = ui.interact(rect, ui.scope_id().with("resize corner"), Sense::drag());
    if response.dragged() {
        let wanted = screen.size() + response.drag_delta();
        let min = vec2(EDITOR_MIN_SIZE.0, EDITOR_MIN_SIZE.1);
        ui.send_viewport_cmd(ViewportCommand::InnerSize(wanted.max(min)));
    }
    paint_resize_corner(ui, &response);
}
