//! What differs between the instrument and the effect: names, ids, ports and categories.

use std::num::NonZeroU32;

use nice_plug::prelude::*;

/// One of the two plugins built from the same code.
pub trait Kind: Default + Send + Sync + 'static {
    /// Display name.
    const NAME: &'static str;
    /// CLAP id, reverse-domain.
    const CLAP_ID: &'static str;
    /// One-line description.
    const DESCRIPTION: &'static str;
    /// CLAP categories.
    const CLAP_FEATURES: &'static [ClapFeature];
    /// VST3 class id: 16 bytes, unique.
    const VST3_CLASS_ID: [u8; 16];
    /// VST3 categories.
    const VST3_SUBCATEGORIES: &'static [Vst3SubCategory];
    /// Audio ports.
    const AUDIO_IO_LAYOUTS: &'static [AudioIOLayout];
    /// Whether this is the effect: its main input excites the modes and is mixed in dry.
    const IS_EFFECT: bool;
}

/// The instrument: MIDI in, stereo out, and a stereo "Exciter" input for audio excitation.
#[derive(Default)]
pub struct Instrument;

/// The effect: stereo in excites the resonators, stereo out with dry/wet; MIDI optional.
#[derive(Default)]
pub struct Effect;

impl Kind for Instrument {
    const NAME: &'static str = "Modal Resonator";
    const CLAP_ID: &'static str = "org.modal-resonator.instrument";
    const DESCRIPTION: &'static str = "Modal synthesis: struck objects from physics and recordings";
    const CLAP_FEATURES: &'static [ClapFeature] = &[
        ClapFeature::Instrument,
        ClapFeature::Synthesizer,
        ClapFeature::Stereo,
    ];
    const VST3_CLASS_ID: [u8; 16] = *b"ModalResonatorIn";
    const VST3_SUBCATEGORIES: &'static [Vst3SubCategory] = &[
        Vst3SubCategory::Instrument,
        Vst3SubCategory::Synth,
        Vst3SubCategory::Stereo,
    ];
    const AUDIO_IO_LAYOUTS: &'static [AudioIOLayout] = &[
        AudioIOLayout {
            main_input_channels: None,
            main_output_channels: NonZeroU32::new(2),
            aux_input_ports: &[new_nonzero_u32(2)],
            names: PortNames {
                layout: Some("Stereo with exciter input"),
                aux_inputs: &["Exciter"],
                ..PortNames::const_default()
            },
            ..AudioIOLayout::const_default()
        },
        AudioIOLayout {
            main_input_channels: None,
            main_output_channels: NonZeroU32::new(2),
            ..AudioIOLayout::const_default()
        },
    ];
    const IS_EFFECT: bool = false;
}

impl Kind for Effect {
    const NAME: &'static str = "Modal Resonator FX";
    const CLAP_ID: &'static str = "org.modal-resonator.effect";
    const DESCRIPTION: &'static str = "Modal resonator bank excited by audio, with dry/wet";
    const CLAP_FEATURES: &'static [ClapFeature] = &[
        ClapFeature::AudioEffect,
        ClapFeature::Filter,
        ClapFeature::Stereo,
    ];
    const VST3_CLASS_ID: [u8; 16] = *b"ModalResonatorFx";
    const VST3_SUBCATEGORIES: &'static [Vst3SubCategory] = &[
        Vst3SubCategory::Fx,
        Vst3SubCategory::Filter,
        Vst3SubCategory::Stereo,
    ];
    const AUDIO_IO_LAYOUTS: &'static [AudioIOLayout] = &[AudioIOLayout {
        main_input_channels: NonZeroU32::new(2),
        main_output_channels: NonZeroU32::new(2),
        ..AudioIOLayout::const_default()
    }];
    const IS_EFFECT: bool = true;
}
