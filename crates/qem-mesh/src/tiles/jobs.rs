//! The tile pipeline as jobs over the files of one directory: [`split`] a mesh into
//! tiles, simplify each tile on its own ([`TileDir::simplify_tile`]), [`merge`] the
//! simplified tiles. Any scheduler can run the tile jobs, each in its own process and
//! on any machine that sees the directory: `qem tiles` (a Slurm array, Kubernetes Jobs,
//! a shell loop) and the Python package (`qem.tiles`, and `qem.distributed` on Dask)
//! both call these functions, so they write the same files, byte for byte.
//!
//! The directory holds:
//! - `tiles.json` ([`MANIFEST_NAME`]), the [`Manifest`]: the input's name and size, its
//!   counts, how it was cut, and one entry per tile (triangle, vertex and
//!   border-vertex counts, the box of its triangle centroids, the size and CRC-32 of
//!   its file), with a `split_id` (a CRC-32 of all that) naming this split. [`split`]
//!   writes it last, so a split that did not finish leaves none, and removes the old
//!   one first.
//! - `tile-NNNNN.ply` ([`tile_file`]): tile NNNNN, binary PLY with its border vertices
//!   first (as many as its entry's `border_vertices`).
//! - `tile-NNNNN.simplified.ply`, `tile-NNNNN.quadrics` and `tile-NNNNN.done.json`
//!   ([`simplified_file`], [`quadrics_file`], [`status_file`]): the simplified tile
//!   (simplified with its border vertices and their neighbours locked,
//!   [`Tile::locked_vertices`]; its border vertices first again), its vertices'
//!   quadrics (for a run that goes on from the merged tiles, as
//!   [`super::budget`]'s does), and its [`TileStatus`], each written atomically, the
//!   status last.
//!
//! **What "done" means.** A tile is done only when its status names this split, this
//! tile's file (size and CRC-32), the same options (a [`fingerprint`] of them and of
//! qem's version) and a simplified file and quadrics of the recorded sizes and
//! CRC-32s. Anything else (no status: a job killed before it wrote one; a simplified
//! file changed or cut short; other options) is simplified again, giving the same
//! bytes. One status file
//! per tile, each job writing only its own tile's files, so jobs running at once never
//! write the same file; two jobs on the same tile write the same bytes, each
//! atomically. A job is therefore idempotent: run again, or retried by a scheduler, it
//! leaves the same files. It removes only the temporary files of its own tile's killed
//! writers, since other tiles' writers may be alive on machines whose processes it
//! cannot see (two jobs of one tile at once on two machines still leave the same
//! files, but one may fail, having had its unfinished temporary file taken for a killed
//! writer's).
//!
//! Nothing here holds the tiles together in memory except [`merge`], which holds the
//! simplified mesh it writes. [`split`] streams its input to disk as it reads it and
//! builds the tiles from there one at a time (`tiles::split`): it holds the input's
//! vertices while reading (PLY, OFF and OBJ; STL none; glTF is read whole), then one
//! tile.
//!
//! Errors are [`TilesError`]s that name the file; those a later step fixes say which
//! ([`TilesError::remedy`]), for the caller to word in its own terms (a command line,
//! a Python call).
//!
//! ```
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use qem_mesh::simplify::{NoObserver, SimplifyOptions, Target};
//! use qem_mesh::tiles::jobs::{merge, split, TileCount, TileDir, TileOptions};
//!
//! // A 12 x 12 grid of squares (288 triangles), as a PLY file.
//! let n = 12u32;
//! let positions = (0..=n)
//!     .flat_map(|y| (0..=n).map(move |x| [x as f64, y as f64, ((x * y) % 3) as f64 * 0.1]))
//!     .collect();
//! let triangles = (0..n)
//!     .flat_map(|y| (0..n).map(move |x| y * (n + 1) + x))
//!     .flat_map(|v| [[v, v + 1, v + n + 2], [v, v + n + 2, v + n + 1]])
//!     .collect();
//! let scratch = tempfile::tempdir()?;
//! let input = scratch.path().join("grid.ply");
//! qem_mesh::io::write_path(&input, &qem_mesh::IndexedMesh::new(positions, triangles))?;
//!
//! let dir = scratch.path().join("tiles");
//! let manifest = split(&input, &dir, TileCount::Tiles(3), &mut NoObserver)?;
//! assert_eq!(manifest.tiles.len(), 3);
//!
//! let options = TileOptions::new(SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.5)))?;
//! let tiles = TileDir::open(&dir)?;
//! for k in 0..tiles.len() {
//!     let outcome = tiles.simplify_tile(k, &options, &mut NoObserver)?;
//!     assert!(!outcome.already_done);
//! }
//! // Run again (as a retried job would be): nothing to do, nothing rewritten.
//! assert!(tiles.simplify_tile(1, &options, &mut NoObserver)?.already_done);
//!
//! let report = merge(&dir, &scratch.path().join("grid-half.ply"), &mut NoObserver)?;
//! assert_eq!(report.tiles, 3);
//! assert!(report.triangles_out < 288);
//! # Ok(()) }
//! ```

use super::split::{remove_stale_scratch, Spill, Spilled};
use super::{Tile, Welder};
use crate::io::{
    directory_of, fingerprint, read_bytes, remove_stale_temporaries, remove_stale_temporaries_of,
    stream_path, write_atomically, write_json_atomically, write_path, write_to, Format, IoError,
    OutputStamp, Streamed, TriangleSink,
};
use crate::simplify::{
    simplify_carrying, CarriedQuadrics, Length, Method, Observer, SimplifyError, SimplifyOptions,
    StopReason, Target,
};
use crate::{IndexedMesh, InputError};
use qem_core::{DVec3, Quadric};
use serde::{Deserialize, Serialize};
use std::io::{ErrorKind, Write};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// The manifest's name inside the tile directory.
pub const MANIFEST_NAME: &str = "tiles.json";

/// The manifest's and the statuses' format version; another version is refused.
const VERSION: u32 = 2;

/// The default of [`TileCount::MaxTriangles`]: a tile's simplification then peaks near
/// 200 MB (the engine holds about 200 bytes a triangle, BENCHMARKS.md).
pub const DEFAULT_TILE_TRIANGLES: usize = 1_000_000;

/// What [`split`] warns of when the input has attributes, after the input's name.
pub const ATTRIBUTES_DROPPED: &str =
    "tiles carry positions only; its attributes (UVs, normals, colours, materials) are left out";

/// The name of tile `k`'s file: `tile-NNNNN.ply`.
///
/// ```
/// assert_eq!(qem_mesh::tiles::jobs::tile_file(7), "tile-00007.ply");
/// ```
pub fn tile_file(k: usize) -> String {
    format!("tile-{k:05}.ply")
}

/// The name of tile `k`'s simplified file: `tile-NNNNN.simplified.ply`.
pub fn simplified_file(k: usize) -> String {
    format!("tile-{k:05}.simplified.ply")
}

/// The name of tile `k`'s quadrics: `tile-NNNNN.quadrics`. Each vertex's quadric of
/// the simplified tile, in world units about the split's
/// [`Manifest::quadric_origin`] ([`qem_core::Frame::quadric_to_world`]): what its
/// vertex stands for of the tile's input surface. The file is [`QUADRICS_MAGIC`], the
/// vertex count (a little-endian `u64`), the origin (three little-endian `f64`s), then
/// the ten entries of each quadric ([`Quadric::entries`], little-endian `f64`s), in
/// the simplified file's vertex order.
pub fn quadrics_file(k: usize) -> String {
    format!("tile-{k:05}.quadrics")
}

/// The first bytes of a [`quadrics_file`].
pub const QUADRICS_MAGIC: &[u8; 16] = b"qem quadrics v1\n";

/// The bytes of a [`quadrics_file`] holding `quadrics` about `origin`.
fn quadrics_bytes(quadrics: &[Quadric], origin: DVec3) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(QUADRICS_HEADER + 80 * quadrics.len());
    bytes.extend_from_slice(QUADRICS_MAGIC);
    bytes.extend_from_slice(&(quadrics.len() as u64).to_le_bytes());
    for e in origin.to_array() {
        bytes.extend_from_slice(&e.to_le_bytes());
    }
    for q in quadrics {
        for e in q.entries() {
            bytes.extend_from_slice(&e.to_le_bytes());
        }
    }
    bytes
}

/// The bytes of a [`quadrics_file`] before its quadrics.
const QUADRICS_HEADER: usize = 16 + 8 + 24;

/// The quadrics of a [`quadrics_file`]'s `bytes`, when they hold `vertices` of them
/// about `origin` (else `None`).
fn quadrics_of(bytes: &[u8], vertices: usize, origin: DVec3) -> Option<Vec<Quadric>> {
    let rest = bytes.strip_prefix(QUADRICS_MAGIC)?;
    let (count, rest) = rest.split_first_chunk::<8>()?;
    let (written_origin, entries) = rest.split_first_chunk::<24>()?;
    let origin_bytes: Vec<u8> = (origin.to_array().iter())
        .flat_map(|e| e.to_le_bytes())
        .collect();
    if u64::from_le_bytes(*count) != vertices as u64
        || written_origin[..] != origin_bytes[..]
        || entries.len() != 80 * vertices
    {
        return None;
    }
    let quadrics = entries.chunks_exact(80).map(|quadric| {
        let mut e = [0.0; 10];
        for (e, bytes) in e.iter_mut().zip(quadric.chunks_exact(8)) {
            *e = f64::from_le_bytes(bytes.try_into().expect("chunks of 8"));
        }
        Quadric::from_entries(e)
    });
    Some(quadrics.collect())
}

/// The name of tile `k`'s status: `tile-NNNNN.done.json`.
pub fn status_file(k: usize) -> String {
    format!("tile-{k:05}.done.json")
}

/// How finely [`split`] cuts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TileCount {
    /// At most this many triangles per tile: the triangles over this, rounded up,
    /// tiles (0 is taken as 1). Past [`SAMPLE_CAP`](super::SAMPLE_CAP) triangles the
    /// cut is made from a sample of the centroids, and a tile may hold a fraction of a
    /// percent more (0.2% in a 2.3M-triangle test).
    MaxTriangles(usize),
    /// This many tiles (at least 1, at most one per triangle), of equal triangle
    /// counts within one (within a fraction of a percent past
    /// [`SAMPLE_CAP`](super::SAMPLE_CAP) triangles).
    Tiles(usize),
}

impl Default for TileCount {
    /// [`TileCount::MaxTriangles`] of [`DEFAULT_TILE_TRIANGLES`].
    fn default() -> Self {
        TileCount::MaxTriangles(DEFAULT_TILE_TRIANGLES)
    }
}

impl TileCount {
    /// The number of tiles to cut `triangles` triangles into.
    fn tiles_for(self, triangles: usize) -> usize {
        match self {
            TileCount::Tiles(n) => n,
            TileCount::MaxTriangles(k) => triangles.div_ceil(k.max(1)),
        }
    }
}

// The names of the four manifest types below are part of every `split_id`, which is a
// fingerprint of the manifest's `Debug` form: renaming one would give every split a
// new id (and mark every tile of an existing directory as not done).

/// The manifest, `tiles.json`: what [`split`] wrote. Fields in file order.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct Manifest {
    /// The format version (2).
    pub qem_tiles: u32,
    /// A CRC-32 (8 hex digits) of the rest of the manifest: which split a status
    /// belongs to.
    pub split_id: String,
    /// The input mesh.
    pub input: InputJson,
    /// How it was cut.
    pub partition: PartitionJson,
    /// One entry per tile, tile `k` at index `k`.
    pub tiles: Vec<TileEntry>,
}

impl Manifest {
    /// The point the tiles' quadrics are about ([`quadrics_file`]): the centre of the
    /// box of every tile's centroids. Near the mesh, so that the quadrics keep their
    /// precision whatever its coordinates; from the manifest, so that every tile job
    /// and the merge find the same one.
    pub fn quadric_origin(&self) -> DVec3 {
        if self.tiles.is_empty() {
            return DVec3::ZERO;
        }
        let corners = (self.tiles.iter()).flat_map(|t| [t.centroid_min, t.centroid_max]);
        let (lo, hi) = super::bounds(corners);
        DVec3::from_array(lo) * 0.5 + DVec3::from_array(hi) * 0.5
    }
}

/// The input of a split, as its manifest describes it.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct InputJson {
    /// The input's file name (not its path, so the same file split from elsewhere
    /// gives the same manifest).
    pub name: String,
    /// The input file's size in bytes.
    pub size_bytes: u64,
    /// Its vertices, as read.
    pub vertices: usize,
    /// Its triangles, as read (polygons split into triangles).
    pub triangles: usize,
    /// Vertices not kept as such: merged into another with a bit-identical position
    /// (`-0.0` as `+0.0`), or used by no triangle (the input's vertices less the
    /// distinct positions its triangles use).
    pub welded_vertices: usize,
    /// Whether the input had attributes (UVs, normals, colours, materials), which the
    /// tiles do not carry.
    pub attributes_dropped: bool,
}

/// How a split cut its input.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PartitionJson {
    /// `kd-median`: halves (in proportion to the tile counts on each side) at the
    /// median triangle centroid along the axis of their largest spread; the median of
    /// a sample of the centroids, every one up to 2^20 triangles
    /// ([`SAMPLE_CAP`](super::SAMPLE_CAP)), every `2^k`-th beyond.
    pub method: String,
    /// The tile count asked for ([`TileCount::Tiles`], or the triangles over
    /// [`TileCount::MaxTriangles`]).
    pub tiles_requested: usize,
    /// The smallest corner of the box of the welded mesh's vertices.
    pub bbox_min: [f64; 3],
    /// The largest corner of that box.
    pub bbox_max: [f64; 3],
}

/// One tile, as its manifest lists it.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct TileEntry {
    /// The tile's number, its index in [`Manifest::tiles`].
    pub index: usize,
    /// Its file, [`tile_file`] of `index`.
    pub file: String,
    /// Its triangles.
    pub triangles: usize,
    /// Its vertices.
    pub vertices: usize,
    /// The first `border_vertices` vertices of the tile are used by other tiles too.
    pub border_vertices: usize,
    /// The smallest corner of the box of its triangles' centroids.
    pub centroid_min: [f64; 3],
    /// The largest corner of that box.
    pub centroid_max: [f64; 3],
    /// Its file's size and CRC-32.
    pub stamp: OutputStamp,
}

/// What `tile-NNNNN.done.json` says: that tile NNNNN of split `split_id` was
/// simplified with the options `options` into a file with `output_stamp`. Fields in
/// file order.
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct TileStatus {
    /// The format version (2).
    pub qem_tiles_status: u32,
    /// The split the tile belongs to ([`Manifest::split_id`]).
    pub split_id: String,
    /// The tile's number.
    pub tile: usize,
    /// The tile file simplified (as the manifest lists it).
    pub input_stamp: OutputStamp,
    /// The fingerprint of the options and qem's version ([`TileOptions::fingerprint`]).
    pub options: String,
    /// The simplified file's name ([`simplified_file`]).
    pub output: String,
    /// The simplified file's size and CRC-32.
    pub output_stamp: OutputStamp,
    /// The quadrics file's size and CRC-32 ([`quadrics_file`]).
    pub quadrics_stamp: OutputStamp,
    /// The first `border_vertices` vertices of the output are the tile's border ones.
    pub border_vertices: usize,
    /// The tile's triangles.
    pub triangles_in: usize,
    /// The simplified tile's triangles.
    pub triangles_out: usize,
    /// Why the simplification stopped ([`StopReason::as_str`]).
    pub stop_reason: String,
}

/// What [`merge`] did.
#[derive(Serialize, Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct MergeReport {
    /// The split merged ([`Manifest::split_id`]).
    pub split_id: String,
    /// The fingerprint of the options every tile was simplified with.
    pub options: String,
    /// The number of tiles merged.
    pub tiles: usize,
    /// The tiles' triangles before simplification (the input's, after the weld).
    pub triangles_in: usize,
    /// The merged mesh's triangles.
    pub triangles_out: usize,
    /// The merged mesh's vertices.
    pub vertices_out: usize,
}

/// An option the tile jobs do not take, and why ([`TileOptions::new`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum RefusedOption {
    /// A target in triangles ([`Target::Triangles`]): each tile gets a ratio.
    TriangleTarget,
    /// Locked vertices: the tiles lock their own (their borders).
    LockedVertices,
    /// Vertex clustering ([`Method::Clustering`]), which would not keep the borders.
    Clustering,
    /// Virtual pairs (a pair threshold above 0), which would reach past the locked
    /// neighbours of the border vertices and make the sides overlap.
    VirtualPairs,
}

impl RefusedOption {
    /// Why the tile jobs refuse it, for a message that names the option first.
    pub fn reason(self) -> &'static str {
        "each tile is simplified by a ratio of its triangles with its border vertices \
         locked (clustering would not keep them, and virtual pairs would reach past them)"
    }

    fn what(self) -> &'static str {
        match self {
            RefusedOption::TriangleTarget => "a target in triangles",
            RefusedOption::LockedVertices => "locked vertices",
            RefusedOption::Clustering => "vertex clustering",
            RefusedOption::VirtualPairs => "virtual pairs (a pair threshold above 0)",
        }
    }
}

impl std::fmt::Display for RefusedOption {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the tile jobs do not take {}: {}",
            self.what(),
            self.reason()
        )
    }
}

impl std::error::Error for RefusedOption {}

/// The options of a tile job: simplification options the tiles can honour, and their
/// fingerprint (what a [`TileStatus`] records).
#[derive(Clone, Debug, PartialEq)]
pub struct TileOptions {
    options: SimplifyOptions,
    fingerprint: String,
}

impl TileOptions {
    /// Checks that `options` suit tiles: a ratio (or no target), no locked vertices, no
    /// clustering, no virtual pairs; each tile's border is locked by the job itself.
    ///
    /// ```
    /// use qem_mesh::simplify::{SimplifyOptions, Target};
    /// use qem_mesh::tiles::jobs::{RefusedOption, TileOptions};
    /// let tenth = SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.1));
    /// assert!(TileOptions::new(tenth).is_ok());
    /// let count = SimplifyOptions::DEFAULT.with_target(Target::Triangles(100));
    /// assert_eq!(TileOptions::new(count), Err(RefusedOption::TriangleTarget));
    /// ```
    pub fn new(options: SimplifyOptions) -> Result<TileOptions, RefusedOption> {
        let threshold = match options.pair_threshold {
            Length::DiagonalFraction(v) | Length::Absolute(v) => v,
        };
        let refused = [
            (
                matches!(options.target, Target::Triangles(_)),
                RefusedOption::TriangleTarget,
            ),
            (
                !options.locked_vertices.is_empty(),
                RefusedOption::LockedVertices,
            ),
            (
                options.method == Method::Clustering,
                RefusedOption::Clustering,
            ),
            (threshold > 0.0, RefusedOption::VirtualPairs),
        ];
        if let Some(&(_, option)) = refused.iter().find(|(given, _)| *given) {
            return Err(option);
        }
        // "tiles/ply": the output format is part of what decides the bytes.
        let fingerprint = fingerprint(&options, &"tiles/ply");
        Ok(TileOptions {
            options,
            fingerprint,
        })
    }

    /// The simplification options (without the tile's locked vertices).
    pub fn options(&self) -> &SimplifyOptions {
        &self.options
    }

    /// The fingerprint of the options and qem's version, as statuses record it.
    pub fn fingerprint(&self) -> &str {
        &self.fingerprint
    }
}

/// What a later step fixes an error with, for the caller to word as its own command.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum Remedy {
    /// Split the input into the directory (again).
    Split,
    /// Simplify this tile (again).
    SimplifyTile(usize),
}

/// What is wrong with a file of the tile directory ([`TilesError::File`]).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Problem {
    /// The tile directory does not exist.
    NoDirectory,
    /// The manifest is missing: not a tile directory, or its split did not finish.
    NoManifest,
    /// The manifest does not parse as one.
    NotManifest(String),
    /// The manifest parses but cannot be used: another version, no tiles, an entry out
    /// of place.
    CorruptManifest(String),
    /// The split has no such tile.
    NoSuchTile {
        /// The tile asked for.
        tile: usize,
        /// How many tiles the split has.
        tiles: usize,
    },
    /// A tile file is not the one the manifest lists (another split's, or changed).
    TileOfAnotherSplit,
    /// A tile has no status: it is not simplified yet.
    NotSimplified {
        /// The tile.
        tile: usize,
    },
    /// A status file does not parse as one of this version, or names another file.
    NotStatus {
        /// The tile.
        tile: usize,
    },
    /// A status belongs to another split (or to another tile file).
    StatusOfAnotherSplit {
        /// The tile.
        tile: usize,
    },
    /// A tile was simplified with other options than tile 0.
    OtherOptions {
        /// The tile.
        tile: usize,
    },
    /// A simplified file or its quadrics do not match its status (changed or cut
    /// short).
    SimplifiedChanged {
        /// The tile.
        tile: usize,
    },
    /// A simplified file has fewer vertices than its status's border vertices.
    FewerVerticesThanBorder,
    /// Simplifying the tile failed.
    Simplify(SimplifyError),
    /// The merged mesh does not validate (a bug, or files edited by hand).
    InvalidMerge(InputError),
}

impl Problem {
    fn remedy(&self) -> Option<Remedy> {
        match self {
            Problem::NoDirectory
            | Problem::NoManifest
            | Problem::CorruptManifest(_)
            | Problem::TileOfAnotherSplit => Some(Remedy::Split),
            Problem::NotSimplified { tile }
            | Problem::NotStatus { tile }
            | Problem::StatusOfAnotherSplit { tile }
            | Problem::SimplifiedChanged { tile } => Some(Remedy::SimplifyTile(*tile)),
            _ => None,
        }
    }
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Problem::NoDirectory => write!(f, "no such directory"),
            Problem::NoManifest => write!(
                f,
                "missing: this is not a tile directory, or its split did not finish"
            ),
            Problem::NotManifest(e) => write!(f, "not a tile manifest: {e}"),
            Problem::CorruptManifest(why) => write!(f, "corrupt tile manifest: {why}"),
            Problem::NoSuchTile { tile, tiles } => write!(
                f,
                "there is no tile {tile}: the split has tiles 0 to {}",
                tiles.saturating_sub(1)
            ),
            Problem::TileOfAnotherSplit => write!(
                f,
                "not the tile {MANIFEST_NAME} lists (its size or CRC-32 differ): a tile of \
                 another split, or changed since"
            ),
            Problem::NotSimplified { tile } => {
                write!(f, "missing: tile {tile} is not simplified yet")
            }
            Problem::NotStatus { tile } => write!(f, "not a status of tile {tile}"),
            Problem::StatusOfAnotherSplit { tile } => {
                write!(f, "tile {tile} was simplified for another split")
            }
            Problem::OtherOptions { tile } => write!(
                f,
                "tile {tile} was simplified with other options than tile 0; simplify them \
                 all with the same options"
            ),
            Problem::SimplifiedChanged { .. } => {
                write!(f, "does not match its status (changed or cut short)")
            }
            Problem::FewerVerticesThanBorder => {
                write!(f, "has fewer vertices than its status's border vertices")
            }
            Problem::Simplify(e) => write!(f, "{e}"),
            Problem::InvalidMerge(e) => write!(f, "the merged mesh is not valid: {e}"),
        }
    }
}

/// Why a tile job failed. Its `Display` is one line that starts with the file
/// concerned (except for [`TilesError::Refused`] and [`TilesError::Cancelled`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TilesError {
    /// A file could not be read or written, or is not a mesh.
    #[error(transparent)]
    Io(#[from] IoError),
    /// A file of the tile directory is missing or not what it should be.
    #[error("{}: {problem}", path.display())]
    File {
        /// The file (or directory).
        path: PathBuf,
        /// What is wrong with it.
        problem: Problem,
    },
    /// The options cannot be used for tiles.
    #[error(transparent)]
    Refused(#[from] RefusedOption),
    /// The observer asked to stop; what was written is whole (every file is written
    /// atomically), and a run again carries on.
    #[error("cancelled")]
    Cancelled,
}

impl TilesError {
    /// What fixes this error, when it is a step of the pipeline: the caller words it
    /// (`run qem tiles simplify DIR --tile 3`, `qem.tiles.simplify(directory, tile=3)`).
    ///
    /// ```
    /// use qem_mesh::tiles::jobs::{Remedy, TileDir};
    /// let dir = tempfile::tempdir().unwrap();
    /// let err = TileDir::open(dir.path()).unwrap_err();
    /// assert!(err.to_string().ends_with("tiles.json: missing: this is not a tile \
    ///                                    directory, or its split did not finish"));
    /// assert_eq!(err.remedy(), Some(Remedy::Split));
    /// ```
    pub fn remedy(&self) -> Option<Remedy> {
        match self {
            TilesError::File { problem, .. } => problem.remedy(),
            _ => None,
        }
    }

    fn file(path: PathBuf, problem: Problem) -> TilesError {
        TilesError::File { path, problem }
    }
}

/// An operating-system error on `path` while trying to `action` it.
fn os_error(path: &Path, action: &'static str, source: std::io::Error) -> TilesError {
    TilesError::Io(IoError::File {
        path: path.to_path_buf(),
        action,
        source,
    })
}

/// Reads `path` whole, naming it in the error.
fn read_file(path: &Path) -> Result<Vec<u8>, TilesError> {
    std::fs::read(path).map_err(|e| os_error(path, "read", e))
}

/// `mesh` as binary PLY bytes (the format of every tile file).
fn ply_bytes(mesh: &IndexedMesh, path: &Path) -> Result<Vec<u8>, TilesError> {
    let mut bytes = Vec::new();
    write_to(&mut bytes, mesh, Format::Ply).map_err(|e| os_error(path, "write", e))?;
    Ok(bytes)
}

/// Reads tile bytes as the PLY they should be, naming `path` in the error.
fn ply_mesh(bytes: &[u8], path: &Path) -> Result<IndexedMesh, TilesError> {
    let loaded = read_bytes(bytes, Format::Ply).map_err(|source| IoError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(loaded.mesh)
}

/// `bytes` written to `path` atomically.
fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), TilesError> {
    Ok(write_atomically(path, |f| f.write_all(bytes))?)
}

/// Streams the input to disk as it reads it, cuts it into tiles as
/// [`Tiling`](super::Tiling) cuts (vertices welded by bit-identical position), and
/// writes the tiles and then the manifest into `dir` (created if missing). Returns the
/// manifest.
///
/// The old manifest goes first, so a split stopped half way leaves no manifest that
/// could pass for a finished one (or for the earlier split, whose tiles are being
/// replaced); the files of tiles past the new count are removed. The same input and
/// count give the same files, bit for bit, wherever the input and `dir` are. The
/// input's attributes are not carried ([`InputJson::attributes_dropped`] says when
/// there were some; [`ATTRIBUTES_DROPPED`] is the warning to give).
///
/// `observer` is asked [`Observer::should_stop`] once the input is read and before
/// each tile; `true` gives [`TilesError::Cancelled`] and leaves no manifest.
pub fn split(
    input: &Path,
    dir: &Path,
    count: TileCount,
    observer: &mut dyn Observer,
) -> Result<Manifest, TilesError> {
    let manifest_path = clear_for_split(dir)?;
    let mut spill = Spill::create(dir)?;
    let streamed = stream_path(input, &mut spill)?;
    if observer.should_stop() {
        return Err(TilesError::Cancelled);
    }
    let source = Source::of_file(input, &streamed)?;
    let spilled = spill.finish()?;
    write_tiles(source, spilled, dir, &manifest_path, count, observer)
}

/// What the manifest says of a split's input besides its triangles.
pub(super) struct Source {
    name: String,
    size_bytes: u64,
    vertices: usize,
    pub(super) attributes_dropped: bool,
}

impl Source {
    /// The account of file `input`, as `streamed` read it.
    pub(super) fn of_file(input: &Path, streamed: &Streamed) -> Result<Source, TilesError> {
        let size_bytes = std::fs::metadata(input)
            .map_err(|e| os_error(input, "read", e))?
            .len();
        let name = input
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        Ok(Source {
            name,
            size_bytes,
            vertices: streamed.vertices,
            attributes_dropped: !streamed.attributes.is_empty(),
        })
    }

    /// The name and size, for a [`SplitInput`] of the same file read whole.
    pub(super) fn file(&self) -> (String, u64) {
        (self.name.clone(), self.size_bytes)
    }
}

/// [`split`] of an input whose triangles are on disk already (streamed by
/// [`super::budget`] to learn whether it fits): the same files.
pub(super) fn split_spilled(
    source: Source,
    spilled: Spilled,
    dir: &Path,
    count: TileCount,
    observer: &mut dyn Observer,
) -> Result<Manifest, TilesError> {
    let manifest_path = clear_for_split(dir)?;
    write_tiles(source, spilled, dir, &manifest_path, count, observer)
}

/// A mesh to [`split_mesh`], already in memory, with what the manifest says of the file
/// it came from.
#[derive(Clone, Debug)]
pub struct SplitInput {
    /// The input file's name (without its directory), for [`InputJson::name`].
    pub name: String,
    /// The input file's size in bytes, for [`InputJson::size_bytes`].
    pub size_bytes: u64,
    /// The mesh, taken over (welded in place and cut: one copy at the peak).
    pub mesh: IndexedMesh,
}

/// [`split`] for a mesh already read: the same files as [`split`] of the file it was
/// read from, given that file's name and size. For a caller that reads the input
/// anyway (the memory budget of [`super::budget`] decides on it), so it is not read
/// twice. The mesh is let go once its triangles are on disk. Triangles with an index
/// out of range are left out (a mesh that passed
/// [`IndexedMesh::validate`](crate::IndexedMesh::validate) has none).
pub fn split_mesh(
    input: SplitInput,
    dir: &Path,
    count: TileCount,
    observer: &mut dyn Observer,
) -> Result<Manifest, TilesError> {
    let manifest_path = clear_for_split(dir)?;
    let SplitInput {
        name,
        size_bytes,
        mesh,
    } = input;
    let mut spill = Spill::create(dir)?;
    for t in &mesh.triangles {
        let corners = t.map(|v| mesh.positions.get(v as usize).copied());
        if let [Some(a), Some(b), Some(c)] = corners {
            spill.triangle([a, b, c])?;
        }
    }
    let source = Source {
        name,
        size_bytes,
        vertices: mesh.vertex_count(),
        attributes_dropped: !mesh.attributes.is_empty(),
    };
    drop(mesh);
    let spilled = spill.finish()?;
    write_tiles(source, spilled, dir, &manifest_path, count, observer)
}

/// Creates `dir` if missing and removes its old manifest (and stale temporaries)
/// before a split; returns the manifest's path.
fn clear_for_split(dir: &Path) -> Result<PathBuf, TilesError> {
    std::fs::create_dir_all(dir).map_err(|e| os_error(dir, "create", e))?;
    let _ = remove_stale_temporaries(dir);
    remove_stale_scratch(dir);
    let manifest_path = dir.join(MANIFEST_NAME);
    match std::fs::remove_file(&manifest_path) {
        Err(e) if e.kind() != ErrorKind::NotFound => {
            return Err(os_error(&manifest_path, "remove", e))
        }
        _ => {}
    }
    Ok(manifest_path)
}

/// The split's work once the input is on disk: the cut, the tiles, the manifest.
fn write_tiles(
    source: Source,
    spilled: Spilled,
    dir: &Path,
    manifest_path: &Path,
    count: TileCount,
    observer: &mut dyn Observer,
) -> Result<Manifest, TilesError> {
    let Source {
        name,
        size_bytes,
        vertices,
        attributes_dropped,
    } = source;
    let triangles = spilled.triangles as usize;
    let requested = count.tiles_for(triangles);
    let (bbox_min, bbox_max) = match spilled.bbox {
        (lo, hi) if triangles > 0 => (lo, hi),
        _ => ([0.0; 3], [0.0; 3]),
    };
    let routed = spilled.route(requested)?;
    let welded_vertices = vertices.saturating_sub(routed.distinct_positions);
    let mut tiles = Vec::with_capacity(routed.len());
    for k in 0..routed.len() {
        if observer.should_stop() {
            return Err(TilesError::Cancelled);
        }
        let (tile, (centroid_min, centroid_max)) = routed.tile(k)?;
        let path = dir.join(tile_file(k));
        let bytes = ply_bytes(&tile.mesh, &path)?;
        write_bytes(&path, &bytes)?;
        tiles.push(TileEntry {
            index: k,
            file: tile_file(k),
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
        input: InputJson {
            name,
            size_bytes,
            vertices,
            triangles,
            welded_vertices,
            attributes_dropped,
        },
        partition: PartitionJson {
            method: "kd-median".to_string(),
            tiles_requested: requested,
            bbox_min,
            bbox_max,
        },
        tiles,
    };
    manifest.split_id = split_id(&manifest);
    write_json_atomically(manifest_path, &manifest)?;
    Ok(manifest)
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
        let ours = [tile_file(k), simplified_file(k), status_file(k)];
        if k >= count && ours.iter().any(|o| o == name) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Reads `path`'s status; `None` when there is none or it does not parse (a file that
/// is not one of ours: it is then written anew).
fn read_status(path: &Path) -> Option<TileStatus> {
    let text = std::fs::read_to_string(path).ok()?;
    serde_json::from_str::<TileStatus>(&text)
        .ok()
        .filter(|s| s.qem_tiles_status == VERSION)
}

/// A directory [`split`] wrote, its manifest read and checked: the place the tile jobs
/// run in.
#[derive(Clone, Debug)]
pub struct TileDir {
    dir: PathBuf,
    manifest: Manifest,
}

/// Whether a tile has work left ([`TileDir::prepare`]).
#[derive(Debug)]
pub enum TileWork<'a> {
    /// The tile is done for these options: its status.
    Done(TileStatus),
    /// The tile is read and ready to simplify.
    ToDo(PendingTile<'a>),
}

/// A tile read from its file, with its border found, ready to simplify
/// ([`PendingTile::run`]).
#[derive(Debug)]
pub struct PendingTile<'a> {
    dir: &'a TileDir,
    options: &'a TileOptions,
    k: usize,
    tile: Tile,
    locked: Vec<u32>,
    input_stamp: OutputStamp,
}

/// A tile whose locked vertices leave little room for its target
/// ([`PendingTile::crowding`]); its `Display` is the warning to give.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct Crowding {
    /// The tile.
    pub tile: usize,
    /// Its locked vertices: its border vertices and their neighbours.
    pub locked: usize,
    /// Its target, in triangles.
    pub target: usize,
}

impl std::fmt::Display for Crowding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "tile {}: its {} locked vertices (its border and their neighbours) leave little \
             room for {} triangles, so the error near its borders will be large; split into \
             fewer, larger tiles or use a higher ratio",
            self.tile, self.locked, self.target
        )
    }
}

/// What [`TileDir::simplify_tile`] did.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct TileOutcome {
    /// The tile's status (as written now, or as found).
    pub status: TileStatus,
    /// Whether the tile was done already, with the same options, and left as it was.
    pub already_done: bool,
}

impl TileDir {
    /// Reads and checks `dir/tiles.json`.
    pub fn open(dir: &Path) -> Result<TileDir, TilesError> {
        let path = dir.join(MANIFEST_NAME);
        if !dir.is_dir() {
            return Err(TilesError::file(dir.to_path_buf(), Problem::NoDirectory));
        }
        let text = match std::fs::read_to_string(&path) {
            Ok(t) => t,
            Err(e) if e.kind() == ErrorKind::NotFound => {
                return Err(TilesError::file(path, Problem::NoManifest))
            }
            Err(e) => return Err(os_error(&path, "read", e)),
        };
        let manifest: Manifest = match serde_json::from_str(&text) {
            Ok(m) => m,
            Err(e) => return Err(TilesError::file(path, Problem::NotManifest(e.to_string()))),
        };
        let corrupt = |why: String| {
            Err(TilesError::file(
                path.clone(),
                Problem::CorruptManifest(why),
            ))
        };
        if manifest.qem_tiles != VERSION {
            return corrupt(format!(
                "version {} (this qem reads version {VERSION})",
                manifest.qem_tiles
            ));
        }
        if manifest.tiles.is_empty() {
            return corrupt("no tiles".to_string());
        }
        for (k, t) in manifest.tiles.iter().enumerate() {
            if t.index != k || t.file != tile_file(k) || t.border_vertices > t.vertices {
                return corrupt(format!("entry {k} is not tile {k}"));
            }
        }
        Ok(TileDir {
            dir: dir.to_path_buf(),
            manifest,
        })
    }

    /// The directory.
    pub fn path(&self) -> &Path {
        &self.dir
    }

    /// The manifest.
    pub fn manifest(&self) -> &Manifest {
        &self.manifest
    }

    /// The number of tiles (at least 1).
    pub fn len(&self) -> usize {
        self.manifest.tiles.len()
    }

    /// Whether there are no tiles (never: [`TileDir::open`] refuses such a manifest).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The tiles to work on: `tile` alone when given (an error naming the manifest
    /// when the split has no such tile), else every tile.
    pub fn select(&self, tile: Option<usize>) -> Result<Range<usize>, TilesError> {
        match tile {
            None => Ok(0..self.len()),
            Some(k) => self.check_tile(k).map(|()| k..k + 1),
        }
    }

    fn check_tile(&self, k: usize) -> Result<(), TilesError> {
        if k < self.len() {
            Ok(())
        } else {
            Err(TilesError::file(
                self.dir.join(MANIFEST_NAME),
                Problem::NoSuchTile {
                    tile: k,
                    tiles: self.len(),
                },
            ))
        }
    }

    /// Tile `k`'s status if it belongs to this split (this split's id, this tile and
    /// its file as the manifest lists it, the simplified file's name), whatever the
    /// options; otherwise an error naming the status file.
    fn status_of_this_split(&self, k: usize) -> Result<TileStatus, TilesError> {
        self.check_tile(k)?;
        let path = self.dir.join(status_file(k));
        if !path.exists() {
            return Err(TilesError::file(path, Problem::NotSimplified { tile: k }));
        }
        let Some(status) = read_status(&path).filter(|s| s.output == simplified_file(k)) else {
            return Err(TilesError::file(path, Problem::NotStatus { tile: k }));
        };
        if status.split_id != self.manifest.split_id
            || status.tile != k
            || status.input_stamp != self.manifest.tiles[k].stamp
        {
            return Err(TilesError::file(
                path,
                Problem::StatusOfAnotherSplit { tile: k },
            ));
        }
        Ok(status)
    }

    /// Tile `k`'s status when it is done for `options` (see the [module docs](self)):
    /// its status belongs to this split, records these options, and the simplified
    /// file and quadrics on disk have the recorded sizes and CRC-32s.
    pub fn done(&self, k: usize, options: &TileOptions) -> Option<TileStatus> {
        let status = self.status_of_this_split(k).ok()?;
        let simplified = OutputStamp::of(&self.dir.join(simplified_file(k)));
        let quadrics = OutputStamp::of(&self.dir.join(quadrics_file(k)));
        (status.options == options.fingerprint
            && simplified == Some(status.output_stamp)
            && quadrics == Some(status.quadrics_stamp))
        .then_some(status)
    }

    /// Tile `k`'s work: [`TileWork::Done`] when it is done for `options`, else the tile
    /// read from its file (checked against the manifest) and ready to simplify. Removes
    /// the temporary files that killed writers of this tile's files left (only this
    /// tile's: the writers of other tiles may run on other machines, which no process
    /// table here lists).
    pub fn prepare<'a>(
        &'a self,
        k: usize,
        options: &'a TileOptions,
    ) -> Result<TileWork<'a>, TilesError> {
        self.check_tile(k)?;
        let _ = remove_stale_temporaries_of(
            &self.dir,
            &[&simplified_file(k), &quadrics_file(k), &status_file(k)],
        );
        if let Some(status) = self.done(k, options) {
            return Ok(TileWork::Done(status));
        }
        let entry = &self.manifest.tiles[k];
        let path = self.dir.join(tile_file(k));
        let bytes = read_file(&path)?;
        let input_stamp = OutputStamp::of_bytes(&bytes);
        if input_stamp != entry.stamp {
            return Err(TilesError::file(path, Problem::TileOfAnotherSplit));
        }
        let mesh = ply_mesh(&bytes, &path)?;
        drop(bytes);
        let tile = Tile {
            border_vertices: entry.border_vertices.min(mesh.vertex_count()),
            mesh,
        };
        let locked = tile.locked_vertices();
        Ok(TileWork::ToDo(PendingTile {
            dir: self,
            options,
            k,
            tile,
            locked,
            input_stamp,
        }))
    }

    /// Simplifies tile `k` with `options` unless it is done already
    /// ([`TileDir::prepare`], then [`PendingTile::run`]).
    pub fn simplify_tile(
        &self,
        k: usize,
        options: &TileOptions,
        observer: &mut dyn Observer,
    ) -> Result<TileOutcome, TilesError> {
        Ok(match self.prepare(k, options)? {
            TileWork::Done(status) => TileOutcome {
                status,
                already_done: true,
            },
            TileWork::ToDo(pending) => TileOutcome {
                status: pending.run(observer)?,
                already_done: false,
            },
        })
    }
}

impl PendingTile<'_> {
    /// The tile's number.
    pub fn tile(&self) -> usize {
        self.k
    }

    /// Whether the tile's locked vertices (its border and their neighbours) leave
    /// little room for its target: a tile simplified to fewer triangles than about
    /// twice its locked vertices keeps its border strip and little more than long
    /// triangles spanning from border to border, far from the surface (BENCHMARKS.md,
    /// "Tiles": the dragon at ratio 0.01 in 8 tiles against 2).
    pub fn crowding(&self) -> Option<Crowding> {
        let target = match self.options.options.target {
            Target::None => return None,
            t => t.triangles_for(self.tile.mesh.triangle_count()),
        };
        let locked = self.locked.len();
        (target < 2 * locked).then_some(Crowding {
            tile: self.k,
            locked,
            target,
        })
    }

    /// Simplifies the tile with its border locked, then writes the simplified tile, its
    /// quadrics and then its status (each atomically), and returns the status.
    /// `observer` sees the simplification; a stop it asks for gives
    /// [`TilesError::Cancelled`] and writes nothing.
    pub fn run(self, observer: &mut dyn Observer) -> Result<TileStatus, TilesError> {
        let dir = &self.dir.dir;
        let k = self.k;
        let border_positions = self.tile.mesh.positions[..self.tile.border_vertices].to_vec();
        let triangles_in = self.tile.mesh.triangle_count();
        let options = self
            .options
            .options
            .clone()
            .with_locked_vertices(self.locked);
        let origin = self.dir.manifest.quadric_origin();
        let simplified = simplify_carrying(self.tile.mesh, &options, None, origin, observer);
        let (result, quadrics) = simplified.map_err(|e| match e {
            SimplifyError::Cancelled { .. } => TilesError::Cancelled,
            e => TilesError::file(dir.join(tile_file(k)), Problem::Simplify(e)),
        })?;
        if result.report.stop_reason == StopReason::Cancelled || observer.should_stop() {
            return Err(TilesError::Cancelled);
        }
        let stop_reason = result.report.stop_reason.as_str().to_string();
        let (tile, new_number) = Tile::border_first_numbered(&border_positions, result.mesh);
        let mut numbered = vec![Quadric::ZERO; quadrics.quadrics.len()];
        for (q, &new) in quadrics.quadrics.into_iter().zip(&new_number) {
            numbered[new as usize] = q;
        }
        let out_path = dir.join(simplified_file(k));
        let out = ply_bytes(&tile.mesh, &out_path)?;
        write_bytes(&out_path, &out)?;
        let quadrics = quadrics_bytes(&numbered, origin);
        write_bytes(&dir.join(quadrics_file(k)), &quadrics)?;
        let status = TileStatus {
            qem_tiles_status: VERSION,
            split_id: self.dir.manifest.split_id.clone(),
            tile: k,
            input_stamp: self.input_stamp,
            options: self.options.fingerprint.clone(),
            output: simplified_file(k),
            output_stamp: OutputStamp::of_bytes(&out),
            quadrics_stamp: OutputStamp::of_bytes(&quadrics),
            border_vertices: tile.border_vertices,
            triangles_in,
            triangles_out: tile.mesh.triangle_count(),
            stop_reason,
        };
        write_json_atomically(&dir.join(status_file(k)), &status)?;
        Ok(status)
    }
}

/// Joins the simplified tiles of `dir` into one mesh, merging the border vertices at
/// equal positions, and writes it to `output` (atomically; the format from its name).
///
/// Every status is checked first, so a tile without one (or with one for another
/// split, or with other options than tile 0) is found before any mesh is read; then
/// each simplified file is checked against its status as it is read. The quadrics
/// files are not read: the merged mesh does not need them (the memory budget's merge,
/// which does, checks them too). `observer` is asked [`Observer::should_stop`] before
/// each tile.
pub fn merge(
    dir: &Path,
    output: &Path,
    observer: &mut dyn Observer,
) -> Result<MergeReport, TilesError> {
    Format::from_path(output).map_err(|source| IoError::Read {
        path: output.to_path_buf(),
        source,
    })?;
    let (merged, _, report) = join(dir, Carrying::No, observer)?;
    merged
        .validate()
        .map_err(|e| TilesError::file(output.to_path_buf(), Problem::InvalidMerge(e)))?;
    let _ = remove_stale_temporaries(&directory_of(output));
    write_path(output, &merged)?;
    Ok(report)
}

/// [`merge`] in memory, with the merged vertices' quadrics read from the tiles'
/// [`quadrics_file`]s: not carried for a border vertex (its quadric in each tile holds
/// the planes of the tile's cut, which are not the surface's).
pub(crate) fn merge_carrying(
    dir: &Path,
    observer: &mut dyn Observer,
) -> Result<(IndexedMesh, CarriedQuadrics, MergeReport), TilesError> {
    let (merged, carried, report) = join(dir, Carrying::Quadrics, observer)?;
    merged
        .validate()
        .map_err(|e| TilesError::file(dir.to_path_buf(), Problem::InvalidMerge(e)))?;
    Ok((merged, carried, report))
}

/// Whether [`join`] reads the tiles' quadrics.
#[derive(Clone, Copy, PartialEq)]
enum Carrying {
    No,
    Quadrics,
}

/// The simplified tiles of `dir` joined (see [`merge`]), with their vertices' quadrics
/// when `carrying` asks for them (else none).
fn join(
    dir: &Path,
    carrying: Carrying,
    observer: &mut dyn Observer,
) -> Result<(IndexedMesh, CarriedQuadrics, MergeReport), TilesError> {
    let tiles = TileDir::open(dir)?;
    let origin = tiles.manifest.quadric_origin();
    let mut statuses: Vec<TileStatus> = Vec::with_capacity(tiles.len());
    for k in 0..tiles.len() {
        let status = tiles.status_of_this_split(k)?;
        if statuses
            .first()
            .is_some_and(|first| first.options != status.options)
        {
            return Err(TilesError::file(
                dir.join(status_file(k)),
                Problem::OtherOptions { tile: k },
            ));
        }
        statuses.push(status);
    }
    let mut welder = Welder::default();
    for (k, status) in statuses.iter().enumerate() {
        if observer.should_stop() {
            return Err(TilesError::Cancelled);
        }
        let path = dir.join(simplified_file(k));
        let bytes = read_file(&path)?;
        if OutputStamp::of_bytes(&bytes) != status.output_stamp {
            return Err(TilesError::file(
                path,
                Problem::SimplifiedChanged { tile: k },
            ));
        }
        let mesh = ply_mesh(&bytes, &path)?;
        if status.border_vertices > mesh.vertex_count() {
            return Err(TilesError::file(path, Problem::FewerVerticesThanBorder));
        }
        let tile = Tile {
            border_vertices: status.border_vertices,
            mesh,
        };
        if carrying == Carrying::No {
            welder.push(&tile);
            continue;
        }
        let path = dir.join(quadrics_file(k));
        let bytes = read_file(&path)?;
        let quadrics = (OutputStamp::of_bytes(&bytes) == status.quadrics_stamp)
            .then(|| quadrics_of(&bytes, tile.mesh.vertex_count(), origin))
            .flatten()
            .ok_or_else(|| TilesError::file(path, Problem::SimplifiedChanged { tile: k }))?;
        welder.push_carrying(&tile, &quadrics);
    }
    let (merged, quadrics) = welder.finish_carrying();
    let carried = CarriedQuadrics { origin, quadrics };
    let report = MergeReport {
        split_id: tiles.manifest.split_id.clone(),
        options: statuses
            .first()
            .map(|s| s.options.clone())
            .unwrap_or_default(),
        tiles: statuses.len(),
        triangles_in: statuses.iter().map(|s| s.triangles_in).sum(),
        triangles_out: merged.triangle_count(),
        vertices_out: merged.vertex_count(),
    };
    Ok((merged, carried, report))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::read_path;
    use crate::simplify::{is_carried, NoObserver};
    use std::collections::BTreeMap;

    /// An open, bumpy `n` x `n` grid of squares (2 n² triangles) written as PLY.
    fn grid_file(dir: &Path, n: u32) -> PathBuf {
        let positions = (0..=n)
            .flat_map(|y| {
                (0..=n).map(move |x| {
                    let (fx, fy) = (x as f64, y as f64);
                    [fx, fy, 0.3 * (fx * 0.7).sin() * (fy * 0.5).cos()]
                })
            })
            .collect();
        let triangles = (0..n)
            .flat_map(|y| (0..n).map(move |x| y * (n + 1) + x))
            .flat_map(|v| [[v, v + 1, v + n + 2], [v, v + n + 2, v + n + 1]])
            .collect();
        let path = dir.join("grid.ply");
        write_path(&path, &IndexedMesh::new(positions, triangles)).expect("write the grid");
        path
    }

    /// The split of a file, streamed to disk, gives the tiles of
    /// [`Tiling`](super::super::Tiling) on the mesh read from it, as PLY and as an STL
    /// soup (whose facets share no vertex), and the same manifest counts.
    #[test]
    fn the_streamed_split_gives_the_tiling_of_the_read_mesh() {
        let tmp = tempfile::tempdir().expect("a temporary directory");
        let ply = grid_file(tmp.path(), 23);
        let mesh = read_path(&ply).expect("read").mesh;
        let stl = tmp.path().join("grid.stl");
        write_path(&stl, &mesh).expect("write the soup");
        for (input, tiles) in [(&ply, 5), (&stl, 7), (&ply, 1)] {
            let read = read_path(input).expect("read").mesh;
            let dir = tmp.path().join("t");
            let manifest =
                split(input, &dir, TileCount::Tiles(tiles), &mut NoObserver).expect("split");
            let tiling = super::super::Tiling::new(read.clone(), tiles);
            assert_eq!(manifest.tiles.len(), tiling.len());
            assert_eq!(manifest.input.vertices, read.vertex_count());
            assert_eq!(manifest.input.welded_vertices, tiling.welded_vertices());
            let dir = TileDir::open(&dir).expect("open");
            for k in 0..tiling.len() {
                let expected = tiling.tile(k);
                let file = dir.path().join(tile_file(k));
                let got = read_path(&file).expect("read the tile").mesh;
                assert_eq!(
                    got.positions, expected.mesh.positions,
                    "tile {k} of {input:?}"
                );
                assert_eq!(
                    got.triangles, expected.mesh.triangles,
                    "tile {k} of {input:?}"
                );
                let entry = &manifest.tiles[k];
                assert_eq!(entry.border_vertices, expected.border_vertices);
                let boxed = tiling.centroid_box(k);
                assert_eq!((entry.centroid_min, entry.centroid_max), boxed);
            }
            // Nothing of the split's scratch is left.
            let left: Vec<_> = std::fs::read_dir(dir.path())
                .expect("list")
                .filter_map(|e| e.ok())
                .filter(|e| e.file_name().to_string_lossy().starts_with(".qem-split-"))
                .collect();
            assert!(left.is_empty(), "{left:?}");
        }
    }

    fn ratio(r: f64) -> TileOptions {
        TileOptions::new(SimplifyOptions::DEFAULT.with_target(Target::Ratio(r)))
            .expect("a ratio suits tiles")
    }

    /// Every file of `dir` (name → bytes).
    fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
        std::fs::read_dir(dir)
            .expect("list")
            .map(|e| {
                let e = e.expect("an entry");
                let name = e.file_name().to_string_lossy().into_owned();
                (name, std::fs::read(e.path()).expect("read"))
            })
            .collect()
    }

    fn problem(e: TilesError) -> (PathBuf, Problem) {
        match e {
            TilesError::File { path, problem } => (path, problem),
            e => panic!("not a file problem: {e}"),
        }
    }

    #[test]
    fn the_pipeline_reruns_to_the_same_bytes_and_skips_what_is_done() {
        let tmp = tempfile::tempdir().expect("a temporary directory");
        let input = grid_file(tmp.path(), 20);
        let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
        let manifest =
            split(&input, &a, TileCount::MaxTriangles(200), &mut NoObserver).expect("split");
        assert_eq!(manifest.tiles.len(), 4, "800 triangles, at most 200 a tile");
        assert_eq!(manifest.input.triangles, 800);
        // Another directory: the same manifest, the same files.
        assert_eq!(
            split(&input, &b, TileCount::Tiles(4), &mut NoObserver)
                .expect("split")
                .split_id,
            manifest.split_id
        );
        assert_eq!(files(&a), files(&b));

        let options = ratio(0.5);
        let tiles = TileDir::open(&a).expect("open");
        assert_eq!(tiles.select(None).expect("all"), 0..4);
        for k in tiles.select(None).expect("all") {
            let outcome = tiles
                .simplify_tile(k, &options, &mut NoObserver)
                .expect("simplify");
            assert!(!outcome.already_done);
            assert_eq!(outcome.status.triangles_in, 200);
        }
        let done = files(&a);
        let again = tiles
            .simplify_tile(2, &options, &mut NoObserver)
            .expect("again");
        assert!(again.already_done);
        assert_eq!(files(&a), done);
        // One tile at a time in another order, in the other directory: the same files.
        let other = TileDir::open(&b).expect("open");
        for k in [3, 1, 0, 2] {
            other
                .simplify_tile(k, &options, &mut NoObserver)
                .expect("simplify");
        }
        assert_eq!(files(&b), done);
        // Other options are not the work done.
        assert!(tiles.done(0, &ratio(0.4)).is_none());
        assert!(tiles.done(0, &options).is_some());

        let report = merge(&a, &tmp.path().join("m.ply"), &mut NoObserver).expect("merge");
        assert_eq!((report.tiles, report.triangles_in), (4, 800));
        assert_eq!(report.split_id, manifest.split_id);
        assert_eq!(report.options, options.fingerprint());
        assert!(report.triangles_out < 800);
    }

    /// The merge carries each tile's quadrics for its own vertices and none for the
    /// border vertices (whose quadrics hold the cut's planes); a tile whose quadrics
    /// file is gone is not done, and its job writes the same file again.
    #[test]
    fn merged_quadrics_are_the_tiles_own_and_none_at_their_borders() {
        let tmp = tempfile::tempdir().expect("a temporary directory");
        let input = grid_file(tmp.path(), 20);
        let dir = tmp.path().join("t");
        split(&input, &dir, TileCount::Tiles(4), &mut NoObserver).expect("split");
        let tiles = TileDir::open(&dir).expect("open");
        let origin = tiles.manifest.quadric_origin();
        let options = ratio(0.5);
        let mut own = Vec::new();
        let mut border_positions = Vec::new();
        for k in 0..tiles.len() {
            let status = tiles
                .simplify_tile(k, &options, &mut NoObserver)
                .expect("simplify")
                .status;
            let mesh = ply_mesh(
                &std::fs::read(dir.join(simplified_file(k))).expect("read"),
                &dir,
            )
            .expect("a mesh");
            let bytes = std::fs::read(dir.join(quadrics_file(k))).expect("read");
            let quadrics = quadrics_of(&bytes, mesh.vertex_count(), origin).expect("one a vertex");
            assert!(quadrics_of(&bytes, mesh.vertex_count(), origin + DVec3::X).is_none());
            assert!(quadrics
                .iter()
                .all(|q| q.entries().iter().all(|e| e.is_finite())));
            own.extend_from_slice(&quadrics[status.border_vertices..]);
            border_positions.extend_from_slice(&mesh.positions[..status.border_vertices]);
        }
        let (merged, carried, report) = merge_carrying(&dir, &mut NoObserver).expect("merge");
        assert_eq!(carried.origin, origin);
        let carried = carried.quadrics;
        assert_eq!(carried.len(), merged.vertex_count());
        assert_eq!(report.vertices_out, merged.vertex_count());
        let kept: Vec<Quadric> = carried.iter().copied().filter(is_carried).collect();
        assert_eq!(kept, own, "the tiles' own vertices' quadrics, in order");
        for (q, p) in carried.iter().zip(&merged.positions) {
            assert_eq!(!is_carried(q), border_positions.contains(p));
        }
        assert!(carried.len() > kept.len(), "the grid's tiles have borders");

        let path = dir.join(quadrics_file(1));
        let before = std::fs::read(&path).expect("read");
        std::fs::remove_file(&path).expect("remove");
        assert!(tiles.done(1, &options).is_none());
        let again = tiles
            .simplify_tile(1, &options, &mut NoObserver)
            .expect("simplify");
        assert!(!again.already_done);
        assert_eq!(std::fs::read(&path).expect("read"), before);
        // Cut short, it is caught by its stamp.
        std::fs::write(&path, &before[..before.len() - 8]).expect("write");
        match merge_carrying(&dir, &mut NoObserver) {
            Err(TilesError::File { path: p, problem }) => {
                assert_eq!(p, path);
                assert_eq!(problem, Problem::SimplifiedChanged { tile: 1 });
            }
            other => panic!("not refused: {other:?}"),
        }
    }

    /// The split id is a fingerprint of the manifest's `Debug` form (type names
    /// included) and qem's version: this pins it, so that renaming a manifest type (or
    /// a change to the cut) cannot go unnoticed; either would leave every existing
    /// directory's tiles not done. A new version of qem changes it too, on purpose.
    #[test]
    fn the_split_id_is_pinned() {
        let tmp = tempfile::tempdir().expect("a temporary directory");
        let input = grid_file(tmp.path(), 6);
        let manifest = split(
            &input,
            &tmp.path().join("t"),
            TileCount::Tiles(3),
            &mut NoObserver,
        )
        .expect("split");
        assert_eq!(
            (manifest.split_id.as_str(), env!("CARGO_PKG_VERSION")),
            ("7b6d7b55", "0.1.0"),
            "a new version changes the split id: update both"
        );
    }

    #[test]
    fn options_the_tiles_cannot_keep_are_refused() {
        let d = SimplifyOptions::DEFAULT;
        for (options, refused) in [
            (
                d.clone().with_target(Target::Triangles(10)),
                RefusedOption::TriangleTarget,
            ),
            (
                d.clone().with_locked_vertices(vec![1]),
                RefusedOption::LockedVertices,
            ),
            (
                d.clone().with_method(Method::Clustering),
                RefusedOption::Clustering,
            ),
            (
                d.clone().with_pair_threshold(Length::Absolute(0.1)),
                RefusedOption::VirtualPairs,
            ),
        ] {
            assert_eq!(TileOptions::new(options), Err(refused));
            assert!(refused.to_string().contains(refused.reason()));
        }
        assert_ne!(ratio(0.5).fingerprint(), ratio(0.25).fingerprint());
    }

    #[test]
    fn errors_name_the_file_and_the_step_that_fixes_them() {
        let tmp = tempfile::tempdir().expect("a temporary directory");
        let input = grid_file(tmp.path(), 10);
        let missing = tmp.path().join("missing");
        let (path, p) = problem(TileDir::open(&missing).expect_err("no directory"));
        assert_eq!((path, p), (missing.clone(), Problem::NoDirectory));

        let dir = tmp.path().join("t");
        split(&input, &dir, TileCount::Tiles(2), &mut NoObserver).expect("split");
        let tiles = TileDir::open(&dir).expect("open");
        let e = tiles.select(Some(2)).expect_err("no tile 2");
        assert!(e.to_string().contains("there is no tile 2"), "{e}");
        let e = tiles.prepare(5, &ratio(0.5)).expect_err("no tile 5");
        assert!(e.to_string().contains("tiles.json"), "{e}");

        let out = tmp.path().join("m.ply");
        let e = merge(&dir, &out, &mut NoObserver).expect_err("nothing simplified");
        assert_eq!(e.remedy(), Some(Remedy::SimplifyTile(0)));
        assert!(e.to_string().contains("tile-00000.done.json"), "{e}");

        tiles
            .simplify_tile(0, &ratio(0.5), &mut NoObserver)
            .expect("tile 0");
        tiles
            .simplify_tile(1, &ratio(0.4), &mut NoObserver)
            .expect("tile 1");
        let (path, p) = problem(merge(&dir, &out, &mut NoObserver).expect_err("mixed"));
        assert_eq!(
            (path, p),
            (dir.join(status_file(1)), Problem::OtherOptions { tile: 1 })
        );

        // A tile file changed since the split.
        std::fs::write(dir.join(tile_file(1)), b"ply\n").expect("write");
        let e = tiles.prepare(1, &ratio(0.5)).expect_err("changed");
        assert_eq!(e.remedy(), Some(Remedy::Split));
        let (path, p) = problem(e);
        assert_eq!(
            (path, p),
            (dir.join(tile_file(1)), Problem::TileOfAnotherSplit)
        );

        // An input that is not a mesh, an output format qem cannot write.
        let junk = tmp.path().join("junk.ply");
        std::fs::write(&junk, b"not a mesh").expect("write");
        let e = split(
            &junk,
            &tmp.path().join("j"),
            TileCount::default(),
            &mut NoObserver,
        );
        assert!(e
            .expect_err("junk")
            .to_string()
            .starts_with(&junk.display().to_string()));
        let e = merge(&dir, &tmp.path().join("m.xyz"), &mut NoObserver).expect_err("xyz");
        assert!(e.to_string().contains("m.xyz"), "{e}");
        assert!(!out.exists());
    }

    /// A tile job removes what killed writers of its own files left, and nothing of
    /// another tile's: that writer may be alive on another machine.
    #[test]
    fn a_tile_job_removes_only_its_own_tiles_temporaries() {
        let tmp = tempfile::tempdir().expect("a temporary directory");
        let input = grid_file(tmp.path(), 10);
        let dir = tmp.path().join("t");
        split(&input, &dir, TileCount::Tiles(2), &mut NoObserver).expect("split");
        // PIDs on Linux stay below 2^22: no process 99999999 exists.
        let own = dir.join(".tile-00000.simplified.ply.qem-tmp-99999999-0");
        let other = dir.join(".tile-00001.simplified.ply.qem-tmp-99999999-0");
        std::fs::write(&own, b"half").expect("write");
        std::fs::write(&other, b"half").expect("write");
        let tiles = TileDir::open(&dir).expect("open");
        tiles
            .simplify_tile(0, &ratio(0.5), &mut NoObserver)
            .expect("tile 0");
        if cfg!(target_os = "linux") {
            assert!(!own.exists());
        }
        assert!(other.exists());
    }

    #[test]
    fn a_stop_asked_writes_nothing() {
        struct Stop;
        impl Observer for Stop {
            fn should_stop(&mut self) -> bool {
                true
            }
        }
        let tmp = tempfile::tempdir().expect("a temporary directory");
        let input = grid_file(tmp.path(), 10);
        let dir = tmp.path().join("t");
        let e = split(&input, &dir, TileCount::Tiles(2), &mut Stop).expect_err("stopped");
        assert!(matches!(e, TilesError::Cancelled));
        assert!(!dir.join(MANIFEST_NAME).exists());
        split(&input, &dir, TileCount::Tiles(2), &mut NoObserver).expect("split");
        let tiles = TileDir::open(&dir).expect("open");
        let e = tiles
            .simplify_tile(0, &ratio(0.5), &mut Stop)
            .expect_err("stopped");
        assert!(matches!(e, TilesError::Cancelled));
        assert!(!dir.join(simplified_file(0)).exists());
        assert!(!dir.join(status_file(0)).exists());
    }
}
