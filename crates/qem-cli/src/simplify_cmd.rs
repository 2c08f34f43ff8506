//! `qem simplify`: one file in, one simplified file out, an optional JSON report.

use crate::report::{write_json_atomically, SimplifyJson};
use clap::Args;
use qem_mesh::io::{read_path, write_path};
use qem_mesh::simplify::{simplify, Length, SimplifyOptions, Target};
use std::path::PathBuf;
use std::time::Instant;

/// Arguments of `qem simplify`.
#[derive(Args, Debug)]
pub struct SimplifyArgs {
    /// Input mesh (.obj .ply .stl .off, optionally .gz).
    pub input: PathBuf,
    /// Output mesh; the format follows the extension (.obj .ply .stl .off).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Target as a fraction of the input's triangles, in (0, 1] [default: 0.5 when
    /// --triangles is not given].
    #[arg(long, conflicts_with = "triangles", value_parser = parse_ratio)]
    pub ratio: Option<f64>,
    /// Target triangle count.
    #[arg(long)]
    pub triangles: Option<usize>,
    /// Stop before the first contraction whose error would exceed this distance: a
    /// fraction of the input's bounding-box diagonal, or model units with --absolute
    /// [default: no bound].
    #[arg(long, value_parser = parse_non_negative)]
    pub max_error: Option<f64>,
    /// Unconnected vertex pairs closer than this may merge (virtual pairs): a fraction
    /// of the bounding-box diagonal, or model units with --absolute; 0 = edges only.
    #[arg(long, default_value_t = 0.0, value_parser = parse_non_negative)]
    pub pair_threshold: f64,
    /// Read --max-error and --pair-threshold in model units instead of fractions of the
    /// bounding-box diagonal.
    #[arg(long)]
    pub absolute: bool,
    /// Write a JSON report of the run here.
    #[arg(long)]
    pub report: Option<PathBuf>,
}

fn parse_ratio(s: &str) -> Result<f64, String> {
    let r: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if r > 0.0 && r <= 1.0 {
        Ok(r)
    } else {
        Err(format!(
            "{r} is outside (0, 1]; use e.g. 0.1 for 10% of the triangles"
        ))
    }
}

fn parse_non_negative(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if v >= 0.0 && v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{v} must be a finite number ≥ 0"))
    }
}

impl SimplifyArgs {
    fn length(&self, v: f64) -> Length {
        if self.absolute {
            Length::Absolute(v)
        } else {
            Length::DiagonalFraction(v)
        }
    }

    /// The library options these arguments ask for.
    pub fn options(&self) -> SimplifyOptions {
        let target = match (self.triangles, self.ratio) {
            (Some(n), _) => Target::Triangles(n),
            (None, Some(r)) => Target::Ratio(r),
            (None, None) => Target::Ratio(0.5),
        };
        SimplifyOptions::DEFAULT
            .with_target(target)
            .with_max_error(self.max_error.map(|e| self.length(e)))
            .with_pair_threshold(self.length(self.pair_threshold))
    }
}

/// Runs `qem simplify`; the error is the one-line message for stderr.
pub fn run(args: &SimplifyArgs) -> Result<(), String> {
    let clock = Instant::now();
    let loaded = read_path(&args.input).map_err(|e| e.to_string())?;
    let load = clock.elapsed();

    let clock = Instant::now();
    let result = simplify(&loaded.mesh, &args.options())
        .map_err(|e| format!("{}: {e}", args.input.display()))?;
    let simplify_time = clock.elapsed();

    let clock = Instant::now();
    write_path(&args.output, &result.mesh).map_err(|e| e.to_string())?;
    let write = clock.elapsed();

    if let Some(path) = &args.report {
        let json = SimplifyJson::new(
            &args.input,
            &args.output,
            &result.report,
            load,
            simplify_time,
            write,
        );
        write_json_atomically(path, &json)?;
    }
    Ok(())
}
