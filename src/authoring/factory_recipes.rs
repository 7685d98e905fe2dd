//! How the analytic factory banks are designed: a table of objects (`bars.rs`, `surfaces.rs`),
//! each a shape, a material, the note it is tuned to and what it departs from its family's
//! defaults, built with the shapes' designer ([`design_bank`]).
//!
//! The factory itself ([`crate::bank::factory`]) holds no design: it plays the files these
//! recipes wrote to `presets/<slug>.json`. The test `factory_presets_are_up_to_date`
//! (tests/factory_presets.rs) fails when a file and its recipe drift apart, and
//! `UPDATE_PRESETS=1 cargo test --test factory_presets` writes the files again.

mod bars;
mod surfaces;

use crate::authoring::materials::Material;
use crate::authoring::shapes::{design_bank, BankDesign, ModeLimits, Shape};
use crate::bank::factory::{factory_slug, preset_json};
use crate::bank::Bank;
use crate::units::midi_key_to_hz;
use std::path::{Path, PathBuf};

/// MIDI keys of the pitches the factory objects are tuned to.
mod key {
    pub const A1: u8 = 33;
    pub const C2: u8 = 36;
    pub const E2: u8 = 40;
    pub const F2: u8 = 41;
    pub const A2: u8 = 45;
    pub const A3: u8 = 57;
    pub const D3: u8 = 50;
    pub const F3: u8 = 53;
    pub const C4: u8 = 60;
    pub const G4: u8 = 67;
    pub const A4: u8 = 69;
    pub const C5: u8 = 72;
    pub const E5: u8 = 76;
    pub const F5: u8 = 77;
    pub const A5: u8 = 81;
    pub const C6: u8 = 84;
    pub const D6: u8 = 86;
    pub const G6: u8 = 91;
    pub const D7: u8 = 98;
}

/// One analytic factory bank before it is built.
struct FactoryObject {
    /// Display name, also the source of the slug.
    name: &'static str,
    /// What it is and how it sounds (the shape's summary is appended).
    description: &'static str,
    /// The object, with starting dimensions; [`Self::root_key`] retunes it.
    shape: Shape,
    /// What it is made of.
    material: &'static Material,
    /// MIDI key of the pitch the object is tuned to.
    root_key: u8,
    /// Departures from what the object's family gets by default.
    tweaks: Tweaks,
}

/// Settings a factory bank may change from its family's defaults.
#[derive(Debug, Clone, Copy)]
struct Tweaks {
    /// Mallet contact time in ms, instead of the family's.
    hardness_ms: Option<f64>,
    /// Name of the position struck by default, moved to the front, instead of the one nearest
    /// the family's usual strike point.
    strike_at: Option<&'static str>,
    /// A contact the bank is played with by default, instead of a strike.
    contact: Option<Contact>,
}

/// A contact a factory bank is played with: `defaults.exciter` and the contact's settings.
#[derive(Debug, Clone, Copy)]
struct Contact {
    /// `scrape`, `roll` or `rub`.
    exciter: &'static str,
    /// Roughness, 0 to 1.
    roughness: f64,
    /// Radius of a rolling object in mm (a roll only).
    rolling_radius_mm: Option<f64>,
    /// Speed in m/s.
    speed_m_per_s: f64,
    /// Force at full velocity, 0 to 1.
    force: f64,
}

impl Tweaks {
    /// The family's defaults throughout.
    const NONE: Tweaks = Tweaks {
        hardness_ms: None,
        strike_at: None,
        contact: None,
    };
}

/// Every analytic factory object, in display order.
fn factory_objects() -> Vec<FactoryObject> {
    let mut objects = bars::objects();
    objects.extend(surfaces::objects());
    objects
}

impl FactoryObject {
    fn build(&self) -> Bank {
        let design = BankDesign {
            name: self.name.to_string(),
            description: self.description.to_string(),
            shape: self.shape.clone(),
            material: self.material,
            positions: None,
            limits: ModeLimits::default(),
            root_hz: Some(midi_key_to_hz(f64::from(self.root_key))),
        };
        let (mut bank, _) =
            design_bank(&design).unwrap_or_else(|e| panic!("factory bank {:?}: {e}", self.name));
        let defaults = bank.defaults.get_or_insert_with(Default::default);
        if let Some(hardness_ms) = self.tweaks.hardness_ms {
            defaults.hardness_ms = Some(hardness_ms);
        }
        if let Some(c) = self.tweaks.contact {
            defaults.exciter = Some(c.exciter.to_string());
            defaults.roughness = Some(c.roughness);
            defaults.rolling_radius_mm = c.rolling_radius_mm;
            defaults.contact_speed_m_per_s = Some(c.speed_m_per_s);
            defaults.contact_force = Some(c.force);
        }
        if let Some(name) = self.tweaks.strike_at {
            strike_first(&mut bank, name)
                .unwrap_or_else(|| panic!("factory bank {:?}: no position {name:?}", self.name));
        }
        bank
    }
}

/// Moves the position called `name`, and its gain in every mode, to the front: a bank is struck
/// at its first position by default, and its loudness is set there. `None` if there is no such
/// position.
fn strike_first(bank: &mut Bank, name: &str) -> Option<()> {
    let k = bank.positions.iter().position(|p| p.name == name)?;
    let position = bank.positions.remove(k);
    bank.positions.insert(0, position);
    for mode in &mut bank.modes {
        let gain = mode.gains.remove(k);
        mode.gains.insert(0, gain);
    }
    Some(())
}

/// The analytic factory banks as their recipes design them, in display order: what
/// `presets/<slug>.json` must hold.
pub fn designed_factory_banks() -> Vec<Bank> {
    factory_objects().iter().map(FactoryObject::build).collect()
}

/// Writes every designed analytic factory bank to `dir/<slug>.json`, creating `dir` if needed;
/// returns the paths. (The fitted banks are made from recordings, by `tests/fit_recordings.rs`,
/// the meshed ones by `tests/mesh_presets.rs`.)
pub fn write_factory_presets(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    designed_factory_banks()
        .iter()
        .map(|bank| {
            let path = dir.join(format!("{}.json", factory_slug(bank)));
            std::fs::write(&path, preset_json(bank))?;
            Ok(path)
        })
        .collect()
}

#[cfg(test)]
mod tests;
