//! `qem tiles split | simplify | merge`: the tile pipeline as separate commands over
//! the files of one directory, so that a scheduler (a Slurm array, Kubernetes Jobs, a
//! shell loop) runs the tile jobs independently. The geometry (the cut, the border
//! vertices, the weld) is `qem_mesh::tiles`; this module keeps the files.
//!
//! The directory holds:
//! - `tiles.json`, the manifest: the input's name and size, its counts, how it was
//!   cut, and one entry per tile (triangle, vertex and border-vertex counts, the box of
//!   its triangle centroids, the size and CRC-32 of its file), with a `split_id` (a
//!   CRC-32 of all that) naming this split. `qem tiles split` writes it last, so a
//!   split that did not finish leaves none, and removes the old one first.
//! - `tile-NNNNN.ply`: tile NNNNN, binary PLY with its border vertices first (as many
//!   as the manifest's `border_vertices`).
//! - `tile-NNNNN.simplified.ply` and `tile-NNNNN.done.json`: the simplified tile
//!   (simplified with its border vertices and their neighbours locked,
//!   `Tile::locked_vertices`; its border vertices first again) and its status, each
//!   written atomically, the status
//!   after the tile. A tile counts as done only when its status names this split, this
//!   tile's file (size and CRC-32), the same options (a fingerprint) and a simplified
//!   file of the recorded size and CRC-32; anything else (no status: a job killed
//!   before it wrote one; a simplified file changed or cut short) is simplified again,
//!   giving the same bytes. One status file per tile, each job writing only its own
//!   tile's files, so jobs running at once never write the same file (two jobs on the
//!   same tile write the same bytes, each atomically).
//!
//! Nothing here holds the tiles together in memory except `merge`, which holds the
//! simplified mesh it writes; `split` reads the input whole (see `run_split`).

use crate::failure::Failure;
use crate::manifest::{fingerprint, OutputStamp};
use crate::options::SimplifyFlags;
use crate::progress::{bars_wanted, interrupted, simplify_bar, BarObserver};
use crate::report::write_json_atomically;
use clap::{Args, Subcommand};
use qem_mesh::io::{read_bytes, read_path, write_atomically, write_path, write_to, Format};
use qem_mesh::simplify::{simplify_owned, SimplifyError, StopReason, Target};
use qem_mesh::tiles::{Tile, Tiling, Welder};
use serde::{Deserialize, Serialize};
use std::io::{ErrorKind, Write};
use std::path::{Path, PathBuf};

/// The manifest's name inside the tile directory.
pub const MANIFEST_NAME: &str = "tiles.json";

/// The manifest's and the statuses' format version; another version is refused.
const VERSION: u32 = 1;

/// The default of `--tile-triangles`: a tile's simplification then peaks near 200 MB
/// (the engine holds about 200 bytes a triangle, BENCHMARKS.md).
const DEFAULT_TILE_TRIANGLES: usize = 1_000_000;

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
    /// Input mesh (.obj .ply .stl .off .gltf .glb, optionally .gz); read whole.
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

fn parse_positive(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if n > 0 => Ok(n),
        _ => Err(format!("`{s}` is not a whole number above 0")),
    }
}

/// The manifest, `tiles.json`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
struct Manifest {
    /// The format version ([`VERSION`]).
    qem_tiles: u32,
    /// A CRC-32 (hex) of the rest of the manifest: which split a status belongs to.
    split_id: String,
    input: InputJson,
    partition: PartitionJson,
    tiles: Vec<TileEntry>,
}

#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
struct InputJson {
    /// The input's file name (not its path, so the same file split from elsewhere
    /// gives the same manifest).
    name: String,
    size_bytes: u64,
    vertices: usize,
    triangles: usize,
    /// Vertices merged into another with a bit-identical position before the cut.
    welded_vertices: usize,
    /// Whether the input had attributes (UVs, normals, colours, materials), which the
    /// tiles do not carry.
    attributes_dropped: bool,
}

#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
struct PartitionJson {
    /// `kd-median`: halves (in proportion to the tile counts on each side) at the
    /// median triangle centroid along the axis of their largest spread.
    method: String,
    /// The tile count asked for (`--tiles`, or the triangles over `--tile-triangles`).
    tiles_requested: usize,
    /// The box of the welded mesh's vertices.
    bbox_min: [f64; 3],
    bbox_max: [f64; 3],
}

#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
struct TileEntry {
    index: usize,
    file: String,
    triangles: usize,
    vertices: usize,
    /// The first `border_vertices` vertices of the tile are used by other tiles too.
    border_vertices: usize,
    centroid_min: [f64; 3],
    centroid_max: [f64; 3],
    stamp: OutputStamp,
}

/// What `tile-NNNNN.done.json` says: that tile NNNNN of split `split_id` was
/// simplified with the options `options` into a file with `output_stamp`.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
struct Status {
    qem_tiles_status: u32,
    split_id: String,
    tile: usize,
    /// The tile file simplified (as the manifest lists it).
    input_stamp: OutputStamp,
    /// The fingerprint of the options and qem's version.
    options: String,
    output: String,
    output_stamp: OutputStamp,
    /// The first `border_vertices` vertices of the output are the tile's border ones.
    border_vertices: usize,
    triangles_in: usize,
    triangles_out: usize,
    stop_reason: String,
}

fn tile_name(k: usize) -> String {
    format!("tile-{k:05}.ply")
}

fn simplified_name(k: usize) -> String {
    format!("tile-{k:05}.simplified.ply")
}

fn status_name(k: usize) -> String {
    format!("tile-{k:05}.done.json")
}

/// Runs `qem tiles`.
pub fn run(args: &TilesArgs) -> Result<(), Failure> {
    match &args.command {
        TilesCommand::Split(a) => run_split(a),
        TilesCommand::Simplify(a) => run_simplify(a),
        TilesCommand::Merge(a) => run_merge(a),
    }
}

fn failed(path: &Path, message: impl std::fmt::Display) -> Failure {
    Failure::Failed(format!("{}: {message}", path.display()))
}

/// `bytes` written to `path` atomically.
fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), Failure> {
    write_atomically(path, |f| f.write_all(bytes)).map_err(|e| Failure::Failed(e.to_string()))
}

/// `mesh` as binary PLY bytes (the format of every tile file).
fn ply_bytes(mesh: &qem_mesh::IndexedMesh, path: &Path) -> Result<Vec<u8>, Failure> {
    let mut bytes = Vec::new();
    write_to(&mut bytes, mesh, Format::Ply).map_err(|e| failed(path, e))?;
    Ok(bytes)
}

/// Reads the input whole (the streaming readers give whole meshes, not a triangle at
/// a time, yet), welds it, cuts it, and writes the tiles and then the manifest.
fn run_split(args: &SplitArgs) -> Result<(), Failure> {
    let dir = &args.dir;
    std::fs::create_dir_all(dir).map_err(|e| failed(dir, format!("cannot create: {e}")))?;
    let _ = qem_mesh::io::remove_stale_temporaries(dir);
    // First, so that a split stopped half way leaves no manifest that could pass for
    // a finished one (or for the earlier split, whose tiles are being replaced).
    let manifest_path = dir.join(MANIFEST_NAME);
    match std::fs::remove_file(&manifest_path) {
        Err(e) if e.kind() != ErrorKind::NotFound => {
            return Err(failed(&manifest_path, format!("cannot remove: {e}")))
        }
        _ => {}
    }
    let size_bytes = std::fs::metadata(&args.input)
        .map_err(|e| failed(&args.input, format!("cannot read: {e}")))?
        .len();
    let loaded = read_path(&args.input).map_err(|e| Failure::Failed(e.to_string()))?;
    if interrupted() {
        return Err(Failure::Interrupted);
    }
    let mesh = loaded.mesh;
    let attributes_dropped = !mesh.attributes.is_empty();
    if attributes_dropped && !args.quiet {
        eprintln!(
            "qem: warning: {}: tiles carry positions only; its attributes (UVs, normals, \
             colours, materials) are left out",
            args.input.display()
        );
    }
    let triangles = mesh.triangle_count();
    let requested = match (args.tiles, args.tile_triangles) {
        (Some(n), _) => n,
        (None, k) => triangles.div_ceil(k.unwrap_or(DEFAULT_TILE_TRIANGLES)),
    };
    let input = InputJson {
        name: args
            .input
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        size_bytes,
        vertices: mesh.vertex_count(),
        triangles,
        welded_vertices: 0,
        attributes_dropped,
    };
    let tiling = Tiling::new(mesh, requested);
    let input = InputJson {
        welded_vertices: tiling.welded_vertices(),
        ..input
    };
    let (bbox_min, bbox_max) = tiling
        .welded_mesh()
        .bounding_box()
        .unwrap_or(([0.0; 3], [0.0; 3]));
    let mut tiles = Vec::with_capacity(tiling.len());
    for k in 0..tiling.len() {
        if interrupted() {
            return Err(Failure::Interrupted);
        }
        let tile = tiling.tile(k);
        let path = dir.join(tile_name(k));
        let bytes = ply_bytes(&tile.mesh, &path)?;
        write_bytes(&path, &bytes)?;
        let (centroid_min, centroid_max) = tiling.centroid_box(k);
        tiles.push(TileEntry {
            index: k,
            file: tile_name(k),
            triangles: tile.mesh.triangle_count(),
            vertices: tile.mesh.vertex_count(),
            border_vertices: tile.border_vertices,
            centroid_min,
            centroid_max,
            stamp: OutputStamp::of_bytes(&bytes),
        });
    }
    remove_other_tiles(dir, tiles.len());
    let mut manifest = Manifest {
        qem_tiles: VERSION,
        split_id: String::new(),
        input,
        partition: PartitionJson {
            method: "kd-median".to_string(),
            tiles_requested: requested,
            bbox_min,
            bbox_max,
        },
        tiles,
    };
    manifest.split_id = split_id(&manifest);
    write_json_atomically(&manifest_path, &manifest).map_err(Failure::Failed)?;
    if !args.quiet {
        let counts = manifest.tiles.iter().map(|t| t.triangles);
        eprintln!(
            "{} → {}: {} tiles of {} to {} triangles ({} triangles, {} welded vertices)",
            args.input.display(),
            dir.display(),
            manifest.tiles.len(),
            counts.clone().min().unwrap_or(0),
            counts.max().unwrap_or(0),
            triangles,
            manifest.input.welded_vertices
        );
    }
    Ok(())
}

/// The CRC-32 (hex) of the manifest with an empty `split_id`.
fn split_id(manifest: &Manifest) -> String {
    let blank = Manifest {
        split_id: String::new(),
        ..manifest.clone()
    };
    fingerprint(&blank, &"split")
}

/// Removes the tile files (`tile-NNNNN.*` of the three kinds this module writes) of
/// tiles numbered `count` or more: an earlier split's, into more tiles. Best effort:
/// the manifest says which tiles exist, so one left behind is never read.
fn remove_other_tiles(dir: &Path, count: usize) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name();
        let Some(name) = name.to_str() else { continue };
        let Some(number) = name.strip_prefix("tile-").and_then(|r| r.get(..5)) else {
            continue;
        };
        let Ok(k) = number.parse::<usize>() else {
            continue;
        };
        let ours = [tile_name(k), simplified_name(k), status_name(k)];
        if k >= count && ours.iter().any(|o| o == name) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Reads and checks `DIR/tiles.json`.
fn read_manifest(dir: &Path) -> Result<Manifest, Failure> {
    let path = dir.join(MANIFEST_NAME);
    if !dir.is_dir() {
        return Err(failed(
            dir,
            "no such directory (run qem tiles split INPUT DIR first)",
        ));
    }
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) if e.kind() == ErrorKind::NotFound => {
            return Err(failed(
                &path,
                "missing: this is not a tile directory, or its split did not finish \
                 (run qem tiles split INPUT DIR)",
            ))
        }
        Err(e) => return Err(failed(&path, format!("cannot read: {e}"))),
    };
    let manifest: Manifest = serde_json::from_str(&text)
        .map_err(|e| failed(&path, format!("not a tile manifest: {e}")))?;
    let corrupt = |why: String| failed(&path, format!("corrupt tile manifest: {why}"));
    if manifest.qem_tiles != VERSION {
        return Err(corrupt(format!(
            "version {} (this qem reads version {VERSION}; split again)",
            manifest.qem_tiles
        )));
    }
    if manifest.tiles.is_empty() {
        return Err(corrupt("no tiles".to_string()));
    }
    for (k, t) in manifest.tiles.iter().enumerate() {
        if t.index != k || t.file != tile_name(k) || t.border_vertices > t.vertices {
            return Err(corrupt(format!("entry {k} is not tile {k}")));
        }
    }
    Ok(manifest)
}

/// Reads `path` whole, naming it in the error.
fn read_file(path: &Path) -> Result<Vec<u8>, Failure> {
    std::fs::read(path).map_err(|e| failed(path, format!("cannot read: {e}")))
}

/// Reads `path`'s status; `None` when there is none or it does not parse (a file that
/// is not one of ours: it is then written anew).
fn read_status(path: &Path) -> Option<Status> {
    let text = std::fs::read_to_string(path).ok()?;
    serde_json::from_str::<Status>(&text)
        .ok()
        .filter(|s| s.qem_tiles_status == VERSION)
}

/// Whether tile `k` is done for `manifest` with the options `options`.
fn is_done(dir: &Path, manifest: &Manifest, k: usize, options: &str) -> bool {
    let Some(status) = read_status(&dir.join(status_name(k))) else {
        return false;
    };
    status.split_id == manifest.split_id
        && status.tile == k
        && status.input_stamp == manifest.tiles[k].stamp
        && status.options == options
        && status.output == simplified_name(k)
        && OutputStamp::of(&dir.join(simplified_name(k))) == Some(status.output_stamp)
}

fn run_simplify(args: &SimplifyTilesArgs) -> Result<(), Failure> {
    let refused = [
        (args.flags.triangles.is_some(), "--triangles"),
        (args.flags.lock.is_some(), "--lock"),
        (args.flags.cluster, "--cluster"),
        // A virtual pair could join a border vertex to a vertex past its locked
        // neighbours (see `Tile::locked_vertices`), and the sides would overlap.
        (args.flags.pair_threshold > 0.0, "--pair-threshold"),
    ];
    if let Some((_, flag)) = refused.iter().find(|(given, _)| *given) {
        return Err(Failure::Usage(format!(
            "qem tiles simplify does not take {flag}: each tile is simplified by --ratio \
             with its border vertices locked (clustering would not keep them, and \
             virtual pairs would reach past them)"
        )));
    }
    let manifest = read_manifest(&args.dir)?;
    let options = args.flags.options()?;
    let print = fingerprint(&options, &"tiles/ply");
    let tiles: Vec<usize> = match args.tile {
        Some(k) if k >= manifest.tiles.len() => {
            return Err(Failure::Failed(format!(
                "{}: there is no tile {k}: the split has tiles 0 to {}",
                args.dir.join(MANIFEST_NAME).display(),
                manifest.tiles.len() - 1
            )))
        }
        Some(k) => vec![k],
        None => (0..manifest.tiles.len()).collect(),
    };
    // Only temporaries of writers that are gone: other jobs may be writing now.
    let _ = qem_mesh::io::remove_stale_temporaries(&args.dir);
    for k in tiles {
        if interrupted() {
            return Err(Failure::Interrupted);
        }
        if is_done(&args.dir, &manifest, k, &print) {
            if !args.quiet {
                eprintln!("tile {k}: done already");
            }
            continue;
        }
        let status = simplify_tile(args, &manifest, k, &options, &print)?;
        if !args.quiet {
            eprintln!(
                "tile {k}: {} → {} triangles ({})",
                status.triangles_in, status.triangles_out, status.stop_reason
            );
        }
    }
    Ok(())
}

/// Simplifies tile `k` with its border locked; writes the simplified tile, then its
/// status.
fn simplify_tile(
    args: &SimplifyTilesArgs,
    manifest: &Manifest,
    k: usize,
    options: &qem_mesh::simplify::SimplifyOptions,
    print: &str,
) -> Result<Status, Failure> {
    let dir = &args.dir;
    let entry = &manifest.tiles[k];
    let path = dir.join(tile_name(k));
    let bytes = read_file(&path)?;
    let input_stamp = OutputStamp::of_bytes(&bytes);
    if input_stamp != entry.stamp {
        return Err(failed(
            &path,
            format!(
                "not the tile {} lists (its size or CRC-32 differ): a tile of another \
                 split, or changed since; run qem tiles split again",
                dir.join(MANIFEST_NAME).display()
            ),
        ));
    }
    let mesh = read_bytes(&bytes, Format::Ply)
        .map_err(|e| failed(&path, e))?
        .mesh;
    drop(bytes);
    let tile = Tile {
        border_vertices: entry.border_vertices.min(mesh.vertex_count()),
        mesh,
    };
    let border_positions = tile.mesh.positions[..tile.border_vertices].to_vec();
    let triangles_in = tile.mesh.triangle_count();
    let locked = tile.locked_vertices();
    if !args.quiet {
        warn_crowded(k, locked.len(), triangles_in, options.target);
    }
    let locked = options.clone().with_locked_vertices(locked);
    let mesh = tile.mesh;
    let bar = simplify_bar(bars_wanted(args.quiet), &tile_name(k));
    let result = simplify_owned(mesh, &locked, &mut BarObserver::new(&bar));
    bar.finish_and_clear();
    let result = result.map_err(|e| match e {
        SimplifyError::Cancelled { .. } => Failure::Interrupted,
        e => failed(&path, e),
    })?;
    if result.report.stop_reason == StopReason::Cancelled || interrupted() {
        return Err(Failure::Interrupted);
    }
    let stop_reason = result.report.stop_reason.as_str().to_string();
    let tile = Tile::border_first(&border_positions, result.mesh);
    let out_path = dir.join(simplified_name(k));
    let out = ply_bytes(&tile.mesh, &out_path)?;
    write_bytes(&out_path, &out)?;
    let status = Status {
        qem_tiles_status: VERSION,
        split_id: manifest.split_id.clone(),
        tile: k,
        input_stamp,
        options: print.to_string(),
        output: simplified_name(k),
        output_stamp: OutputStamp::of_bytes(&out),
        border_vertices: tile.border_vertices,
        triangles_in,
        triangles_out: tile.mesh.triangle_count(),
        stop_reason,
    };
    write_json_atomically(&dir.join(status_name(k)), &status).map_err(Failure::Failed)?;
    Ok(status)
}

/// Warns when tile `k`'s `locked` vertices (its border and their neighbours) leave
/// little room for its target: a tile simplified to fewer triangles than about twice
/// its locked vertices keeps its border strip and little more than long triangles
/// spanning from border to border, far from the surface (BENCHMARKS.md, "Tiles": the
/// dragon at ratio 0.01 in 8 tiles against 2).
fn warn_crowded(k: usize, locked: usize, triangles: usize, target: Target) {
    let target = match target {
        Target::Ratio(r) => (r * triangles as f64) as usize,
        Target::Triangles(n) => n,
        Target::None => return,
    };
    if target < 2 * locked {
        eprintln!(
            "qem: warning: tile {k}: its {locked} locked vertices (its border and their \
             neighbours) leave little room for {target} triangles, so the error near its \
             borders will be large; split into larger tiles (--tile-triangles) or use a \
             higher --ratio"
        );
    }
}

fn run_merge(args: &MergeArgs) -> Result<(), Failure> {
    let dir = &args.dir;
    Format::from_path(&args.output).map_err(|e| failed(&args.output, e))?;
    let manifest = read_manifest(dir)?;
    // Every status first: a missing tile is found before any mesh is read.
    let mut statuses = Vec::with_capacity(manifest.tiles.len());
    for (k, entry) in manifest.tiles.iter().enumerate() {
        let path = dir.join(status_name(k));
        let again = format!("run qem tiles simplify {} --tile {k}", dir.display());
        if !path.exists() {
            return Err(failed(
                &path,
                format!("missing: tile {k} is not simplified yet; {again}"),
            ));
        }
        let status = read_status(&path)
            .ok_or_else(|| failed(&path, format!("not a tile status; {again}")))?;
        if status.split_id != manifest.split_id
            || status.tile != k
            || status.input_stamp != entry.stamp
        {
            return Err(failed(
                &path,
                format!("tile {k} was simplified for another split; {again}"),
            ));
        }
        if let Some(first) = statuses.first().map(|s: &Status| &s.options) {
            if *first != status.options {
                return Err(failed(
                    &path,
                    format!(
                        "tile {k} was simplified with other options than tile 0; \
                         simplify them all with the same options"
                    ),
                ));
            }
        }
        statuses.push(status);
    }
    let _ = qem_mesh::io::remove_stale_temporaries(&qem_mesh::io::directory_of(&args.output));
    let mut welder = Welder::default();
    for (k, status) in statuses.iter().enumerate() {
        if interrupted() {
            return Err(Failure::Interrupted);
        }
        let path = dir.join(simplified_name(k));
        let bytes = read_file(&path)?;
        if OutputStamp::of_bytes(&bytes) != status.output_stamp {
            return Err(failed(
                &path,
                format!(
                    "does not match its status (changed or cut short); run qem tiles \
                     simplify {} --tile {k}",
                    dir.display()
                ),
            ));
        }
        let mesh = read_bytes(&bytes, Format::Ply)
            .map_err(|e| failed(&path, e))?
            .mesh;
        if status.border_vertices > mesh.vertex_count() {
            return Err(failed(
                &path,
                "has fewer vertices than its status's border vertices",
            ));
        }
        welder.push(&Tile {
            mesh,
            border_vertices: status.border_vertices,
        });
    }
    let merged = welder.finish();
    merged
        .validate()
        .map_err(|e| failed(&args.output, format!("the merged mesh is not valid: {e}")))?;
    write_path(&args.output, &merged).map_err(|e| Failure::Failed(e.to_string()))?;
    if !args.quiet {
        let triangles_in: usize = statuses.iter().map(|s| s.triangles_in).sum();
        eprintln!(
            "{} → {}: {} tiles, {} → {} triangles, {} vertices",
            dir.display(),
            args.output.display(),
            statuses.len(),
            triangles_in,
            merged.triangle_count(),
            merged.vertex_count()
        );
    }
    Ok(())
}
