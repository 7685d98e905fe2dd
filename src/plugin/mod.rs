//! The plugins: host glue only. Parameters and note events become plain values and the engine
//! does the rest. The instrument and the effect share everything but their [`Kind`].

mod bank_loader;
mod kind;

use std::marker::PhantomData;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, RwLock};

use crossbeam_channel::{Receiver, Sender};
use nice_plug::prelude::*;

pub use bank_loader::{bank_from_state, build_engine, LoadedEngine, DEFAULT_FACTORY_BANK};
pub use kind::{Effect, Instrument, Kind};

use crate::dsp::onset::OnsetDetector;
use crate::engine::{Engine, NoteEvent as EngineEvent, NoteExpression};
use crate::params::{InputMode, ModalParams};

/// The instrument plugin.
pub type ModalResonator = ModalPlugin<Instrument>;
/// The effect plugin.
pub type ModalResonatorFx = ModalPlugin<Effect>;

/// Most note events (host events plus detected onsets) handled per block; more are dropped.
const MAX_EVENTS: usize = 2048;

/// Lowest sample rate the engine runs at, in Hz.
const MIN_SAMPLE_RATE_HZ: f32 = 8_000.0;

/// Work for the background thread.
pub enum Task {
    /// Build an engine for the bank saved in the parameters, at this generation.
    LoadBank(u64),
    /// Drop the engines the audio thread has handed back.
    CollectGarbage,
}

/// Records the last problem loading a bank (or clears it).
fn set_error(shared: &Shared, message: Option<String>) {
    if let Ok(mut e) = shared.bank_error.write() {
        *e = message;
    }
}

/// Settings the background thread needs to build engines.
#[derive(Default)]
struct Shared {
    /// Sample rate in Hz, as f32 bits.
    sample_rate_bits: AtomicU32,
    /// Largest block the host sends.
    max_block: AtomicU32,
    /// The last problem loading a bank, for the editor; the previous bank keeps playing.
    bank_error: RwLock<Option<String>>,
}

/// A Modal Resonator plugin of kind `K`.
pub struct ModalPlugin<K: Kind> {
    /// Host parameters and the saved bank.
    params: Arc<ModalParams>,
    /// The engine; `None` until activated.
    engine: Option<Box<Engine>>,
    /// Settings shared with the background thread.
    shared: Arc<Shared>,
    /// Engines built by the background thread.
    loaded_tx: Sender<LoadedEngine>,
    loaded_rx: Receiver<LoadedEngine>,
    /// Engines the audio thread is done with, dropped by the background thread.
    trash_tx: Sender<Box<Engine>>,
    trash_rx: Receiver<Box<Engine>>,
    /// An old engine waiting for room in the trash.
    pending_trash: Option<Box<Engine>>,
    /// The bank generation last asked for.
    requested_generation: u64,
    /// Note events of the current block, in time order.
    events: Vec<EngineEvent>,
    /// Mono mix of the audio input.
    input: Vec<f32>,
    /// Dry input of the effect.
    dry: [Vec<f32>; 2],
    /// Onsets of the input in trigger mode.
    onsets: OnsetDetector,
    /// Pitch bend, -1 to 1.
    bend: f32,
    /// Mod wheel, 0 to 1.
    mod_wheel: f32,
    /// Channel pressure, 0 to 1.
    pressure: f32,
    /// Last key struck, if any: the pitch of onsets (else the bank's root).
    last_key: Option<u8>,
    /// Dry/wet mix at the end of the last block; `None` after a reset (no ramp needed).
    wet: Option<f32>,
    _kind: PhantomData<K>,
}

impl<K: Kind> Default for ModalPlugin<K> {
    fn default() -> Self {
        let (loaded_tx, loaded_rx) = crossbeam_channel::bounded(4);
        let (trash_tx, trash_rx) = crossbeam_channel::bounded(4);
        Self {
            params: Arc::new(ModalParams::new(K::IS_EFFECT)),
            engine: None,
            shared: Arc::new(Shared::default()),
            loaded_tx,
            loaded_rx,
            trash_tx,
            trash_rx,
            pending_trash: None,
            requested_generation: 0,
            events: Vec::with_capacity(MAX_EVENTS),
            input: Vec::new(),
            dry: [Vec::new(), Vec::new()],
            onsets: OnsetDetector::new(48_000.0),
            bend: 0.0,
            mod_wheel: 0.0,
            pressure: 0.0,
            last_key: None,
            wet: None,
            _kind: PhantomData,
        }
    }
}

impl<K: Kind> ModalPlugin<K> {
    /// The last problem loading a bank, if any.
    pub fn bank_error(&self) -> Option<String> {
        self.shared.bank_error.read().ok().and_then(|e| e.clone())
    }

    /// Swaps in an engine the background thread finished, and hands old engines back to it.
    /// Returns whether any engine went to the trash (the background thread should drop it).
    fn take_loaded_engine(&mut self) -> bool {
        let mut trashed = false;
        if let Some(old) = self.pending_trash.take() {
            trashed |= self.discard(old);
        }
        if self.pending_trash.is_some() {
            return trashed;
        }
        let rate = f32::from_bits(self.shared.sample_rate_bits.load(Ordering::Acquire));
        while let Ok(loaded) = self.loaded_rx.try_recv() {
            // Superseded by a newer request, or built before the host changed the sample rate:
            // discard it. Otherwise swap it in and discard the old one.
            let current = loaded.generation == self.requested_generation
                && loaded.engine.sample_rate_hz() == rate;
            let old = if current {
                self.engine.replace(loaded.engine)
            } else {
                Some(loaded.engine)
            };
            if let Some(old) = old {
                trashed |= self.discard(old);
                if self.pending_trash.is_some() {
                    break;
                }
            }
        }
        trashed
    }

    /// Hands `engine` to the background thread to be dropped there, or keeps it for later when
    /// the trash is full. Never drops it here.
    fn discard(&mut self, engine: Box<Engine>) -> bool {
        match self.trash_tx.try_send(engine) {
            Ok(()) => true,
            Err(e) => {
                self.pending_trash = Some(e.into_inner());
                false
            }
        }
    }

    /// Reads the block's note events into `self.events` (sample times within the block) and
    /// updates the channel's expression.
    fn read_events(&mut self, context: &mut impl ProcessContext<Self>) {
        self.events.clear();
        while let Some(event) = context.next_event() {
            let mapped = match event {
                NoteEvent::NoteOn {
                    timing,
                    key,
                    velocity,
                    ..
                } => {
                    let key = key.number_or_middle_c();
                    if velocity > 0.0 {
                        self.last_key = Some(key);
                    }
                    Some(EngineEvent::On {
                        time: timing,
                        key,
                        velocity,
                    })
                }
                // A wildcard key means every note.
                NoteEvent::NoteOff { timing, key, .. } => Some(match key.number() {
                    Some(key) => EngineEvent::Off { time: timing, key },
                    None => EngineEvent::AllNotesOff { time: timing },
                }),
                NoteEvent::Choke { timing, key, .. } => Some(match key.number() {
                    Some(key) => EngineEvent::Choke { time: timing, key },
                    None => EngineEvent::AllSoundOff { time: timing },
                }),
                NoteEvent::PolyTuning {
                    timing,
                    key,
                    tuning,
                    ..
                } => Some(EngineEvent::Expression {
                    time: timing,
                    key: key.number_or_middle_c(),
                    expression: NoteExpression::Tuning(tuning),
                }),
                NoteEvent::PolyPressure {
                    timing,
                    key,
                    pressure,
                    ..
                } => Some(EngineEvent::Expression {
                    time: timing,
                    key: key.number_or_middle_c(),
                    expression: NoteExpression::Pressure(pressure),
                }),
                NoteEvent::MidiPitchBend { value, .. } => {
                    self.bend = (value * 2.0 - 1.0).clamp(-1.0, 1.0);
                    None
                }
                NoteEvent::MidiChannelPressure { pressure, .. } => {
                    self.pressure = pressure.clamp(0.0, 1.0);
                    None
                }
                NoteEvent::MidiCC {
                    timing, cc, value, ..
                } => match cc {
                    control_change::MODULATION_MSB => {
                        self.mod_wheel = value.clamp(0.0, 1.0);
                        None
                    }
                    control_change::ALL_SOUND_OFF => {
                        Some(EngineEvent::AllSoundOff { time: timing })
                    }
                    control_change::ALL_NOTES_OFF => {
                        Some(EngineEvent::AllNotesOff { time: timing })
                    }
                    _ => None,
                },
                _ => None,
            };
            if let Some(e) = mapped {
                if self.events.len() < MAX_EVENTS {
                    self.events.push(e);
                }
            }
        }
    }

    /// Adds a strike at each onset of the input (trigger mode), keeping events in time order.
    fn add_onsets(&mut self, n: usize) {
        let threshold = util::db_to_gain(self.params.trigger_threshold.value());
        let retrigger_s = self.params.retrigger.value() * 1e-3;
        let root = self.engine.as_ref().map_or(60.0, |e| e.bank().root_key);
        let key = self
            .last_key
            .unwrap_or(root.round().clamp(0.0, 127.0) as u8);
        let events = &mut self.events;
        self.onsets
            .process(&self.input[..n], threshold, retrigger_s, |onset| {
                if events.len() < MAX_EVENTS {
                    let event = EngineEvent::On {
                        time: onset.time,
                        key,
                        velocity: onset.strength,
                    };
                    // Insert in time order; after events at the same time.
                    let at = events.partition_point(|e| e.time() <= onset.time);
                    events.insert(at, event);
                }
            });
    }
}

impl<K: Kind> Plugin for ModalPlugin<K> {
    const NAME: &'static str = K::NAME;
    const VENDOR: &'static str = "Modal Resonator";
    const URL: &'static str = "https://modal-resonator.org";
    const EMAIL: &'static str = "info@modal-resonator.org";
    const VERSION: &'static str = env!("CARGO_PKG_VERSION");
    const AUDIO_IO_LAYOUTS: &'static [AudioIOLayout] = K::AUDIO_IO_LAYOUTS;
    const MIDI_INPUT: MidiConfig = MidiConfig::MidiCCs;
    const SAMPLE_ACCURATE_AUTOMATION: bool = false;

    type Editor = ();
    type SysExMessage = ();
    type BackgroundTask = Task;

    fn params(&self) -> Arc<dyn Params> {
        self.params.clone()
    }

    fn task_executor(&mut self) -> TaskExecutor<Self> {
        let params = self.params.clone();
        let shared = self.shared.clone();
        let loaded_tx = self.loaded_tx.clone();
        let trash_rx = self.trash_rx.clone();
        Box::new(move |task| {
            // Engines the audio thread is done with are dropped here, off the audio thread.
            while trash_rx.try_recv().is_ok() {}
            match task {
                Task::CollectGarbage => {}
                Task::LoadBank(generation) => {
                    // A newer bank is already on its way: building this one would be wasted.
                    if params.bank.generation.load(Ordering::Acquire) != generation {
                        return;
                    }
                    let json = params
                        .bank
                        .json
                        .read()
                        .map(|j| j.clone())
                        .unwrap_or_default();
                    match bank_from_state(&json) {
                        Ok(bank) => {
                            let rate =
                                f32::from_bits(shared.sample_rate_bits.load(Ordering::Acquire));
                            let max_block = shared.max_block.load(Ordering::Acquire) as usize;
                            let engine = build_engine(&bank, rate, max_block);
                            set_error(&shared, None);
                            let _ = loaded_tx.try_send(LoadedEngine { generation, engine });
                        }
                        Err(message) => set_error(&shared, Some(message)),
                    }
                }
            }
        })
    }

    fn activate(
        &mut self,
        _layout: &AudioIOLayout,
        config: &BufferConfig,
        _context: &mut impl ActivateContext<Self>,
    ) -> bool {
        let rate = config.sample_rate;
        if !(rate.is_finite() && rate >= MIN_SAMPLE_RATE_HZ) {
            return false;
        }
        let max_block = config.max_buffer_size.max(1) as usize;
        self.shared
            .sample_rate_bits
            .store(rate.to_bits(), Ordering::Release);
        self.shared
            .max_block
            .store(max_block as u32, Ordering::Release);
        self.input = vec![0.0; max_block];
        self.dry = [vec![0.0; max_block], vec![0.0; max_block]];
        self.onsets = OnsetDetector::new(rate);
        // Build the engine here, synchronously, so offline renders start with the right bank.
        self.requested_generation = self.params.bank.generation.load(Ordering::Acquire);
        let json = self
            .params
            .bank
            .json
            .read()
            .map(|j| j.clone())
            .unwrap_or_default();
        let bank = match bank_from_state(&json) {
            Ok(bank) => {
                set_error(&self.shared, None);
                bank
            }
            Err(message) => {
                set_error(&self.shared, Some(message));
                // Keep the bank that was playing; the factory default only on a first start.
                match self.engine.as_ref() {
                    Some(engine) => engine.bank().source.clone(),
                    None => match bank_from_state("") {
                        Ok(bank) => bank,
                        Err(_) => return false,
                    },
                }
            }
        };
        self.engine = Some(build_engine(&bank, rate, max_block));
        // Nothing queued for an older setting may replace it.
        while let Ok(stale) = self.loaded_rx.try_recv() {
            drop(stale);
        }
        true
    }

    fn reset(&mut self) {
        if let Some(engine) = self.engine.as_mut() {
            engine.reset();
        }
        self.onsets.reset();
        self.wet = None;
        // Pitch bend, mod wheel and pressure are where the player left them: a host resets
        // the plugin on every start of processing, and the wheel has not moved.
    }

    fn process(
        &mut self,
        buffer: &mut Buffer,
        aux: &mut AuxiliaryBuffers,
        context: &mut impl ProcessContext<Self>,
    ) -> ProcessStatus {
        let generation = self.params.bank.generation.load(Ordering::Acquire);
        if generation != self.requested_generation {
            self.requested_generation = generation;
            context.execute_background(Task::LoadBank(generation));
        }
        if self.take_loaded_engine() {
            context.execute_background(Task::CollectGarbage);
        }
        self.read_events(context);

        let n = buffer.samples();
        let channels = buffer.as_slice();
        if self.engine.is_none() || channels.len() < 2 || n > self.input.len() {
            for channel in channels.iter_mut() {
                channel.fill(0.0);
            }
            return ProcessStatus::Normal;
        }

        // The audio input: the effect's main input, or the instrument's exciter input.
        let mode = self.params.input_mode.value();
        let mut have_input = false;
        if K::IS_EFFECT {
            for (dry, channel) in self.dry.iter_mut().zip(channels.iter()) {
                dry[..n].copy_from_slice(&channel[..n]);
            }
            mix_to_mono(&self.dry[0][..n], &self.dry[1][..n], &mut self.input[..n]);
            have_input = true;
        } else if let Some(exciter) = aux.inputs.first_mut() {
            let ex = exciter.as_slice_immutable();
            if ex.len() >= 2 && ex[0].len() >= n && ex[1].len() >= n {
                mix_to_mono(&ex[0][..n], &ex[1][..n], &mut self.input[..n]);
                have_input = true;
            }
        }
        if have_input && mode == InputMode::Trigger {
            self.add_onsets(n);
        }
        let drive = (have_input && mode == InputMode::Direct).then_some(&self.input[..n]);

        let controls = self
            .params
            .controls(self.bend, self.mod_wheel, self.pressure);
        let engine = self.engine.as_mut().expect("checked above");
        engine.set_controls(&controls);
        let (left, rest) = channels.split_at_mut(1);
        engine.process(&self.events, drive, &mut left[0][..n], &mut rest[0][..n]);

        if K::IS_EFFECT {
            // Ramp from the last block's mix to this one's, so automation does not zipper.
            let to = self.params.dry_wet.value();
            let from = self.wet.unwrap_or(to);
            let step = (to - from) / n as f32;
            for (channel, dry) in channels.iter_mut().zip(&self.dry) {
                for (i, (out, d)) in channel[..n].iter_mut().zip(&dry[..n]).enumerate() {
                    let wet = from + step * (i + 1) as f32;
                    *out = wet * *out + (1.0 - wet) * d;
                }
            }
            self.wet = Some(to);
        }
        if engine.is_silent() {
            ProcessStatus::Normal
        } else {
            ProcessStatus::KeepAlive
        }
    }
}

/// `out = (left + right) / 2`.
fn mix_to_mono(left: &[f32], right: &[f32], out: &mut [f32]) {
    for ((o, l), r) in out.iter_mut().zip(left).zip(right) {
        *o = 0.5 * (l + r);
    }
}

impl<K: Kind> ClapPlugin for ModalPlugin<K> {
    const CLAP_ID: &'static str = K::CLAP_ID;
    const CLAP_DESCRIPTION: Option<&'static str> = Some(K::DESCRIPTION);
    const CLAP_MANUAL_URL: Option<&'static str> = None;
    const CLAP_SUPPORT_URL: Option<&'static str> = None;
    const CLAP_FEATURES: &'static [ClapFeature] = K::CLAP_FEATURES;
}

impl<K: Kind> Vst3Plugin for ModalPlugin<K> {
    const VST3_CLASS_ID: [u8; 16] = K::VST3_CLASS_ID;
    const VST3_SUBCATEGORIES: &'static [Vst3SubCategory] = K::VST3_SUBCATEGORIES;
}

nice_export_clap!(ModalResonator, ModalResonatorFx);
nice_export_vst3!(ModalResonator, ModalResonatorFx);
