//! The VST3 plugins driven in-process through their factory, as a host and Steinberg's validator
//! drive them: the hidden parameters that carry MIDI controllers.

use std::collections::BTreeSet;
use std::ffi::{c_char, c_void};
use std::ptr;

use modal_resonator::plugin::VST3_MIDI_CONTROLLERS;
use modal_resonator::{ModalResonator, ModalResonatorFx};
use nice_plug::prelude::Vst3Plugin;
// The VST3 bindings nice-plug's wrapper is built on, as it re-exports them.
use nice_plug::wrapper::vst3::vst3::Steinberg::Vst::ParameterInfo_::ParameterFlags_::{
    kIsHidden, kIsReadOnly,
};
use nice_plug::wrapper::vst3::vst3::Steinberg::Vst::*;
use nice_plug::wrapper::vst3::vst3::Steinberg::*;
use nice_plug::wrapper::vst3::vst3::{ComPtr, Interface};

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
