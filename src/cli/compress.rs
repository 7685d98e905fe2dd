//! `modal-resonator compress`: a bank made cheaper by merging modes a listener cannot tell apart
//! and dropping weak ones (the library's `authoring::compress`).

use std::path::{Path, PathBuf};

use clap::Args;

use modal_resonator::authoring::compress::{compress_bank, CompressOptions, DEFAULT_DROP_BELOW_DB};

use super::{check_output, load_bank, output_name, save_bank_output, say};

/// Arguments of `compress`.
#[derive(Debug, Args)]
pub(super) struct CompressArgs {
    /// Bank file (JSON) or factory bank name.
    bank: String,
    /// Bank file (JSON) to write; - writes it to standard output.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Modes closer than this many frequency difference limens merge (about 5 Hz at 2 kHz and
    /// 80 Hz at 8 kHz for 1); 0 merges nothing.
    #[arg(long, default_value_t = 1.0, value_name = "SCALE")]
    limen_scale: f64,
    /// Modes whose largest gain over the positions is further below the strongest mode's than
    /// this are dropped.
    #[arg(long, default_value_t = DEFAULT_DROP_BELOW_DB, allow_hyphen_values = true, value_name = "DB")]
    drop_below_db: f64,
    /// Drop no mode for its level (only merge).
    #[arg(long, conflicts_with = "drop_below_db")]
    keep_weak: bool,
}

/// Compresses, saves atomically and prints what was removed. Nothing is written on failure.
pub(super) fn run(args: &CompressArgs) -> Result<(), String> {
    let loaded = load_bank(&args.bank)?;
    let inputs: Vec<(&str, &Path)> = loaded
        .file
        .iter()
        .map(|f| ("the bank", f.as_path()))
        .collect();
    check_output("-o", &args.output, &inputs)?;
    let bank = loaded.bank;
    let options = CompressOptions {
        limen_scale: args.limen_scale,
        drop_below_db: (!args.keep_weak).then_some(args.drop_below_db),
    };
    let (compressed, report) = compress_bank(&bank, &options).map_err(|e| e.to_string())?;
    save_bank_output(&compressed, &args.output)?;
    say(&args.output, &report.to_string());
    say(
        &args.output,
        &format!(
            "{}: {} modes, {} positions",
            output_name(&args.output),
            compressed.modes.len(),
            compressed.positions.len()
        ),
    );
    Ok(())
}
