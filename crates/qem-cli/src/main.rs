//! The `qem` command: quadric mesh simplification of messy meshes.
//!
//! Exit codes: 0 on success, 1 when the work failed (the message names the file and
//! the cause), 2 on a usage error (from the argument parser).
#![forbid(unsafe_code)]

mod measure_cmd;
mod report;
mod simplify_cmd;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Quadric-error-metric simplification of triangle meshes (OBJ, PLY, STL, OFF; .gz input).
#[derive(Parser, Debug)]
#[command(name = "qem", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simplify one mesh file.
    Simplify(simplify_cmd::SimplifyArgs),
    /// Metro-style distance between two meshes (Hausdorff, mean, RMS; % of A's diagonal).
    Measure(measure_cmd::MeasureArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Simplify(args) => simplify_cmd::run(&args),
        Command::Measure(args) => measure_cmd::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("qem: error: {message}");
            ExitCode::from(1)
        }
    }
}
