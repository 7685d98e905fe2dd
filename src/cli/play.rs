//! `modal-resonator play` (and no subcommand): the instrument standalone.

/// Runs the instrument through nice-plug's standalone wrapper until it is stopped. With no
/// display it runs headless on the audio backend named, and refuses to start when none is: the
/// automatic choice would fall back to a silent backend with nothing to show or stop it.
#[cfg(feature = "standalone")]
pub(super) fn run(args: Vec<String>) -> Result<(), String> {
    let help = args.iter().any(|a| a == "-h" || a == "--help");
    if !help && !has_display() {
        if matches!(backend(&args), None | Some("auto")) {
            return Err(
                "no display to open the instrument's window on (DISPLAY is not set). \
                 To play without a window, name the audio backend: `play --backend jack` or \
                 `play --backend alsa` (`--backend dummy` runs silent); `play --help` lists \
                 the options"
                    .to_string(),
            );
        }
        modal_resonator::plugin::play_without_editor();
    }
    let argv = std::iter::once("modal-resonator".to_string()).chain(args);
    if nice_plug::prelude::nice_export_standalone_with_args::<modal_resonator::ModalResonator, _>(
        argv,
    ) {
        Ok(())
    } else {
        Err(
            "the standalone stopped on the error above: its audio backend or its window \
             could not start"
                .to_string(),
        )
    }
}

/// The backend named in the standalone's options, in any of the spellings its parser takes
/// (`--backend X`, `--backend=X`, `-b X`, `-bX`, `-b=X`); the last one named counts.
#[cfg(feature = "standalone")]
fn backend(args: &[String]) -> Option<&str> {
    let mut named = None;
    let mut words = args.iter();
    while let Some(a) = words.next() {
        if a == "--backend" || a == "-b" {
            named = words.next().map(String::as_str);
        } else if let Some(v) = a.strip_prefix("--backend=") {
            named = Some(v);
        } else if let Some(v) = a.strip_prefix("-b").filter(|_| !a.starts_with("--")) {
            named = Some(v.strip_prefix('=').unwrap_or(v));
        }
    }
    named
}

/// Whether a window can be opened: on Linux and the BSDs, an X11 display is named.
#[cfg(feature = "standalone")]
fn has_display() -> bool {
    if cfg!(all(unix, not(target_os = "macos"))) {
        std::env::var_os("DISPLAY").is_some_and(|d| !d.is_empty())
    } else {
        true
    }
}

/// Without the standalone feature there is nothing to play: say so.
#[cfg(not(feature = "standalone"))]
pub(super) fn run(_args: Vec<String>) -> Result<(), String> {
    let _ = <super::Cli as clap::CommandFactory>::command().print_help();
    Err("this build has no standalone player (build with the `standalone` feature)".to_string())
}
