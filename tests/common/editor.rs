//! A headless editor for tests: an egui context without a window, a host that applies parameter
//! changes at once, and pointer and key events fed frame by frame.
#![allow(dead_code)]

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use egui::{pos2, vec2, Event, Modifiers, PointerButton, Pos2, RawInput, Rect, Vec2};
use modal_resonator::bank::io::bank_to_json;
use modal_resonator::bank::{parse_bank_str, Bank};
use modal_resonator::editor::{Audition, EditorApp, EditorLinks, EditorShared, EDITOR_SIZE};
use modal_resonator::params::ModalParams;
use nice_plug::prelude::*;

/// A host that applies parameter changes at once and counts gestures.
#[derive(Default)]
pub struct TestHost {
    /// Gestures begun.
    begun: AtomicUsize,
    /// Gestures ended.
    ended: AtomicUsize,
}

impl GuiContextInner for TestHost {
    fn plugin_api(&self) -> PluginApi {
        PluginApi::Standalone
    }

    unsafe fn raw_begin_set_parameter(&self, _param: ParamPtr) {
        self.begun.fetch_add(1, Ordering::Relaxed);
    }

    unsafe fn raw_set_parameter_normalized(&self, param: ParamPtr, normalized: f32) {
        // SAFETY: the pointer comes from a parameter of the params the test keeps alive.
        unsafe { param._internal_set_normalized_value(normalized) };
    }

    unsafe fn raw_end_set_parameter(&self, _param: ParamPtr) {
        self.ended.fetch_add(1, Ordering::Relaxed);
    }

    fn get_state(&self) -> PluginState {
        PluginState {
            version: String::new(),
            params: Default::default(),
            fields: Default::default(),
        }
    }

    fn set_state(&self, _state: PluginState) {}

    fn request_restart(&self) {}
}

/// An editor, its plugin's parameters and shared data, and an egui context without a window.
pub struct Harness {
    pub ctx: egui::Context,
    pub app: EditorApp,
    pub host: TestHost,
    pub params: Arc<ModalParams>,
    pub shared: Arc<EditorShared>,
    /// Window size in points.
    pub size: Vec2,
    /// Physical pixels per point.
    pub pixels_per_point: f32,
    /// Input time of the last frame.
    pub time_s: f64,
    /// The user bank folder.
    pub dir: tempfile::TempDir,
    /// Every command the editor sent its window, oldest first.
    pub commands: Vec<egui::ViewportCommand>,
}

impl Harness {
    /// An instrument's editor playing `bank` (the default bank when `None`).
    pub fn new(bank: Option<&Bank>) -> Self {
        Self::build(bank, false, None)
    }

    /// An instrument's editor in a project saved with the window at `size` (logical points),
    /// opening at the default size.
    pub fn with_size(bank: Option<&Bank>, size: (f32, f32)) -> Self {
        Self::build(bank, false, Some(size))
    }

    /// The editor of the effect (`is_effect`) or the instrument, playing `bank`.
    pub fn with_kind(bank: Option<&Bank>, is_effect: bool) -> Self {
        Self::build(bank, is_effect, None)
    }

    fn build(bank: Option<&Bank>, is_effect: bool, saved_size: Option<(f32, f32)>) -> Self {
        let params = Arc::new(ModalParams::new(is_effect));
        *params.editor_size.write().unwrap() = saved_size;
        if let Some(bank) = bank {
            params.bank.replace(bank_to_json(bank));
        }
        let shared = Arc::new(EditorShared::new());
        let dir = tempfile::tempdir().unwrap();
        let app = EditorApp::new(EditorLinks {
            params: params.clone(),
            shared: shared.clone(),
            bank_error: Arc::new(|| None),
            is_effect,
        })
        .with_user_dir(dir.path().join("banks"));
        let mut h = Self {
            ctx: egui::Context::default(),
            app,
            host: TestHost::default(),
            params,
            shared,
            size: vec2(EDITOR_SIZE.0 as f32, EDITOR_SIZE.1 as f32),
            pixels_per_point: 1.0,
            time_s: 0.0,
            dir,
            commands: Vec::new(),
        };
        h.settle();
        h
    }

    /// Runs one frame with `events`.
    pub fn frame(&mut self, events: Vec<Event>) -> egui::FullOutput {
        self.time_s += 1.0 / 60.0;
        let mut input = RawInput {
            screen_rect: Some(Rect::from_min_size(Pos2::ZERO, self.size)),
            time: Some(self.time_s),
            events,
            ..RawInput::default()
        };
        input
            .viewports
            .entry(input.viewport_id)
            .or_default()
            .native_pixels_per_point = Some(self.pixels_per_point);
        let setter = ParamSetter::new(&self.host);
        let app = &mut self.app;
        let mut output = self.ctx.run_ui(input, |ui| app.draw(ui, &setter));
        // Tessellating exercises the painting as a window would; no GPU takes the textures.
        let primitives = self
            .ctx
            .tessellate(output.shapes.clone(), output.pixels_per_point);
        assert!(!primitives.is_empty(), "nothing to paint");
        output.textures_delta.clear();
        for viewport in output.viewport_output.values() {
            self.commands.extend(viewport.commands.iter().cloned());
        }
        output
    }

    /// A few frames without input, so the layout settles.
    pub fn settle(&mut self) {
        for _ in 0..3 {
            self.frame(Vec::new());
        }
    }

    pub fn move_to(&mut self, p: Pos2) {
        self.frame(vec![Event::PointerMoved(p)]);
    }

    pub fn button(&mut self, p: Pos2, pressed: bool, modifiers: Modifiers) {
        self.frame(vec![
            Event::PointerMoved(p),
            Event::PointerButton {
                pos: p,
                button: PointerButton::Primary,
                pressed,
                modifiers,
            },
        ]);
    }

    pub fn click(&mut self, p: Pos2) {
        self.move_to(p);
        self.button(p, true, Modifiers::NONE);
        self.button(p, false, Modifiers::NONE);
        self.settle();
    }

    /// Presses at `from`, moves to `to` in `steps` frames with `modifiers` held, and releases.
    pub fn drag(&mut self, from: Pos2, to: Pos2, steps: usize, modifiers: Modifiers) {
        self.frame(vec![Event::ModifiersChanged(modifiers)]);
        self.move_to(from);
        self.button(from, true, modifiers);
        for i in 1..=steps {
            let p = from + (to - from) * (i as f32 / steps as f32);
            self.move_to(p);
        }
        self.button(to, false, modifiers);
        self.frame(vec![Event::ModifiersChanged(Modifiers::NONE)]);
        self.settle();
    }

    /// Loads the bank file at `path` as the browser's "Load" button does.
    pub fn load(&mut self, path: &Path) -> bool {
        let setter = ParamSetter::new(&self.host);
        self.app.load_file(path, &setter)
    }

    /// The bank the plugin would play now.
    pub fn played(&self) -> Bank {
        parse_bank_str(&self.params.bank.json.read().unwrap(), "state").unwrap()
    }

    pub fn generation(&self) -> u64 {
        self.params.bank.generation.load(Ordering::Acquire)
    }

    /// Every strike-pad request queued so far.
    pub fn auditions(&self) -> Vec<Audition> {
        std::iter::from_fn(|| self.shared.next_audition()).collect()
    }

    pub fn gestures_balanced(&self) -> bool {
        self.host.begun.load(Ordering::Relaxed) == self.host.ended.load(Ordering::Relaxed)
    }
}

/// Point `(x, y)` (0 to 1, y up) of `area`.
pub fn at(area: Rect, x: f32, y: f32) -> Pos2 {
    pos2(
        area.left() + area.width() * x,
        area.bottom() - area.height() * y,
    )
}
