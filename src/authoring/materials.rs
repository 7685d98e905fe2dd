//! Materials for the analytic shapes: elastic constants and internal friction.
//!
//! A mode of frequency `f` decays at `d = pi f tan(phi) + AIR_DAMPING_PER_S` (internal friction,
//! seed 000 eq. 3.13, i.e. a constant quality factor `Q = 1 / tan(phi)`; the constant term is the
//! frequency-independent part of Rayleigh damping, seed 000 eq. 3.18).
//!
//! Sources of the figures. Elastic constants of metals and their loss factors: Cremer, Heckl &
//! Petersson, *Structure-Borne Sound* (Springer), table of material properties, as reproduced in
//! T. Irvine, *Damping properties of materials* (rev. C, 2004); where a range is given the chosen
//! value is stated. Woods: Fletcher & Rossing, *The Physics of Musical Instruments* (2nd ed.),
//! ch. 10 and 19 (spruce, marimba woods), and U. Wegst, *Wood for sound*, Am. J. Botany 93 (2006).
//! Glass, porcelain, acrylic and polyester film: common engineering tables (manufacturers' data
//! sheets). Loss factors are order-of-magnitude figures: they vary with alloy, grain, temperature
//! and frequency by a factor of two or more, so the values below sit inside the published ranges
//! and were chosen so that the objects ring for musically plausible times (see the tests).
//!
//! The families of the analytic objects each have a representative, also found by the family's
//! name: porcelain for the ceramics ("ceramic"), rosewood for the hard woods ("hardwood"),
//! spruce for the soft woods ("softwood").

/// Decay rate in 1/s added to every mode, whatever its frequency.
///
/// Stands for losses the internal-friction term does not model: sound radiation, air friction,
/// the supports. 0.2 /s caps T60 at about 35 s, the order of the longest-ringing bells and
/// vibraphone bars; for everything but the lowest-loss metals the frequency-proportional term
/// dominates.
pub const AIR_DAMPING_PER_S: f64 = 0.2;

/// Broad family of a material, used to pick defaults such as the mallet hardness.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MaterialClass {
    /// Metals and alloys: hard, bright, long ringing.
    Metal,
    /// Glass and fired ceramics: hard and brittle.
    GlassCeramic,
    /// Woods (figures along the grain).
    Wood,
    /// Plastics and polymer films.
    Polymer,
}

/// An isotropic, linear elastic material with hysteretic (constant-Q) internal friction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Identifier used in bank sources and on the command line: lowercase ASCII, no spaces.
    pub name: &'static str,
    /// Name for people, e.g. "Rosewood".
    pub display_name: &'static str,
    /// Other names it is found by: the family it stands for ("ceramic", "hardwood") or
    /// another spelling ("aluminum"). Lowercase ASCII.
    pub aliases: &'static [&'static str],
    /// Family of the material, for defaults.
    pub class: MaterialClass,
    /// Density in kg/m^3.
    pub density_kg_m3: f64,
    /// Young's modulus in Pa (along the grain for woods).
    pub youngs_modulus_pa: f64,
    /// Poisson's ratio, dimensionless.
    pub poisson_ratio: f64,
    /// Internal loss factor `tan(phi)` (= 1/Q), dimensionless.
    pub loss_factor: f64,
}

/// Carbon steel. 7850 kg/m^3, 200 GPa, nu 0.30: common engineering values (Cremer & Heckl list
/// 7800 kg/m^3, 210 GPa, 0.31). Loss factor: Cremer & Heckl give 0.2e-4 to 3e-4 (iron, flexural,
/// 2e-4 to 6e-4); 3e-4 gives a glockenspiel bar at 1 kHz a T60 of about 6 s.
pub const STEEL: Material = Material {
    name: "steel",
    display_name: "Steel",
    aliases: &[],
    class: MaterialClass::Metal,
    density_kg_m3: 7850.0,
    youngs_modulus_pa: 200e9,
    poisson_ratio: 0.30,
    loss_factor: 3e-4,
};

/// Aluminium. 2700 kg/m^3, 70 GPa, nu 0.33 (Cremer & Heckl: 2700, 72 GPa, 0.34). Loss factor:
/// Cremer & Heckl give about 1e-4 (flexural): vibraphone bars ring for tens of seconds.
pub const ALUMINIUM: Material = Material {
    name: "aluminium",
    display_name: "Aluminium",
    aliases: &["aluminum"],
    class: MaterialClass::Metal,
    density_kg_m3: 2700.0,
    youngs_modulus_pa: 70e9,
    poisson_ratio: 0.33,
    loss_factor: 1e-4,
};

/// Brass. 8500 kg/m^3, 100 GPa, nu 0.34 (Cremer & Heckl: 8500, 95 GPa, 0.33; other tables
/// 100-110 GPa). Loss factor: Cremer & Heckl give 0.2e-3 to 1e-3; 5e-4 chosen.
pub const BRASS: Material = Material {
    name: "brass",
    display_name: "Brass",
    aliases: &[],
    class: MaterialClass::Metal,
    density_kg_m3: 8500.0,
    youngs_modulus_pa: 100e9,
    poisson_ratio: 0.34,
    loss_factor: 5e-4,
};

/// Bell bronze (about 80% copper, 20% tin). 8700 kg/m^3, 105 GPa, nu 0.34: engineering tables
/// for cast tin bronzes. Loss factor 3e-4, inside the range Cremer & Heckl give for brass and
/// copper alloys, at its low end because bells are cast and tuned to sustain.
pub const BRONZE: Material = Material {
    name: "bronze",
    display_name: "Bell bronze",
    aliases: &["bell-bronze"],
    class: MaterialClass::Metal,
    density_kg_m3: 8700.0,
    youngs_modulus_pa: 105e9,
    poisson_ratio: 0.34,
    loss_factor: 3e-4,
};

/// Soda-lime glass. 2500 kg/m^3, 70 GPa, nu 0.23 (engineering tables; Cremer & Heckl give
/// 2500 kg/m^3, 60 GPa). Loss factor: Cremer & Heckl give 0.6e-3 to 2e-3; 1e-3 chosen.
pub const GLASS: Material = Material {
    name: "glass",
    display_name: "Glass",
    aliases: &[],
    class: MaterialClass::GlassCeramic,
    density_kg_m3: 2500.0,
    youngs_modulus_pa: 70e9,
    poisson_ratio: 0.23,
    loss_factor: 1e-3,
};

/// Porcelain. 2400 kg/m^3, 80 GPa, nu 0.22: engineering tables give 2300-2500 kg/m^3 and
/// 60-100 GPa. Loss factor 8e-4: of the order of glass (seed 004 table 5.1 puts ceramic a little
/// below glass in Q; measured values for fired ceramics are of the order of 1e-3).
pub const PORCELAIN: Material = Material {
    name: "porcelain",
    display_name: "Porcelain",
    aliases: &["ceramic"],
    class: MaterialClass::GlassCeramic,
    density_kg_m3: 2400.0,
    youngs_modulus_pa: 80e9,
    poisson_ratio: 0.22,
    loss_factor: 8e-4,
};

/// Rosewood (Honduras rosewood, the classic marimba wood; padauk is similar). About 1000 kg/m^3
/// and 18 GPa along the grain, nu 0.3 (Fletcher & Rossing ch. 19; Wegst 2006). Loss factor
/// 4.5e-3, at the low-loss end of the woods in Wegst 2006: a bar at 500 Hz rings for T60 about
/// 1 s, and its upper partials die faster.
pub const ROSEWOOD: Material = Material {
    name: "rosewood",
    display_name: "Rosewood",
    aliases: &["hardwood", "hard-wood"],
    class: MaterialClass::Wood,
    density_kg_m3: 1000.0,
    youngs_modulus_pa: 18e9,
    poisson_ratio: 0.30,
    loss_factor: 4.5e-3,
};

/// Spruce (Sitka or European, the soundboard wood). 450 kg/m^3 and 11 GPa along the grain,
/// nu 0.37 (Fletcher & Rossing ch. 10, tables of wood properties). Loss factor 8e-3 (Wegst 2006
/// gives about 6e-3 to 1e-2 along the grain).
pub const SPRUCE: Material = Material {
    name: "spruce",
    display_name: "Spruce",
    aliases: &["softwood", "soft-wood"],
    class: MaterialClass::Wood,
    density_kg_m3: 450.0,
    youngs_modulus_pa: 11e9,
    poisson_ratio: 0.37,
    loss_factor: 8e-3,
};

/// Acrylic (PMMA, Plexiglas). 1190 kg/m^3, 3.2 GPa, nu 0.37 (manufacturers' data sheets).
/// Loss factor: Cremer & Heckl give 2e-2 to 4e-2 for Plexiglas; 3e-2 chosen (Q about 33, inside
/// the range seed 004 section 5.1.2 gives for plastic).
pub const ACRYLIC: Material = Material {
    name: "acrylic",
    display_name: "Acrylic",
    aliases: &["pmma", "plexiglas"],
    class: MaterialClass::Polymer,
    density_kg_m3: 1190.0,
    youngs_modulus_pa: 3.2e9,
    poisson_ratio: 0.37,
    loss_factor: 3e-2,
};

/// Polyester film (PET, Mylar), the material of drum heads. 1390 kg/m^3, 4.5 GPa, nu 0.38
/// (manufacturers' data sheets). Loss factor 1e-2: an *effective* figure for a drum head, which
/// loses most of its energy to radiation rather than internal friction; it gives a tom-like
/// head at 150 Hz a T60 of about 1.4 s, and 0.2 s at 1 kHz.
pub const MYLAR: Material = Material {
    name: "mylar",
    display_name: "Mylar (polyester film)",
    aliases: &["polyester", "pet"],
    class: MaterialClass::Polymer,
    density_kg_m3: 1390.0,
    youngs_modulus_pa: 4.5e9,
    poisson_ratio: 0.38,
    loss_factor: 1e-2,
};

/// Every material the shapes know, in display order.
pub const MATERIALS: &[Material] = &[
    STEEL, ALUMINIUM, BRASS, BRONZE, GLASS, PORCELAIN, ROSEWOOD, SPRUCE, ACRYLIC, MYLAR,
];

impl Material {
    /// The material called `name`: its identifier, display name or one of its aliases, in any
    /// case, with spaces or underscores taken for hyphens ("hard wood" finds rosewood).
    pub fn by_name(name: &str) -> Option<&'static Material> {
        let name = name.trim();
        let hyphenated = name.replace([' ', '_'], "-");
        MATERIALS.iter().find(|material| {
            material.name.eq_ignore_ascii_case(name)
                || material.display_name.eq_ignore_ascii_case(name)
                || material
                    .aliases
                    .iter()
                    .any(|alias| alias.eq_ignore_ascii_case(&hyphenated))
        })
    }

    /// Every material's identifier with its aliases, e.g. "porcelain (ceramic)", for listings
    /// and error messages.
    pub fn names_with_aliases() -> Vec<String> {
        MATERIALS
            .iter()
            .map(|material| {
                let aliases: Vec<&str> = material
                    .aliases
                    .iter()
                    .copied()
                    .filter(|alias| !alias.contains('-'))
                    .collect();
                if aliases.is_empty() {
                    material.name.to_string()
                } else {
                    format!("{} ({})", material.name, aliases.join(", "))
                }
            })
            .collect()
    }

    /// Quality factor `Q = 1 / tan(phi)` of the internal friction alone.
    pub fn quality_factor(&self) -> f64 {
        1.0 / self.loss_factor
    }

    /// Decay rate in 1/s of a mode at `freq_hz`: internal friction (seed 000 eq. 3.13,
    /// `tau = 1 / (pi f tan(phi))`) plus [`AIR_DAMPING_PER_S`].
    pub fn decay_per_s(&self, freq_hz: f64) -> f64 {
        std::f64::consts::PI * freq_hz * self.loss_factor + AIR_DAMPING_PER_S
    }

    /// Speed of longitudinal waves in a thin rod, `sqrt(E / rho)`, in m/s.
    pub fn rod_wave_speed_m_per_s(&self) -> f64 {
        (self.youngs_modulus_pa / self.density_kg_m3).sqrt()
    }
}

pub use crate::units::decay_to_t60_s;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_found() {
        for (i, material) in MATERIALS.iter().enumerate() {
            assert_eq!(Material::by_name(material.name), Some(material));
            assert_eq!(
                Material::by_name(&material.display_name.to_uppercase()),
                Some(material)
            );
            for other in &MATERIALS[i + 1..] {
                assert_ne!(material.name, other.name);
            }
            assert!(material.name.bytes().all(|b| b.is_ascii_lowercase()));
            for alias in material.aliases {
                assert_eq!(Material::by_name(alias), Some(material), "{alias}");
                let others = MATERIALS.iter().filter(|m| m.name != material.name);
                for other in others {
                    assert!(!other.aliases.contains(alias) && other.name != *alias);
                }
            }
        }
        assert_eq!(Material::by_name("unobtainium"), None);
        // The families the analytic objects are asked for by.
        assert_eq!(Material::by_name("ceramic"), Some(&PORCELAIN));
        assert_eq!(Material::by_name("Hard wood"), Some(&ROSEWOOD));
        assert_eq!(Material::by_name("soft_wood"), Some(&SPRUCE));
        assert_eq!(Material::by_name("aluminum"), Some(&ALUMINIUM));
        let listed = Material::names_with_aliases();
        assert!(
            listed.contains(&"porcelain (ceramic)".to_string()),
            "{listed:?}"
        );
        assert!(
            listed.contains(&"rosewood (hardwood)".to_string()),
            "{listed:?}"
        );
    }

    #[test]
    fn figures_are_physical() {
        for material in MATERIALS {
            assert!(material.density_kg_m3 > 100.0 && material.density_kg_m3 < 20_000.0);
            assert!(material.youngs_modulus_pa > 1e8 && material.youngs_modulus_pa < 5e11);
            assert!(material.poisson_ratio > 0.0 && material.poisson_ratio < 0.5);
            assert!(material.loss_factor > 0.0 && material.loss_factor < 0.1);
        }
    }

    #[test]
    fn ringing_times_are_musically_plausible() {
        // A steel glockenspiel bar around 1 kHz rings for several seconds.
        let steel_t60_s = decay_to_t60_s(STEEL.decay_per_s(1046.5));
        assert!(
            (4.0..=10.0).contains(&steel_t60_s),
            "steel at 1046.5 Hz: T60 {steel_t60_s} s"
        );
        // A rosewood marimba bar at 500 Hz rings for about a second ...
        let rosewood_t60_s = decay_to_t60_s(ROSEWOOD.decay_per_s(500.0));
        assert!(
            (0.8..=1.2).contains(&rosewood_t60_s),
            "rosewood at 500 Hz: T60 {rosewood_t60_s} s"
        );
        // ... and its partials two octaves up die at least three times as fast.
        let rosewood_high_t60_s = decay_to_t60_s(ROSEWOOD.decay_per_s(2000.0));
        assert!(rosewood_high_t60_s < rosewood_t60_s / 3.0);
        // Ordering of the families: metal rings longest, then glass, then wood, then plastic.
        let t60_at_1k = |m: &Material| decay_to_t60_s(m.decay_per_s(1000.0));
        assert!(t60_at_1k(&ALUMINIUM) > t60_at_1k(&STEEL));
        assert!(t60_at_1k(&STEEL) > t60_at_1k(&GLASS));
        assert!(t60_at_1k(&GLASS) > t60_at_1k(&ROSEWOOD));
        assert!(t60_at_1k(&SPRUCE) > t60_at_1k(&ACRYLIC));
    }
}
