//! Simplification under a memory budget (`qem simplify --memory-budget`): a mesh whose
//! in-core run would not fit is cut into tiles on disk, each tile simplified with its
//! border locked, the tiles merged, and the merged mesh finished in one piece once it
//! fits.
//!
//! The plan, from the measured bytes a triangle of a whole in-core run
//! ([`IN_CORE_BYTES_PER_TRIANGLE`]):
//! - `room`: the triangles an in-core run can hold within the budget. A mesh of at most
//!   `room` triangles is simplified in core, as without a budget.
//! - Otherwise, a **round**: the mesh is split into tiles of at most `room` triangles
//!   (about, past 2^20 triangles: see [`TileCount::MaxTriangles`]; in a temporary
//!   directory: a file's first round as [`super::jobs::split`] cuts it, a mesh's as
//!   [`super::jobs::split_mesh`]), each tile is simplified
//!   to the ratio that leaves `keep = max(target, room × MERGED_SHARE)` triangles in
//!   all, and the tiles are merged. The merged mesh keeps each tile's border strip
//!   (the locked border vertices and their neighbours), which is why it aims below
//!   `room`.
//! - Rounds repeat until the merged mesh fits; then it is simplified in core to the
//!   target, with no border locked: the old borders' strips are simplified like the
//!   rest. (A later round cuts the merged mesh anew, so its tiles' borders fall
//!   elsewhere.)
//! - The in-core finish starts from the vertex quadrics the tiles ended with (their
//!   [`quadrics_file`](super::jobs::quadrics_file)s, in world units about a point
//!   near the mesh so that they keep their precision far from zero), not from
//!   quadrics summed anew from the merged mesh's faces: each vertex still stands for
//!   the part of the input surface it replaced. Only the tiles' border vertices,
//!   whose quadrics in the tiles hold the planes of the cut, have theirs summed from
//!   the faces around them (input faces still: their neighbours were locked too, so
//!   a mixed weighting's mean area is taken over those faces). The finish sums its
//!   quadrics (`QuadricMode::Sum`): which planes two carried quadrics share is not
//!   carried.
//!
//!   Measured on the 10M-triangle cube-sphere at ratio 0.01 (BENCHMARKS.md, "Under a
//!   memory budget"): quadrics summed anew gave a Hausdorff distance 31% above the
//!   in-core run's, carried ones 7% above it, the mean error within 2% either way. On
//!   the dragon the summed quadrics cost the mean error 5.5 to 7.6% (as `--quadrics
//!   sum` does in core). A second round cuts the merged mesh without its quadrics
//!   (the split writes meshes only), so its tiles sum theirs from the merged mesh's
//!   faces.
//!
//! Why not tile straight to the target: locked strips take a share of each tile's
//! budget that grows as the ratio falls, and tiles simplified far below it fold. On
//! the dragon in 8 tiles, tiles to 10% and then one piece to 1% gave a Hausdorff
//! distance of 0.384% and a mean of 0.0265% of the diagonal, in-core 0.393% and
//! 0.0274%; tiles straight to 4% gave 9.8% and 0.41% (BENCHMARKS.md, "Tiles").
//!
//! What holds memory at each step, besides the program: the input's vertices while
//! [`simplify_file_within`] streams a file's triangles to disk (or, given a mesh,
//! [`simplify_within`]'s input mesh), and the split's sample; then one tile of the
//! split (checked against the budget before a mesh in memory is split); one
//! tile's simplification; the merged mesh and its vertices' quadrics (80 bytes a
//! vertex, which become the finish's own quadrics); the in-core finish. The input's
//! attributes are not carried by tiles: a run that tiles drops them (the caller is
//! told, in [`BudgetRun::rounds`]).

use super::jobs::{
    merge_carrying, split_mesh, split_spilled, Source, SplitInput, TileCount, TileDir, TileOptions,
    TilesError,
};
use super::split::{Spill, Spilled};
use crate::io::{read_path, stream_path, IoError, ReadNotes};
use crate::simplify::{
    simplify_carrying, simplify_owned, CarriedQuadrics, Method, Observer, Simplified,
    SimplifyError, SimplifyOptions, Target,
};
use crate::IndexedMesh;
use std::path::Path;
use std::time::{Duration, Instant};

/// Bytes a triangle of a whole in-core `qem simplify` process with the contraction
/// engine, the most measured on a large closed mesh, rounded up: 255 (the defaults),
/// 183 (`--fast`) and 279 (`--order greedy`) on the versus bench's `sphere:1M` at
/// ratio 0.01; 220 and 227 with the defaults at 10M and 100M (BENCHMARKS.md,
/// "Memory budget").
pub const IN_CORE_BYTES_PER_TRIANGLE: u64 = 280;

/// Bytes a triangle of a whole in-core process with vertex clustering: 46 on
/// `sphere:1M` at ratio 0.01, rounded up.
pub const CLUSTER_BYTES_PER_TRIANGLE: u64 = 48;

/// Bytes of a process before its mesh: the program, the readers' and writers'
/// windows, the threads' stacks (a run on the 5,856-triangle cow peaks near 10 MB).
pub const FIXED_BYTES: u64 = 32 << 20;

/// What the split holds beside the mesh it cuts (`tiles::split`): while the triangles
/// go to disk, the cut's sample (32 bytes a centroid, at most
/// [`SAMPLE_CAP`](super::SAMPLE_CAP) of them); then, the mesh let go, the tiles' file
/// buffers ([`BUFFER_BYTES_PER_TILE`] a tile, [`MAX_BUFFER_BYTES`] in all at most) and
/// one tile at a time, whose positions' bits are sorted (72 bytes a tile triangle) and
/// which is then numbered and written (about 80 bytes a tile triangle, with its file's
/// bytes).
const SAMPLE_BYTES_PER_TRIANGLE: u64 = 32;
const BUFFER_BYTES_PER_TILE: u64 = 128 << 10;
const MAX_BUFFER_BYTES: u64 = 64 << 20;
const TILE_BYTES_PER_TRIANGLE: u64 = 80;

/// The share of `room` a round aims to leave, so that the merged mesh, border strips
/// and all, still fits.
const MERGED_SHARE: f64 = 0.8;

/// A budget leaving room for fewer triangles than this in core is refused: the tiles
/// would be all border.
const MIN_ROOM: usize = 10_000;

/// At most this many rounds of tiles (each must shrink the mesh, or the run stops as
/// [`BudgetError::Stuck`]; the runs measured needed one).
const MAX_ROUNDS: usize = 8;

/// One round of tiles.
#[derive(Clone, Debug, PartialEq)]
pub struct BudgetRound {
    /// Triangles in the mesh the round cut.
    pub triangles_in: usize,
    /// How many tiles.
    pub tiles: usize,
    /// The ratio each tile was simplified to.
    pub tile_ratio: f64,
    /// Triangles in the merged mesh.
    pub triangles_out: usize,
    /// Whether the mesh the round cut carried attributes (which tiles do not keep).
    pub attributes_dropped: bool,
}

/// What [`simplify_within`] did.
#[derive(Clone, Debug, PartialEq)]
pub struct BudgetRun {
    /// The last, in-core simplification: its mesh is the result. When rounds of tiles
    /// ran first, its report speaks of the merged mesh it started from
    /// (`triangles_in`); its `max_error` is that of its own contractions, on the
    /// quadrics the tiles carried over.
    pub result: Simplified,
    /// The rounds of tiles before it, none when the input fitted.
    pub rounds: Vec<BudgetRound>,
    /// The budget, in bytes.
    pub budget: u64,
    /// The triangles an in-core run can hold within it.
    pub room: usize,
    /// The triangle count asked of the input.
    pub target_triangles: usize,
}

/// Why [`simplify_within`] failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum BudgetError {
    /// The budget cannot hold a step of the run.
    #[error(
        "a memory budget of {} is too small for {what}: it needs about {}",
        megabytes(*budget),
        megabytes(*needed)
    )]
    TooSmall {
        /// The budget, in bytes.
        budget: u64,
        /// About how many bytes the step needs.
        needed: u64,
        /// The step.
        what: &'static str,
    },
    /// A tile job failed (a file of the temporary directory, or an option the tiles
    /// refuse).
    #[error(transparent)]
    Tiles(#[from] TilesError),
    /// The temporary directory could not be made.
    #[error(transparent)]
    Io(#[from] IoError),
    /// The in-core simplification failed.
    #[error(transparent)]
    Simplify(#[from] SimplifyError),
    /// A round of tiles did not shrink the mesh (its tiles all border).
    #[error(
        "the tiles of {triangles_in} triangles came back with {triangles_out}: \
         the budget leaves too little room for their borders"
    )]
    Stuck {
        /// Triangles the round cut.
        triangles_in: usize,
        /// Triangles it merged.
        triangles_out: usize,
    },
}

fn megabytes(bytes: u64) -> String {
    format!("{:.0} MB", bytes as f64 / 1e6)
}

/// Bytes a triangle of an in-core run with `options`.
fn bytes_per_triangle(options: &SimplifyOptions) -> u64 {
    match options.method {
        Method::Clustering => CLUSTER_BYTES_PER_TRIANGLE,
        _ => IN_CORE_BYTES_PER_TRIANGLE,
    }
}

/// About how many bytes a whole in-core run with `options` holds for `triangles`
/// input triangles (the estimate [`simplify_within`] decides by).
///
/// ```
/// use qem_mesh::simplify::SimplifyOptions;
/// use qem_mesh::tiles::budget::in_core_bytes;
/// let ten_million = in_core_bytes(10_000_000, &SimplifyOptions::DEFAULT);
/// assert!(ten_million > 2_000_000_000 && ten_million < 3_000_000_000);
/// ```
pub fn in_core_bytes(triangles: usize, options: &SimplifyOptions) -> u64 {
    FIXED_BYTES + bytes_per_triangle(options) * triangles as u64
}

/// Simplifies `input`'s mesh with `options` holding about `budget` bytes at most: in
/// core when it fits, else in rounds of tiles in a temporary directory made in
/// `scratch` (removed at the end, whatever the outcome) and an in-core finish (see the
/// [module docs](self)). The same input, options and budget give the same result, bit
/// for bit.
///
/// The tiles take what [`TileOptions`] takes: a ratio or no target (a count is asked
/// of the input as a ratio of it), no locked vertices, no virtual pairs; clustering
/// runs only in core. `observer` sees each tile's and the finish's simplification.
///
/// The budget is checked against the estimates above, not against the process's
/// measured memory: the figures in BENCHMARKS.md ("Under a memory budget") are the
/// measurement.
pub fn simplify_within(
    input: SplitInput,
    options: &SimplifyOptions,
    budget: u64,
    scratch: &Path,
    observer: &mut dyn Observer,
) -> Result<BudgetRun, BudgetError> {
    run(
        RoundInput::Mesh(input),
        None,
        options,
        budget,
        scratch,
        observer,
    )
}

/// What a round of tiles is cut from: a mesh in memory, or a file's triangles already
/// streamed to disk (the first round of [`simplify_file_within`]).
enum RoundInput {
    Mesh(SplitInput),
    Spilled(Source, Spilled),
}

impl RoundInput {
    fn triangles(&self) -> usize {
        match self {
            RoundInput::Mesh(input) => input.mesh.triangle_count(),
            RoundInput::Spilled(_, spilled) => spilled.triangles as usize,
        }
    }

    fn attributes_dropped(&self) -> bool {
        match self {
            RoundInput::Mesh(input) => !input.mesh.attributes.is_empty(),
            RoundInput::Spilled(source, _) => source.attributes_dropped,
        }
    }
}

/// [`simplify_within`] for a file, which it reads itself so that a file too large
/// to fit is never held: the file is streamed to disk as it is read (as `qem tiles
/// split` streams it: the reader holds its vertices, 24 bytes each, not its
/// triangles); when its triangles fit in core after all, the spill is let go and the
/// file is read again, as [`read_path`] reads it, and simplified in core (so a file
/// that fits is read twice). Otherwise its first round of tiles is cut from the spill.
/// The same file, options and budget give what [`simplify_within`] gives for the mesh
/// read from it.
pub fn simplify_file_within(
    input: &Path,
    options: &SimplifyOptions,
    budget: u64,
    scratch: &Path,
    observer: &mut dyn Observer,
) -> Result<FileBudgetRun, BudgetError> {
    let clock = Instant::now();
    let room = room_for(budget, options);
    let work = work_directory(scratch)?;
    let mut spill = Spill::create(work.path())?;
    let streamed = stream_path(input, &mut spill)?;
    let spilled = spill.finish()?;
    let source = Source::of_file(input, &streamed)?;
    let (triangles_in, vertices_in) = (streamed.triangles, streamed.vertices);
    if triangles_in <= room {
        drop(spilled);
        drop(work);
        let loaded = read_path(input)?;
        let load = clock.elapsed();
        let attributes = loaded.mesh.attributes.names();
        let (name, size_bytes) = source.file();
        let split = SplitInput {
            name,
            size_bytes,
            mesh: loaded.mesh,
        };
        let run = run(
            RoundInput::Mesh(split),
            None,
            options,
            budget,
            scratch,
            observer,
        )?;
        return Ok(FileBudgetRun {
            run,
            triangles_in,
            vertices_in,
            notes: loaded.notes,
            attributes,
            load,
        });
    }
    let load = clock.elapsed();
    let first = RoundInput::Spilled(source, spilled);
    Ok(FileBudgetRun {
        run: run(first, Some(work), options, budget, scratch, observer)?,
        triangles_in,
        vertices_in,
        notes: streamed.notes,
        attributes: streamed.attributes,
        load,
    })
}

/// What [`simplify_file_within`] did, and what it read.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct FileBudgetRun {
    /// The run.
    pub run: BudgetRun,
    /// The file's triangles, as read.
    pub triangles_in: usize,
    /// Its vertices, as read.
    pub vertices_in: usize,
    /// What the reader passed over.
    pub notes: ReadNotes,
    /// The names of the file's attributes ([`Attributes::names`](crate::attributes::Attributes::names)).
    pub attributes: Vec<String>,
    /// The time spent reading the file (streaming it, and reading it again when it
    /// fitted).
    pub load: Duration,
}

/// The triangles an in-core run with `options` can hold within `budget`.
fn room_for(budget: u64, options: &SimplifyOptions) -> usize {
    (budget.saturating_sub(FIXED_BYTES) / bytes_per_triangle(options)) as usize
}

/// A temporary directory for a run's files in `scratch`.
fn work_directory(scratch: &Path) -> Result<tempfile::TempDir, IoError> {
    tempfile::Builder::new()
        .prefix(".qem-budget-")
        .tempdir_in(scratch)
        .map_err(|source| IoError::File {
            path: scratch.to_path_buf(),
            action: "create a temporary directory in",
            source,
        })
}

/// The run from `first` (see [`simplify_within`]); `work` is the temporary directory
/// a spilled input is in (one is made in `scratch` when a mesh must be tiled).
fn run(
    first: RoundInput,
    work: Option<tempfile::TempDir>,
    options: &SimplifyOptions,
    budget: u64,
    scratch: &Path,
    observer: &mut dyn Observer,
) -> Result<BudgetRun, BudgetError> {
    let triangles_in = first.triangles();
    let target = options.target.triangles_for(triangles_in);
    let room = room_for(budget, options);
    let finish_target = match options.target {
        Target::None => Target::None,
        _ => Target::Triangles(target),
    };
    let mut rounds: Vec<BudgetRound> = Vec::new();
    let (mesh, carried) = match first {
        RoundInput::Mesh(input) if triangles_in <= room => (input.mesh, None),
        first => {
            if options.method == Method::Clustering {
                return Err(BudgetError::TooSmall {
                    budget,
                    needed: in_core_bytes(triangles_in, options),
                    what: "vertex clustering, which runs in one piece",
                });
            }
            if target > room {
                return Err(BudgetError::TooSmall {
                    budget,
                    needed: in_core_bytes(target, options),
                    what: "the last step, which holds the output's triangles in one piece",
                });
            }
            if room < MIN_ROOM {
                return Err(BudgetError::TooSmall {
                    budget,
                    needed: in_core_bytes(MIN_ROOM, options),
                    what: "tiles of at least 10,000 triangles",
                });
            }
            // Checked before any file is written: a tile job refuses the same options.
            TileOptions::new(options.clone().with_target(Target::Ratio(0.5)))
                .map_err(TilesError::from)?;
            if let RoundInput::Mesh(input) = &first {
                let needed = split_bytes(&input.mesh, room);
                if needed > budget {
                    return Err(BudgetError::TooSmall {
                        budget,
                        needed,
                        what: "cutting the mesh into tiles",
                    });
                }
            }
            let work = match work {
                Some(work) => work,
                None => work_directory(scratch)?,
            };
            let rounds = &mut rounds;
            let (mesh, quadrics) = tile_rounds(
                first, options, room, target, budget, &work, rounds, observer,
            )?;
            (mesh, Some(quadrics))
        }
    };
    let finish = options.clone().with_target(finish_target);
    let result = match carried {
        Some(carried) => {
            let origin = carried.origin;
            simplify_carrying(mesh, &finish, Some(carried), origin, observer)?.0
        }
        None => simplify_owned(mesh, &finish, observer)?,
    };
    Ok(BudgetRun {
        result,
        rounds,
        budget,
        room,
        target_triangles: target,
    })
}

/// Rounds of tiles in `work` until the merged mesh fits in `room` triangles: the first
/// cut from `first`, the later ones from the merged mesh of the round before. Returns
/// the last merged mesh and its vertices' quadrics; each round goes to `rounds`.
#[allow(clippy::too_many_arguments)]
fn tile_rounds(
    first: RoundInput,
    options: &SimplifyOptions,
    room: usize,
    target: usize,
    budget: u64,
    work: &tempfile::TempDir,
    rounds: &mut Vec<BudgetRound>,
    observer: &mut dyn Observer,
) -> Result<(IndexedMesh, CarriedQuadrics), BudgetError> {
    let mut input = first;
    loop {
        let dir = work.path().join(format!("round-{}", rounds.len() + 1));
        let (round, mesh, quadrics) = tile_round(input, options, room, target, &dir, observer)?;
        if round.triangles_out >= round.triangles_in {
            return Err(BudgetError::Stuck {
                triangles_in: round.triangles_in,
                triangles_out: round.triangles_out,
            });
        }
        // The round's files are not needed again: free the disk as we go.
        let _ = std::fs::remove_dir_all(&dir);
        rounds.push(round);
        if mesh.triangle_count() <= room {
            return Ok((mesh, quadrics));
        }
        if rounds.len() == MAX_ROUNDS {
            return Err(BudgetError::Stuck {
                triangles_in: round_in(rounds),
                triangles_out: mesh.triangle_count(),
            });
        }
        let needed = split_bytes(&mesh, room);
        if needed > budget {
            return Err(BudgetError::TooSmall {
                budget,
                needed,
                what: "cutting the mesh into tiles",
            });
        }
        // The split cuts meshes only: this round's quadrics are not needed again, and
        // not held through the next.
        drop(quadrics);
        input = RoundInput::Mesh(SplitInput {
            // What the next round's manifest names as its input: no file.
            name: format!("the merged tiles of round {}", rounds.len()),
            size_bytes: 0,
            mesh,
        });
    }
}

/// The triangles the last of `rounds` cut.
fn round_in(rounds: &[BudgetRound]) -> usize {
    rounds.last().map_or(0, |r| r.triangles_in)
}

/// About the bytes the split of `mesh` into tiles of at most `room` triangles holds:
/// the mesh and the cut's sample while its triangles go to disk, or (the mesh let go)
/// the routing buffers and one tile, whichever is more.
fn split_bytes(mesh: &IndexedMesh, room: usize) -> u64 {
    let (v, t) = (mesh.vertex_count() as u64, mesh.triangle_count() as u64);
    let sample = SAMPLE_BYTES_PER_TRIANGLE * t.min(super::SAMPLE_CAP as u64);
    let spilling = 24 * v + 12 * t + attribute_bytes(mesh) + sample;
    let tiles = t.div_ceil(room.max(1) as u64);
    let buffers = (BUFFER_BYTES_PER_TILE * (tiles + 1)).min(MAX_BUFFER_BYTES);
    let tiling = buffers + TILE_BYTES_PER_TRIANGLE * (room as u64).min(t);
    FIXED_BYTES + spilling.max(tiling)
}

/// The bytes of `mesh`'s attribute channels (values and corners).
fn attribute_bytes(mesh: &IndexedMesh) -> u64 {
    let channels = mesh.attributes.channels.iter();
    channels
        .map(|c| 4 * c.values.len() as u64 + 12 * c.corners.len() as u64)
        .sum()
}

/// One round: `input` split into tiles of at most `room` triangles in `dir`, each
/// simplified to leave `max(target, room × MERGED_SHARE)` triangles in all, merged;
/// the merged mesh comes with its vertices' quadrics.
fn tile_round(
    input: RoundInput,
    options: &SimplifyOptions,
    room: usize,
    target: usize,
    dir: &Path,
    observer: &mut dyn Observer,
) -> Result<(BudgetRound, IndexedMesh, CarriedQuadrics), BudgetError> {
    let (triangles_in, attributes_dropped) = (input.triangles(), input.attributes_dropped());
    let keep = target.max((room as f64 * MERGED_SHARE) as usize);
    let tile_ratio = keep as f64 / triangles_in as f64;
    let tile_options = TileOptions::new(options.clone().with_target(Target::Ratio(tile_ratio)))
        .map_err(TilesError::from)?;
    let count = TileCount::MaxTriangles(room);
    match input {
        RoundInput::Mesh(input) => split_mesh(input, dir, count, observer)?,
        RoundInput::Spilled(source, spilled) => {
            split_spilled(source, spilled, dir, count, observer)?
        }
    };
    let tiles = TileDir::open(dir)?;
    for k in 0..tiles.len() {
        tiles.simplify_tile(k, &tile_options, observer)?;
    }
    let (merged, quadrics, report) = merge_carrying(dir, observer)?;
    let round = BudgetRound {
        triangles_in,
        tiles: tiles.len(),
        tile_ratio,
        triangles_out: report.triangles_out,
        attributes_dropped,
    };
    Ok((round, merged, quadrics))
}
