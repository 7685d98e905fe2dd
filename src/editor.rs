//! The editor: an egui GUI for both plugins and the standalone, showing the object ringing.
//!
//! The interface with the audio thread is narrow and one way each:
//! - audio thread to GUI: [`EditorShared`], atomics written by the audio thread only while the
//!   editor is open (meters at most every [`METER_INTERVAL_S`], per-mode energies in a
//!   fixed-capacity array allocated once with the plugin);
//! - GUI to audio thread: parameters through the host ([`ParamSetter`]), banks through
//!   [`BankField::replace`](crate::params::BankField::replace) (built off the audio thread), and
//!   strikes from the strike pad as [`Audition`]s in a bounded lock-free queue.
//!
//! The drawing code ([`EditorApp::draw`]) knows nothing of the window, so tests run it headlessly.
//!
//! [`ParamSetter`]: nice_plug::prelude::ParamSetter

mod app;
mod bank_browser;
mod bank_info;
mod meters;
mod mode_editor;
mod mode_view;
mod params_panel;
mod session;
mod slider;
mod strike_pad;
mod style;
mod window_size;

use std::sync::atomic::{fence, AtomicU32, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::Duration;

use crossbeam_channel::{Receiver, Sender};
use nice_plug::editor::dpi::LogicalSize;
use nice_plug::prelude::{ParamSetter, ResizeHint};
use nice_plug_egui::{create_egui_editor, EguiEditor, EguiEditorState, EguiNiceSettings};

pub use app::{BankErrorSource, EditorApp, EditorLayout};
pub use mode_view::DB_SPAN as MODE_VIEW_DB_SPAN;
pub use params_panel::fixed_strike_axes;
pub use session::BankSession;
pub use slider::control_rect;

use crate::bank::validate::MAX_MODES;
use crate::engine::{Engine, Note, NoteEvent, VoiceModulation};
use crate::params::ModalParams;

/// Size the editor opens at, in logical pixels.
pub const EDITOR_SIZE: (u32, u32) = (1200, 760);

/// Smallest size the editor can be resized to, in logical pixels: every panel still fits.
pub const EDITOR_MIN_SIZE: (f32, f32) = (900.0, 600.0);

/// How often the audio thread publishes meters and mode energies while the editor is open, in
/// seconds: about the GUI's frame rate, so drawing sees every update and no more work is done.
pub const METER_INTERVAL_S: f32 = 1.0 / 30.0;

/// Modes whose energy is metered: the bank format's maximum, so every mode of any valid bank is
/// shown. The array costs 4 bytes a mode, allocated once with the plugin.
pub const MAX_METERED_MODES: usize = MAX_MODES;

/// Strike-pad requests the queue holds until the audio thread takes them; more are dropped.
const AUDITION_QUEUE: usize = 64;

/// Times the GUI tries to copy the energies when publications keep tearing the copy.
const READ_ATTEMPTS: usize = 4;

/// Note id of the strike pad's notes, which the host never hears of (CLAP note ids are never
/// negative).
pub const AUDITION_NOTE_ID: i32 = -2;

/// Energy slot value of a mode that sounds in no voice.
const SILENT_BITS: u32 = 0xBF80_0000; // -1.0f32

/// A strike from the editor's strike pad, played without MIDI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Audition {
    /// Strike the object at normalised position `(x, y)` (0 to 1, as the strike position
    /// parameters) with `velocity` (0 to 1), on the last key played or the bank's root.
    Strike { x: f32, y: f32, velocity: f32 },
    /// Release the last audition strike (the pointer was lifted).
    Release,
}

impl Audition {
    /// The engine events that play this request on `key` at the start of a block: a strike
    /// with the pad's position held by its voice alone, or the strike's release.
    pub fn events(self, key: u8) -> impl Iterator<Item = NoteEvent> {
        let note = Note {
            key,
            channel: 0,
            id: Some(AUDITION_NOTE_ID),
        };
        let modulate = |modulation| NoteEvent::Modulate {
            time: 0,
            id: AUDITION_NOTE_ID,
            modulation,
        };
        let events = match self {
            Audition::Strike { x, y, velocity } => [
                Some(NoteEvent::On {
                    time: 0,
                    note,
                    velocity,
                }),
                Some(modulate(VoiceModulation::StrikeX(x))),
                Some(modulate(VoiceModulation::StrikeY(y))),
            ],
            Audition::Release => [Some(NoteEvent::Off { time: 0, note }), None, None],
        };
        events.into_iter().flatten()
    }
}

/// What the audio thread last measured, for the meters.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct MeterReading {
    /// Voices sounding.
    pub voices: u32,
    /// Modes above the truncation threshold, over all voices.
    pub live_modes: u32,
    /// Modes the kernels advance per sample, over all voices.
    pub computed_modes: u32,
    /// Live modes switched off by pruning or the budget, over all voices.
    pub pruned_modes: u32,
    /// Modes in the bank playing.
    pub bank_modes: u32,
    /// Largest absolute output sample since the last reading, linear.
    pub peak: f32,
    /// Largest share of a block's duration the audio thread spent processing it, since the last
    /// reading (1 = all of it).
    pub dsp_load: f32,
}

/// What the widgets need of the plugin for one frame.
#[derive(Clone, Copy)]
pub struct Host<'a> {
    /// The parameters.
    pub params: &'a ModalParams,
    /// Sets parameters through the host.
    pub setter: &'a ParamSetter<'a>,
    /// The audio thread's meters and the strike pad's queue.
    pub shared: &'a EditorShared,
}

/// Data the audio thread publishes for the editor, and the strike pad's queue. Owned by the
/// plugin, shared with the editor. The audio thread only stores into atomics and never waits.
pub struct EditorShared {
    /// Voices sounding.
    voices: AtomicU32,
    /// Live modes over all voices.
    live_modes: AtomicU32,
    /// Computed modes over all voices.
    computed_modes: AtomicU32,
    /// Live modes switched off by pruning or the budget.
    pruned_modes: AtomicU32,
    /// Modes in the bank playing.
    bank_modes: AtomicU32,
    /// Largest absolute output sample since the GUI last read it, as f32 bits (non-negative
    /// floats order like their bits, so `fetch_max` works on them).
    peak_bits: AtomicU32,
    /// Largest DSP load since the GUI last read it, as f32 bits.
    load_bits: AtomicU32,
    /// Summed energy `|z|^2` of each mode over the voices (in the prepared bank's order), as f32
    /// bits; `SILENT_BITS` for a mode sounding nowhere.
    energy: Box<[AtomicU32]>,
    /// One bit per mode (same order), set for a mode pruning or the budget has switched off in
    /// some voice: its energy is carried analytically, not computed.
    pruned: Box<[AtomicU32]>,
    /// How many entries of `energy` the last publication wrote.
    energy_modes: AtomicU32,
    /// The bank generation (see [`BankField`](crate::params::BankField)) the energies belong to.
    energy_generation: AtomicU64,
    /// Incremented after every publication.
    serial: AtomicU64,
    /// Odd while the audio thread writes the energies, incremented before and after: the GUI
    /// keeps a copy only when it reads the same even value before and after copying.
    energy_seq: AtomicU64,
    /// Samples until the next publication (audio thread only).
    countdown: AtomicU32,
    /// Strike-pad requests, GUI to audio thread.
    audition_tx: Sender<Audition>,
    /// The audio thread's end of the queue.
    audition_rx: Receiver<Audition>,
}

impl Default for EditorShared {
    fn default() -> Self {
        Self::new()
    }
}

impl EditorShared {
    /// Everything zero, with room for [`MAX_METERED_MODES`] energies. Allocates.
    pub fn new() -> Self {
        let (audition_tx, audition_rx) = crossbeam_channel::bounded(AUDITION_QUEUE);
        Self {
            voices: AtomicU32::new(0),
            live_modes: AtomicU32::new(0),
            computed_modes: AtomicU32::new(0),
            pruned_modes: AtomicU32::new(0),
            bank_modes: AtomicU32::new(0),
            peak_bits: AtomicU32::new(0),
            load_bits: AtomicU32::new(0),
            energy: (0..MAX_METERED_MODES)
                .map(|_| AtomicU32::new(SILENT_BITS))
                .collect(),
            pruned: (0..MAX_METERED_MODES.div_ceil(32))
                .map(|_| AtomicU32::new(0))
                .collect(),
            energy_modes: AtomicU32::new(0),
            energy_generation: AtomicU64::new(0),
            serial: AtomicU64::new(0),
            energy_seq: AtomicU64::new(0),
            countdown: AtomicU32::new(0),
            audition_tx,
            audition_rx,
        }
    }

    /// Audio thread, after each block while the editor is open: records the block's output peak
    /// and DSP load (`elapsed` processing a block of `channels[0].len()` samples), and every
    /// [`METER_INTERVAL_S`] the engine's meters and mode energies for bank `generation`. Does not
    /// allocate, lock or wait.
    pub fn measure_block(
        &self,
        engine: Option<&Engine>,
        generation: u64,
        channels: &[&mut [f32]],
        elapsed: Duration,
        sample_rate_hz: f32,
    ) {
        let samples = channels.first().map_or(0, |c| c.len());
        let peak = channels.iter().flat_map(|c| c.iter()).fold(0.0f32, |p, x| {
            if x.abs() > p {
                x.abs()
            } else {
                p
            }
        });
        self.peak_bits.fetch_max(peak.to_bits(), Ordering::Relaxed);
        if samples > 0 && sample_rate_hz > 0.0 {
            let load = elapsed.as_secs_f32() * sample_rate_hz / samples as f32;
            self.load_bits.fetch_max(load.to_bits(), Ordering::Relaxed);
        }
        let left = self.countdown.load(Ordering::Relaxed) as usize;
        if left > samples {
            self.countdown
                .store((left - samples) as u32, Ordering::Relaxed);
            return;
        }
        // The next publication is an interval after this one was due, not after this block.
        let interval = (METER_INTERVAL_S * sample_rate_hz).max(1.0) as usize;
        let next = interval.saturating_sub(samples - left).max(1);
        self.countdown.store(next as u32, Ordering::Relaxed);
        if let Some(engine) = engine {
            self.publish(engine, generation);
        }
    }

    /// Stores the engine's meters and mode energies. Audio thread; does not allocate.
    pub fn publish(&self, engine: &Engine, generation: u64) {
        let stats = engine.stats();
        self.voices.store(stats.voices as u32, Ordering::Relaxed);
        self.live_modes
            .store(stats.live_modes as u32, Ordering::Relaxed);
        self.computed_modes
            .store(stats.computed_modes as u32, Ordering::Relaxed);
        self.pruned_modes
            .store(stats.dormant_modes as u32, Ordering::Relaxed);
        let n = engine.bank().num_modes().min(self.energy.len());
        self.bank_modes
            .store(engine.bank().num_modes() as u32, Ordering::Relaxed);
        let seq = self.energy_seq.load(Ordering::Relaxed);
        self.energy_seq
            .store(seq.wrapping_add(1), Ordering::Relaxed);
        fence(Ordering::Release);
        for slot in &self.energy[..n] {
            slot.store(SILENT_BITS, Ordering::Relaxed);
        }
        engine.visit_mode_energies(|m, e| {
            if let Some(slot) = self.energy.get(m) {
                let sum = f32::from_bits(slot.load(Ordering::Relaxed)).max(0.0) + e;
                slot.store(sum.to_bits(), Ordering::Relaxed);
            }
        });
        for word in &self.pruned[..n.div_ceil(32)] {
            word.store(0, Ordering::Relaxed);
        }
        engine.visit_switched_off_modes(|m| {
            if m < n {
                self.pruned[m / 32].fetch_or(1 << (m % 32), Ordering::Relaxed);
            }
        });
        self.energy_modes.store(n as u32, Ordering::Relaxed);
        self.energy_generation.store(generation, Ordering::Relaxed);
        self.energy_seq
            .store(seq.wrapping_add(2), Ordering::Release);
        self.serial.fetch_add(1, Ordering::Release);
    }

    /// GUI: the meters, taking the peak and load held since the last reading.
    pub fn take_reading(&self) -> MeterReading {
        MeterReading {
            voices: self.voices.load(Ordering::Relaxed),
            live_modes: self.live_modes.load(Ordering::Relaxed),
            computed_modes: self.computed_modes.load(Ordering::Relaxed),
            pruned_modes: self.pruned_modes.load(Ordering::Relaxed),
            bank_modes: self.bank_modes.load(Ordering::Relaxed),
            peak: f32::from_bits(self.peak_bits.swap(0, Ordering::Relaxed)),
            dsp_load: f32::from_bits(self.load_bits.swap(0, Ordering::Relaxed)),
        }
    }

    /// GUI: the energy of each mode of bank `generation` (prepared order) into `out`, `None` for
    /// modes sounding nowhere, and into `pruned` whether pruning or the budget has switched the
    /// mode off (its energy then carried analytically). Returns `false` (and clears both) when
    /// the energies published belong to another bank.
    pub fn read_energies(
        &self,
        generation: u64,
        out: &mut Vec<Option<f32>>,
        pruned: &mut Vec<bool>,
    ) -> bool {
        // A copy torn by a publication under way is read again; a GUI frame never waits long.
        for _ in 0..READ_ATTEMPTS {
            out.clear();
            pruned.clear();
            let before = self.energy_seq.load(Ordering::Acquire);
            if before % 2 == 1 {
                std::hint::spin_loop();
                continue;
            }
            let same_bank = self.energy_generation.load(Ordering::Relaxed) == generation;
            if same_bank {
                let n = (self.energy_modes.load(Ordering::Relaxed) as usize).min(self.energy.len());
                out.extend(self.energy[..n].iter().map(|slot| {
                    let e = f32::from_bits(slot.load(Ordering::Relaxed));
                    (e >= 0.0).then_some(e)
                }));
                pruned.extend(
                    (0..n).map(|m| {
                        self.pruned[m / 32].load(Ordering::Relaxed) & (1 << (m % 32)) != 0
                    }),
                );
            }
            fence(Ordering::Acquire);
            if self.energy_seq.load(Ordering::Relaxed) == before {
                if !same_bank {
                    out.clear();
                    pruned.clear();
                }
                return same_bank;
            }
        }
        out.clear();
        pruned.clear();
        false
    }

    /// How many times meters were published so far.
    pub fn serial(&self) -> u64 {
        self.serial.load(Ordering::Acquire)
    }

    /// GUI: asks the audio thread to play `audition`. Returns `false` when the queue is full.
    pub fn request(&self, audition: Audition) -> bool {
        self.audition_tx.try_send(audition).is_ok()
    }

    /// Audio thread: the next strike-pad request, if any. Does not allocate, lock or wait.
    pub fn next_audition(&self) -> Option<Audition> {
        self.audition_rx.try_recv().ok()
    }
}

/// The editor state a plugin instance starts with: the default size at the host's scale.
pub fn default_state() -> Arc<EguiEditorState> {
    EguiEditorState::from_size(
        LogicalSize::new(EDITOR_SIZE.0 as f32, EDITOR_SIZE.1 as f32),
        1.0,
    )
}

/// The editor of a plugin named `title`: resizable down to [`EDITOR_MIN_SIZE`].
pub fn create(
    title: &str,
    state: Arc<EguiEditorState>,
    app: EditorApp,
) -> Option<EguiEditor<EditorApp>> {
    let min = LogicalSize::new(EDITOR_MIN_SIZE.0, EDITOR_MIN_SIZE.1);
    let settings = EguiNiceSettings::new()
        .with_tile(title)
        .with_resize_hint(ResizeHint::resizable().with_min_logical_size(min));
    create_egui_editor(state, Default::default(), settings, app)
}

/// The parameters and shared data an editor needs, for [`EditorApp::new`].
pub struct EditorLinks {
    /// The plugin's parameters and bank.
    pub params: Arc<ModalParams>,
    /// Meters and the strike pad's queue.
    pub shared: Arc<EditorShared>,
    /// The background loader's last error.
    pub bank_error: BankErrorSource,
    /// Whether the plugin is the effect (shows dry/wet).
    pub is_effect: bool,
}
