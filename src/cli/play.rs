//! `modal-resonator play` (and no subcommand): the instrument standalone.

/// Runs the instrument through nice-plug's standalone wrapper until it is stopped.
#[cfg(feature = "standalone")]
pub(super) fn run(args: Vec<String>) -> Result<(), String> {
    let argv = std::iter::once("modal-resonator".to_string()).chain(args);
    if nice_plug::prelude::nice_export_standalone_with_args::<modal_resonator::ModalResonator, _>(
        argv,
    ) {
        Ok(())
    } else {
        Err("the standalone could not start an audio backend".to_string())
    }
}

/// Without the standalone feature there is nothing to play: say so.
#[cfg(not(feature = "standalone"))]
pub(super) fn run(_args: Vec<String>) -> Result<(), String> {
    let _ = <super::Cli as clap::CommandFactory>::command().print_help();
    Err("this build has no standalone player (build with the `standalone` feature)".to_string())
}
