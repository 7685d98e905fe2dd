//! Controls by name, as `--set name=value` gives them: every numeric control, material, exciter
//! and the pruning switch, with errors that name the range or the choices.

use super::{Controls, Material, MATERIAL_Q_RANGE, NUMERIC_CONTROLS};
use crate::dsp::ExciterKind;
use crate::engine::ExpressionTarget;

impl Controls {
    /// Sets a control from text, as in `--set name=value`: any numeric control,
    /// `material_q` (a number or `authored`), `material` (plastic, wood, ceramic, glass, metal),
    /// `exciter` (impulse, mallet, noise, scrape, roll, rub), `mod_wheel_target` and
    /// `pressure_target` (none, position, damping, speed, force), `pruning` and `mpe` (on, off).
    /// Values outside a range are errors, not clamped.
    pub fn set_by_name(&mut self, name: &str, value: &str) -> Result<(), String> {
        let value = value.trim();
        match name {
            "material" => {
                let names = Material::ALL.iter().map(|m| m.name());
                self.set_material(one_of(name, value, Material::from_name(value), names)?);
            }
            "exciter" => {
                let names = ExciterKind::ALL.iter().map(|k| k.name());
                self.exciter = one_of(name, value, ExciterKind::from_name(value), names)?;
            }
            "mod_wheel_target" | "pressure_target" => {
                let names = ExpressionTarget::ALL.iter().map(|t| t.name());
                let target = one_of(name, value, ExpressionTarget::from_name(value), names)?;
                if name == "mod_wheel_target" {
                    self.mod_wheel_target = target;
                } else {
                    self.pressure_target = target;
                }
            }
            "pruning" | "mpe" => {
                let on = on_or_off(name, value)?;
                if name == "mpe" {
                    self.mpe = on;
                } else {
                    self.pruning = on;
                }
            }
            "material_q" if value == "authored" => self.material_q = None,
            "material_q" => {
                let q = parse_in_range(name, value, MATERIAL_Q_RANGE.0, MATERIAL_Q_RANGE.1)?;
                self.material_q = Some(q);
            }
            _ => self.set_numeric(name, value)?,
        }
        Ok(())
    }

    /// Sets numeric control `name` (one of [`NUMERIC_CONTROLS`]) from text, within its range.
    fn set_numeric(&mut self, name: &str, value: &str) -> Result<(), String> {
        let spec = NUMERIC_CONTROLS
            .iter()
            .find(|s| s.name == name)
            .ok_or_else(|| {
                let mut names: Vec<_> = NUMERIC_CONTROLS.iter().map(|s| s.name).collect();
                names.extend([
                    "material_q",
                    "material",
                    "exciter",
                    "mod_wheel_target",
                    "pressure_target",
                ]);
                format!(
                    "unknown control \"{name}\"; known controls: {}",
                    names.join(", ")
                )
            })?;
        let v = parse_in_range(name, value, spec.min, spec.max)?;
        if spec.integer && v.fract() != 0.0 {
            return Err(format!(
                "{name}: expected a whole number from {} to {}, found {v}",
                spec.min, spec.max
            ));
        }
        (spec.set)(self, v);
        Ok(())
    }
}

/// The choice `found` for `value` of control `name`, or an error listing its `names`.
fn one_of<T>(
    name: &str,
    value: &str,
    found: Option<T>,
    names: impl Iterator<Item = &'static str>,
) -> Result<T, String> {
    found.ok_or_else(|| {
        let names: Vec<_> = names.collect();
        format!(
            "{name}: expected one of {}, found \"{value}\"",
            names.join(", ")
        )
    })
}

/// A switch's `value` of control `name`: on or off (true, false, 1, 0), in any case.
fn on_or_off(name: &str, value: &str) -> Result<bool, String> {
    match value.to_ascii_lowercase().as_str() {
        "on" | "true" | "1" => Ok(true),
        "off" | "false" | "0" => Ok(false),
        _ => Err(format!(
            "{name}: expected on or off (true, false, 1, 0), found \"{value}\""
        )),
    }
}

fn parse_in_range(name: &str, value: &str, min: f32, max: f32) -> Result<f32, String> {
    let v: f32 = value
        .parse()
        .map_err(|_| format!("{name}: expected a number from {min} to {max}, found \"{value}\""))?;
    if !(min..=max).contains(&v) {
        return Err(format!(
            "{name}: expected a number from {min} to {max}, found {v}"
        ));
    }
    Ok(v)
}
