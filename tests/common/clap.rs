//! A CLAP host for tests and benchmarks: loads the built bundle with clack-host, plays a script
//! of notes, parameter changes, audio input and state loads, and returns what came out.

use std::ffi::CStr;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant};

use clack_extensions::params::{ParamInfoBuffer, ParamInfoFlags, PluginParams};
use clack_extensions::state::PluginState;
use clack_host::events::event_types::*;
use clack_host::events::Match;
use clack_host::prelude::*;

pub const RATE: f64 = 48_000.0;
pub const BLOCK: usize = 256;
pub const INSTRUMENT: &CStr = c"org.modal-resonator.instrument";
pub const EFFECT: &CStr = c"org.modal-resonator.effect";

pub struct Shared {
    state_ext: OnceLock<Option<PluginState>>,
    params_ext: OnceLock<Option<PluginParams>>,
    callback_requested: AtomicBool,
}

impl<'a> SharedHandler<'a> for Shared {
    fn initializing(&self, instance: InitializingPluginHandle<'a>) {
        let _ = self.state_ext.set(instance.get_extension());
        let _ = self.params_ext.set(instance.get_extension());
    }
    fn request_restart(&self) {}
    fn request_process(&self) {}
    fn request_callback(&self) {
        self.callback_requested.store(true, Ordering::SeqCst);
    }
}

pub struct Host;
impl HostHandlers for Host {
    type Shared<'a> = Shared;
    type MainThread<'a> = ();
    type AudioProcessor<'a> = ();
}

/// Which built bundle a test loads.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Build {
    /// `cargo xtask bundle modal-resonator --release`, in `target/bundled`.
    Release,
    /// `cargo xtask bundle modal-resonator --features assert_process_allocs`, its
    /// `target/bundled` then moved to `target/alloc-check/bundled`: a debug build that aborts
    /// on any allocation in `process`.
    AllocCheck,
}

/// The path of a built CLAP bundle, found from this test's own target directory.
pub fn bundle(build: Build) -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    // target/<profile>/deps/<test> -> target
    let target = exe
        .parent()
        .and_then(|p| p.parent())
        .and_then(|p| p.parent())
        .unwrap();
    let (dir, how) = match build {
        Build::Release => (
            target.to_path_buf(),
            "cargo xtask bundle modal-resonator --release",
        ),
        Build::AllocCheck => (
            target.join("alloc-check"),
            "cargo xtask bundle modal-resonator --features assert_process_allocs && rm -rf \
             target/alloc-check && mkdir target/alloc-check && mv target/bundled \
             target/alloc-check/ && cargo xtask bundle modal-resonator --release",
        ),
    };
    let path = dir.join("bundled").join("Modal Resonator.clap");
    assert!(
        path.exists(),
        "{} is missing: run `{how}` first",
        path.display()
    );
    path
}

/// A bundle, loaded once for the whole test process: loading and unloading a plugin library
/// from several threads at once is not something hosts do.
pub fn entry(build: Build) -> &'static PluginEntry {
    static RELEASE: OnceLock<PluginEntry> = OnceLock::new();
    static ALLOC_CHECK: OnceLock<PluginEntry> = OnceLock::new();
    let cell = if build == Build::Release {
        &RELEASE
    } else {
        &ALLOC_CHECK
    };
    // SAFETY: the bundle is our own plugin, built for this machine.
    cell.get_or_init(|| unsafe { PluginEntry::load(bundle(build)) }.expect("the bundle loads"))
}

/// Held by each session: one plugin instance at a time, as in a host's test of one track.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// The CLAP parameter id nice-plug derives from a parameter's string id.
pub fn param_id(id: &str) -> ClapId {
    let mut hash: u32 = 0;
    for b in id.bytes() {
        hash = hash.wrapping_mul(31).wrapping_add(b as u32);
    }
    ClapId::new(hash & !(1 << 31))
}

/// Something the host sends at an absolute sample time.
#[derive(Clone, Copy)]
pub enum Send {
    On(u16, f64),
    Off(u16),
    /// A parameter by string id, in CLAP's value (normalised 0..1, or the index of an enum).
    Param(&'static str, f64),
    /// A raw MIDI message on port 0.
    Midi([u8; 3]),
    /// A CLAP note expression on a key.
    Expression(NoteExpressionType, u16, f64),
    /// A note-on with a channel and a note id: key, channel, id, velocity.
    NoteOn(u16, u16, u32, f64),
    /// Polyphonic modulation of a parameter (by string id) on one note id, in CLAP's
    /// normalised units.
    Mod(&'static str, u32, f64),
}

/// A note end the plugin reported: absolute sample time, note id (-1 for none), key, channel.
pub type NoteEnd = (usize, i32, i16, i16);

/// What one session with a plugin produced.
pub struct Session {
    pub left: Vec<f32>,
    pub right: Vec<f32>,
    pub state: Vec<u8>,
    /// What the plugin answered after each block: whether it may be put to sleep.
    pub statuses: Vec<ProcessStatus>,
    /// Time spent inside the plugin's process calls.
    pub process_time: Duration,
    /// The note ends the plugin reported.
    pub note_ends: Vec<NoteEnd>,
}

/// What a session plays.
pub struct Script<'a> {
    /// Which bundle.
    pub build: Build,
    /// Which plugin in it.
    pub plugin: &'a CStr,
    /// A state restored before activation.
    pub state: Option<&'a [u8]>,
    /// Events at absolute sample times.
    pub events: &'a [(usize, Send)],
    /// Audio on the input port.
    pub input: Option<&'a [Vec<f32>; 2]>,
    /// Samples to render.
    pub samples: usize,
    /// A state loaded while active, between blocks, at this sample: a bank swap.
    pub swap: Option<(usize, &'a [u8])>,
    /// Sample rate in Hz.
    pub rate: f64,
    /// Block sizes, used in turn.
    pub blocks: &'a [usize],
    /// The largest block announced at activation (default: the largest of `blocks`).
    pub max_block: Option<usize>,
    /// A sample at which the host stops and restarts processing (which resets the plugin).
    pub restart_at: Option<usize>,
}

impl<'a> Script<'a> {
    pub fn new(plugin: &'a CStr, samples: usize) -> Self {
        Self {
            build: Build::Release,
            plugin,
            state: None,
            events: &[],
            input: None,
            samples,
            swap: None,
            rate: RATE,
            blocks: &[BLOCK],
            max_block: None,
            restart_at: None,
        }
    }
}

/// Loads `plugin` from the bundle, restores `state` if given, activates at 48 kHz, plays `events`
/// with `input` on the input port, renders `samples` samples, saves the state and returns.
pub fn session(
    plugin: &CStr,
    state: Option<&[u8]>,
    events: &[(usize, Send)],
    input: Option<&[Vec<f32>; 2]>,
    samples: usize,
) -> Session {
    run(&Script {
        state,
        events,
        input,
        ..Script::new(plugin, samples)
    })
}

/// What the host's main thread is asked to do while the audio thread plays.
#[derive(Clone, Copy)]
enum MainThread {
    /// Load the script's swapped state now.
    LoadSwap,
    /// Run the plugin's main-thread callback if it asked for one.
    Serve,
}

/// Renders `script` on an audio thread of its own while `main_thread` serves the plugin's
/// callback requests on this (the main) thread, as a host does. When the script has a swap, the
/// audio thread waits between blocks at its sample while the state loads here, as a host loading
/// a state while it plays.
#[allow(clippy::too_many_arguments)] // test plumbing: every output has its own place
fn render_span(
    script: &Script,
    processor: StoppedPluginAudioProcessor<Host>,
    span: std::ops::Range<usize>,
    main_thread: &mut dyn FnMut(MainThread),
    left: &mut Vec<f32>,
    right: &mut Vec<f32>,
    statuses: &mut Vec<ProcessStatus>,
    process_time: &mut Duration,
    note_ends: &mut Vec<NoteEnd>,
) -> StoppedPluginAudioProcessor<Host> {
    let reached = AtomicBool::new(false);
    let loaded = AtomicBool::new(false);
    std::thread::scope(|s| {
        let audio = s.spawn(|| {
            let mut p = processor.start_processing().unwrap();
            let mut in_ports = AudioPorts::with_capacity(2, 1);
            let mut out_ports = AudioPorts::with_capacity(2, 1);
            // Room for every note end of a block, so the plugin's pushes never allocate here
            // (the allocation-checking build would count them as its own).
            let mut out_events = EventBuffer::with_capacity(4_096);
            let mut start = span.start;
            let mut block = 0;
            while start < span.end {
                let n = script.blocks[block % script.blocks.len()].min(span.end - start);
                block += 1;
                let mut evs = EventBuffer::new();
                for &(t, e) in script
                    .events
                    .iter()
                    .filter(|(t, _)| (start..start + n).contains(t))
                {
                    let time = (t - start) as u32;
                    match e {
                        Send::On(key, vel) => evs.push(&NoteOnEvent::new(
                            time,
                            Pckn::new(0u16, 0u16, key, Match::All),
                            vel,
                        )),
                        Send::Off(key) => evs.push(&NoteOffEvent::new(
                            time,
                            Pckn::new(0u16, 0u16, key, Match::All),
                            0.0,
                        )),
                        Send::Param(id, value) => evs.push(&ParamValueEvent::new(
                            time,
                            param_id(id),
                            Pckn::match_all(),
                            value,
                        )),
                        Send::Midi(bytes) => evs.push(&MidiEvent::new(time, 0, bytes)),
                        Send::Expression(kind, key, value) => evs.push(&NoteExpressionEvent::new(
                            time,
                            Pckn::new(0u16, 0u16, key, Match::All),
                            kind,
                            value,
                        )),
                        Send::NoteOn(key, channel, id, vel) => evs.push(&NoteOnEvent::new(
                            time,
                            Pckn::new(0u16, channel, key, id),
                            vel,
                        )),
                        Send::Mod(param, id, amount) => evs.push(&ParamModEvent::new(
                            time,
                            param_id(param),
                            Pckn::new(Match::All, Match::All, Match::All, id),
                            amount,
                        )),
                    }
                }
                let mut inp: [Vec<f32>; 2] = match script.input {
                    Some(x) => [
                        x[0][start..start + n].to_vec(),
                        x[1][start..start + n].to_vec(),
                    ],
                    None => [vec![0.0; n], vec![0.0; n]],
                };
                let mut out = [vec![0.0f32; n], vec![0.0f32; n]];
                let input_audio = in_ports.with_input_buffers([AudioPortBuffer {
                    latency: 0,
                    channels: AudioPortBufferType::f32_input_only(
                        inp.iter_mut()
                            .map(|b| InputChannel::constant(b.as_mut_slice())),
                    ),
                }]);
                let mut output_audio = out_ports.with_output_buffers([AudioPortBuffer {
                    latency: 0,
                    channels: AudioPortBufferType::f32_output_only(
                        out.iter_mut().map(|b| b.as_mut_slice()),
                    ),
                }]);
                out_events.clear();
                let started = Instant::now();
                let status = p
                    .process(
                        &input_audio,
                        &mut output_audio,
                        &evs.as_input(),
                        &mut out_events.as_output(),
                        None,
                        None,
                    )
                    .expect("process succeeds");
                *process_time += started.elapsed();
                for e in out_events.iter() {
                    if let Some(end) = e.as_event::<NoteEndEvent>() {
                        let pckn = end.pckn();
                        note_ends.push((
                            start + end.header().time() as usize,
                            pckn.raw_note_id(),
                            pckn.raw_key(),
                            pckn.raw_channel(),
                        ));
                    }
                }
                statuses.push(status);
                left.extend_from_slice(&out[0]);
                right.extend_from_slice(&out[1]);
                start += n;
                if script
                    .restart_at
                    .is_some_and(|at| start - n < at && start >= at)
                {
                    p = p.stop_processing().start_processing().unwrap();
                }
                if let Some((at, _)) = script.swap {
                    if start >= at && !reached.swap(true, Ordering::SeqCst) {
                        while !loaded.load(Ordering::SeqCst) {
                            std::thread::sleep(Duration::from_millis(1));
                        }
                    }
                    if start >= at && start < at + 64 * BLOCK {
                        // Give the background thread time to build the new bank's engine.
                        std::thread::sleep(Duration::from_millis(2));
                    }
                }
            }
            p.stop_processing()
        });
        // The main thread, as a host's: it serves the plugin's callback requests while the
        // audio thread plays, and loads the swapped state when the audio reaches it.
        let mut swapped = script.swap.is_none();
        loop {
            let finished = audio.is_finished();
            if !swapped && (finished || reached.load(Ordering::SeqCst)) {
                main_thread(MainThread::LoadSwap);
                loaded.store(true, Ordering::SeqCst);
                swapped = true;
            }
            main_thread(MainThread::Serve);
            if finished {
                break;
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        audio.join().unwrap()
    })
}

/// A fresh instance of `plugin` from the `build` bundle.
fn instantiate(build: Build, plugin: &CStr) -> PluginInstance<Host> {
    let host_info = HostInfo::new(
        "modal-resonator-tests",
        "Modal Resonator",
        "https://modal-resonator.org",
        "0.1.0",
    )
    .unwrap();
    PluginInstance::<Host>::new(
        |_| Shared {
            state_ext: OnceLock::new(),
            params_ext: OnceLock::new(),
            callback_requested: AtomicBool::new(false),
        },
        |_| (),
        entry(build),
        plugin,
        &host_info,
    )
    .expect("the plugin instantiates")
}

/// A parameter as the CLAP params extension lists it.
#[derive(Debug)]
pub struct ParamDesc {
    pub id: ClapId,
    pub name: String,
    /// The module path hosts group it under.
    pub module: String,
    /// Whether it is the plugin's bypass (CLAP_PARAM_IS_BYPASS).
    pub bypass: bool,
}

/// The parameters `plugin` lists through the CLAP params extension.
pub fn param_infos(plugin: &CStr) -> Vec<ParamDesc> {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let mut instance = instantiate(Build::Release, plugin);
    let ext = instance
        .access_shared_handler(|h| *h.params_ext.get().unwrap())
        .expect("params extension");
    let handle = instance.plugin_handle();
    let mut buffer = ParamInfoBuffer::new();
    (0..ext.count(&handle))
        .map(|i| {
            let info = ext.get_info(&handle, i, &mut buffer).expect("param info");
            ParamDesc {
                id: info.id,
                name: String::from_utf8_lossy(info.name).into_owned(),
                module: String::from_utf8_lossy(info.module).into_owned(),
                bypass: info.flags.contains(ParamInfoFlags::IS_BYPASS),
            }
        })
        .collect()
}

/// Plays `script` in a fresh instance.
pub fn run(script: &Script) -> Session {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let mut instance = instantiate(script.build, script.plugin);
    let state_ext = instance
        .access_shared_handler(|h| *h.state_ext.get().unwrap())
        .expect("state extension");
    if let Some(bytes) = script.state {
        state_ext
            .load(
                &instance.plugin_handle(),
                &mut std::io::Cursor::new(bytes.to_vec()),
            )
            .expect("state loads");
    }
    let max_block = script
        .max_block
        .unwrap_or_else(|| script.blocks.iter().copied().max().unwrap_or(BLOCK));
    let config = PluginAudioConfiguration {
        sample_rate: script.rate,
        min_frames_count: 1,
        max_frames_count: max_block as u32,
    };
    let mut processor = instance
        .activate(|_, _| (), config)
        .expect("the plugin activates");
    let mut left = Vec::with_capacity(script.samples);
    let mut right = Vec::with_capacity(script.samples);
    let mut statuses = Vec::new();
    let mut process_time = Duration::ZERO;
    let mut note_ends = Vec::new();
    let mut main_thread = |call: MainThread| match call {
        MainThread::LoadSwap => {
            if let Some((_, bytes)) = script.swap {
                state_ext
                    .load(
                        &instance.plugin_handle(),
                        &mut std::io::Cursor::new(bytes.to_vec()),
                    )
                    .expect("state loads");
            }
        }
        MainThread::Serve => {
            if instance
                .access_shared_handler(|h| h.callback_requested.swap(false, Ordering::SeqCst))
            {
                instance.call_on_main_thread_callback();
            }
        }
    };
    processor = render_span(
        script,
        processor,
        0..script.samples,
        &mut main_thread,
        &mut left,
        &mut right,
        &mut statuses,
        &mut process_time,
        &mut note_ends,
    );
    let mut saved = Vec::new();
    state_ext
        .save(&instance.plugin_handle(), &mut saved)
        .expect("state saves");
    instance.deactivate(processor);
    Session {
        left,
        right,
        state: saved,
        statuses,
        process_time,
        note_ends,
    }
}

/// `state` (a saved CLAP state: length, then JSON) with `bank` as its saved bank.
pub fn with_bank(state: &[u8], bank: &modal_resonator::bank::Bank) -> Vec<u8> {
    with_bank_text(state, &modal_resonator::bank::io::bank_to_json(bank))
}

/// The saved bank's JSON text in `state`.
pub fn bank_text(state: &[u8]) -> String {
    let json: serde_json::Value = serde_json::from_slice(&state[8..]).unwrap();
    serde_json::from_str(json["fields"]["bank"].as_str().unwrap()).unwrap()
}

/// `state` with `text` (valid or not) as its saved bank's JSON.
pub fn with_bank_text(state: &[u8], text: &str) -> Vec<u8> {
    let mut json: serde_json::Value = serde_json::from_slice(&state[8..]).unwrap();
    json["fields"]["bank"] = serde_json::Value::String(serde_json::to_string(text).unwrap());
    let text = serde_json::to_string(&json).unwrap();
    let mut bytes = (text.len() as u64).to_le_bytes().to_vec();
    bytes.extend_from_slice(text.as_bytes());
    bytes
}

/// A one-mode bank at `freq_hz`, rooted there.
pub fn sine_bank(freq_hz: f64) -> modal_resonator::bank::Bank {
    let mut bank = super::simple_bank(&[(freq_hz, 3.0, 1.0)]);
    bank.root_hz = Some(freq_hz);
    bank
}
