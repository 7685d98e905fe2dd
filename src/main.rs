//! The `modal-resonator` command: plays the instrument standalone, renders banks offline, makes
//! them from recordings and analytic objects, compresses, inspects and validates them.
//! The subcommands are in `cli/`, thin over the library.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
