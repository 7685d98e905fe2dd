//! The editor's window contents: the layout of the widgets and the flow between them, the
//! plugin's parameters and bank, and what the audio thread publishes.

use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::Duration;

use egui::{vec2, CentralPanel, Panel, Pos2, Rect, RichText, ScrollArea, Ui};
use nice_plug::context::gui::GuiContext;
use nice_plug::prelude::ParamSetter;
use nice_plug_egui::baseview::HandlerError;
use nice_plug_egui::{Frame, NiceEguiApp};

use super::bank_browser::{BankBrowser, Loaded};
use super::meters::Meters;
use super::mode_view::{ModeView, ViewInput};
use super::session::BankSession;
use super::strike_pad::StrikePad;
use super::window_size::WindowSize;
use super::{bank_info, mode_editor, params_panel, style};
use super::{Audition, EditorLinks, EditorShared, Host, MeterReading, METER_INTERVAL_S};
use crate::bank::factory::bank_from_state;
use crate::bank::summary::BankSummary;
use crate::params::ModalParams;

mod flow;

/// Reads the plugin's last problem loading a bank in the background, if any.
pub type BankErrorSource = Arc<dyn Fn() -> Option<String> + Send + Sync>;

/// Share of the central area's height the mode view takes.
const MODE_VIEW_SHARE: f32 = 0.58;
/// Smallest height of the mode view, in points.
const MODE_VIEW_MIN_HEIGHT: f32 = 180.0;
/// Share of the window's width each side panel starts with.
const SIDE_PANEL_SHARE: f32 = 0.25;
/// Narrowest and widest default width of the side panels, in points.
const SIDE_PANEL_WIDTH: (f32, f32) = (220.0, 320.0);
/// Largest share of the window's width a side panel can be resized to.
const SIDE_PANEL_MAX_SHARE: f32 = 0.28;
/// Share of the central area's width the strike pad takes, beside the mode editor.
const STRIKE_PAD_SHARE: f32 = 0.6;
/// Share of the bank panel's height the bank's facts start with, below the browser.
const BANK_FACTS_SHARE: f32 = 0.3;
/// Least height of the bank's facts, in points.
const BANK_FACTS_MIN_HEIGHT: f32 = 80.0;
/// Largest share of the bank panel's height the bank's facts can be resized to: the browser
/// keeps the rest.
const BANK_FACTS_MAX_SHARE: f32 = 0.8;

/// Where the widgets were drawn, in points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EditorLayout {
    /// The mode view's plotting area.
    pub mode_view: Rect,
    /// The strike pad's area (positions 0 to 1 on each axis, y up).
    pub strike_area: Rect,
    /// The whole strike pad, the positions' names included.
    pub strike_pad: Rect,
    /// The visible part of the list of factory banks.
    pub bank_list: Rect,
    /// The user banks, loading and saving, below the list of factory banks.
    pub bank_files: Rect,
}

/// The editor. Lives as long as the plugin instance, across openings of the window.
pub struct EditorApp {
    /// The plugin's parameters and bank.
    params: Arc<ModalParams>,
    /// Meters and the strike pad's queue.
    shared: Arc<EditorShared>,
    /// The background loader's last error.
    bank_error: BankErrorSource,
    /// Whether the plugin is the effect.
    is_effect: bool,
    /// The host's context while the window is open.
    gui_context: Option<GuiContext>,
    /// The bank shown and edited.
    session: BankSession,
    /// Why the bank saved in the plugin state could not be read, if it could not.
    state_error: Option<String>,
    /// Factory banks, user banks, loading and saving.
    browser: BankBrowser,
    /// The mode view.
    view: ModeView,
    /// The strike pad.
    pad: StrikePad,
    /// The meters.
    meters: Meters,
    /// Live energy of each mode in the engine's order, as last read.
    energies: Vec<Option<f32>>,
    /// The same by index in the bank, when it belongs to the bank shown.
    energy_by_mode: Vec<Option<f32>>,
    /// Whether each mode is switched off by pruning, as published (prepared order).
    pruned: Vec<bool>,
    /// The same by index in the bank.
    pruned_by_mode: Vec<bool>,
    /// Whether `energy_by_mode` belongs to the bank shown.
    energies_valid: bool,
    /// The bank's summary, with the session version it was made for.
    summary: Option<(u64, BankSummary)>,
    /// Input time of the last frame, in seconds.
    last_time_s: Option<f64>,
    /// Whether the context has the editor's look.
    styled: bool,
    /// The window's size, saved with the project.
    window: WindowSize,
}

impl EditorApp {
    /// An editor for the plugin behind `links`, with the platform's user bank folder.
    pub fn new(links: EditorLinks) -> Self {
        let EditorLinks {
            params,
            shared,
            bank_error,
            is_effect,
        } = links;
        let generation = params.bank.generation.load(Ordering::Acquire);
        let json = params.bank.json_text();
        let (bank, state_error) = match bank_from_state(&json) {
            Ok(bank) => (bank, None),
            Err(e) => (
                bank_from_state("").expect("the default factory bank exists"),
                Some(e),
            ),
        };
        Self {
            params,
            shared,
            bank_error,
            is_effect,
            gui_context: None,
            session: BankSession::new(bank, "Plugin state", generation),
            state_error,
            browser: BankBrowser::new(BankBrowser::default_user_dir()),
            view: ModeView::default(),
            pad: StrikePad::default(),
            meters: Meters::default(),
            energies: Vec::new(),
            energy_by_mode: Vec::new(),
            pruned: Vec::new(),
            pruned_by_mode: Vec::new(),
            energies_valid: false,
            summary: None,
            last_time_s: None,
            styled: false,
            window: WindowSize::new(),
        }
    }

    /// Uses `dir` as the user bank folder.
    pub fn with_user_dir(mut self, dir: PathBuf) -> Self {
        self.browser = BankBrowser::new(Some(dir));
        self
    }

    /// The bank shown and edited.
    pub fn session(&self) -> &BankSession {
        &self.session
    }

    /// The bank shown, to edit.
    pub fn session_mut(&mut self) -> &mut BankSession {
        &mut self.session
    }

    /// The selected mode, by index in the bank.
    pub fn selected_mode(&self) -> Option<usize> {
        self.view.selected
    }

    /// Selects mode `i` (by index in the bank).
    pub fn select_mode(&mut self, i: Option<usize>) {
        self.view.selected = i;
    }

    /// The mode under the pointer in the last frame.
    pub fn hovered_mode(&self) -> Option<usize> {
        self.view.hovered()
    }

    /// How many stems the mode view drew in the last frame.
    pub fn stems_drawn(&self) -> usize {
        self.view.stems_drawn()
    }

    /// How many live levels and truncation marks the mode view drew in the last frame.
    pub fn marks_drawn(&self) -> (usize, usize) {
        self.view.marks_drawn()
    }

    /// How many of the live levels drawn in the last frame were of modes switched off by
    /// pruning (drawn hollow).
    pub fn pruned_drawn(&self) -> usize {
        self.view.pruned_drawn()
    }

    /// Where the mode view drew mode `i`'s stem head in the last frame.
    pub fn stem_head(&self, i: usize) -> Option<Pos2> {
        self.view.head(i)
    }

    /// Where the last frame put the widgets.
    pub fn layout(&self) -> EditorLayout {
        let (bank_list, bank_files) = self.browser.rects();
        EditorLayout {
            mode_view: self.view.plot_rect(),
            strike_area: self.pad.area(),
            strike_pad: self.pad.rect(),
            bank_list,
            bank_files,
        }
    }

    /// How many factory banks the browser's list showed whole in the last frame.
    pub fn factory_banks_shown(&self) -> usize {
        self.browser.factory_shown()
    }

    /// The positions' names the strike pad wrote in the last frame, with where.
    pub fn strike_pad_labels(&self) -> &[(String, Rect)] {
        self.pad.labels()
    }

    /// The meters' last reading.
    pub fn meter_reading(&self) -> MeterReading {
        self.meters.reading()
    }

    /// The names of the parameters the parameter panel shows.
    pub fn shown_parameter_names(&self) -> Vec<String> {
        params_panel::shown_names(&self.params)
    }

    /// The user bank folder.
    pub fn user_dir(&self) -> Option<&Path> {
        self.browser.user_dir()
    }

    /// The browser's last message: text and whether it is an error.
    pub fn browser_message(&self) -> Option<(&str, bool)> {
        self.browser.message()
    }

    /// Loads the bank file at `path` as the browser's "Load" does.
    pub fn load_file(&mut self, path: &Path, setter: &ParamSetter) -> bool {
        match self.browser.load_file(path) {
            Some(loaded) => {
                self.install(loaded, setter);
                true
            }
            None => false,
        }
    }

    /// Saves the bank heard under `name` in the user folder, as the browser's "Save" does.
    pub fn save_as(&mut self, name: &str) -> Option<PathBuf> {
        self.browser.save(&self.session, name)
    }

    /// Draws the whole editor into `ui` and acts on what the player did. Needs no window.
    pub fn draw(&mut self, ui: &mut Ui, setter: &ParamSetter) {
        if !self.styled {
            style::apply(ui.ctx());
            self.styled = true;
        }
        self.sync_bank();
        self.read_meters(ui);
        self.shortcuts(ui);
        let params = self.params.clone();
        let shared = self.shared.clone();
        let positions = self.session.positions();
        let fixed_axes = [!positions.moves_along(0), !positions.moves_along(1)];
        let width = ui.available_width();
        let side_width = (width * SIDE_PANEL_SHARE).clamp(SIDE_PANEL_WIDTH.0, SIDE_PANEL_WIDTH.1);
        let side_range = SIDE_PANEL_WIDTH.0.min(side_width)..=(width * SIDE_PANEL_MAX_SHARE);
        let host = Host {
            params: &params,
            setter,
            shared: &shared,
        };

        Panel::top("header").show(ui, |ui| self.header(ui));
        Panel::bottom("meters").show(ui, |ui| {
            ui.add_space(2.0);
            self.meters
                .show(ui, params.voices.polyphony.value().max(1) as u32);
            ui.add_space(2.0);
        });
        Panel::left("parameters")
            .resizable(true)
            .default_size(side_width)
            .size_range(side_range.clone())
            .show(ui, |ui| {
                ScrollArea::vertical().id_salt("parameters").show(ui, |ui| {
                    params_panel::show(ui, &params, setter, side_width, fixed_axes)
                });
            });
        let loaded = Panel::right("bank")
            .resizable(true)
            .default_size(side_width)
            .size_range(side_range.clone())
            .show(ui, |ui| self.bank_panel(ui))
            .inner;
        CentralPanel::default().show(ui, |ui| self.central(ui, &host));
        if let Some(loaded) = loaded {
            self.install(loaded, setter);
        }

        // An edit gesture ends once the pointer is up and no field is being typed in.
        let idle = ui.input(|i| !i.pointer.any_down()) && ui.memory(|m| m.focused().is_none());
        if idle {
            self.session.end_gesture();
        }
        self.push_bank();
        flow::resize_corner(ui);
        self.window.update(ui, &self.params.editor_size);
        ui.ctx()
            .request_repaint_after(Duration::from_secs_f32(METER_INTERVAL_S));
    }

    fn header(&mut self, ui: &mut Ui) {
        ui.horizontal(|ui| {
            let title = if self.is_effect {
                "Modal Resonator FX"
            } else {
                "Modal Resonator"
            };
            ui.label(RichText::new(title).strong().size(16.0));
            ui.separator();
            ui.label(RichText::new(&self.session.bank().name).size(14.0));
            if self.session.is_edited() {
                ui.label(RichText::new("edited").italics().weak());
            }
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                let redo = ui.add_enabled(self.session.can_redo(), egui::Button::new("Redo"));
                if redo.on_hover_text("Ctrl+Shift+Z").clicked() {
                    self.session.redo();
                }
                let undo = ui.add_enabled(self.session.can_undo(), egui::Button::new("Undo"));
                if undo.on_hover_text("Ctrl+Z").clicked() {
                    self.session.undo();
                }
            });
        });
    }

    /// The bank panel: the bank's facts below, in a share of the height the player can change;
    /// the browser above, its list of factory banks taking the rest. Returns a bank the player
    /// chose in the browser.
    fn bank_panel(&mut self, ui: &mut Ui) -> Option<Loaded> {
        let height = ui.available_height();
        Panel::bottom("bank facts")
            .frame(egui::Frame::NONE)
            .resizable(true)
            .default_size(height * BANK_FACTS_SHARE)
            .size_range(BANK_FACTS_MIN_HEIGHT..=height * BANK_FACTS_MAX_SHARE)
            .show(ui, |ui| {
                ui.add_space(ui.spacing().item_spacing.y);
                ScrollArea::vertical()
                    .id_salt("bank facts")
                    .show(ui, |ui| self.bank_facts(ui));
            });
        self.browser.show(ui, &self.session)
    }

    /// Problems with the bank, then what the bank is.
    fn bank_facts(&mut self, ui: &mut Ui) {
        if let Some(error) = (self.bank_error)() {
            ui.label(
                RichText::new(format!("The plugin could not load a bank:\n{error}"))
                    .color(style::ERROR),
            );
        }
        if let Some(error) = &self.state_error {
            ui.label(
                RichText::new(format!("The saved bank could not be read:\n{error}"))
                    .color(style::ERROR),
            );
        }
        let version = self.session.version();
        if self.summary.as_ref().is_none_or(|(v, _)| *v != version) {
            self.summary = Some((version, BankSummary::of(self.session.bank())));
        }
        if let Some((_, summary)) = &self.summary {
            bank_info::show(
                ui,
                self.session.bank(),
                summary,
                self.session.origin(),
                self.session.is_edited(),
            );
        }
    }

    /// The mode view above the strike pad and the mode editor.
    fn central(&mut self, ui: &mut Ui, host: &Host) {
        let params = host.params;
        let weights = self.session.positions().weights(
            params.strike.strike_x.value(),
            params.strike.strike_y.value(),
        );
        let available = ui.available_size();
        let height = (available.y * MODE_VIEW_SHARE).max(MODE_VIEW_MIN_HEIGHT);
        let input = ViewInput {
            weights,
            energy: self.energies_valid.then_some(&self.energy_by_mode[..]),
            pruned: self.energies_valid.then_some(&self.pruned_by_mode[..]),
            sounding: self.meters.reading().voices > 0,
        };
        self.view
            .show(ui, vec2(available.x, height), &mut self.session, &input);
        ui.separator();
        let names: Vec<String> = self
            .session
            .bank()
            .positions
            .iter()
            .map(|p| p.name.clone())
            .collect();
        let below = ui.available_size();
        let pad_width = (below.x * STRIKE_PAD_SHARE).floor();
        let layout = egui::Layout::top_down(egui::Align::Min);
        ui.horizontal_top(|ui| {
            ui.allocate_ui_with_layout(vec2(pad_width, below.y), layout, |ui| {
                ui.label(RichText::new("Strike pad").strong());
                let size = vec2(pad_width, ui.available_height());
                self.pad
                    .show(ui, size, self.session.positions(), &names, host);
            });
            ui.separator();
            ui.allocate_ui_with_layout(ui.available_size(), layout, |ui| {
                ui.label(RichText::new("Selected mode").strong());
                mode_editor::show(ui, &mut self.session, self.view.selected, &weights);
            });
        });
    }
}

impl NiceEguiApp for EditorApp {
    fn build(
        &mut self,
        egui_ctx: egui::Context,
        nice_gui_ctx: GuiContext,
        _frame: &mut Frame,
    ) -> Result<(), HandlerError> {
        style::apply(&egui_ctx);
        self.styled = true;
        self.gui_context = Some(nice_gui_ctx);
        self.window.reopen();
        Ok(())
    }

    fn ui(&mut self, ui: &mut Ui, _frame: &mut Frame) {
        let Some(context) = self.gui_context.clone() else {
            return;
        };
        let setter = context.param_setter();
        self.draw(ui, &setter);
    }

    fn editor_closed(&mut self) {
        // A strike held while the window closed must not stay held.
        if self.pad.forget_hold() {
            self.shared.request(Audition::Release);
        }
        self.gui_context = None;
        self.styled = false;
    }
}
