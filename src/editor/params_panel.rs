//! Every host parameter as a labelled control with its value and unit, in groups. Sliders
//! ([`super::slider`]) reset on double-click (or Ctrl-click), move finely with Shift held, and take
//! typed values when their value is clicked; they read the parameters every frame, so host
//! automation moves them live.

use egui::{CollapsingHeader, ComboBox, Grid, Ui};
use nice_plug::prelude::{BoolParam, Enum, EnumParam, FloatParam, IntParam, Param, ParamSetter};

use super::slider::param_slider;
use crate::params::ModalParams;

/// Room the label and value columns need beside a slider, in points.
const LABEL_AND_VALUE_WIDTH: f32 = 215.0;
/// Narrowest and widest slider, in points.
const SLIDER_WIDTH: (f32, f32) = (70.0, 150.0);

/// One control.
enum Control<'a> {
    Float(&'a FloatParam),
    Int(&'a IntParam),
    Bool(&'a BoolParam),
    /// An enum parameter: its name, current index and a setter by index.
    Choice(&'a dyn ChoiceParam),
}

/// An enum parameter seen without its type.
trait ChoiceParam {
    fn name(&self) -> &str;
    fn variants(&self) -> &'static [&'static str];
    fn index(&self) -> usize;
    fn set_index(&self, setter: &ParamSetter, index: usize);
    fn default_index(&self) -> usize;
}

impl<T: Enum + PartialEq + 'static> ChoiceParam for EnumParam<T> {
    fn name(&self) -> &str {
        Param::name(self)
    }
    fn variants(&self) -> &'static [&'static str] {
        T::variants()
    }
    fn index(&self) -> usize {
        self.value().to_index()
    }
    fn set_index(&self, setter: &ParamSetter, index: usize) {
        setter.begin_set_parameter(self);
        setter.set_parameter(self, T::from_index(index));
        setter.end_set_parameter(self);
    }
    fn default_index(&self) -> usize {
        self.default_plain_value().to_index()
    }
}

/// The groups and their controls, in display order.
fn groups(p: &ModalParams) -> Vec<(&'static str, Vec<Control<'_>>)> {
    use Control::*;
    // The instrument's dry/wet mixes its exciter input, the effect's its audio input.
    let output = vec![
        Float(&p.output.output_gain),
        Float(&p.output.width),
        Float(&p.output.dry_wet),
        Bool(&p.bypass),
    ];
    vec![
        (
            "Object",
            vec![
                Float(&p.object.size),
                Float(&p.object.key_tracking),
                Float(&p.object.fine_tune),
                Float(&p.object.bend_range),
            ],
        ),
        (
            "Strike",
            vec![
                Float(&p.strike.strike_x),
                Float(&p.strike.strike_y),
                Float(&p.strike.position_variation),
                Float(&p.strike.strike_variation),
                Choice(&p.strike.exciter),
                Float(&p.strike.hardness),
                Float(&p.strike.velocity_sensitivity),
                Float(&p.strike.velocity_to_hardness),
                Float(&p.strike.roughness),
                Float(&p.strike.rolling_radius),
                Float(&p.strike.contact_speed),
                Float(&p.strike.contact_force),
            ],
        ),
        (
            "Material",
            vec![
                Choice(&p.material.material),
                Float(&p.material.material_q),
                Float(&p.material.damping_tilt),
                Float(&p.material.release_damping),
            ],
        ),
        (
            "Voices",
            vec![
                Int(&p.voices.polyphony),
                Float(&p.voices.truncation),
                Choice(&p.voices.mod_wheel_target),
                Choice(&p.voices.pressure_target),
                Bool(&p.voices.mpe),
                Float(&p.voices.mpe_bend_range),
            ],
        ),
        (
            "Pruning",
            vec![
                Bool(&p.pruning.pruning),
                Float(&p.pruning.masking_offset),
                Float(&p.pruning.playback_level),
                Float(&p.pruning.analysis_frame),
                Int(&p.pruning.mode_budget),
                Float(&p.pruning.target_load),
            ],
        ),
        ("Output", output),
        (
            "Input",
            vec![
                Choice(&p.input.input_mode),
                Float(&p.input.input_gain),
                Float(&p.input.trigger_threshold),
                Float(&p.input.retrigger),
            ],
        ),
    ]
}

/// The strike axes the panel last marked as changing nothing for the bank shown (for tests).
pub fn fixed_strike_axes(ctx: &egui::Context) -> Option<[bool; 2]> {
    ctx.memory(|m| m.data.get_temp(fixed_axes_id()))
}

fn fixed_axes_id() -> egui::Id {
    egui::Id::unique("fixed-strike-axes")
}

/// The names of every parameter the panel shows, in order (for tests).
pub fn shown_names(params: &ModalParams) -> Vec<String> {
    groups(params)
        .iter()
        .flat_map(|(_, controls)| controls.iter().map(control_name))
        .collect()
}

fn control_name(c: &Control) -> String {
    match c {
        Control::Float(p) => p.name().to_string(),
        Control::Int(p) => p.name().to_string(),
        Control::Bool(p) => p.name().to_string(),
        Control::Choice(p) => p.name().to_string(),
    }
}

/// Draws the parameter groups in a panel `panel_width` points wide (the width the panel starts
/// with: sizing the sliders by the width left would let the panel creep frame by frame).
/// `fixed_axes` says along which axes the bank's strike positions do not vary: the strike
/// position there changes nothing, and its label says so.
pub fn show(
    ui: &mut Ui,
    params: &ModalParams,
    setter: &ParamSetter,
    panel_width: f32,
    fixed_axes: [bool; 2],
) {
    let width = (panel_width - LABEL_AND_VALUE_WIDTH).clamp(SLIDER_WIDTH.0, SLIDER_WIDTH.1);
    ui.memory_mut(|m| m.data.insert_temp(fixed_axes_id(), fixed_axes));
    ui.label(
        egui::RichText::new("Double-click resets · Shift-drag fine · click a value to type")
            .small()
            .weak(),
    );
    for (group, controls) in groups(params) {
        CollapsingHeader::new(group)
            .default_open(true)
            .show(ui, |ui| {
                Grid::new(group)
                    .num_columns(2)
                    .spacing([8.0, 4.0])
                    .show(ui, |ui| {
                        for control in &controls {
                            let name = control_name(control);
                            let fixed = [&params.strike.strike_x, &params.strike.strike_y]
                                .iter()
                                .zip(fixed_axes)
                                .any(|(p, fixed)| fixed && p.name() == name);
                            if fixed {
                                ui.label(egui::RichText::new(&name).weak()).on_hover_text(
                                    "The bank's strike positions do not vary along this axis: \
                                     moving it changes nothing for this bank.",
                                );
                            } else {
                                ui.label(name);
                            }
                            show_control(ui, control, setter, width);
                            ui.end_row();
                        }
                    });
            });
    }
}

fn show_control(ui: &mut Ui, control: &Control, setter: &ParamSetter, width: f32) {
    match control {
        Control::Float(p) => param_slider(ui, *p, setter, width),
        Control::Int(p) => param_slider(ui, *p, setter, width),
        Control::Bool(p) => {
            let mut on = p.value();
            let text = if on { "On" } else { "Off" };
            let response = ui.checkbox(&mut on, text);
            if response.changed() {
                setter.begin_set_parameter(*p);
                setter.set_parameter(*p, on);
                setter.end_set_parameter(*p);
            }
        }
        Control::Choice(p) => {
            let variants = p.variants();
            let current = p.index();
            let mut chosen = current;
            let response = ComboBox::from_id_salt(p.name())
                .width(width)
                .selected_text(variants.get(current).copied().unwrap_or("?"))
                .show_ui(ui, |ui| {
                    for (i, name) in variants.iter().enumerate() {
                        ui.selectable_value(&mut chosen, i, *name);
                    }
                })
                .response;
            if response.double_clicked() {
                chosen = p.default_index();
            }
            if chosen != current {
                p.set_index(setter, chosen);
            }
        }
    }
}
