//! `modal-resonator shape`: a bank from an analytic object (the library's `authoring::shapes`).

use std::path::PathBuf;

use clap::Args;

use modal_resonator::authoring::materials::{Material, MATERIALS};
use modal_resonator::authoring::shapes::{
    design_bank, BankDesign, Dimension, ModeLimits, ObjectKind, ObjectSpec, PlateEdge, BAR_TUNINGS,
    DEFAULT_MAX_MODES, MAX_AUDIBLE_HZ, OBJECTS,
};
use modal_resonator::bank::summary::{note_name, note_to_midi_key};
use modal_resonator::bank::Position;
use modal_resonator::units::{decay_to_t60_s, midi_key_to_hz};

use super::{check_output, output_name, save_bank_output, say};

/// Arguments of `shape`.
#[derive(Debug, Args)]
#[command(after_help = objects_and_materials())]
pub(super) struct ShapeArgs {
    /// Object to build (listed below).
    #[arg(value_parser = parse_object, value_name = "OBJECT")]
    object: &'static ObjectKind,
    /// Bank file (JSON) to write; - writes it to standard output.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Material (listed below); each object has its usual one.
    #[arg(long, value_parser = parse_material)]
    material: Option<&'static Material>,
    /// Length in metres (a rectangle's side along x; a tine's free length).
    #[arg(long, value_parser = parse_positive, value_name = "M", allow_hyphen_values = true)]
    length: Option<f64>,
    /// Width in metres (a rectangle's side along y).
    #[arg(long, value_parser = parse_positive, value_name = "M", allow_hyphen_values = true)]
    width: Option<f64>,
    /// Thickness in metres (in the direction of vibration).
    #[arg(long, value_parser = parse_positive, value_name = "M", allow_hyphen_values = true)]
    thickness: Option<f64>,
    /// Radius in metres.
    #[arg(long, value_parser = parse_positive, value_name = "M", allow_hyphen_values = true)]
    radius: Option<f64>,
    /// Diameter in metres (a wire; a bell's mouth).
    #[arg(long, value_parser = parse_positive, value_name = "M", allow_hyphen_values = true)]
    diameter: Option<f64>,
    /// Tension: N for a string, N/m for a membrane.
    #[arg(long, value_parser = parse_positive, value_name = "N|N/M", allow_hyphen_values = true)]
    tension: Option<f64>,
    /// Tuning of a tuned bar: marimba, vibraphone, xylophone, or ratios such as "1,4,10".
    #[arg(long, value_parser = parse_tuning)]
    tuning: Option<Ratios>,
    /// Rim of a circular plate: free or clamped.
    #[arg(long, value_parser = parse_edge)]
    edge: Option<PlateEdge>,
    /// Strike positions as "[NAME=]X[,Y]; ...": along a line, fractions of the length; on a
    /// rectangle, fractions of the sides; on a disc, fractions of the radius from the centre.
    #[arg(long, value_parser = parse_positions, value_name = "LIST")]
    positions: Option<PositionList>,
    /// Most modes kept, the lowest.
    #[arg(long, default_value_t = DEFAULT_MAX_MODES, value_parser = clap::value_parser!(usize))]
    modes: usize,
    /// Modes at or above this frequency in Hz are left out.
    #[arg(long, default_value_t = MAX_AUDIBLE_HZ, value_parser = parse_positive, value_name = "HZ")]
    max_hz: f64,
    /// Retune the object to this fundamental in Hz (strings and heads by tension, bars by
    /// length, plates and bells by size).
    #[arg(long, value_parser = parse_positive, value_name = "HZ", conflicts_with = "root_note")]
    tune_hz: Option<f64>,
    /// Retune the object to this note, e.g. C4, F#2 or a MIDI key number.
    #[arg(long, value_parser = parse_note, value_name = "NOTE")]
    root_note: Option<f64>,
    /// Bank name (default: material and object, e.g. "Steel free-free bar").
    #[arg(long)]
    name: Option<String>,
    /// Author written into the bank.
    #[arg(long, default_value = "")]
    author: String,
    /// SPDX licence of the bank.
    #[arg(long, default_value = "CC0-1.0")]
    license: String,
}

/// Frequency ratios of a tuned bar's first modes (one option value holding several numbers).
#[derive(Debug, Clone)]
struct Ratios(Vec<f64>);

/// Strike positions (one option value holding several positions).
#[derive(Debug, Clone)]
struct PositionList(Vec<Position>);

/// Builds the bank, saves it atomically and prints what it is. Nothing is written on failure.
pub(super) fn run(args: &ShapeArgs) -> Result<(), String> {
    check_output("-o", &args.output, &[])?;
    let given = [
        (Dimension::Length, args.length),
        (Dimension::Width, args.width),
        (Dimension::Thickness, args.thickness),
        (Dimension::Radius, args.radius),
        (Dimension::Diameter, args.diameter),
        (Dimension::Tension, args.tension),
    ];
    let spec = ObjectSpec {
        object: args.object,
        dimensions: given
            .iter()
            .filter_map(|&(d, v)| v.map(|v| (d, v)))
            .collect(),
        tuning: args.tuning.as_ref().map(|r| r.0.clone()),
        edge: args.edge,
    };
    let shape = spec
        .shape()
        .map_err(|e| format!("{}: {e}", args.object.name))?;
    let material = args.material.unwrap_or(args.object.default_material);
    let name = args.name.clone().unwrap_or_else(|| {
        let object = args.object.name.replace('-', " ");
        format!("{} {object}", material.display_name)
    });
    let design = BankDesign {
        name,
        description: String::new(),
        shape,
        material,
        positions: args.positions.as_ref().map(|p| p.0.clone()),
        limits: ModeLimits {
            max_freq_hz: args.max_hz,
            max_modes: args.modes,
        },
        root_hz: args.tune_hz.or(args.root_note),
    };
    let (mut bank, _) = design_bank(&design).map_err(|e| format!("{}: {e}", args.object.name))?;
    if !args.author.is_empty() {
        bank.author = args.author.clone();
    }
    bank.license = args.license.clone();
    save_bank_output(&bank, &args.output)?;

    let root_hz = bank.effective_root_hz();
    let (lo, hi) = bank.modes.iter().fold((f64::MAX, 0.0f64), |(lo, hi), m| {
        (lo.min(m.freq_hz), hi.max(m.freq_hz))
    });
    let t60 = |d: f64| decay_to_t60_s(d);
    let (t_short, t_long) = bank.modes.iter().fold((f64::MAX, 0.0f64), |(s, l), m| {
        (s.min(t60(m.decay_per_s)), l.max(t60(m.decay_per_s)))
    });
    let say = |line: &str| say(&args.output, line);
    say(&bank.description);
    say(&format!(
        "  root {root_hz:.2} Hz ({}), {} modes from {lo:.2} Hz to {hi:.2} Hz, T60 {t_short:.3} s \
         to {t_long:.3} s",
        note_name(root_hz),
        bank.modes.len()
    ));
    let positions: Vec<String> = bank
        .positions
        .iter()
        .map(|p| {
            let coords: Vec<String> = p.coords.iter().map(|c| format!("{c}")).collect();
            format!("{} ({})", p.name, coords.join(", "))
        })
        .collect();
    say(&format!("  positions: {}", positions.join(", ")));
    say(&format!(
        "{}: {} modes, {} positions",
        output_name(&args.output),
        bank.modes.len(),
        bank.positions.len()
    ));
    Ok(())
}

/// The objects with the dimensions they take and the materials, for `--help`.
fn objects_and_materials() -> String {
    let mut text = String::from("Objects (typical dimensions, used for those not given):\n");
    for object in OBJECTS {
        text.push_str(&format!(
            "  {:<21} {}\n  {:<21} {}; {} by default\n",
            object.name,
            object.about,
            "",
            object.usage(),
            object.default_material.name
        ));
    }
    text.push_str("\nMaterials (density, Young's modulus, loss factor):\n");
    for material in MATERIALS {
        let aliases = if material.aliases.is_empty() {
            String::new()
        } else {
            format!(" (also {})", material.aliases.join(", "))
        };
        text.push_str(&format!(
            "  {:<10} {:>5.0} kg/m^3 {:>6.1} GPa  {:.1e}{aliases}\n",
            material.name,
            material.density_kg_m3,
            material.youngs_modulus_pa * 1e-9,
            material.loss_factor
        ));
    }
    text
}

/// Parses the object name.
fn parse_object(text: &str) -> Result<&'static ObjectKind, String> {
    ObjectKind::by_name(text).ok_or_else(|| {
        format!(
            "unknown object \"{text}\": expected one of {}",
            ObjectKind::names().join(", ")
        )
    })
}

/// Parses `--material`.
pub(super) fn parse_material(text: &str) -> Result<&'static Material, String> {
    Material::by_name(text).ok_or_else(|| {
        format!(
            "unknown material \"{text}\": expected one of {}",
            Material::names_with_aliases().join(", ")
        )
    })
}

/// Parses a positive finite number.
pub(super) fn parse_positive(text: &str) -> Result<f64, String> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v > 0.0)
        .ok_or_else(|| format!("expected a number above 0, found \"{text}\""))
}

/// Largest loss factor (`1/Q` of internal friction) an option takes: a Q of 2, far lossier than
/// rubber (about 0.1), where a struck object no longer rings.
pub(super) const MAX_LOSS_FACTOR: f64 = 0.5;

/// Parses a loss factor: above 0, at most [`MAX_LOSS_FACTOR`].
pub(super) fn parse_loss_factor(text: &str) -> Result<f64, String> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| *v > 0.0 && *v <= MAX_LOSS_FACTOR)
        .ok_or_else(|| {
            format!(
                "expected a loss factor above 0 and at most {MAX_LOSS_FACTOR} (a Q of 2; metals \
                 are about 1e-4, wood 8e-3, rubber 0.1), found \"{text}\""
            )
        })
}

/// Parses `--tuning`: a named tuning or comma-separated ratios.
fn parse_tuning(text: &str) -> Result<Ratios, String> {
    if let Some((_, ratios)) = BAR_TUNINGS
        .iter()
        .find(|(name, _)| name.eq_ignore_ascii_case(text.trim()))
    {
        return Ok(Ratios(ratios.to_vec()));
    }
    let names: Vec<&str> = BAR_TUNINGS.iter().map(|(name, _)| *name).collect();
    text.split(',')
        .map(|r| parse_positive(r).ok())
        .collect::<Option<Vec<f64>>>()
        .map(Ratios)
        .ok_or_else(|| {
            format!(
                "expected one of {} or ratios such as \"1,4,10\", found \"{text}\"",
                names.join(", ")
            )
        })
}

/// Parses `--edge`.
fn parse_edge(text: &str) -> Result<PlateEdge, String> {
    PlateEdge::from_name(text).ok_or_else(|| {
        let names: Vec<&str> = PlateEdge::ALL.iter().map(|e| e.name()).collect();
        format!("expected one of {}, found \"{text}\"", names.join(", "))
    })
}

/// Parses `--root-note` to a frequency in Hz.
fn parse_note(text: &str) -> Result<f64, String> {
    note_to_midi_key(text)
        .map(|key| midi_key_to_hz(f64::from(key)))
        .ok_or_else(|| {
            format!("expected a note such as C4, F#2 or Bb5, or a MIDI key, found \"{text}\"")
        })
}

/// Parses `--positions`: `[NAME=]X[,Y]` separated by semicolons; unnamed positions are named
/// after their coordinates.
fn parse_positions(text: &str) -> Result<PositionList, String> {
    text.split(';')
        .map(str::trim)
        .filter(|item| !item.is_empty())
        .map(|item| {
            let (name, coords) = match item.split_once('=') {
                Some((name, coords)) => (Some(name.trim()), coords),
                None => (None, item),
            };
            let coords = coords
                .split(',')
                .map(|c| c.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
                .collect::<Option<Vec<f64>>>()
                .filter(|c| (1..=2).contains(&c.len()))
                .ok_or_else(|| {
                    format!("\"{item}\": expected [NAME=]X or [NAME=]X,Y with numbers")
                })?;
            let name = match name {
                Some(name) if !name.is_empty() => name.to_string(),
                _ => {
                    let parts: Vec<String> = coords.iter().map(|c| format!("{c}")).collect();
                    parts.join(", ")
                }
            };
            Ok(Position { name, coords })
        })
        .collect::<Result<Vec<_>, String>>()
        .and_then(|positions| {
            if positions.is_empty() {
                Err("expected at least one position".to_string())
            } else {
                Ok(PositionList(positions))
            }
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positions_parse_with_and_without_names() {
        let p = parse_positions("tip=1.0; 0.5 ;edge = 0.2, 0.3").unwrap().0;
        assert_eq!(p[0].name, "tip");
        assert_eq!(p[0].coords, vec![1.0]);
        assert_eq!(p[1].name, "0.5");
        assert_eq!(p[2].name, "edge");
        assert_eq!(p[2].coords, vec![0.2, 0.3]);
        for bad in ["", "a=", "x=1,2,3", "1;two"] {
            assert!(parse_positions(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn tunings_and_notes_parse() {
        assert_eq!(parse_tuning("Marimba").unwrap().0, vec![1.0, 4.0, 10.0]);
        assert_eq!(parse_tuning("1, 3.9").unwrap().0, vec![1.0, 3.9]);
        assert!(parse_tuning("banjo").unwrap_err().contains("marimba"));
        assert!((parse_note("A4").unwrap() - 440.0).abs() < 1e-9);
        assert!(parse_note("H4").is_err());
        assert!(parse_object("kazoo").unwrap_err().contains("free-free-bar"));
        assert!(parse_material("cheese")
            .unwrap_err()
            .contains("porcelain (ceramic)"));
    }
}
