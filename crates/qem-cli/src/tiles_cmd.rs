//! `qem tiles split | simplify | merge`: the tile pipeline as separate commands over
//! the files of one directory, so that a scheduler (a Slurm array, Kubernetes Jobs, a
//! shell loop) runs the tile jobs independently. The jobs themselves (the files, the
//! manifest, what "done" means, the options a tile takes) are
//! `qem_mesh::tiles::jobs`, which the Python package calls too, so both write the same
//! bytes; this module parses the arguments, draws the progress, prints the summary
//! lines and words the errors' remedies as commands to run.

use crate::failure::Failure;
use crate::options::SimplifyFlags;
use crate::progress::{bars_wanted, interrupted, simplify_bar, BarObserver, CtrlCObserver};
use clap::{Args, Subcommand};
use qem_mesh::tiles::jobs::{
    merge, split, tile_file, RefusedOption, Remedy, TileCount, TileDir, TileOptions, TileWork,
    TilesError, ATTRIBUTES_DROPPED,
};
use std::path::{Path, PathBuf};

/// Arguments of `qem tiles`.
#[derive(Args, Debug)]
pub struct TilesArgs {
    #[command(subcommand)]
    command: TilesCommand,
}

#[derive(Subcommand, Debug)]
enum TilesCommand {
    /// Cut a mesh into spatial tiles (files in DIR, with a manifest).
    Split(SplitArgs),
    /// Simplify the tiles not yet done (or one tile), their borders locked.
    Simplify(SimplifyTilesArgs),
    /// Join the simplified tiles into one mesh, welding their borders.
    Merge(MergeArgs),
}

/// Arguments of `qem tiles split`.
#[derive(Args, Debug)]
struct SplitArgs {
    /// Input mesh (.obj .ply .stl .off .gltf .glb, optionally .gz); streamed to a temporary directory in DIR (PLY, OFF, STL and OBJ without holding its triangles; glTF read whole first).
    input: PathBuf,
    /// Directory for the tiles and the manifest (created if missing).
    dir: PathBuf,
    /// At most this many triangles per tile [default: 1000000].
    #[arg(long, conflicts_with = "tiles", value_parser = parse_positive)]
    tile_triangles: Option<usize>,
    /// Cut into this many tiles (of equal triangle counts, within one) instead.
    #[arg(long, value_parser = parse_positive)]
    tiles: Option<usize>,
    /// No summary line; errors are still printed [default: off].
    #[arg(short, long)]
    quiet: bool,
}

/// Arguments of `qem tiles simplify`.
#[derive(Args, Debug)]
struct SimplifyTilesArgs {
    /// The directory `qem tiles split` wrote.
    dir: PathBuf,
    /// Simplify only this tile (0-based), e.g. `--tile $SLURM_ARRAY_TASK_ID`
    /// [default: every tile not yet done].
    #[arg(long)]
    tile: Option<usize>,
    /// The options of `qem simplify`; --ratio applies to each tile, whose border
    /// vertices are locked. --triangles, --lock and --cluster are refused.
    #[command(flatten)]
    flags: SimplifyFlags,
    /// No progress bar and no summary lines; errors are still printed [default: off].
    #[arg(short, long)]
    quiet: bool,
}

/// Arguments of `qem tiles merge`.
#[derive(Args, Debug)]
struct MergeArgs {
    /// The directory `qem tiles split` wrote and `qem tiles simplify` completed.
    dir: PathBuf,
    /// Output mesh; the format follows the extension (.obj .ply .stl .off .gltf .glb,
    /// optionally .gz).
    #[arg(short, long)]
    output: PathBuf,
    /// No summary line; errors are still printed [default: off].
    #[arg(short, long)]
    quiet: bool,
}

// `--tile-triangles`'s help gives the library's default in words.
const _: () = assert!(qem_mesh::tiles::jobs::DEFAULT_TILE_TRIANGLES == 1_000_000);

fn parse_positive(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if n > 0 => Ok(n),
        _ => Err(format!("`{s}` is not a whole number above 0")),
    }
}

/// Runs `qem tiles`.
pub fn run(args: &TilesArgs) -> Result<(), Failure> {
    match &args.command {
        TilesCommand::Split(a) => run_split(a),
        TilesCommand::Simplify(a) => run_simplify(a),
        TilesCommand::Merge(a) => run_merge(a),
    }
}

/// `error` as the command's failure, its remedy worded as the command to run on `dir`.
fn failure(error: TilesError, dir: &Path) -> Failure {
    let remedy = match error.remedy() {
        Some(Remedy::Split) => format!("; run qem tiles split INPUT {}", dir.display()),
        Some(Remedy::SimplifyTile(k)) => {
            format!("; run qem tiles simplify {} --tile {k}", dir.display())
        }
        _ => String::new(),
    };
    match error {
        TilesError::Cancelled => Failure::Interrupted,
        TilesError::Refused(option) => refused("qem tiles simplify", option),
        e => Failure::Failed(format!("{e}{remedy}")),
    }
}

/// The usage error for an option the tiles do not take, named by its flag, given to
/// `command` (`qem tiles simplify`, or `qem simplify --memory-budget`).
pub(crate) fn refused(command: &str, option: RefusedOption) -> Failure {
    let flag = match option {
        RefusedOption::TriangleTarget => "--triangles",
        RefusedOption::LockedVertices => "--lock",
        RefusedOption::Clustering => "--cluster",
        RefusedOption::VirtualPairs => "--pair-threshold",
        _ => "one of these options",
    };
    Failure::Usage(format!(
        "{command} does not take {flag}: {}",
        option.reason()
    ))
}

fn run_split(args: &SplitArgs) -> Result<(), Failure> {
    let count = match (args.tiles, args.tile_triangles) {
        (Some(n), _) => TileCount::Tiles(n),
        (None, Some(k)) => TileCount::MaxTriangles(k),
        (None, None) => TileCount::default(),
    };
    let manifest = split(&args.input, &args.dir, count, &mut CtrlCObserver)
        .map_err(|e| failure(e, &args.dir))?;
    if args.quiet {
        return Ok(());
    }
    if manifest.input.attributes_dropped {
        eprintln!(
            "qem: warning: {}: {ATTRIBUTES_DROPPED}",
            args.input.display()
        );
    }
    let counts = manifest.tiles.iter().map(|t| t.triangles);
    eprintln!(
        "{} → {}: {} tiles of {} to {} triangles ({} triangles, {} welded vertices)",
        args.input.display(),
        args.dir.display(),
        manifest.tiles.len(),
        counts.clone().min().unwrap_or(0),
        counts.max().unwrap_or(0),
        manifest.input.triangles,
        manifest.input.welded_vertices
    );
    Ok(())
}

fn run_simplify(args: &SimplifyTilesArgs) -> Result<(), Failure> {
    // --lock is refused before its file is read: reading it could only fail or be
    // wasted.
    let options = match args.flags.lock {
        Some(_) => Err(RefusedOption::LockedVertices),
        None => TileOptions::new(args.flags.options()?),
    }
    .map_err(|o| refused("qem tiles simplify", o))?;
    let dir = &args.dir;
    let tiles = TileDir::open(dir).map_err(|e| failure(e, dir))?;
    for k in tiles.select(args.tile).map_err(|e| failure(e, dir))? {
        if interrupted() {
            return Err(Failure::Interrupted);
        }
        let pending = match tiles.prepare(k, &options).map_err(|e| failure(e, dir))? {
            TileWork::Done(_) => {
                if !args.quiet {
                    eprintln!("tile {k}: done already");
                }
                continue;
            }
            TileWork::ToDo(pending) => pending,
        };
        if let Some(crowding) = pending.crowding().filter(|_| !args.quiet) {
            eprintln!("qem: warning: {crowding}");
        }
        let bar = simplify_bar(bars_wanted(args.quiet), &tile_file(k));
        let status = pending.run(&mut BarObserver::new(&bar));
        bar.finish_and_clear();
        let status = status.map_err(|e| failure(e, dir))?;
        if !args.quiet {
            eprintln!(
                "tile {k}: {} → {} triangles ({})",
                status.triangles_in, status.triangles_out, status.stop_reason
            );
        }
    }
    Ok(())
}

fn run_merge(args: &MergeArgs) -> Result<(), Failure> {
    let report =
        merge(&args.dir, &args.output, &mut CtrlCObserver).map_err(|e| failure(e, &args.dir))?;
    if !args.quiet {
        eprintln!(
            "{} → {}: {} tiles, {} → {} triangles, {} vertices",
            args.dir.display(),
            args.output.display(),
            report.tiles,
            report.triangles_in,
            report.triangles_out,
            report.vertices_out
        );
    }
    Ok(())
}
