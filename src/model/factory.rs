//! The factory banks: analytic objects at musical pitches, shipped as `presets/<slug>.json`.
//!
//! The committed preset files are generated from this table; the test
//! `factory_presets_are_up_to_date` (tests/factory_presets.rs) fails when they drift, and
//! `UPDATE_PRESETS=1 cargo test factory_presets` rewrites them along with `presets/FACTORY.md`.

use crate::model::materials::{self, Material};
use crate::model::shapes::{
    build_bank, Bar, CircularMembrane, ModeLimits, RectangularPlate, Shape, StretchedString,
    TunedBar, TunedBell, MARIMBA_RATIOS, VIBRAPHONE_RATIOS,
};
use crate::model::Bank;
use std::path::{Path, PathBuf};

/// Name of the generated table of factory banks, next to the presets.
pub const FACTORY_TABLE_FILE: &str = "README.md";

/// Marks the start of the generated factory table in `presets/README.md`.
pub const FACTORY_TABLE_BEGIN: &str = "<!-- factory table: generated, do not edit -->\n";

/// Marks the end of the generated factory table in `presets/README.md`.
pub const FACTORY_TABLE_END: &str = "<!-- end of factory table -->\n";

/// `readme` with the text between the factory table markers replaced by `table`, or `None` when
/// the markers are missing.
pub fn splice_factory_table(readme: &str, table: &str) -> Option<String> {
    let start = readme.find(FACTORY_TABLE_BEGIN)? + FACTORY_TABLE_BEGIN.len();
    let end = start + readme[start..].find(FACTORY_TABLE_END)?;
    Some(format!("{}{}{}", &readme[..start], table, &readme[end..]))
}

/// MIDI keys of the pitches the factory objects are tuned to.
mod key {
    pub const E2: u8 = 40;
    pub const A2: u8 = 45;
    pub const D3: u8 = 50;
    pub const F3: u8 = 53;
    pub const C4: u8 = 60;
    pub const A4: u8 = 69;
    pub const F5: u8 = 77;
    pub const C6: u8 = 84;
}

/// One factory bank before it is built.
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
}

fn factory_objects() -> Vec<FactoryObject> {
    vec![
        FactoryObject {
            name: "Ideal string",
            description: "A string with no stiffness, struck by a point hammer: a pure harmonic \
                          series whose spectrum falls as 1/n, with the harmonics at the strike \
                          point's nodes missing. The textbook reference for every other bank.",
            shape: Shape::IdealString(StretchedString {
                length_m: 0.65,
                diameter_m: 0.9e-3,
                tension_n: 100.0,
            }),
            material: &materials::STEEL,
            root_key: key::A2,
        },
        FactoryObject {
            name: "Piano-like stiff string",
            description: "A plain steel piano wire at middle C, struck near one end like a \
                          piano hammer: the wire's stiffness stretches the upper partials sharp \
                          (inharmonicity B about 4e-4), the shimmer of a real piano tone.",
            shape: Shape::StiffString(StretchedString {
                length_m: 0.62,
                diameter_m: 1.0e-3,
                tension_n: 650.0,
            }),
            material: &materials::STEEL,
            root_key: key::C4,
        },
        FactoryObject {
            name: "Steel free-free bar",
            description: "A uniform steel bar free at both ends, like a glockenspiel bar: a \
                          bright, long-ringing bell tone with the inharmonic overtones \
                          1 : 2.76 : 5.40 : 8.93.",
            shape: Shape::FreeFreeBar(Bar {
                length_m: 0.2,
                width_m: 0.025,
                thickness_m: 0.008,
            }),
            material: &materials::STEEL,
            root_key: key::C6,
        },
        FactoryObject {
            name: "Rosewood marimba bar",
            description: "A rosewood marimba bar undercut to the classic 1 : 4 : 10 tuning: a \
                          warm, woody note that rings for a second or two, its upper partials \
                          gone within a fraction of a second. Dimensions are those of an \
                          equivalent uniform bar.",
            shape: Shape::TunedBar(TunedBar {
                bar: Bar {
                    length_m: 0.38,
                    width_m: 0.06,
                    thickness_m: 0.009,
                },
                tuned_ratios: MARIMBA_RATIOS.to_vec(),
            }),
            material: &materials::ROSEWOOD,
            root_key: key::C4,
        },
        FactoryObject {
            name: "Aluminium vibraphone bar",
            description: "An aluminium bar undercut so its first overtone sits two octaves up, \
                          like a vibraphone bar with the motor off: a pure, very long sustain. \
                          Dimensions are those of an equivalent uniform bar.",
            shape: Shape::TunedBar(TunedBar {
                bar: Bar {
                    length_m: 0.38,
                    width_m: 0.057,
                    thickness_m: 0.006,
                },
                tuned_ratios: VIBRAPHONE_RATIOS.to_vec(),
            }),
            material: &materials::ALUMINIUM,
            root_key: key::F3,
        },
        FactoryObject {
            name: "Circular membrane",
            description: "A 13-inch polyester drum head tuned by its tension: the dense, \
                          inharmonic Bessel-zero spectrum of a tom, short and thuddy. Struck at \
                          the centre only the axisymmetric modes sound. Air loading, which pulls \
                          a real drum's modes closer together, is not modelled.",
            shape: Shape::CircularMembrane(CircularMembrane {
                radius_m: 0.165,
                thickness_m: 0.25e-3,
                tension_n_per_m: 1400.0,
            }),
            material: &materials::MYLAR,
            root_key: key::D3,
        },
        FactoryObject {
            name: "Steel plate",
            description: "A thin rectangular steel plate with hinged edges, like a thunder \
                          sheet or a plate reverb: hundreds of closely spaced modes ringing for \
                          many seconds, a metallic wash.",
            shape: Shape::RectangularPlate(RectangularPlate {
                length_x_m: 0.4,
                length_y_m: 0.3,
                thickness_m: 2e-3,
            }),
            material: &materials::STEEL,
            root_key: key::E2,
        },
        FactoryObject {
            name: "Glass plate",
            description: "A small pane of glass held at its edges and tapped: a dense, glassy \
                          ring that fades within a few seconds.",
            shape: Shape::RectangularPlate(RectangularPlate {
                length_x_m: 0.2,
                length_y_m: 0.15,
                thickness_m: 4e-3,
            }),
            material: &materials::GLASS,
            root_key: key::F5,
        },
        FactoryObject {
            name: "Bronze bell",
            description: "A tuned church bell in bell bronze: hum an octave below the strike \
                          note, minor-third tierce, fifth and nominal octave, the hum lingering \
                          after the rest. Partial ratios are those of a tuned bell; gains along \
                          the profile are a heuristic.",
            shape: Shape::Bell(TunedBell {
                diameter_m: 0.6,
                thickness_m: 0.046,
            }),
            material: &materials::BRONZE,
            root_key: key::A4,
        },
    ]
}

impl FactoryObject {
    fn build(&self) -> Bank {
        let shape = self
            .shape
            .tuned_to(
                self.material,
                crate::dsp::coeffs::midi_key_to_hz(f64::from(self.root_key)),
            )
            .unwrap_or_else(|e| panic!("factory bank {:?}: {e}", self.name));
        let description = format!("{} {}", self.description, shape.summary(self.material));
        build_bank(
            self.name,
            &description,
            &shape,
            self.material,
            &shape.default_positions(),
            &ModeLimits::default(),
        )
        .unwrap_or_else(|e| panic!("factory bank {:?}: {e}", self.name))
    }
}

/// Every factory bank, in display order.
pub fn factory_banks() -> Vec<Bank> {
    factory_objects().iter().map(FactoryObject::build).collect()
}

/// The bank's name in lowercase with runs of anything but ASCII letters and digits turned into
/// single hyphens: "Piano-like stiff string" gives "piano-like-stiff-string". Used as the preset
/// file name and on the command line.
pub fn factory_slug(bank: &Bank) -> String {
    slugify(&bank.name)
}

fn slugify(name: &str) -> String {
    let mut slug = String::with_capacity(name.len());
    for c in name.chars() {
        if c.is_ascii_alphanumeric() {
            slug.push(c.to_ascii_lowercase());
        } else if !slug.is_empty() && !slug.ends_with('-') {
            slug.push('-');
        }
    }
    while slug.ends_with('-') {
        slug.pop();
    }
    slug
}

/// The factory bank with this name (any case) or slug.
pub fn factory_bank(name_or_slug: &str) -> Option<Bank> {
    let wanted = slugify(name_or_slug);
    factory_objects()
        .iter()
        .find(|object| slugify(object.name) == wanted)
        .map(FactoryObject::build)
}

/// The text of a bank's preset file: pretty JSON and a trailing newline.
pub fn preset_json(bank: &Bank) -> String {
    crate::model::io::bank_to_json(bank)
}

/// Writes every factory bank to `dir/<slug>.json`, creating `dir` if needed; returns the paths.
pub fn write_factory_presets(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    factory_banks()
        .iter()
        .map(|bank| {
            let path = dir.join(format!("{}.json", factory_slug(bank)));
            std::fs::write(&path, preset_json(bank))?;
            Ok(path)
        })
        .collect()
}

/// Where two banks differ, or `None` when they are equal with numbers compared to a relative
/// tolerance `rel_tol` (JSON text keeps every digit, but parsers may round the last bit).
///
/// The answer names the JSON path of the first difference, e.g. `modes[12].gains[3]: 0.25 vs
/// 0.5`.
pub fn first_difference(a: &Bank, b: &Bank, rel_tol: f64) -> Option<String> {
    let a = serde_json::to_value(a).expect("a bank always serialises");
    let b = serde_json::to_value(b).expect("a bank always serialises");
    value_difference("", &a, &b, rel_tol)
}

fn value_difference(
    path: &str,
    a: &serde_json::Value,
    b: &serde_json::Value,
    rel_tol: f64,
) -> Option<String> {
    use serde_json::Value;
    let here = || if path.is_empty() { "(root)" } else { path }.to_string();
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64()?, y.as_f64()?);
            let close = (x - y).abs() <= rel_tol * x.abs().max(y.abs());
            (!close).then(|| format!("{}: {x} vs {y}", here()))
        }
        (Value::Array(xs), Value::Array(ys)) => {
            if xs.len() != ys.len() {
                return Some(format!("{}: {} vs {} items", here(), xs.len(), ys.len()));
            }
            xs.iter()
                .zip(ys)
                .enumerate()
                .find_map(|(i, (x, y))| value_difference(&format!("{path}[{i}]"), x, y, rel_tol))
        }
        (Value::Object(xs), Value::Object(ys)) => {
            let keys = xs.keys().chain(ys.keys().filter(|k| !xs.contains_key(*k)));
            keys.into_iter().find_map(|key| {
                let sub = if path.is_empty() {
                    key.clone()
                } else {
                    format!("{path}.{key}")
                };
                match (xs.get(key), ys.get(key)) {
                    (Some(x), Some(y)) => value_difference(&sub, x, y, rel_tol),
                    _ => Some(format!("{sub}: present in only one")),
                }
            })
        }
        _ => (a != b).then(|| format!("{}: {a} vs {b}", here())),
    }
}

/// The Markdown table of the factory banks, kept in `presets/README.md`.
pub fn factory_table_markdown(banks: &[Bank]) -> String {
    let mut text = String::from(
        "Generated from `src/model/factory.rs` by `UPDATE_PRESETS=1 cargo test factory_presets`; \
         do not edit by hand. Every bank is analytic (`source.kind = \"analytic\"`): closed-form \
         modes of the object (`src/model/shapes/`), decays from the material \
         (`src/model/materials.rs`), gains `Psi_n(p) / omega_n` at each strike position.\n\n\
         | Name | Slug (file, CLI) | Object | Material | Root | Modes | Strike positions |\n\
         |---|---|---|---|---|---|---|\n",
    );
    for bank in banks {
        let source = bank.source.as_ref();
        let field = |key: &str| {
            source
                .and_then(|s| s.get(key))
                .and_then(|v| v.as_str())
                .unwrap_or("")
                .to_string()
        };
        let root_hz = bank.root_hz.unwrap_or(0.0);
        let positions: Vec<&str> = bank.positions.iter().map(|p| p.name.as_str()).collect();
        text.push_str(&format!(
            "| {} | `{}` | {} | {} | {:.2} Hz ({}) | {} | {} |\n",
            bank.name,
            factory_slug(bank),
            field("shape"),
            field("material"),
            root_hz,
            crate::model::summary::note_name(root_hz),
            bank.modes.len(),
            positions.join(", "),
        ));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::summary::note_name;
    use std::collections::HashSet;

    #[test]
    fn banks_are_complete_and_distinct() {
        let banks = factory_banks();
        assert!(banks.len() >= 6);
        let mut names = HashSet::new();
        let mut slugs = HashSet::new();
        for bank in &banks {
            let what = &bank.name;
            assert!(
                names.insert(bank.name.to_lowercase()),
                "duplicate name {what}"
            );
            assert!(
                slugs.insert(factory_slug(bank)),
                "duplicate slug for {what}"
            );
            assert!(!bank.positions.is_empty(), "{what}");
            assert!(!bank.modes.is_empty(), "{what}");
            assert!(bank.description.len() > 40, "{what}");
            assert_eq!(bank.license, "CC0-1.0");
            assert_eq!(bank.author, "Modal Resonator");
            assert_eq!(bank.format, crate::model::bank::FORMAT_NAME);
            assert_eq!(bank.version, crate::model::bank::FORMAT_VERSION);
            let root_hz = bank.root_hz.unwrap();
            assert!(root_hz > 20.0 && root_hz < 5000.0, "{what}: {root_hz}");
            // The root is a mode of the bank (for the bell, the prime above the hum).
            assert!(
                bank.modes
                    .iter()
                    .any(|m| (m.freq_hz / root_hz - 1.0).abs() < 1e-12),
                "{what}"
            );
            for mode in &bank.modes {
                assert_eq!(mode.gains.len(), bank.positions.len(), "{what}");
            }
        }
    }

    #[test]
    fn banks_sit_on_equal_tempered_notes() {
        for bank in factory_banks() {
            let note = note_name(bank.root_hz.unwrap());
            assert!(!note.contains(" c"), "{}: {note}", bank.name);
        }
        assert_eq!(note_name(440.0), "A4");
        assert_eq!(note_name(261.625_565_300_598_6), "C4");
        assert_eq!(note_name(27.5), "A0");
        assert_eq!(note_name(446.0), "A4 +23 c");
    }

    #[test]
    fn slugs_and_lookup() {
        assert_eq!(
            slugify("Piano-like stiff string"),
            "piano-like-stiff-string"
        );
        assert_eq!(slugify("  Steel  plate (2 mm)! "), "steel-plate-2-mm");
        for bank in factory_banks() {
            let slug = factory_slug(&bank);
            assert_eq!(factory_bank(&slug).as_ref(), Some(&bank));
            assert_eq!(
                factory_bank(&bank.name.to_uppercase()).as_ref(),
                Some(&bank)
            );
        }
        assert_eq!(factory_bank("no such bank"), None);
    }

    #[test]
    fn presets_round_trip_through_json() {
        for bank in factory_banks() {
            let text = preset_json(&bank);
            assert!(text.ends_with("}\n"));
            let parsed: Bank = serde_json::from_str(&text).unwrap();
            assert_eq!(
                first_difference(&parsed, &bank, 1e-15),
                None,
                "{}",
                bank.name
            );
        }
    }

    #[test]
    fn differences_are_located() {
        let bank = factory_bank("steel-plate").unwrap();
        assert_eq!(first_difference(&bank, &bank, 0.0), None);
        let mut nudged = bank.clone();
        nudged.modes[12].gains[3] *= 1.0 + 1e-13;
        assert_eq!(first_difference(&bank, &nudged, 1e-12), None);
        nudged.modes[12].gains[3] *= 2.0;
        let found = first_difference(&bank, &nudged, 1e-12).unwrap();
        assert!(found.starts_with("modes[12].gains[3]: "), "{found}");
        let mut renamed = bank.clone();
        renamed.name.push('!');
        let found = first_difference(&bank, &renamed, 1e-12).unwrap();
        assert!(found.starts_with("name: "), "{found}");
        let mut fewer = bank.clone();
        fewer.positions.pop();
        let found = first_difference(&bank, &fewer, 1e-12).unwrap();
        assert!(found.starts_with("positions: 4 vs 3 items"), "{found}");
    }

    #[test]
    fn writes_one_file_per_bank() {
        let dir = tempfile::tempdir().unwrap();
        let paths = write_factory_presets(dir.path()).unwrap();
        let banks = factory_banks();
        assert_eq!(paths.len(), banks.len());
        for (path, bank) in paths.iter().zip(&banks) {
            assert_eq!(
                path.file_name().unwrap().to_str().unwrap(),
                format!("{}.json", factory_slug(bank))
            );
            assert_eq!(std::fs::read_to_string(path).unwrap(), preset_json(bank));
        }
    }
}
