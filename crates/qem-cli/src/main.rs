//! The `qem` command: quadric mesh simplification of messy meshes.
//!
//! Exit codes: 0 on success, 1 when the work failed (the message names the file and
//! the cause; for `batch`, when any file failed), 2 on a usage error, 130 when Ctrl-C
//! stopped the run (no partial output is left behind).
#![forbid(unsafe_code)]

mod batch_cmd;
mod failure;
mod info_cmd;
mod inputs;
mod manifest;
mod materials;
mod measure_cmd;
mod options;
mod progress;
mod report;
mod simplify_cmd;
mod tiles_cmd;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Quadric-error-metric simplification of triangle meshes (OBJ, PLY, STL, OFF, glTF;
/// .gz input).
#[derive(Parser, Debug)]
#[command(name = "qem", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simplify one mesh file (or write a chain of levels of detail with --lods).
    Simplify(simplify_cmd::SimplifyArgs),
    /// Metro-style distance between two meshes (Hausdorff, mean, RMS; % of A's diagonal).
    Measure(measure_cmd::MeasureArgs),
    /// Simplify many files in parallel into one directory, with one report.
    Batch(batch_cmd::BatchArgs),
    /// Count what is messy about a mesh: parts, borders, non-manifold places,
    /// duplicate and degenerate faces, bounding box.
    #[command(after_long_help = info_cmd::DEFINITIONS)]
    Info(info_cmd::InfoArgs),
    /// The tile pipeline as separate jobs: `split` a mesh into spatial tiles,
    /// `simplify` each (borders locked), `merge` them back (borders welded).
    Tiles(tiles_cmd::TilesArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    progress::catch_ctrl_c();
    let result = match cli.command {
        Command::Simplify(args) => simplify_cmd::run(&args),
        Command::Measure(args) => measure_cmd::run(&args).map_err(failure::Failure::Failed),
        Command::Batch(args) => batch_cmd::run(&args),
        Command::Info(args) => info_cmd::run(&args),
        Command::Tiles(args) => tiles_cmd::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => failure.exit(),
    }
}
