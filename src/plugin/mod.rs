//! The plugins: host glue only. Parameters and note events become plain values and the engine
//! does the rest. The instrument and the effect share everything but their [`Kind`].

mod bank_loader;
mod engines;
mod events;
mod kind;
mod poly;

use std::marker::PhantomData;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering};
use std::sync::{Arc, RwLock};
use std::time::Instant;

use nice_plug::midi::{Channel, Key, VoiceID};
use nice_plug::plugin::ParamValue;
use nice_plug::prelude::*;
use nice_plug_egui::{EguiEditor, EguiEditorState};

pub use bank_loader::{build_engine, LoadedEngine};
pub use events::VST3_MIDI_CONTROLLERS;
pub use kind::{Effect, Instrument, Kind};

use crate::bank::factory::bank_from_state;
use crate::editor::{self, EditorApp, EditorLinks, EditorShared, AUDITION_NOTE_ID};
use crate::engine::{
    mix_to_mono, Controls, EndedVoice, MidiInput, NoteEvent as EngineEvent, OnsetTrigger,
    OutputStage, PositionMap, MAX_POLYPHONY,
};
use crate::params::{InputMode, ModalParams, STATE_FORMAT, STATE_FORMAT_FIELD};
use engines::Engines;
use poly::PolyTable;

/// Set by a standalone with no display: its plugin then offers no editor, so the standalone
/// plays headless until it is stopped, and stopping it is no error.
static WITHOUT_EDITOR: AtomicBool = AtomicBool::new(false);

/// Makes the plugins of this process offer no editor: for a standalone on a machine with no
/// display, where opening the window can only fail.
pub fn play_without_editor() {
    WITHOUT_EDITOR.store(true, Ordering::Relaxed);
}

/// The instrument plugin.
pub type ModalResonator = ModalPlugin<Instrument>;
/// The effect plugin.
pub type ModalResonatorFx = ModalPlugin<Effect>;

/// Most note events (host events plus detected onsets) handled per block; more are dropped.
const MAX_EVENTS: usize = 2048;

/// Notes whose polyphonic modulation is tracked (the engine's voices, counting those fading).
const POLY_NOTES: usize = 2 * MAX_POLYPHONY;

/// Work for the background thread.
pub enum Task {
    /// Build an engine for the bank saved in the parameters, at this generation, for this
    /// activation.
    LoadBank { generation: u64, epoch: u64 },
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
    /// The last bank generation that failed to load (not asked for again).
    failed_generation: AtomicU64,
    /// The JSON of the bank playing, put back in the state when a new one fails to load.
    playing_json: RwLock<String>,
}

/// A Modal Resonator plugin of kind `K`.
pub struct ModalPlugin<K: Kind> {
    /// Host parameters and the saved bank.
    params: Arc<ModalParams>,
    /// The engine playing, the one fading out, and those on their way.
    engines: Engines,
    /// Settings shared with the background thread.
    shared: Arc<Shared>,
    /// The background thread's ends of the engine channels.
    background: engines::BackgroundEnds,
    /// Note events of the current block, in time order.
    events: Vec<EngineEvent>,
    /// Note events of the part of the block being rendered, timed from its start.
    segment_events: Vec<EngineEvent>,
    /// The host's polyphonic modulation offsets, per note id.
    poly: PolyTable,
    /// Mono mix of the audio input.
    input: Vec<f32>,
    /// Dry input (the effect's input, or the instrument's exciter input).
    dry: [Vec<f32>; 2],
    /// Strikes at the input's onsets in trigger mode.
    onsets: OnsetTrigger,
    /// The MIDI being played: channels' controllers, pedals, sustained notes.
    midi: MidiInput,
    /// The engine's controls from the parameters, for this block (MIDI is read with them).
    block_controls: Controls,
    /// Last key struck, if any: the pitch of onsets (else the bank's root).
    last_key: Option<u8>,
    /// The dry/wet mix, the bypass and the flush of subnormals.
    output: OutputStage,
    /// The editor's size and whether it is open.
    editor_state: Arc<EguiEditorState>,
    /// Meters for the editor and its strike pad's requests.
    editor_shared: Arc<EditorShared>,
    /// The key of the strike pad's note while it is held.
    audition_key: Option<u8>,
    _kind: PhantomData<K>,
}

impl<K: Kind> Default for ModalPlugin<K> {
    fn default() -> Self {
        let (engines, background) = Engines::new(MAX_EVENTS);
        Self {
            params: Arc::new(ModalParams::new(K::IS_EFFECT)),
            engines,
            shared: Arc::new(Shared::default()),
            background,
            events: Vec::with_capacity(MAX_EVENTS),
            segment_events: Vec::with_capacity(MAX_EVENTS),
            poly: PolyTable::new(POLY_NOTES),
            input: Vec::new(),
            dry: [Vec::new(), Vec::new()],
            onsets: OnsetTrigger::new(48_000.0),
            midi: MidiInput::default(),
            block_controls: Controls::default(),
            last_key: None,
            output: OutputStage::default(),
            editor_state: editor::default_state(),
            editor_shared: Arc::new(EditorShared::new()),
            audition_key: None,
            _kind: PhantomData,
        }
    }
}

impl<K: Kind> ModalPlugin<K> {
    /// The last problem loading a bank, if any.
    pub fn bank_error(&self) -> Option<String> {
        self.shared.bank_error.read().ok().and_then(|e| e.clone())
    }

    /// The key of strikes that come without one (onsets, the editor's strike pad): the last key
    /// played, else the bank's root.
    fn strike_key(&self) -> u8 {
        let root = self
            .engines
            .current
            .as_ref()
            .map_or(60.0, |e| e.bank().root_key);
        self.last_key
            .unwrap_or(root.round().clamp(0.0, 127.0) as u8)
    }

    /// Adds a strike at each onset of `self.input[..n]` (trigger mode) to the segment's events,
    /// keeping them in time order.
    fn add_onsets(&mut self, n: usize) {
        let threshold = util::db_to_gain(self.params.input.trigger_threshold.value());
        let retrigger_s = self.params.input.retrigger.value() * 1e-3;
        let key = self.strike_key();
        self.onsets.add_strikes(
            &self.input[..n],
            threshold,
            retrigger_s,
            key,
            &mut self.segment_events,
            MAX_EVENTS,
        );
    }

    /// Renders samples `start..end` of the block (at most the announced maximum block): the
    /// engine (and an outgoing one fading out), the audio input and the effect's dry/wet mix.
    /// `self.segment_events` holds the segment's events, timed from `start`.
    fn render_segment(
        &mut self,
        channels: &mut [&mut [f32]],
        exciter: Option<&[&mut [f32]]>,
        start: usize,
        end: usize,
        context: &mut impl ProcessContext<Self>,
    ) {
        let n = end - start;
        // The audio input: the effect's main input, or the instrument's exciter input.
        let mode = self.params.input.input_mode.value();
        let mut have_input = false;
        if K::IS_EFFECT {
            for (dry, channel) in self.dry.iter_mut().zip(channels.iter()) {
                dry[..n].copy_from_slice(&channel[start..end]);
            }
            mix_to_mono(&self.dry[0][..n], &self.dry[1][..n], &mut self.input[..n]);
            have_input = true;
        } else if let Some(ex) = exciter {
            if ex.len() >= 2 && ex[0].len() >= end && ex[1].len() >= end {
                for (dry, channel) in self.dry.iter_mut().zip(ex.iter()) {
                    dry[..n].copy_from_slice(&channel[start..end]);
                }
                mix_to_mono(&ex[0][start..end], &ex[1][start..end], &mut self.input[..n]);
                have_input = true;
            }
        }
        if have_input && mode == InputMode::Trigger {
            self.add_onsets(n);
        }
        let drive = (have_input && mode == InputMode::Direct).then_some(&self.input[..n]);

        let controls = self.block_controls.clone();
        let (left, rest) = channels.split_at_mut(1);
        let (out_l, out_r) = (&mut left[0][start..end], &mut rest[0][start..end]);
        let Some(engine) = self.engines.current.as_mut() else {
            return;
        };
        engine.set_controls(&controls);
        engine.process(&self.segment_events, drive, out_l, out_r);
        for ended in engine.take_ended_voices() {
            let time = ended.time + start as u32;
            report_ended(&mut self.poly, context, EndedVoice { time, ..ended });
        }

        let outgoing = &mut self.engines.outgoing;
        let out = [&mut *out_l, &mut *out_r];
        if let Some(done) = outgoing.add_to(out, &controls, &self.segment_events, drive) {
            if self.engines.discard(done) {
                context.execute_background(Task::CollectGarbage);
            }
        }

        let input = have_input.then_some([&self.dry[0][..n], &self.dry[1][..n]]);
        let wet = self.params.output.dry_wet.value();
        let bypassed = self.params.bypass.value();
        let rate = f32::from_bits(self.shared.sample_rate_bits.load(Ordering::Acquire));
        let out = [out_l, out_r];
        self.output
            .apply(out, input, wet, bypassed, K::IS_EFFECT, rate);
    }
}

/// Tells the host a note ended (CLAP note end; needed for polyphonic modulation) and forgets its
/// modulation.
fn report_ended<P: Plugin>(
    poly: &mut PolyTable,
    context: &mut impl ProcessContext<P>,
    ended: EndedVoice,
) {
    if let Some(id) = ended.note.id {
        poly.remove(id);
    }
    // The editor's strike pad auditions are the plugin's own notes: the host never saw them.
    if ended.note.id == Some(AUDITION_NOTE_ID) {
        return;
    }
    // Hosts without an output event list (or with a full one) do not need to know.
    let _ = context.try_send_event(NoteEvent::VoiceTerminated {
        timing: ended.time,
        voice_id: ended.note.id.map_or(VoiceID::Wildcard, VoiceID::ID),
        channel: Channel::Number(ended.note.channel),
        key: Key::Number(ended.note.key),
    });
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

    type Editor = EguiEditor<EditorApp>;
    type SysExMessage = ();
    type BackgroundTask = Task;

    fn params(&self) -> Arc<dyn Params> {
        self.params.clone()
    }

    fn editor(&mut self, _async_executor: AsyncExecutor<Self>) -> Option<Self::Editor> {
        if WITHOUT_EDITOR.load(Ordering::Relaxed) {
            return None;
        }
        let shared = self.shared.clone();
        let app = EditorApp::new(EditorLinks {
            params: self.params.clone(),
            shared: self.editor_shared.clone(),
            bank_error: Arc::new(move || shared.bank_error.read().ok().and_then(|e| e.clone())),
            is_effect: K::IS_EFFECT,
        });
        editor::create(K::NAME, self.editor_state.clone(), app)
    }

    fn task_executor(&mut self) -> TaskExecutor<Self> {
        let params = self.params.clone();
        let shared = self.shared.clone();
        let loaded_tx = self.background.loaded_tx.clone();
        let trash_rx = self.background.trash_rx.clone();
        Box::new(move |task| {
            // Engines the audio thread is done with are dropped here, off the audio thread.
            while trash_rx.try_recv().is_ok() {}
            let Task::LoadBank { generation, epoch } = task else {
                return;
            };
            // A newer bank is already on its way: building this one would be wasted.
            if params.bank.generation.load(Ordering::Acquire) != generation {
                return;
            }
            let json = params.bank.json_text();
            match bank_from_state(&json) {
                Ok(bank) => {
                    let rate = f32::from_bits(shared.sample_rate_bits.load(Ordering::Acquire));
                    let max_block = shared.max_block.load(Ordering::Acquire) as usize;
                    let engine = build_engine(&bank, params.polyphony(), rate, max_block);
                    // A rebuild of the bank kept after a failed load leaves that failure shown.
                    if shared.failed_generation.load(Ordering::Acquire) != generation {
                        set_error(&shared, None);
                    }
                    if let Ok(mut playing) = shared.playing_json.write() {
                        *playing = json;
                    }
                    // A full queue drops it; the audio thread asks again.
                    let _ = loaded_tx.try_send(LoadedEngine {
                        generation,
                        epoch,
                        engine,
                    });
                }
                Err(message) => {
                    set_error(&shared, Some(message));
                    shared
                        .failed_generation
                        .store(generation, Ordering::Release);
                    // The state keeps the bank that is heard, not the broken text.
                    if let Ok(playing) = shared.playing_json.read() {
                        params.bank.restore(generation, &playing);
                    }
                }
            }
        })
    }

    fn filter_state(state: &mut PluginState) {
        migrate_state(state);
    }

    fn activate(
        &mut self,
        _layout: &AudioIOLayout,
        config: &BufferConfig,
        _context: &mut impl ActivateContext<Self>,
    ) -> bool {
        let rate = config.sample_rate;
        // Any rate a host asks plays: modes above the engine's limit below Nyquist are left out.
        if !(rate.is_finite() && rate > 0.0) {
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
        self.engines.outgoing.prepare(max_block);
        self.poly.clear();
        self.onsets = OnsetTrigger::new(rate);
        // Build the engine here, synchronously, so offline renders start with the right bank.
        let generation = self.params.bank.generation.load(Ordering::Acquire);
        let json = self.params.bank.json_text();
        let bank = match bank_from_state(&json) {
            Ok(bank) => {
                set_error(&self.shared, None);
                if let Ok(mut playing) = self.shared.playing_json.write() {
                    *playing = json;
                }
                bank
            }
            Err(message) => {
                set_error(&self.shared, Some(message));
                // Keep the bank that was playing (in the state too); the factory default only
                // on a first start.
                let playing = self
                    .shared
                    .playing_json
                    .read()
                    .map(|j| j.clone())
                    .unwrap_or_default();
                self.params.bank.restore(generation, &playing);
                match self.engines.current.as_ref() {
                    Some(engine) => engine.bank().source.clone(),
                    None => match bank_from_state(&playing) {
                        Ok(bank) => bank,
                        Err(_) => return false,
                    },
                }
            }
        };
        let mut engine = build_engine(&bank, self.params.polyphony(), rate, max_block);
        engine.set_last_key(self.last_key);
        // The wheels are where the player left them, whatever the host's new settings.
        if let Some(current) = self.engines.current.as_ref() {
            engine.set_controllers(current.controllers());
        }
        self.engines.activate(engine, generation);
        true
    }

    fn reset(&mut self) {
        if let Some(engine) = self.engines.current.as_mut() {
            engine.reset();
        }
        self.onsets.reset();
        self.output.reset();
        // A reset ends every note at once, for the host as well, and forgets the last key: a
        // host's test note before a reset leaves nothing behind.
        self.engines.drop_outgoing();
        self.poly.clear();
        self.last_key = None;
        self.midi.forget_notes();
        // Pitch bend, mod wheel and pressure are where the player left them (the engine keeps
        // them through a reset): a host resets the plugin on every start of processing, and
        // the wheel has not moved.
    }

    fn process(
        &mut self,
        buffer: &mut Buffer,
        aux: &mut AuxiliaryBuffers,
        context: &mut impl ProcessContext<Self>,
    ) -> ProcessStatus {
        // Meters are measured only while the editor shows them.
        let started = self.editor_state.is_open().then(Instant::now);
        let generation = self.params.bank.generation.load(Ordering::Acquire);
        let failed = self.shared.failed_generation.load(Ordering::Acquire);
        let polyphony = self.params.polyphony();
        if let Some(generation) = self.engines.request(generation, failed, polyphony) {
            let epoch = self.engines.epoch;
            context.execute_background(Task::LoadBank { generation, epoch });
        }
        let rate = f32::from_bits(self.shared.sample_rate_bits.load(Ordering::Acquire));
        let poly = &mut self.poly;
        let trashed = self.engines.take_loaded(rate, self.last_key, |note| {
            report_ended(poly, context, EndedVoice { time: 0, note });
        });
        if trashed {
            context.execute_background(Task::CollectGarbage);
        }
        self.read_events(context);

        let n = buffer.samples();
        let channels = buffer.as_slice();
        if self.engines.current.is_none() || channels.len() < 2 || self.input.is_empty() {
            for channel in channels.iter_mut() {
                channel.fill(0.0);
            }
            return ProcessStatus::Normal;
        }
        let exciter = aux.inputs.first().map(|b| b.as_slice_immutable());

        // Render in segments no longer than the buffers sized for the announced maximum block.
        let max_segment = self.input.len();
        let (mut start, mut next_event) = (0, 0);
        while start < n {
            let end = (start + max_segment).min(n);
            self.segment_events.clear();
            while let Some(event) = self.events.get(next_event) {
                let time = event.time() as usize;
                if time >= end && end < n {
                    break;
                }
                let at = time.saturating_sub(start).min(end - start - 1);
                self.segment_events.push(event.at(at as u32));
                next_event += 1;
            }
            self.render_segment(channels, exciter, start, end, context);
            start = end;
        }
        // Modulation of notes that no longer sound (their end lost, or never started) is
        // forgotten.
        if let Some(engine) = self.engines.current.as_ref() {
            self.poly.retain(|id| engine.has_note_id(id));
        }
        if let Some(started) = started {
            self.editor_shared.measure_block(
                self.engines.current.as_deref(),
                self.engines.playing_generation,
                channels,
                started.elapsed(),
                rate,
            );
        }
        let silent = self.engines.current.as_ref().is_none_or(|e| e.is_silent())
            && !self.engines.outgoing.is_active();
        if silent {
            ProcessStatus::Normal
        } else {
            ProcessStatus::KeepAlive
        }
    }
}

/// Brings a saved state up to [`STATE_FORMAT`]: states saved before the format was recorded are
/// format 1. A state from a newer version keeps its fields (its newer ones are ignored).
///
/// Format 2: a strike position is a place on the object; in format 1 it was a fraction of the
/// span of the bank's positions, so a saved position is moved to the place it meant.
pub fn migrate_state(state: &mut PluginState) {
    let format = state
        .fields
        .get(STATE_FORMAT_FIELD)
        .and_then(|f| f.trim().parse::<u32>().ok())
        .unwrap_or(1);
    if format > STATE_FORMAT {
        return;
    }
    if format < 2 {
        let json = state
            .fields
            .get("bank")
            .and_then(|field| serde_json::from_str::<String>(field).ok())
            .unwrap_or_default();
        // A bank that does not load is replaced by the last good one, whose positions are not
        // known here: its strike position stays as it was.
        if let Ok(bank) = bank_from_state(&json) {
            let coords: Vec<Vec<f64>> = bank.positions.iter().map(|p| p.coords.clone()).collect();
            let map = PositionMap::new(&coords);
            for (axis, id) in [(0, "posx"), (1, "posy")] {
                if let Some(ParamValue::F32(value)) = state.params.get_mut(id) {
                    *value = map.from_span_fraction(axis, *value);
                }
            }
        }
    }
    state
        .fields
        .insert(STATE_FORMAT_FIELD.to_string(), STATE_FORMAT.to_string());
}

impl<K: Kind> ClapPlugin for ModalPlugin<K> {
    const CLAP_ID: &'static str = K::CLAP_ID;
    const CLAP_DESCRIPTION: Option<&'static str> = Some(K::DESCRIPTION);
    const CLAP_MANUAL_URL: Option<&'static str> = None;
    const CLAP_SUPPORT_URL: Option<&'static str> = None;
    const CLAP_FEATURES: &'static [ClapFeature] = K::CLAP_FEATURES;
    // Notes on one key and channel share a voice (a struck object restruck), so voices never
    // overlap.
    const CLAP_POLY_MODULATION_CONFIG: Option<PolyModulationConfig> = Some(PolyModulationConfig {
        max_voice_capacity: MAX_POLYPHONY as u32,
        supports_overlapping_voices: false,
    });
}

impl<K: Kind> Vst3Plugin for ModalPlugin<K> {
    const VST3_CLASS_ID: [u8; 16] = K::VST3_CLASS_ID;
    const VST3_SUBCATEGORIES: &'static [Vst3SubCategory] = K::VST3_SUBCATEGORIES;
    const VST3_MIDI_CONTROLLERS: &'static [u8] = &VST3_MIDI_CONTROLLERS;
}

nice_export_clap!(ModalResonator, ModalResonatorFx);
nice_export_vst3!(ModalResonator, ModalResonatorFx);

#[cfg(test)]
mod tests {
    use super::*;

    fn state_with(fields: &[(&str, &str)]) -> PluginState {
        PluginState {
            version: String::new(),
            params: Default::default(),
            fields: fields
                .iter()
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .collect(),
        }
    }

    #[test]
    fn a_format_1_strike_position_comes_forward_to_the_place_it_meant() {
        // The default bank, a marimba bar measured from its end to its centre: 0.5 of that span
        // was the quarter point of the bar.
        let mut old = state_with(&[("bank", "\"\"")]);
        old.params.insert("posx".into(), ParamValue::F32(0.5));
        old.params.insert("posy".into(), ParamValue::F32(0.3));
        migrate_state(&mut old);
        assert!(matches!(old.params["posx"], ParamValue::F32(x) if x == 0.25));
        // A line has no y to move along: kept.
        assert!(matches!(old.params["posy"], ParamValue::F32(y) if y == 0.3));
        // Once migrated, it stays.
        migrate_state(&mut old);
        assert!(matches!(old.params["posx"], ParamValue::F32(x) if x == 0.25));
    }

    #[test]
    fn states_are_brought_to_the_current_format() {
        // Saved before the format was recorded: format 1.
        let mut old = state_with(&[("bank", "\"\"")]);
        migrate_state(&mut old);
        assert_eq!(old.fields[STATE_FORMAT_FIELD], STATE_FORMAT.to_string());
        assert_eq!(old.fields["bank"], "\"\"");
        // A newer format is left as it is.
        let newer = (STATE_FORMAT + 1).to_string();
        let mut new = state_with(&[(STATE_FORMAT_FIELD, &newer)]);
        migrate_state(&mut new);
        assert_eq!(new.fields[STATE_FORMAT_FIELD], newer);
    }
}
