//! The `modal-resonator` command line: one file per subcommand, each thin over the library
//! (`modal_resonator`), where every decision about sound lives.

mod compress;
mod fit;
mod info;
mod list;
mod mesh;
mod play;
mod progress;
mod render;
mod scene;
mod schema;
mod shape;
mod validate;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

use modal_resonator::bank::factory::{factory_bank, factory_banks, factory_slug};
use modal_resonator::bank::staged::{destination, exit_removing_temporaries, temp_beside};
use modal_resonator::bank::{load_bank_file, Bank};

/// Modal Resonator: modal-synthesis instrument and bank tool.
#[derive(Debug, Parser)]
#[command(name = "modal-resonator", version, about)]
struct Cli {
    /// What to do; with none, plays the instrument standalone (as `play`, taking its options:
    /// `modal-resonator --backend dummy`).
    #[command(subcommand)]
    command: Option<Command>,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
enum Command {
    /// Play the instrument standalone: audio and MIDI through JACK or ALSA (`--backend dummy`
    /// runs headless). Options after `play` go to the standalone; `play --help` lists them.
    Play {
        /// Standalone options, e.g. --backend alsa --sample-rate 48000 --period-size 256.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
    /// Render notes or a MIDI file through a bank to a stereo WAV file.
    Render(render::RenderArgs),
    /// Fit a bank to recordings of an object struck at one or more positions.
    Fit(fit::FitArgs),
    /// Make a bank from an analytic object (string, bar, tine, membrane, plate, disc, bell) of
    /// given dimensions and material.
    Shape(Box<shape::ShapeArgs>),
    /// Make a bank from a 3-D model (closed OBJ or STL surface) by finite elements: its lowest
    /// modes, decays from the material, gains at strike points on the surface.
    Mesh(Box<mesh::MeshArgs>),
    /// Make a bank cheaper: merge modes closer than the frequency difference limen and drop
    /// modes far below the strongest.
    Compress(compress::CompressArgs),
    /// Check bank files and print every problem found.
    Validate {
        /// Bank files (JSON).
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Describe a bank: modes, positions, frequency range, T60s.
    Info {
        /// Bank file (JSON) or factory preset name.
        bank: String,
    },
    /// List the factory banks.
    List,
    /// Render a scene: objects placed in space, sounded by timed impacts and contacts, heard
    /// from a listener's place.
    Scene(scene::SceneArgs),
    /// Print the JSON Schema of the bank format (of the scene format with --scene).
    Schema {
        /// The scene format's schema instead.
        #[arg(long)]
        scene: bool,
    },
}

/// Parses the command line, runs the subcommand, and reports an error on stderr.
pub fn main() -> ExitCode {
    // Options with no subcommand go to the standalone: `modal-resonator --backend dummy`.
    let argv: Vec<String> = std::env::args().skip(1).collect();
    let standalone_options = argv
        .first()
        .is_some_and(|a| a.starts_with("--") && a != "--help" && a != "--version");
    let cli = if standalone_options {
        Cli {
            command: Some(Command::Play { args: argv }),
        }
    } else if argv.first().is_some_and(|a| a == "play") {
        // Everything after `play` is the standalone's, `--help` too, which lists its options.
        Cli {
            command: Some(Command::Play {
                args: argv[1..].to_vec(),
            }),
        }
    } else {
        let matches = parser().get_matches();
        Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
    };
    let standalone = matches!(cli.command, Some(Command::Play { .. }) | None);
    if !standalone {
        quiet_on_closed_pipe();
        clean_up_on_interrupt();
    }
    let result = match cli.command {
        Some(Command::Render(args)) => render::run(&args),
        Some(Command::Fit(args)) => fit::run(&args).map(|()| ExitCode::SUCCESS),
        Some(Command::Shape(args)) => shape::run(&args).map(|()| ExitCode::SUCCESS),
        Some(Command::Mesh(args)) => mesh::run(&args).map(|()| ExitCode::SUCCESS),
        Some(Command::Compress(args)) => compress::run(&args).map(|()| ExitCode::SUCCESS),
        Some(Command::Validate { files }) => validate::run(&files).map(|()| ExitCode::SUCCESS),
        Some(Command::Info { bank }) => info::run(&bank).map(|()| ExitCode::SUCCESS),
        Some(Command::List) => list::run().map(|()| ExitCode::SUCCESS),
        Some(Command::Scene(args)) => scene::run(&args).map(|()| ExitCode::SUCCESS),
        Some(Command::Schema { scene }) => schema::run(scene).map(|()| ExitCode::SUCCESS),
        Some(Command::Play { args }) => play::run(args).map(|()| ExitCode::SUCCESS),
        None => play::run(Vec::new()).map(|()| ExitCode::SUCCESS),
    };
    match result {
        Ok(code) => code,
        Err(message) => {
            eprintln!("error: {message}");
            ExitCode::FAILURE
        }
    }
}

/// The command line's parser. Every option's value may be a negative number, so that
/// `--scale -1` reaches the option's own check ("expected a number above 0") instead of
/// clap's advice to write `-- -1`, which does not work for an option's value.
fn parser() -> clap::Command {
    Cli::command().mut_subcommands(|sub| {
        sub.mut_args(|arg| {
            if arg.get_action().takes_values() && !arg.is_positional() {
                arg.allow_negative_numbers(true)
            } else {
                arg
            }
        })
    })
}

/// Lets a closed output pipe end the process silently, as it ends `cat` (`info | head`),
/// instead of making every later print fail. Not for the standalone, whose audio and MIDI
/// connections must see a closed socket as an error.
fn quiet_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of SIGPIPE, before any other thread runs.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

/// Ctrl-C, SIGTERM and SIGHUP end the command with status 130 after removing the temporary
/// files beside its outputs; the outputs keep what they held. Not for the standalone, which
/// stops its audio on Ctrl-C itself.
fn clean_up_on_interrupt() {
    // Only fails when a handler is already set, which nothing else here does.
    let _ = ctrlc::set_handler(|| exit_removing_temporaries(130));
}

/// A bank named on the command line, and the file it came from (none for a factory bank).
pub(super) struct LoadedBank {
    /// The bank.
    pub bank: Bank,
    /// The file it was read from; `None` for a factory bank.
    pub file: Option<PathBuf>,
}

/// Loads the bank named on the command line. A bare name of a factory bank (no directory, no
/// extension) is that factory bank, even where a file of that name lies in the working
/// directory (which is said, with how to name the file instead: `./NAME`); anything else is a
/// bank file, validated. An error says which was looked for, and where.
pub(super) fn load_bank(arg: &str) -> Result<LoadedBank, String> {
    let path = Path::new(arg);
    let bare = path.components().count() == 1 && path.extension().is_none();
    if bare {
        if let Some(bank) = factory_bank(arg) {
            if path.exists() {
                eprintln!(
                    "note: \"{arg}\" is a factory bank, played instead of the file of that name \
                     here; write ./{arg} for the file"
                );
            }
            return Ok(LoadedBank { bank, file: None });
        }
    }
    if path.exists() {
        let bank = load_bank_file(path).map_err(|e| e.to_string())?;
        return Ok(LoadedBank {
            bank,
            file: Some(path.to_path_buf()),
        });
    }
    let looked_in = std::env::current_dir()
        .map(|dir| dir.join(path).display().to_string())
        .unwrap_or_else(|_| arg.to_string());
    if bare {
        let names: Vec<String> = factory_banks().iter().map(factory_slug).collect();
        let near = nearest_names(arg, &names);
        Err(format!(
            "no factory bank named \"{arg}\" and no file {looked_in}{}; `modal-resonator list` \
             shows the factory banks",
            if near.is_empty() {
                String::new()
            } else {
                format!(" (did you mean {}?)", near.join(", "))
            }
        ))
    } else {
        Err(format!(
            "{arg}: no such bank file ({looked_in} does not exist)"
        ))
    }
}

/// The names among `names` closest to `wanted` by edit distance (at most a third of its
/// length away), closest first, at most three.
fn nearest_names(wanted: &str, names: &[String]) -> Vec<String> {
    let wanted = wanted.to_lowercase();
    let limit = wanted.chars().count().div_ceil(3).max(2);
    let mut scored: Vec<(usize, &String)> = names
        .iter()
        .map(|name| (edit_distance(&wanted, name), name))
        .filter(|(d, name)| *d <= limit || name.contains(wanted.as_str()))
        .collect();
    scored.sort();
    scored.into_iter().take(3).map(|(_, n)| n.clone()).collect()
}

/// Levenshtein distance between two strings, by characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let above = row[j + 1];
            row[j + 1] = (diagonal + usize::from(ca != cb))
                .min(above + 1)
                .min(row[j] + 1);
            diagonal = above;
        }
    }
    row[b.len()]
}

/// The output path that means standard output.
pub(super) const STDOUT: &str = "-";

/// Whether `output` means standard output.
pub(super) fn is_stdout(output: &Path) -> bool {
    output.as_os_str() == STDOUT
}

/// Writes `bank` to `output`: a file, atomically, or standard output for `-`. Validated first
/// either way; nothing is written when it fails.
pub(super) fn save_bank_output(bank: &Bank, output: &Path) -> Result<(), String> {
    if !is_stdout(output) {
        return modal_resonator::bank::save_bank_file(bank, output).map_err(|e| e.to_string());
    }
    let problems = modal_resonator::bank::validate::validate_bank(bank);
    if let Some(first) = problems.first() {
        return Err(format!(
            "standard output: the bank is not valid ({} problems), first: {first}",
            problems.len()
        ));
    }
    use std::io::Write;
    let json = modal_resonator::bank::io::bank_to_json(bank);
    let mut stdout = std::io::stdout().lock();
    stdout
        .write_all(json.as_bytes())
        .and_then(|()| stdout.flush())
        .map_err(|e| format!("standard output: {e}"))
}

/// Prints a line of a command's summary: on standard output, or on standard error when the
/// command's output goes to standard output.
pub(super) fn say(output: &Path, line: &str) {
    if is_stdout(output) {
        eprintln!("{line}");
    } else {
        println!("{line}");
    }
}

/// How a summary names `output`.
pub(super) fn output_name(output: &Path) -> String {
    if is_stdout(output) {
        "standard output".to_string()
    } else {
        output.display().to_string()
    }
}

/// Checks, before any work, that a command can write `output` (named by the option `option`,
/// such as `-o`): something other than a regular file there (a directory, a device, a named
/// pipe, a socket; a symbolic link is followed) is refused, as is a directory that does not
/// exist or cannot be written in (tried by making and removing a file there), and an output that
/// is one of the command's `inputs` (each with what it is, such as "the bank"), by identity, so
/// a hard or symbolic link to an input is refused too. Every command that writes a file calls
/// it, so none can overwrite what it reads.
pub(super) fn check_output(
    option: &str,
    output: &Path,
    inputs: &[(&str, &Path)],
) -> Result<(), String> {
    if is_stdout(output) {
        return Ok(());
    }
    let shown = output.display();
    let target = destination(output).map_err(|e| {
        format!(
            "{option} {shown}: {e}; name a file to write{}",
            if output.is_dir() { " in it" } else { "" }
        )
    })?;
    for (what, input) in inputs {
        if same_file(input, output) {
            return Err(format!(
                "{option} {shown}: would overwrite an input, {what} {}; write elsewhere",
                input.display()
            ));
        }
    }
    let dir = match target.path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        return Err(format!(
            "{option} {shown}: directory {} does not exist",
            dir.display()
        ));
    }
    // Noted like every temporary file, so an interrupt meanwhile removes it too.
    let probe = temp_beside(&target, ".modal-resonator-probe-", ".tmp");
    match probe {
        Ok(file) => {
            let _ = file.close();
            Ok(())
        }
        Err(e) => Err(format!(
            "{option} {shown}: cannot write in directory {}: {}",
            dir.display(),
            e.raw_os_error().map_or_else(
                || e.kind().to_string(),
                |code| { std::io::Error::from_raw_os_error(code).to_string() }
            )
        )),
    }
}

/// Whether `a` and `b` name the same file, whether it exists yet or is still to be written
/// (`out.json` and `./out.json` are the same): an existing file by its identity (device and
/// inode, so a hard or symbolic link to it is the same file), one still to be written by where
/// its path leads.
pub(super) fn same_file(a: &Path, b: &Path) -> bool {
    if is_stdout(a) || is_stdout(b) {
        return false;
    }
    #[cfg(unix)]
    if let (Ok(x), Ok(y)) = (std::fs::metadata(a), std::fs::metadata(b)) {
        use std::os::unix::fs::MetadataExt;
        return (x.dev(), x.ino()) == (y.dev(), y.ino());
    }
    let resolve = |p: &Path| -> Option<std::path::PathBuf> {
        let p = destination(p)
            .map(|d| d.path)
            .unwrap_or_else(|_| p.to_path_buf());
        if let Ok(path) = p.canonicalize() {
            return Some(path);
        }
        let dir = match p.parent() {
            Some(dir) if !dir.as_os_str().is_empty() => dir,
            _ => Path::new("."),
        };
        Some(dir.canonicalize().ok()?.join(p.file_name()?))
    };
    match (resolve(a), resolve(b)) {
        (Some(a), Some(b)) => a == b,
        _ => a == b,
    }
}
