//! The bank browser: factory banks, the user folder, loading any file by path and saving the bank
//! being edited. Files are read and checked here, on the GUI thread; a bad file leaves the bank
//! playing as it was and shows what is wrong (file, JSON path, what was expected).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use egui::{vec2, Align, Frame, Layout, Panel, Rect, RichText, ScrollArea, TextEdit, Ui};
use nice_plug::prelude::ParamSetter;

use super::session::BankSession;
use super::style;
use crate::bank::factory::{factory_bank, factory_banks, factory_slug};
use crate::bank::{load_bank_file, save_bank_file, Bank};
use crate::engine::Controls;
use crate::params::{ExciterChoice, MaterialChoice, ModalParams};

/// How often the user folder is listed again while the browser shows.
const RESCAN_INTERVAL: Duration = Duration::from_secs(2);
/// Most height the list of user banks takes, in points (the factory banks take the rest).
const USER_LIST_HEIGHT: f32 = 130.0;

/// A bank read and checked, ready to play.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The bank.
    pub bank: Bank,
    /// Where it came from, for display.
    pub origin: String,
}

/// A factory bank in the list.
#[derive(Debug, Clone)]
struct FactoryEntry {
    /// Its slug, to build it again.
    slug: String,
    /// Display name.
    name: String,
    /// Number of modes.
    num_modes: usize,
}

/// The browser's state.
#[derive(Debug, Clone)]
pub struct BankBrowser {
    /// The factory banks, listed when first shown.
    factory: Option<Vec<FactoryEntry>>,
    /// The user folder, if the platform has a data directory.
    user_dir: Option<PathBuf>,
    /// Bank files in the user folder, sorted.
    user_files: Vec<PathBuf>,
    /// When the user folder was last listed.
    scanned_at: Option<Instant>,
    /// The path typed to load.
    path_text: String,
    /// The name to save the edited bank under.
    save_name: String,
    /// The last outcome: text and whether it is an error.
    message: Option<(String, bool)>,
    /// Where the factory list showed in the last frame.
    factory_rect: Rect,
    /// How many factory banks the list showed whole in the last frame.
    factory_shown: usize,
    /// Where the user banks, loading and saving showed in the last frame.
    files_rect: Rect,
}

impl BankBrowser {
    /// A browser whose user folder is `user_dir`.
    pub fn new(user_dir: Option<PathBuf>) -> Self {
        Self {
            factory: None,
            user_dir,
            user_files: Vec::new(),
            scanned_at: None,
            path_text: String::new(),
            save_name: String::new(),
            message: None,
            factory_rect: Rect::NOTHING,
            factory_shown: 0,
            files_rect: Rect::NOTHING,
        }
    }

    /// The platform's data directory for the app, plus "banks": where user banks live.
    pub fn default_user_dir() -> Option<PathBuf> {
        directories::ProjectDirs::from("org", "Modal Resonator", "Modal Resonator")
            .map(|dirs| dirs.data_dir().join("banks"))
    }

    /// The user folder.
    pub fn user_dir(&self) -> Option<&Path> {
        self.user_dir.as_deref()
    }

    /// The last outcome shown: text and whether it is an error.
    pub fn message(&self) -> Option<(&str, bool)> {
        self.message.as_ref().map(|(m, e)| (m.as_str(), *e))
    }

    /// Where the factory list and, below it, the user banks with loading and saving showed in
    /// the last frame.
    pub fn rects(&self) -> (Rect, Rect) {
        (self.factory_rect, self.files_rect)
    }

    /// How many factory banks the list showed whole in the last frame.
    pub fn factory_shown(&self) -> usize {
        self.factory_shown
    }

    /// Reads and checks the bank file at `path`; on failure shows why and returns `None`.
    pub fn load_file(&mut self, path: &Path) -> Option<Loaded> {
        match load_bank_file(path) {
            Ok(bank) => {
                self.message = Some((format!("Loaded {}", path.display()), false));
                Some(Loaded {
                    bank,
                    origin: path.display().to_string(),
                })
            }
            Err(error) => {
                self.message = Some((format!("{error}\nThe bank playing is unchanged."), true));
                None
            }
        }
    }

    /// The factory bank `slug`.
    pub fn load_factory(&mut self, slug: &str) -> Option<Loaded> {
        let bank = factory_bank(slug)?;
        self.message = None;
        Some(Loaded {
            origin: format!("Factory bank {slug}"),
            bank,
        })
    }

    /// Saves `session`'s bank (the modes heard) under `name` in the user folder, creating it;
    /// checked first and written atomically. Returns the file written.
    pub fn save(&mut self, session: &BankSession, name: &str) -> Option<PathBuf> {
        let result = self.try_save(session, name);
        self.scanned_at = None;
        match result {
            Ok(path) => {
                self.message = Some((format!("Saved {}", path.display()), false));
                Some(path)
            }
            Err(message) => {
                self.message = Some((format!("Not saved: {message}"), true));
                None
            }
        }
    }

    fn try_save(&self, session: &BankSession, name: &str) -> Result<PathBuf, String> {
        if name.trim().is_empty() {
            return Err("give the bank a name".to_string());
        }
        let dir = self
            .user_dir
            .as_ref()
            .ok_or("this system has no data directory for user banks")?;
        let bank = session.saved_bank(name)?;
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
        let path = dir.join(format!("{}.json", factory_slug(&bank)));
        save_bank_file(&bank, &path).map_err(|e| e.to_string())?;
        Ok(path)
    }

    /// Lists the `*.json` files of the user folder again.
    fn rescan(&mut self) {
        self.scanned_at = Some(Instant::now());
        self.user_files.clear();
        let Some(dir) = &self.user_dir else { return };
        if let Ok(entries) = std::fs::read_dir(dir) {
            self.user_files = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| {
                    p.extension()
                        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
                })
                .collect();
            self.user_files.sort();
        }
    }

    /// Draws the browser in the height `ui` has: the user banks, loading and saving at the
    /// bottom, and above them the factory banks, listed in all the height left. Returns a bank
    /// the player chose, read and checked.
    pub fn show(&mut self, ui: &mut Ui, session: &BankSession) -> Option<Loaded> {
        let files = Panel::bottom("bank files")
            .frame(Frame::NONE)
            .show_separator_line(false)
            .show(ui, |ui| self.show_files(ui, session));
        self.files_rect = files.response.rect;
        let factory = self.show_factory(ui, session);
        let chosen = factory.and_then(|slug| self.load_factory(&slug));
        files
            .inner
            .and_then(|path| self.load_file(&path))
            .or(chosen)
    }

    /// The factory banks, in all the height `ui` has left; returns the slug of one clicked.
    fn show_factory(&mut self, ui: &mut Ui, session: &BankSession) -> Option<String> {
        let factory = self.factory.get_or_insert_with(|| {
            factory_banks()
                .iter()
                .map(|b| FactoryEntry {
                    slug: factory_slug(b),
                    name: b.name.clone(),
                    num_modes: b.modes.len(),
                })
                .collect()
        });
        ui.label(RichText::new("Factory banks").strong());
        let mut choice = None;
        let list = ScrollArea::vertical()
            .id_salt("factory banks")
            .max_height(ui.available_height())
            .auto_shrink([false, true])
            .show(ui, |ui| {
                for entry in factory.iter() {
                    let current = session.bank().name == entry.name;
                    let label = format!("{}  ·  {} modes", entry.name, entry.num_modes);
                    if ui.selectable_label(current, label).clicked() {
                        choice = Some(entry.slug.clone());
                    }
                }
            });
        let row_pitch = list.content_size.y / factory.len().max(1) as f32;
        let rows = (list.inner_rect.height() / row_pitch.max(1.0)).floor() as usize;
        self.factory_shown = rows.min(factory.len());
        self.factory_rect = list.inner_rect;
        choice
    }

    /// The user banks, a file to load and saving the bank being edited; returns a file chosen.
    fn show_files(&mut self, ui: &mut Ui, session: &BankSession) -> Option<PathBuf> {
        if self
            .scanned_at
            .is_none_or(|t| t.elapsed() > RESCAN_INTERVAL)
        {
            self.rescan();
        }
        ui.add_space(ui.spacing().item_spacing.y);
        ui.label(RichText::new("User banks").strong());
        match &self.user_dir {
            Some(dir) => {
                ui.label(RichText::new(dir.display().to_string()).small().weak());
            }
            None => {
                ui.label(RichText::new("no data directory on this system").weak());
            }
        }
        let mut file_choice = None;
        ScrollArea::vertical()
            .id_salt("user banks")
            .max_height(USER_LIST_HEIGHT)
            .show(ui, |ui| {
                if self.user_files.is_empty() {
                    ui.label(RichText::new("none yet: save one below").weak());
                }
                for path in &self.user_files {
                    let name = path.file_stem().map_or_else(
                        || path.display().to_string(),
                        |s| s.to_string_lossy().into_owned(),
                    );
                    if ui.selectable_label(false, name).clicked() {
                        file_choice = Some(path.clone());
                    }
                }
            });
        self.show_load_and_save(ui, session).or(file_choice)
    }

    /// A path to load and a name to save the bank being edited under, and the last outcome;
    /// returns the path when the player asks to load it.
    fn show_load_and_save(&mut self, ui: &mut Ui, session: &BankSession) -> Option<PathBuf> {
        let mut file_choice = None;
        ui.label(RichText::new("Load a file").strong());
        // Right to left, so the text field takes exactly the width the button leaves.
        let row = vec2(ui.available_width(), ui.spacing().interact_size.y);
        ui.allocate_ui_with_layout(row, Layout::right_to_left(Align::Center), |ui| {
            let load = ui.button("Load").clicked();
            let edit = TextEdit::singleline(&mut self.path_text)
                .hint_text("/path/to/bank.json")
                .desired_width(ui.available_width());
            let response = ui.add(edit);
            let entered = response.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if (load || entered) && !self.path_text.trim().is_empty() {
                file_choice = Some(PathBuf::from(self.path_text.trim()));
            }
        });

        ui.label(RichText::new("Save as").strong());
        if self.save_name.is_empty() {
            self.save_name = format!("{} edit", session.bank().name);
        }
        ui.allocate_ui_with_layout(row, Layout::right_to_left(Align::Center), |ui| {
            let hint = if session.has_mutes() {
                "Save the modes heard (muted ones left out) in the user folder"
            } else {
                "Save the bank in the user folder"
            };
            let save = ui.button("Save").on_hover_text(hint).clicked();
            ui.add(TextEdit::singleline(&mut self.save_name).desired_width(ui.available_width()));
            if save {
                let name = self.save_name.clone();
                self.save(session, &name);
            }
        });

        if let Some((text, is_error)) = &self.message {
            let colour = if *is_error { style::ERROR } else { style::OK };
            ui.label(RichText::new(text).color(colour));
        }
        file_choice
    }
}

/// Sets the parameters a bank's `defaults` name (material, tilt, hardness, strike position, key
/// tracking, exciter and contact), as the plugin does for its default bank.
pub fn apply_bank_defaults(bank: &Bank, params: &ModalParams, setter: &ParamSetter) {
    let c = Controls::for_bank(bank);
    let material = if c.material_q.is_some() {
        MaterialChoice::Custom
    } else {
        MaterialChoice::Authored
    };
    set(setter, &params.material.material, material);
    if let Some(q) = c.material_q {
        set(setter, &params.material.material_q, q);
    }
    set(setter, &params.material.damping_tilt, c.damping_tilt);
    set(setter, &params.strike.hardness, c.hardness_ms);
    set(setter, &params.strike.strike_x, c.strike_x);
    set(setter, &params.strike.strike_y, c.strike_y);
    set(setter, &params.object.key_tracking, c.key_tracking);
    // The exciter a bank names; a bank that names none is struck, not scraped or rolled on.
    let d = bank.defaults.clone().unwrap_or_default();
    let contact = params.strike.exciter.value().kind().is_contact();
    if d.exciter.is_some() || contact {
        set(setter, &params.strike.exciter, ExciterChoice::of(c.exciter));
    }
    let contact_defaults = [
        (d.roughness, &params.strike.roughness, c.roughness),
        (
            d.rolling_radius_mm,
            &params.strike.rolling_radius,
            c.rolling_radius_mm,
        ),
        (
            d.contact_speed_m_per_s,
            &params.strike.contact_speed,
            c.contact_speed_m_per_s,
        ),
        (
            d.contact_force,
            &params.strike.contact_force,
            c.contact_force,
        ),
    ];
    for (named, param, value) in contact_defaults {
        if named.is_some() {
            set(setter, param, value);
        }
    }
}

/// One whole host gesture setting `param` to `value`.
fn set<P: nice_plug::prelude::Param>(setter: &ParamSetter, param: &P, value: P::Plain) {
    setter.begin_set_parameter(param);
    setter.set_parameter(param, value);
    setter.end_set_parameter(param);
}
