//! `modal-resonator play` (and no subcommand): the instrument standalone.

/// Runs the instrument through nice-plug's standalone wrapper until it is stopped. With no
/// display it runs headless on the audio backend named, and refuses to start when none is: the
/// automatic choice would fall back to a silent backend with nothing to show or stop it.
#[cfg(feature = "standalone")]
pub(super) fn run(args: Vec<String>) -> Result<(), String> {
    let asks = |names: &[&str]| {
        args.iter().any(|a| {
            names
                .iter()
                .any(|n| a == n || (n.starts_with("--") && a.starts_with(&format!("{n}="))))
        })
    };
    if !asks(&["-h", "--help", "-V", "--version"]) && !has_display() {
        if !asks(&["-b", "--backend"]) {
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
