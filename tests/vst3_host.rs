//! The VST3 plugins driven in-process through their factory, as a host and Steinberg's validator
//! drive them: the edit controller's view of parameters the host sets while audio is processed,
//! the bypass kept in a saved state, and the hidden parameters that carry MIDI controllers.

use std::cell::{Cell, RefCell};
use std::collections::BTreeSet;
use std::ffi::{c_char, c_void};
use std::ptr;

use modal_resonator::plugin::VST3_MIDI_CONTROLLERS;
use modal_resonator::{ModalResonator, ModalResonatorFx};
use nice_plug::prelude::Vst3Plugin;
// The VST3 bindings nice-plug's wrapper is built on, as it re-exports them.
use nice_plug::wrapper::vst3::vst3::Steinberg::Vst::ParameterInfo_::ParameterFlags_::{
    kIsBypass, kIsHidden, kIsReadOnly,
};
use nice_plug::wrapper::vst3::vst3::Steinberg::Vst::*;
use nice_plug::wrapper::vst3::vst3::Steinberg::*;
use nice_plug::wrapper::vst3::vst3::{Class, ComPtr, ComWrapper, Interface};

unsafe extern "system" {
    /// The factory of the VST3 plugins this crate exports (`nice_export_vst3!`).
    fn GetPluginFactory() -> *mut c_void;
}

/// MIDI channels a VST3 host maps controllers on.
const MIDI_CHANNELS: i16 = 16;
/// VST3's controller numbers: CC 0 to 127, then channel pressure (128) and pitch bend (129).
const VST3_CONTROLLERS: i16 = 130;

/// A plugin instance: one object that is both component and edit controller.
struct Instance {
    component: ComPtr<IComponent>,
    controller: ComPtr<IEditController>,
    processor: ComPtr<IAudioProcessor>,
}

impl Instance {
    /// A new instance of the plugin with class id `cid`, initialised and set up for 48 kHz.
    fn new(cid: [u8; 16]) -> Self {
        // SAFETY: the factory and the objects it makes are used as the VST3 API specifies, each
        // pointer checked for null before use.
        unsafe {
            let factory = ComPtr::<IPluginFactory>::from_raw(GetPluginFactory().cast())
                .expect("the library has a VST3 factory");
            let mut object = ptr::null_mut();
            let cid = cid.map(|b| b as c_char);
            let iid = IComponent::IID.as_ptr() as *const c_char;
            assert_eq!(
                factory.createInstance(cid.as_ptr(), iid, &mut object),
                kResultOk
            );
            let component = ComPtr::<IComponent>::from_raw(object.cast()).expect("a component");
            assert_eq!(component.initialize(ptr::null_mut()), kResultOk);
            let controller = component.cast::<IEditController>().expect("its controller");
            let processor = component.cast::<IAudioProcessor>().expect("its processor");
            let mut setup = ProcessSetup {
                processMode: ProcessModes_::kRealtime as i32,
                symbolicSampleSize: SymbolicSampleSizes_::kSample32 as i32,
                maxSamplesPerBlock: 512,
                sampleRate: 48_000.0,
            };
            assert_eq!(processor.setupProcessing(&mut setup), kResultOk);
            assert_eq!(component.setActive(1), kResultOk);
            Self {
                component,
                controller,
                processor,
            }
        }
    }

    /// Every parameter's info, in the controller's order.
    fn parameters(&self) -> Vec<ParameterInfo> {
        // SAFETY: `info` is written by the controller for indices it counts.
        unsafe {
            (0..self.controller.getParameterCount())
                .map(|i| {
                    let mut info = std::mem::zeroed::<ParameterInfo>();
                    assert_eq!(self.controller.getParameterInfo(i, &mut info), kResultOk);
                    info
                })
                .collect()
        }
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: the reverse of `new`.
        unsafe {
            self.processor.setProcessing(0);
            self.component.setActive(0);
            self.component.terminate();
        }
    }
}

/// A parameter's title.
fn title(info: &ParameterInfo) -> String {
    let end = info
        .title
        .iter()
        .position(|&c| c == 0)
        .unwrap_or(info.title.len());
    String::from_utf16_lossy(&info.title[..end])
}

/// VST3 carries MIDI controllers as hidden parameters hosts map MIDI onto: one for each
/// controller the plugin reads on each channel (MPE plays on all 16), and no more, so hosts that
/// list hidden parameters do not wade through 2,080 of them.
#[test]
fn each_midi_controller_the_plugin_reads_has_a_hidden_parameter_on_every_channel() {
    for cid in [
        ModalResonator::PLATFORM_VST3_CLASS_ID,
        ModalResonatorFx::PLATFORM_VST3_CLASS_ID,
    ] {
        let plugin = Instance::new(cid);
        let mapping = plugin
            .component
            .cast::<IMidiMapping>()
            .expect("MIDI mapping");
        let parameters = plugin.parameters();
        let proxies = parameters
            .iter()
            .filter(|p| p.flags & kIsHidden != 0 && p.flags & kIsReadOnly != 0);
        for proxy in proxies.clone() {
            // JUCE names its proxies so, and hosts built on JUCE (pedalboard) skip them by name.
            let name = title(proxy);
            assert!(
                name.starts_with("MIDI CC "),
                "proxy {} is {name:?}",
                proxy.id
            );
        }
        let hidden: BTreeSet<ParamID> = proxies.map(|p| p.id).collect();
        let mut mapped = BTreeSet::new();
        for channel in 0..MIDI_CHANNELS {
            for controller in 0..VST3_CONTROLLERS {
                let mut id = 0;
                // SAFETY: `id` is written on success.
                let result =
                    unsafe { mapping.getMidiControllerAssignment(0, channel, controller, &mut id) };
                if result == kResultOk {
                    assert!(
                        hidden.contains(&id),
                        "channel {channel} controller {controller} maps to {id}, not listed"
                    );
                    mapped.insert((channel, controller as u8));
                }
            }
        }
        let wanted: BTreeSet<(i16, u8)> = (0..MIDI_CHANNELS)
            .flat_map(|c| VST3_MIDI_CONTROLLERS.iter().map(move |&cc| (c, cc)))
            .collect();
        let extra: Vec<_> = mapped.difference(&wanted).take(8).collect();
        let missing: Vec<_> = wanted.difference(&mapped).collect();
        assert!(
            extra.is_empty() && missing.is_empty(),
            "{} (channel, controller) pairs mapped; not read but mapped: {extra:?}...; read but \
             not mapped: {missing:?}",
            mapped.len()
        );
        assert_eq!(hidden.len(), wanted.len(), "one hidden parameter for each");
    }
}

impl Instance {
    /// The id of the parameter flagged as the bypass.
    fn bypass_id(&self) -> ParamID {
        let bypass = self
            .parameters()
            .into_iter()
            .filter(|p| p.flags & kIsBypass != 0);
        let ids: Vec<ParamID> = bypass.map(|p| p.id).collect();
        assert_eq!(ids.len(), 1, "one bypass parameter");
        ids[0]
    }

    fn set_processing(&self, on: bool) {
        // SAFETY: the processor is set up and active.
        assert_eq!(
            unsafe { self.processor.setProcessing(on.into()) },
            kResultOk
        );
    }

    /// A parameter flush, as the validator sends: no audio, `changes` at sample 0.
    fn flush(&self, changes: &[(ParamID, f64)]) {
        let changes = ComWrapper::new(ParameterChanges::new(changes));
        let changes = changes.to_com_ptr::<IParameterChanges>().unwrap();
        // SAFETY: no buffers and no events, as the VST3 API allows for a flush.
        let result = unsafe {
            let mut data = std::mem::zeroed::<ProcessData>();
            data.processMode = ProcessModes_::kRealtime as i32;
            data.symbolicSampleSize = SymbolicSampleSizes_::kSample32 as i32;
            data.inputParameterChanges = changes.as_ptr();
            self.processor.process(&mut data)
        };
        assert_eq!(result, kResultOk);
    }

    fn set(&self, id: ParamID, normalized: f64) {
        // SAFETY: a plain call on a live controller.
        assert_eq!(
            unsafe { self.controller.setParamNormalized(id, normalized) },
            kResultOk
        );
    }

    fn get(&self, id: ParamID) -> f64 {
        // SAFETY: a plain call on a live controller.
        unsafe { self.controller.getParamNormalized(id) }
    }

    /// The component's state, as a host saves it.
    fn save(&self) -> Vec<u8> {
        let stream = ComWrapper::new(MemoryStream::default());
        let ptr = stream.to_com_ptr::<IBStream>().unwrap();
        // SAFETY: the stream outlives the call.
        assert_eq!(unsafe { self.component.getState(ptr.as_ptr()) }, kResultOk);
        stream.data.take()
    }

    /// Restores `state` to the component, then to the controller, as a host loads a preset.
    fn load(&self, state: &[u8]) {
        for to_controller in [false, true] {
            let stream = ComWrapper::new(MemoryStream::default());
            stream.data.replace(state.to_vec());
            let ptr = stream.to_com_ptr::<IBStream>().unwrap();
            // SAFETY: the stream outlives the call.
            let result = unsafe {
                if to_controller {
                    self.controller.setComponentState(ptr.as_ptr())
                } else {
                    self.component.setState(ptr.as_ptr())
                }
            };
            assert_eq!(result, kResultOk);
        }
    }
}

/// A host's memory stream for states.
#[derive(Default)]
struct MemoryStream {
    /// The bytes.
    data: RefCell<Vec<u8>>,
    /// Where the next read or write starts.
    pos: Cell<usize>,
}

impl Class for MemoryStream {
    type Interfaces = (IBStream,);
}

impl IBStreamTrait for MemoryStream {
    unsafe fn read(&self, buffer: *mut c_void, num_bytes: i32, num_read: *mut i32) -> tresult {
        let data = self.data.borrow();
        let start = self.pos.get().min(data.len());
        let n = usize::try_from(num_bytes)
            .unwrap_or(0)
            .min(data.len() - start);
        // SAFETY: the caller gives room for `num_bytes`.
        unsafe {
            ptr::copy_nonoverlapping(data[start..].as_ptr(), buffer.cast(), n);
            if !num_read.is_null() {
                *num_read = n as i32;
            }
        }
        self.pos.set(start + n);
        kResultOk
    }

    unsafe fn write(&self, buffer: *mut c_void, num_bytes: i32, written: *mut i32) -> tresult {
        let n = usize::try_from(num_bytes).unwrap_or(0);
        // SAFETY: the caller gives `num_bytes` bytes.
        let bytes = unsafe { std::slice::from_raw_parts(buffer.cast::<u8>(), n) };
        let mut data = self.data.borrow_mut();
        let start = self.pos.get();
        let len = data.len().max(start + n);
        data.resize(len, 0);
        data[start..start + n].copy_from_slice(bytes);
        self.pos.set(start + n);
        if !written.is_null() {
            // SAFETY: checked for null.
            unsafe { *written = n as i32 };
        }
        kResultOk
    }

    unsafe fn seek(&self, pos: i64, mode: i32, result: *mut i64) -> tresult {
        let base = match mode as u32 {
            IBStream_::IStreamSeekMode_::kIBSeekSet => 0,
            IBStream_::IStreamSeekMode_::kIBSeekCur => self.pos.get() as i64,
            _ => self.data.borrow().len() as i64,
        };
        let Ok(new) = usize::try_from(base + pos) else {
            return kInvalidArgument;
        };
        self.pos.set(new);
        if !result.is_null() {
            // SAFETY: checked for null.
            unsafe { *result = new as i64 };
        }
        kResultOk
    }

    unsafe fn tell(&self, pos: *mut i64) -> tresult {
        if pos.is_null() {
            return kInvalidArgument;
        }
        // SAFETY: checked for null.
        unsafe { *pos = self.pos.get() as i64 };
        kResultOk
    }
}

/// One parameter's changes in a block: a single point.
struct ParamQueue {
    /// The parameter.
    id: ParamID,
    /// Its value from sample 0.
    value: f64,
}

impl Class for ParamQueue {
    type Interfaces = (IParamValueQueue,);
}

impl IParamValueQueueTrait for ParamQueue {
    unsafe fn getParameterId(&self) -> ParamID {
        self.id
    }

    unsafe fn getPointCount(&self) -> i32 {
        1
    }

    unsafe fn getPoint(&self, index: i32, offset: *mut i32, value: *mut f64) -> tresult {
        if index != 0 || offset.is_null() || value.is_null() {
            return kInvalidArgument;
        }
        // SAFETY: checked for null.
        unsafe {
            *offset = 0;
            *value = self.value;
        }
        kResultOk
    }

    unsafe fn addPoint(&self, _offset: i32, _value: f64, _index: *mut i32) -> tresult {
        kResultFalse
    }
}

/// The parameter changes of a block, as a host hands them to `process`.
struct ParameterChanges {
    /// One queue per parameter.
    queues: Vec<ComWrapper<ParamQueue>>,
}

impl ParameterChanges {
    fn new(changes: &[(ParamID, f64)]) -> Self {
        let queues = changes
            .iter()
            .map(|&(id, value)| ComWrapper::new(ParamQueue { id, value }))
            .collect();
        Self { queues }
    }
}

impl Class for ParameterChanges {
    type Interfaces = (IParameterChanges,);
}

impl IParameterChangesTrait for ParameterChanges {
    unsafe fn getParameterCount(&self) -> i32 {
        self.queues.len() as i32
    }

    unsafe fn getParameterData(&self, index: i32) -> *mut IParamValueQueue {
        usize::try_from(index)
            .ok()
            .and_then(|i| self.queues.get(i))
            .and_then(|q| q.as_com_ref::<IParamValueQueue>())
            .map_or(ptr::null_mut(), |q| q.as_ptr())
    }

    unsafe fn addParameterData(
        &self,
        _id: *const ParamID,
        _index: *mut i32,
    ) -> *mut IParamValueQueue {
        ptr::null_mut()
    }
}

/// Steinberg's validator's bypass persistence test, step by step: while audio is processed, the
/// host sets the bypass on the controller and sends it to the processor; the controller must show
/// it at once, a state saved then holds it, and loading that state brings it back.
#[test]
fn the_controller_shows_the_bypass_the_host_sets_while_processing_and_a_state_keeps_it() {
    for cid in [
        ModalResonator::PLATFORM_VST3_CLASS_ID,
        ModalResonatorFx::PLATFORM_VST3_CLASS_ID,
    ] {
        let plugin = Instance::new(cid);
        let bypass = plugin.bypass_id();

        plugin.set_processing(true);
        plugin.set(bypass, 1.0);
        assert_eq!(plugin.get(bypass), 1.0, "the bypass set while processing");
        plugin.flush(&[(bypass, 1.0)]);
        assert_eq!(plugin.get(bypass), 1.0, "the bypass once processed");
        plugin.set_processing(false);
        let saved = plugin.save();

        plugin.set_processing(true);
        plugin.set(bypass, 0.0);
        assert_eq!(
            plugin.get(bypass),
            0.0,
            "the bypass lifted while processing"
        );
        plugin.flush(&[(bypass, 0.0)]);
        plugin.set_processing(false);
        assert_eq!(plugin.get(bypass), 0.0, "the bypass lifted once processed");

        plugin.load(&saved);
        assert_eq!(plugin.get(bypass), 1.0, "the bypass of the state loaded");
    }
}

/// What the controller shows while processing is what the host set there, until the processor
/// has the change, and then the processor's value.
#[test]
fn a_value_set_on_the_controller_while_processing_shows_until_the_processor_has_it() {
    let plugin = Instance::new(ModalResonator::PLATFORM_VST3_CLASS_ID);
    let param = plugin.parameters()[0].id;
    let before = plugin.get(param);
    let value = if before > 0.5 { 0.25 } else { 0.75 };
    plugin.set_processing(true);
    plugin.set(param, value);
    assert_eq!(
        plugin.get(param),
        value,
        "the controller shows the host's value"
    );
    // The host then sends the processor the change it automates, which the plugin then plays.
    plugin.flush(&[(param, before)]);
    assert_eq!(
        plugin.get(param),
        before,
        "the processor's value once it has a change"
    );
    plugin.set_processing(false);
    assert_eq!(plugin.get(param), before);
}
