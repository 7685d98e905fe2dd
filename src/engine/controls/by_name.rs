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
                let m = Material::from_name(value).ok_or_else(|| {
                    let names: Vec<_> = Material::ALL.iter().map(|m| m.name()).collect();
                    format!(
                        "material: expected one of {}, found \"{value}\"",
                        names.join(", ")
                    )
                })?;
                self.set_material(m);
                Ok(())
            }
            "exciter" => {
                self.exciter = ExciterKind::from_name(value).ok_or_else(|| {
                    let names: Vec<_> = ExciterKind::ALL.iter().map(|k| k.name()).collect();
                    format!(
                        "exciter: expected one of {}, found \"{value}\"",
                        names.join(", ")
                    )
                })?;
                Ok(())
            }
            "mod_wheel_target" | "pressure_target" => {
                let target = ExpressionTarget::from_name(value).ok_or_else(|| {
                    let names: Vec<_> = ExpressionTarget::ALL.iter().map(|t| t.name()).collect();
                    format!(
                        "{name}: expected one of {}, found \"{value}\"",
                        names.join(", ")
                    )
                })?;
                if name == "mod_wheel_target" {
                    self.mod_wheel_target = target;
                } else {
                    self.pressure_target = target;
                }
                Ok(())
            }
            "pruning" | "mpe" => {
                let on = match value.to_ascii_lowercase().as_str() {
                    "on" | "true" | "1" => true,
                    "off" | "false" | "0" => false,
                    _ => {
                        return Err(format!(
                            "{name}: expected on or off (true, false, 1, 0), found \"{value}\""
                        ))
                    }
                };
                if name == "mpe" {
                    self.mpe = on;
                } else {
                    self.pruning = on;
                }
                Ok(())
            }
            "material_q" if value == "authored" => {
                self.material_q = None;
                Ok(())
            }
            "material_q" => {
                let q = parse_in_range(name, value, MATERIAL_Q_RANGE.0, MATERIAL_Q_RANGE.1)?;
                self.material_q = Some(q);
                Ok(())
            }
            _ => {
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
