//! `modal-resonator mesh`: a bank from a 3-D model (the library's `authoring::mesh`).

use std::path::PathBuf;

use clap::Args;
use sha2::{Digest, Sha256};

use modal_resonator::authoring::fit::{read_wav_recording, Recording};
use modal_resonator::authoring::materials::Material;
use modal_resonator::authoring::mesh::strike::spread_names;
use modal_resonator::authoring::mesh::{
    bank_from_modes, check_elements, match_recording, parse_surface, solve_modes_up_to,
    solve_modes_within, spread_strike_points, strike_points, unit_warning, Clamp, MeshError,
    MeshModes, MeshSettings, MeshSource, MeshStage, SolveStage, StrikePoint, StrikeRequest,
    Surface, DEFAULT_ELEMENTS, DEFAULT_MAX_SOLVE_BYTES, MAX_MODES,
};
use modal_resonator::authoring::shapes::{ModeLimits, MAX_AUDIBLE_HZ};
use modal_resonator::bank::summary::note_name;
use modal_resonator::bank::validate::MAX_POSITIONS;

use super::progress::Progress;
use super::shape::{parse_loss_factor, parse_material, parse_positive};
use super::{check_output, save_bank_output, say};

/// A mesh file larger than this is refused before it is read.
const MAX_MESH_FILE_BYTES: u64 = 512 << 20;

/// Strike points spread over the surface when none are given.
const DEFAULT_POINTS: usize = 6;

/// Modes found when neither `--modes` nor `--max-hz` says otherwise.
const DEFAULT_MODES: usize = 100;

/// Arguments of `mesh`.
#[derive(Debug, Args)]
pub(super) struct MeshArgs {
    /// Closed surface of the object: Wavefront OBJ or STL (ASCII or binary).
    #[arg(value_name = "MESH")]
    input: PathBuf,
    /// Bank file (JSON) to write; - writes it to standard output.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Metres per unit of the file's coordinates (0.001 for a file in millimetres).
    #[arg(long, default_value_t = 1.0, value_parser = parse_positive, value_name = "M")]
    scale: f64,
    /// Material (those of `shape`); its constants can be overridden one by one below.
    #[arg(long, value_parser = parse_material, default_value = "steel")]
    material: &'static Material,
    /// Density in kg/m^3, instead of the material's.
    #[arg(long, value_parser = parse_positive, value_name = "KG_M3")]
    density: Option<f64>,
    /// Young's modulus in Pa, instead of the material's.
    #[arg(long, value_parser = parse_positive, value_name = "PA")]
    youngs_modulus: Option<f64>,
    /// Poisson's ratio (0 to 0.49), instead of the material's.
    #[arg(long, value_parser = parse_poisson, value_name = "NU")]
    poisson: Option<f64>,
    /// Loss factor (1/Q of internal friction), instead of the material's.
    #[arg(long, value_parser = parse_loss_factor, value_name = "ETA")]
    loss_factor: Option<f64>,
    /// Held parts, repeatable: a plane as "z<0.002" or "x>0.25" (file units: everything on
    /// that side is clamped), or mesh vertices as "vertices=0,17,42" (0-based; the solid
    /// within a voxel of each is clamped). Free when absent.
    #[arg(long, value_name = "WHERE")]
    fix: Vec<String>,
    /// Strike points: "NAME=X,Y,Z; ..." in file units (moved onto the nearest surface point),
    /// or a count of points to spread over the surface where its lowest modes move most
    /// [default: 6].
    #[arg(long, value_name = "LIST")]
    positions: Option<String>,
    /// Combine with a recording of the object struck at one point: "REC.wav=NAME" (a strike
    /// point of --positions) or "REC.wav=X,Y,Z" (file units; added as a point named after the
    /// recording). The bank takes the recording's frequencies, decays and levels there, and the
    /// mesh's level ratios at the other points.
    #[arg(long = "match", value_name = "REC.wav=POINT")]
    match_recording: Option<String>,
    /// Voxels (elements) to aim for: more is finer and slower.
    #[arg(long, default_value_t = DEFAULT_ELEMENTS, value_name = "N")]
    elements: usize,
    /// Number of modes to find, the lowest, 1 to 500 [default: 100, or with --max-hz as many as
    /// lie below it, up to 500].
    #[arg(long, value_parser = parse_modes, value_name = "N")]
    modes: Option<usize>,
    /// Modes at or above this frequency in Hz are left out [default: 20000]; given without
    /// --modes, modes are sought up to it.
    #[arg(long, value_parser = parse_positive, value_name = "HZ")]
    max_hz: Option<f64>,
    /// Bank name (default: the mesh file's name).
    #[arg(long)]
    name: Option<String>,
    /// Author written into the bank.
    #[arg(long, default_value = "")]
    author: String,
    /// SPDX licence of the bank.
    #[arg(long, default_value = "CC0-1.0")]
    license: String,
}

/// Strike points as asked for: placed now, or spread once the modes are known.
enum PointPlan {
    /// Points given by place, on the surface.
    Given(Vec<StrikePoint>),
    /// This many points to spread where the lowest modes move most.
    Spread(usize),
}

impl PointPlan {
    /// The points' names, known before the solve.
    fn names(&self) -> Vec<String> {
        match self {
            Self::Given(points) => points.iter().map(|p| p.name.clone()).collect(),
            Self::Spread(count) => spread_names(*count),
        }
    }
}

/// Where a recording of `--match` was struck.
enum RecordedAt {
    /// At the strike point of this index.
    Point(usize),
    /// At a place of its own, added as the last strike point.
    Added(StrikePoint),
}

/// Builds the bank, saves it atomically and prints what it is. Nothing is written on failure.
pub(super) fn run(args: &MeshArgs) -> Result<(), String> {
    let recording_file = args
        .match_recording
        .as_deref()
        .and_then(|spec| spec.rsplit_once('='))
        .map(|(path, _)| PathBuf::from(path.trim()));
    let mut inputs = vec![("the mesh", args.input.as_path())];
    if let Some(file) = &recording_file {
        inputs.push(("the recording", file));
    }
    check_output("-o", &args.output, &inputs)?;
    // Before anything is read: the solve's memory grows faster than the element count.
    check_elements(args.elements).map_err(|e| match e {
        MeshError::BadSetting { reason, .. } => format!("--elements: {reason}"),
        other => format!("--elements: {other}"),
    })?;
    let place = args.input.display().to_string();
    let (surface, source) = read_mesh(args)?;
    if let Some(warning) = unit_warning(&surface) {
        eprintln!("warning: {place}: at --scale {}: {warning}", args.scale);
    }
    let mut settings = MeshSettings {
        material: material(args),
        elements: args.elements,
        clamps: clamps(&args.fix, &surface, args.scale)?,
        modes: args.modes.unwrap_or(DEFAULT_MODES),
    };
    // Strike points and the recording first: a mistake in them is reported before the solve.
    let plan = point_plan(args, &surface)?;
    let recording = match args.match_recording.as_deref() {
        Some(spec) => Some(recording_point(spec, &surface, &plan.names(), args.scale)?),
        None => None,
    };
    let modes = solve_up_to_limit(args, &surface, &mut settings)?;
    if let Some(warning) = modes.rigid_warning() {
        eprintln!("warning: {place}: {warning}");
    }
    let mut points = placed_points(plan, &surface, &modes, &place);
    let recording = match recording {
        Some((recording, at, file_name)) => {
            Some((recording, recorded_point(at, &mut points)?, file_name))
        }
        None => None,
    };
    let limits = ModeLimits {
        max_freq_hz: args.max_hz.unwrap_or(MAX_AUDIBLE_HZ),
        max_modes: settings.modes,
    };
    let name = args.name.clone().unwrap_or_else(|| {
        args.input
            .file_stem()
            .map(|s| s.to_string_lossy().replace(['_', '-'], " "))
            .unwrap_or_else(|| "Meshed object".to_string())
    });
    let mut bank = bank_from_modes(&name, &modes, &settings, &points, &limits, &source)
        .map_err(|e| format!("{place}: {e}"))?;
    if let Some((recording, at, file_name)) = recording {
        bank = matched(bank, &recording, at, &file_name)?;
    }
    if !args.author.is_empty() {
        bank.author = args.author.clone();
    }
    bank.license = args.license.clone();
    save_bank_output(&bank, &args.output)?;
    report(args, &modes, &bank);
    Ok(())
}

/// The index among `points` of where a recording was struck (a place of its own added last).
fn recorded_point(at: RecordedAt, points: &mut Vec<StrikePoint>) -> Result<usize, String> {
    match at {
        // Fewer points than asked are spread over a surface of few faces.
        RecordedAt::Point(k) if k >= points.len() => Err(format!(
            "--match: only {} strike points could be spread, so \"p{}\" does not exist",
            points.len(),
            k + 1
        )),
        RecordedAt::Point(k) => Ok(k),
        RecordedAt::Added(point) => {
            points.push(point);
            Ok(points.len() - 1)
        }
    }
}

/// The strike points `--positions` asks for: places (moved onto the surface now), or a count
/// of points to spread (default 6) once the modes are known.
fn point_plan(args: &MeshArgs, surface: &Surface) -> Result<PointPlan, String> {
    let Some(text) = args.positions.as_deref() else {
        return Ok(PointPlan::Spread(DEFAULT_POINTS));
    };
    match text.trim().parse::<usize>() {
        Ok(count) if (1..=MAX_POSITIONS).contains(&count) => Ok(PointPlan::Spread(count)),
        Ok(count) => Err(format!(
            "--positions {count}: expected 1 to {MAX_POSITIONS} points"
        )),
        Err(_) => Ok(PointPlan::Given(strike_points(
            surface,
            &parse_points(text, args.scale)?,
        ))),
    }
}

/// The strike points of `plan`, spread by the solid's `modes` where asked.
fn placed_points(
    plan: PointPlan,
    surface: &Surface,
    modes: &MeshModes,
    place: &str,
) -> Vec<StrikePoint> {
    match plan {
        PointPlan::Given(points) => points,
        PointPlan::Spread(count) => {
            let points = spread_strike_points(surface, modes, count);
            if points.len() < count {
                eprintln!(
                    "{place}: only {} strike points can be spread over a surface of {} faces",
                    points.len(),
                    surface.triangles.len()
                );
            }
            points
        }
    }
}

/// The recording (read) and where it was struck, for `--match REC=POINT`: one of the strike
/// points named `names`, or a place of its own.
fn recording_point(
    spec: &str,
    surface: &Surface,
    names: &[String],
    scale: f64,
) -> Result<(Recording, RecordedAt, String), String> {
    let (path, point) = spec
        .rsplit_once('=')
        .ok_or_else(|| format!("--match \"{spec}\": expected REC.wav=NAME or REC.wav=X,Y,Z"))?;
    let path = PathBuf::from(path.trim());
    let read = |name: &str| read_wav_recording(&path, name).map_err(|e| e.to_string());
    let file_name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    if let Some(k) = names.iter().position(|name| name == point.trim()) {
        return Ok((read(&names[k])?, RecordedAt::Point(k), file_name));
    }
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "recording".to_string());
    let request = parse_points(&format!("{stem}={point}"), scale).map_err(|_| {
        format!(
            "--match \"{spec}\": \"{point}\" is neither a strike point ({}) nor X,Y,Z",
            names.join(", ")
        )
    })?;
    if names.len() >= MAX_POSITIONS {
        return Err(format!(
            "--match: a bank has at most {MAX_POSITIONS} positions"
        ));
    }
    let recording = read(&request[0].name)?;
    let point = strike_points(surface, &request).remove(0);
    Ok((recording, RecordedAt::Added(point), file_name))
}

/// `bank` matched to `recording` (of the file `file_name`), struck at position `at`, with a
/// progress bar.
fn matched(
    bank: modal_resonator::bank::Bank,
    recording: &Recording,
    at: usize,
    file_name: &str,
) -> Result<modal_resonator::bank::Bank, String> {
    let mut progress = Progress::new("fitting the recording");
    let matched = match_recording(&bank, recording, at, file_name, |done| progress.set(done));
    progress.finish();
    let (bank, _) = matched.map_err(|e| format!("{}: {e}", recording.origin))?;
    Ok(bank)
}

/// The surface in metres, and what the bank records of its file.
fn read_mesh(args: &MeshArgs) -> Result<(Surface, MeshSource), String> {
    let place = args.input.display().to_string();
    let size = std::fs::metadata(&args.input)
        .map_err(|e| format!("{place}: cannot read: {e}"))?
        .len();
    if size > MAX_MESH_FILE_BYTES {
        return Err(format!(
            "{place}: {size} bytes, more than the {MAX_MESH_FILE_BYTES} a mesh may have"
        ));
    }
    let bytes = std::fs::read(&args.input).map_err(|e| format!("{place}: cannot read: {e}"))?;
    let file_name = args
        .input
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut surface = parse_surface(&file_name, &bytes).map_err(|e| format!("{place}: {e}"))?;
    surface.scale(args.scale);
    surface.check().map_err(|e| format!("{place}: {e}"))?;
    let sha256 = Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    let source = MeshSource {
        file_name,
        sha256,
        scale: args.scale,
    };
    Ok((surface, source))
}

/// The modes of `surface`: as many as `settings` asks, or, with `--max-hz` and no `--modes`,
/// up to that frequency (at most the library's limit, said when reached).
fn solve_up_to_limit(
    args: &MeshArgs,
    surface: &Surface,
    settings: &mut MeshSettings,
) -> Result<MeshModes, String> {
    let place = args.input.display().to_string();
    let limit = args.max_hz.filter(|_| args.modes.is_none());
    let modes =
        solve_with_progress(surface, settings, limit).map_err(|e| format!("{place}: {e}"))?;
    if let Some(limit) = limit.filter(|&limit| modes.all_below(limit)) {
        if modes.freqs_hz.len() >= MAX_MODES {
            eprintln!(
                "{place}: all {MAX_MODES} modes found lie below --max-hz {limit} Hz; the bank keeps \
                 the lowest {MAX_MODES}"
            );
        }
    }
    Ok(modes)
}

/// Parses `--modes`.
fn parse_modes(text: &str) -> Result<usize, String> {
    text.trim()
        .parse::<usize>()
        .ok()
        .filter(|n| (1..=MAX_MODES).contains(n))
        .ok_or_else(|| format!("expected a whole number from 1 to {MAX_MODES}, found \"{text}\""))
}

/// The material with the overrides given.
fn material(args: &MeshArgs) -> Material {
    let mut material = *args.material;
    if let Some(v) = args.density {
        material.density_kg_m3 = v;
    }
    if let Some(v) = args.youngs_modulus {
        material.youngs_modulus_pa = v;
    }
    if let Some(v) = args.poisson {
        material.poisson_ratio = v;
    }
    if let Some(v) = args.loss_factor {
        material.loss_factor = v;
    }
    material
}

/// The most memory a solve may hold: [`DEFAULT_MAX_SOLVE_BYTES`], or half the machine's
/// memory when that is less (read from `/proc/meminfo` where there is one).
fn memory_limit_bytes() -> usize {
    let machine = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|text| {
            let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
            let kib: usize = line.split_whitespace().nth(1)?.parse().ok()?;
            Some(kib.saturating_mul(1024))
        });
    machine.map_or(DEFAULT_MAX_SOLVE_BYTES, |bytes| {
        (bytes / 2).min(DEFAULT_MAX_SOLVE_BYTES)
    })
}

/// Solves (up to `max_hz` when given) with a progress bar for each stage.
fn solve_with_progress(
    surface: &Surface,
    settings: &mut MeshSettings,
    max_hz: Option<f64>,
) -> Result<MeshModes, MeshError> {
    let mut bar: Option<(&'static str, Progress)> = None;
    let mut stage_bar = |label: &'static str, done: f64| {
        if bar.as_ref().is_none_or(|(l, _)| *l != label) {
            if let Some((_, old)) = bar.take() {
                old.finish();
            }
            bar = Some((label, Progress::new(label)));
        }
        if let Some((_, progress)) = bar.as_mut() {
            progress.set(done);
        }
    };
    let limit = memory_limit_bytes();
    let mut on_stage = |stage| match stage {
        MeshStage::Voxelising => stage_bar("voxelising", 0.0),
        MeshStage::Assembling { .. } => stage_bar("assembling", 0.0),
        MeshStage::Solving(SolveStage::Factorising) => stage_bar("factorising", 0.0),
        MeshStage::Solving(SolveStage::Iterating { steps, expected }) => {
            stage_bar("iterating", steps as f64 / expected.max(1) as f64)
        }
    };
    let modes = match max_hz {
        Some(max_hz) => solve_modes_up_to(surface, settings, max_hz, limit, &mut on_stage),
        None => solve_modes_within(surface, settings, limit, &mut on_stage),
    };
    if let Some((_, progress)) = bar {
        progress.finish();
    }
    modes
}

/// Parses `--poisson`.
fn parse_poisson(text: &str) -> Result<f64, String> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| (0.0..0.5).contains(v))
        .ok_or_else(|| format!("expected a number from 0 up to 0.5, found \"{text}\""))
}

/// Parses `--positions` as named points: `NAME=X,Y,Z` separated by semicolons, in file units.
fn parse_points(text: &str, scale: f64) -> Result<Vec<StrikeRequest>, String> {
    let points = text
        .split(';')
        .map(str::trim)
        .filter(|item| !item.is_empty())
        .map(|item| {
            let expected = || format!("--positions \"{item}\": expected NAME=X,Y,Z with numbers");
            let (name, coords) = item.split_once('=').ok_or_else(expected)?;
            let values = coords
                .split(',')
                .map(|c| c.trim().parse::<f64>().ok().filter(|v| v.is_finite()))
                .collect::<Option<Vec<f64>>>()
                .filter(|c| c.len() == 3)
                .ok_or_else(expected)?;
            if name.trim().is_empty() {
                return Err(expected());
            }
            Ok(StrikeRequest {
                name: name.trim().to_string(),
                point_m: [values[0] * scale, values[1] * scale, values[2] * scale],
            })
        })
        .collect::<Result<Vec<_>, String>>()?;
    for (k, p) in points.iter().enumerate() {
        if points[..k].iter().any(|q| q.name == p.name) {
            return Err(format!("--positions: \"{}\" is named twice", p.name));
        }
    }
    if points.is_empty() || points.len() > MAX_POSITIONS {
        return Err(format!(
            "--positions: expected 1 to {MAX_POSITIONS} points, found {}",
            points.len()
        ));
    }
    Ok(points)
}

/// Parses the `--fix` options into clamps, in metres.
fn clamps(specs: &[String], surface: &Surface, scale: f64) -> Result<Vec<Clamp>, String> {
    let mut clamps = Vec::new();
    for spec in specs {
        let text = spec.trim();
        let bad = || {
            format!(
                "--fix \"{spec}\": expected a plane such as \"z<0.002\" or \"x>0.25\", or \
                 \"vertices=0,17,42\""
            )
        };
        if let Some(list) = text.strip_prefix("vertices=") {
            for item in list.split(',') {
                let index: usize = item.trim().parse().map_err(|_| bad())?;
                let point_m = *surface.vertices.get(index).ok_or_else(|| {
                    format!(
                        "--fix \"{spec}\": vertex {index} does not exist ({} vertices, from 0)",
                        surface.vertices.len()
                    )
                })?;
                clamps.push(Clamp::Near { point_m });
            }
            continue;
        }
        let axis = match text.chars().next() {
            Some('x' | 'X') => 0,
            Some('y' | 'Y') => 1,
            Some('z' | 'Z') => 2,
            _ => return Err(bad()),
        };
        let rest = text[1..].trim_start();
        let (below, value) = if let Some(v) = rest.strip_prefix("<=").or(rest.strip_prefix('<')) {
            (true, v)
        } else if let Some(v) = rest.strip_prefix(">=").or(rest.strip_prefix('>')) {
            (false, v)
        } else {
            return Err(bad());
        };
        let at: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(bad)?;
        let at_m = at * scale;
        clamps.push(if below {
            Clamp::Below { axis, at_m }
        } else {
            Clamp::Above { axis, at_m }
        });
    }
    Ok(clamps)
}

/// Prints what was made.
fn report(args: &MeshArgs, modes: &MeshModes, bank: &modal_resonator::bank::Bank) {
    let stats = &modes.stats;
    let say = |line: &str| say(&args.output, line);
    say(&bank.description);
    say(&format!(
        "  {} elements of {:.3} mm, {} degrees of freedom, {} rigid motions left out, about \
         {:.0} MiB; voxels {:.2} s, assembly {:.2} s, factorisation {:.2} s, {} Lanczos steps \
         {:.2} s",
        stats.elements,
        stats.voxel_m * 1e3,
        stats.dofs,
        stats.rigid_modes,
        stats.memory_bytes as f64 / (1u64 << 20) as f64,
        stats.voxelising.as_secs_f64(),
        stats.assembling.as_secs_f64(),
        stats.factorising.as_secs_f64(),
        stats.steps,
        stats.iterating.as_secs_f64()
    ));
    let root = bank.effective_root_hz();
    let (lo, hi) = bank.modes.iter().fold((f64::MAX, 0.0f64), |(lo, hi), m| {
        (lo.min(m.freq_hz), hi.max(m.freq_hz))
    });
    say(&format!(
        "  root {root:.2} Hz ({}), {} modes from {lo:.2} Hz to {hi:.2} Hz, {} strike points: {}",
        note_name(root),
        bank.modes.len(),
        bank.positions.len(),
        bank.positions
            .iter()
            .map(|p| p.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    ));
    say(&format!(
        "  written to {}",
        super::output_name(&args.output)
    ));
}
