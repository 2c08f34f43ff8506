//! Vertex clustering: one vertex per cell of a uniform grid, placed at the optimum of
//! the cell's quadric, the grid chosen so that the output has about the asked number
//! of triangles.
//!
//! The method is Rossignac and Borrel's ("Multi-resolution 3D approximations for
//! rendering complex scenes", 1993) with the representative vertex of Lindstrom
//! ("Out-of-core simplification of large polygonal models", SIGGRAPH 2000): every input
//! triangle adds its plane's quadric to the cells of its corners, and each cell's vertex
//! goes where the sum of those squared distances is least (kept inside the cell). A
//! triangle survives when its three corners fall in three different cells; triangles
//! that fall on the same three cells are one output triangle. Choosing the grid by a
//! search on the triangle count follows meshoptimizer's `simplifySloppy`.
//!
//! What it is for: speed on any input (it never looks at connectivity, so soups,
//! non-manifold and unwelded input cost nothing extra, and it always reaches a count
//! near the target), at the price of topology (parts merge, holes close, thin parts
//! may collapse) and of the contraction engine's accuracy.
//!
//! Deterministic: the cells, the search and the output order depend only on the input;
//! the parallel counts are integers, and the floating-point sums run in pieces fixed
//! by the input, added in piece order (see `cell_quadrics`), so the bits are the same
//! on any number of threads.

use crate::clean::{clean, CleanOptions};
use crate::input::{IndexedMesh, InputError};
use qem_core::{minimize_by_cofactors, DVec3, Frame, Quadric};
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use std::time::{Duration, Instant};

/// Bits of each quantised coordinate: cells per axis are at most `2^CELL_BITS - 1`, so
/// a cell's three coordinates pack into one `u64` (63 bits).
const CELL_BITS: u32 = 21;

/// The largest number of cells along the longest axis of the box.
const MAX_RESOLUTION: u32 = (1 << CELL_BITS) - 1;

/// The search stops once a grid's count is within this fraction of the target.
const COUNT_TOLERANCE: f64 = 0.02;

/// At most this many grids are counted (each count reads every triangle once).
const MAX_GRIDS: usize = 24;

/// What [`cluster`] made, and how.
#[derive(Clone, Debug, PartialEq)]
pub struct Clustered {
    /// The simplified mesh: one vertex per occupied cell that a surviving triangle uses.
    pub mesh: IndexedMesh,
    /// What happened.
    pub report: ClusterReport,
}

/// What a clustering run did.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct ClusterReport {
    /// Triangles in the input.
    pub triangles_in: usize,
    /// Vertices in the input.
    pub vertices_in: usize,
    /// Triangles in the output.
    pub triangles_out: usize,
    /// Vertices in the output.
    pub vertices_out: usize,
    /// The count asked for.
    pub target_triangles: usize,
    /// Cells along the longest axis of the input's bounding box, in the grid chosen
    /// (not always a whole number: the grid is as fine as the count asks).
    pub resolution: f64,
    /// The edge of a cell, in model units.
    pub cell_size: f64,
    /// How many grids the search counted.
    pub grids_counted: usize,
    /// The largest RMS distance of a cell's vertex to the planes of the triangles that
    /// touch the cell, as a fraction of the bounding-box diagonal (the same measure as
    /// the contraction engine's `max_error`).
    pub max_error: f64,
    /// [`max_error`](Self::max_error) in model units.
    pub max_error_abs: f64,
    /// The diagonal of the bounding box of the vertices the triangles use.
    pub bbox_diagonal: f64,
    /// Time spent choosing the grid.
    pub search: Duration,
    /// Time spent placing the vertices and writing the output.
    pub build: Duration,
}

/// Simplifies `mesh` to about `target_triangles` triangles by vertex clustering (see
/// the module documentation).
///
/// The count reached is the one of the grid whose count is nearest the target among
/// those the search tried: within 5% on every corpus mesh whose target is 100
/// triangles or more (`tests/suite/cluster.rs`), closer on large meshes; a count the
/// grid cannot give (fewer triangles than the coarsest grid keeps, or a step between
/// neighbouring grids on a regular mesh) is approached as closely as the grids tried
/// allow. The output passes the same final cleaning as the contraction engine's
/// (no repeated-index, zero-area or duplicate face, no unreferenced vertex, as
/// [`CleanOptions::OUTPUT`] drops them); unlike it, it may have non-manifold edges.
///
/// ```
/// use qem_mesh::cluster::cluster;
/// use qem_mesh::IndexedMesh;
/// // A 40 x 40 grid of squares, two triangles each.
/// let n = 40;
/// let positions = (0..=n)
///     .flat_map(|y| (0..=n).map(move |x| [x as f64, y as f64, 0.0]))
///     .collect();
/// let at = |x: u32, y: u32| y * (n + 1) + x;
/// let triangles = (0..n)
///     .flat_map(|y| (0..n).flat_map(move |x| {
///         [[at(x, y), at(x + 1, y), at(x + 1, y + 1)], [at(x, y), at(x + 1, y + 1), at(x, y + 1)]]
///     }))
///     .collect();
/// let out = cluster(&IndexedMesh::new(positions, triangles), 320)?;
/// // A flat grid of squares is the hardest case: the count steps by whole rows of
/// // cells (338 here).
/// let got = out.mesh.triangle_count() as f64;
/// assert!((got - 320.0).abs() <= 0.1 * 320.0, "{got}");
/// # Ok::<(), qem_mesh::InputError>(())
/// ```
pub fn cluster(mesh: &IndexedMesh, target_triangles: usize) -> Result<Clustered, InputError> {
    mesh.validate()?;
    let start = Instant::now();
    let used = used_vertices(mesh);
    let frame = used_frame(mesh, &used);
    let quantised = quantise(mesh, &frame);
    let (grid, grids_counted) = choose_grid(mesh, &quantised, target_triangles);
    let search = start.elapsed();

    let start = Instant::now();
    let (out, max_error) = build(mesh, &quantised, &used, grid, &frame);
    let build = start.elapsed();
    let diagonal = frame.world_diagonal();
    let report = ClusterReport {
        triangles_in: mesh.triangle_count(),
        vertices_in: mesh.vertex_count(),
        triangles_out: out.triangle_count(),
        vertices_out: out.vertex_count(),
        target_triangles,
        resolution: resolution_value(grid.resolution),
        cell_size: frame.distance_to_world(NORMALISED_SPAN / resolution_value(grid.resolution)),
        grids_counted,
        max_error: frame.distance_to_diagonal_fraction(max_error),
        max_error_abs: frame.distance_to_world(max_error),
        bbox_diagonal: diagonal,
        search,
        build,
    };
    Ok(Clustered { mesh: out, report })
}

/// The span of the longest axis of the box in the normalised frame (`[-1, 1]`).
const NORMALISED_SPAN: f64 = 2.0;

/// Which vertices some triangle uses (the mesh is validated).
fn used_vertices(mesh: &IndexedMesh) -> Vec<bool> {
    let mut used = vec![false; mesh.vertex_count()];
    for t in &mesh.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    used
}

/// The normalised frame of the box of the `used` vertices (an unused far-off vertex
/// would otherwise stretch the grid).
fn used_frame(mesh: &IndexedMesh, used: &[bool]) -> Frame {
    Frame::from_points(
        mesh.positions
            .iter()
            .zip(used)
            .filter(|(_, &u)| u)
            .map(|(p, _)| DVec3::from_array(*p)),
    )
}

/// Where cells start on every axis, in the normalised frame: the frame centres the
/// box and scales its longest half-axis to 1, so every coordinate is at least -1 (the
/// shorter axes use fewer cells).
const LOW: f64 = -1.0;

/// Each vertex's normalised position as three integers in `[0, 2^CELL_BITS)`, all axes
/// on the scale of the longest one (so cells are cubes). A vertex no triangle uses
/// gets whatever its position gives, clamped; it is never asked.
fn quantise(mesh: &IndexedMesh, frame: &Frame) -> Vec<[u32; 3]> {
    let lo = DVec3::splat(LOW);
    let scale = f64::from(1u32 << CELL_BITS) / NORMALISED_SPAN;
    let top = f64::from(MAX_RESOLUTION);
    mesh.positions
        .par_iter()
        .map(|&p| {
            let n = frame.to_normalized(DVec3::from_array(p)) - lo;
            [n.x, n.y, n.z].map(|x| (x * scale).clamp(0.0, top) as u32)
        })
        .collect()
}

/// A grid's resolution, cells along the longest axis, in fixed point with
/// [`FRACTION_BITS`] bits after the point: a fractional resolution lets the search
/// reach counts between those of whole numbers of cells.
type Resolution = u64;

/// A grid: its resolution, and how far its cells are shifted from the box's corner
/// (in quantised units, less than a cell, the same on every axis).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Grid {
    resolution: Resolution,
    shift: u32,
}

impl Grid {
    /// The unshifted grid of `resolution`.
    fn of(resolution: Resolution) -> Grid {
        Grid {
            resolution,
            shift: 0,
        }
    }
}

/// Bits after the point of a [`Resolution`].
const FRACTION_BITS: u32 = 16;

/// The coarsest grid: one cell along the longest axis.
const ONE_CELL: Resolution = 1 << FRACTION_BITS;

/// The finest grid.
const FINEST: Resolution = (MAX_RESOLUTION as u64) << FRACTION_BITS;

/// A resolution as a number of cells.
fn resolution_value(r: Resolution) -> f64 {
    r as f64 / ONE_CELL as f64
}

/// The cell of a quantised point in `grid`, packed in one integer. (The shifted
/// coordinate is below `2^22` and the resolution below `2^37`: no overflow; a shift is
/// only used on grids of fewer than `2^20` cells, so each cell coordinate stays below
/// `2^21`.)
#[inline]
fn cell_of(q: [u32; 3], grid: Grid) -> u64 {
    let c = q.map(|x| (u64::from(x + grid.shift) * grid.resolution) >> (CELL_BITS + FRACTION_BITS));
    c[0] | (c[1] << CELL_BITS) | (c[2] << (2 * CELL_BITS))
}

/// Whether a triangle's corners fall in three different cells (it survives).
#[inline]
fn three_cells(c: [u64; 3]) -> bool {
    c[0] != c[1] && c[1] != c[2] && c[0] != c[2]
}

/// The triangle's three cells, when they are three different ones.
#[inline]
fn surviving(t: [u32; 3], quantised: &[[u32; 3]], grid: Grid) -> Option<[u64; 3]> {
    let c = t.map(|v| cell_of(quantised[v as usize], grid));
    three_cells(c).then_some(c)
}

/// The triple of cells as a key that does not depend on the corners' order.
#[inline]
fn unordered(mut c: [u64; 3]) -> [u64; 3] {
    c.sort_unstable();
    c
}

/// How many of `triangles` survive a grid (three different cells), before duplicates
/// are merged: one read of each triangle, on all cores.
fn raw_count(triangles: &[[u32; 3]], quantised: &[[u32; 3]], grid: Grid) -> usize {
    triangles
        .par_iter()
        .filter(|&&t| surviving(t, quantised, grid).is_some())
        .count()
}

/// How many distinct output triangles a grid gives (duplicates merged).
fn distinct_count(mesh: &IndexedMesh, quantised: &[[u32; 3]], grid: Grid) -> usize {
    let mut triples: Vec<[u64; 3]> = mesh
        .triangles
        .par_iter()
        .filter_map(|&t| surviving(t, quantised, grid).map(unordered))
        .collect();
    triples.par_sort_unstable();
    triples.dedup();
    triples.len()
}

/// How far a count is from `goal`: an empty output is never a good answer while a
/// grid keeps some triangle.
fn off(count: usize, goal: f64) -> f64 {
    if count == 0 {
        f64::INFINITY
    } else {
        (count as f64 - goal).abs()
    }
}

/// The grid for `target` distinct triangles, and how many grids were counted.
///
/// Two searches: the first on the cheap count before duplicates are merged (every
/// triangle read once per grid, on all cores; on a large mesh, every
/// [`SAMPLE_STRIDE`]-th triangle only), the second, from where the first ended, on the
/// distinct count, which is what the output has (duplicates appear as the cells grow:
/// two triangles across the same three cells); then, if still off, shifted grids.
///
/// Why the sample alone before the distinct search on a large mesh: the full count
/// before merging added two or three counts of every triangle for a guess the distinct
/// search then had to correct anyway (dragon at 0.01: 56 ms against 38 ms in all,
/// medians of 7, `versus --cluster`).
fn choose_grid(mesh: &IndexedMesh, quantised: &[[u32; 3]], target: usize) -> (Grid, usize) {
    let goal = target.max(1) as f64;
    let mut counted = 0;
    let first_guess = ((goal / 2.0).sqrt() * ONE_CELL as f64) as Resolution;
    // On a large mesh every SAMPLE_STRIDE-th triangle (its count times the stride):
    // a few counts at a fraction of the cost bring the guess close.
    let (raw, _) = if mesh.triangle_count() >= SAMPLE_STRIDE * SAMPLE_STRIDE * 1024 {
        let sample: Vec<[u32; 3]> = mesh
            .triangles
            .iter()
            .step_by(SAMPLE_STRIDE)
            .copied()
            .collect();
        let count = |r| SAMPLE_STRIDE * raw_count(&sample, quantised, Grid::of(r));
        search(count, first_guess, goal, &mut counted)
    } else {
        let count = |r| raw_count(&mesh.triangles, quantised, Grid::of(r));
        search(count, first_guess, goal, &mut counted)
    };
    let distinct = |r| distinct_count(mesh, quantised, Grid::of(r));
    let (resolution, mut count) = search(distinct, raw, goal, &mut counted);
    // Still off: the count jumps between neighbouring resolutions (a coarse grid on a
    // small mesh); shifted grids of the same resolution give other counts.
    let mut grid = Grid::of(resolution);
    if off(count, goal) > COUNT_TOLERANCE * goal && resolution < (1 << (20 + FRACTION_BITS)) {
        let cell = ((1u64 << (CELL_BITS + FRACTION_BITS)) / resolution.max(1)) as u32;
        for k in 1..SHIFTS {
            let shifted = Grid {
                resolution,
                shift: cell / SHIFTS * k,
            };
            let c = distinct_count(mesh, quantised, shifted);
            counted += 1;
            if off(c, goal) < off(count, goal) {
                (grid, count) = (shifted, c);
            }
        }
    }
    (grid, counted)
}

/// The stride of the sampled first search of [`choose_grid`] (on meshes of at least
/// `SAMPLE_STRIDE² · 1024` triangles, where the sample still holds thousands).
const SAMPLE_STRIDE: usize = 8;

/// How many shifted grids (the unshifted one included) are tried when the search
/// could not get within [`COUNT_TOLERANCE`].
const SHIFTS: u32 = 16;

/// The resolution whose `count` is nearest `goal` among those tried, and that count,
/// starting from
/// `guess`; `counted` grows by the grids counted. The search ends within
/// [`COUNT_TOLERANCE`] of the goal, after [`MAX_GRIDS`] counts, or when the bracket
/// closes.
///
/// The count grows about as the square of the resolution on a surface (the cells a
/// surface crosses), so each step guesses from the last two counts on a log-log line
/// (a secant; the slope 2 before there are two), kept inside the bracket of
/// resolutions known to give too few and too many; a guess that would not move, or
/// would leave the bracket, bisects it instead.
fn search(
    count: impl Fn(Resolution) -> usize,
    guess: Resolution,
    goal: f64,
    counted: &mut usize,
) -> (Resolution, usize) {
    let mut below = ONE_CELL; // known to give too few (or the coarsest grid)
    let mut above = FINEST + 1; // known to give too many (or past the finest)
    let mut guess = guess.clamp(ONE_CELL, FINEST);
    let mut best: Option<(Resolution, usize)> = None;
    let mut last: Option<(Resolution, usize)> = None;
    for _ in 0..MAX_GRIDS {
        let c = count(guess);
        *counted += 1;
        if best.is_none_or(|(_, b)| off(c, goal) < off(b, goal)) {
            best = Some((guess, c));
        }
        if off(c, goal) <= COUNT_TOLERANCE * goal {
            break;
        }
        if (c as f64) < goal {
            below = below.max(guess);
        } else {
            above = above.min(guess);
        }
        if above <= below + 1 {
            break;
        }
        let slope = match last {
            Some((g0, c0)) if g0 != guess && c0 > 0 && c > 0 => {
                let s =
                    ((c as f64).ln() - (c0 as f64).ln()) / ((guess as f64).ln() - (g0 as f64).ln());
                if s.is_finite() && s > 0.25 {
                    s
                } else {
                    2.0
                }
            }
            _ => 2.0,
        };
        last = Some((guess, c));
        let next = if c > 0 {
            guess as f64 * (goal / c as f64).powf(1.0 / slope)
        } else {
            guess as f64 * 2.0
        };
        let mut next = if next.is_finite() {
            next.round().clamp(ONE_CELL as f64, FINEST as f64) as Resolution
        } else {
            guess
        };
        if next <= below || next >= above || next == guess {
            next = below + (above.min(FINEST) - below) / 2;
            if next == guess || next <= below {
                break;
            }
        }
        guess = next;
    }
    best.expect("the loop counts at least one grid")
}

/// The output of the grid of `resolution`, and the largest RMS distance of a cell's
/// vertex to its planes, in normalised units.
fn build(
    mesh: &IndexedMesh,
    quantised: &[[u32; 3]],
    used: &[bool],
    grid: Grid,
    frame: &Frame,
) -> (IndexedMesh, f64) {
    let cells: Vec<u64> = quantised.par_iter().map(|&q| cell_of(q, grid)).collect();
    // The surviving triangles in input order (on all cores), then each distinct triple
    // once: its first triangle.
    let survivors: Vec<(u32, [u64; 3])> = (0..mesh.triangle_count() as u32)
        .into_par_iter()
        .filter_map(|i| {
            let c = mesh.triangles[i as usize].map(|v| cells[v as usize]);
            three_cells(c).then_some((i, c))
        })
        .collect();
    let mut order: Vec<([u64; 3], u32)> = survivors
        .par_iter()
        .enumerate()
        .map(|(k, &(_, c))| (unordered(c), k as u32))
        .collect();
    order.par_sort_unstable();
    let mut first = vec![false; survivors.len()];
    for (i, &(key, k)) in order.iter().enumerate() {
        first[k as usize] = i == 0 || order[i - 1].0 != key;
    }
    drop(order);
    // The cells numbered in the order the kept triangles first use them.
    let mut number: FxHashMap<u64, u32> = FxHashMap::default();
    let triangles: Vec<[u32; 3]> = survivors
        .iter()
        .zip(&first)
        .filter(|(_, &f)| f)
        .map(|(&(_, c), _)| {
            c.map(|cell| {
                let next = number.len() as u32;
                *number.entry(cell).or_insert(next)
            })
        })
        .collect();
    drop((survivors, first));
    let cell_count = number.len();
    // Each vertex's output number (`NONE` when its cell has no vertex).
    let vertex_id: Vec<u32> = cells
        .par_iter()
        .map(|cell| number.get(cell).copied().unwrap_or(NONE))
        .collect();
    let quadrics = cell_quadrics(mesh, frame, &vertex_id, cell_count);
    let means = cell_means(mesh, frame, used, &vertex_id, cell_count);
    // Each cell's corner, from its packed coordinates.
    let cell_size = NORMALISED_SPAN / resolution_value(grid.resolution);
    // Where the cells start: the grid's shift, in normalised units.
    let origin = LOW - f64::from(grid.shift) * NORMALISED_SPAN / f64::from(1u32 << CELL_BITS);
    let mut corners = vec![DVec3::ZERO; cell_count];
    for (&cell, &id) in &number {
        let c = [0, 1, 2].map(|k| (cell >> (k * CELL_BITS)) & u64::from(MAX_RESOLUTION));
        corners[id as usize] =
            DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * cell_size + DVec3::splat(origin);
    }
    drop(number);
    // Each cell's vertex: the optimum of its quadric plus a faint pull toward the mean
    // of its vertices (where the planes leave a direction free, a flat or straight
    // patch, the vertex stays at the mean instead of anywhere on the plane or line),
    // kept inside the cell. On all cores: each cell reads only its own.
    let placed: Vec<([f64; 3], f64)> = (0..cell_count)
        .into_par_iter()
        .map(|id| {
            let (q, mean, corner) = (quadrics[id], means[id], corners[id]);
            let pull = Quadric::from_point(mean, q.weight().max(f64::MIN_POSITIVE) * MEAN_PULL);
            let p = minimize_by_cofactors(&(q + pull))
                .filter(|p| p.is_finite())
                .unwrap_or(mean)
                .clamp(corner, corner + DVec3::splat(cell_size));
            let error = q.rms_distance(q.evaluate(p).max(0.0));
            (frame.to_world(p).to_array(), error)
        })
        .collect();
    let max_error = placed.iter().map(|&(_, e)| e).fold(0.0, f64::max);
    let positions = placed.into_iter().map(|(p, _)| p).collect();
    // Faces whose cell vertices came out (nearly) collinear, as the engine's own
    // output cleaning drops them; no weld (vertices of different cells stay apart).
    let out = clean(
        &IndexedMesh::new(positions, triangles),
        &CleanOptions::OUTPUT,
    )
    .mesh;
    (out, max_error)
}

/// No output vertex.
const NONE: u32 = u32::MAX;

/// How many pieces of [`cell_quadrics`]'s work run at once (each with its own table).
const PIECES_AT_ONCE: usize = 4;

/// Triangles per piece of [`cell_quadrics`]'s work (at least; see there). A fixed size, so the pieces, and
/// the order their sums are added in, do not depend on the number of threads.
const QUADRIC_CHUNK: usize = 1 << 18;

/// Each output cell's quadric: the planes of every input triangle with a corner in it
/// (collapsed ones included: they say where the surface was), area weighted, once per
/// cell however many corners it holds.
///
/// The triangles are summed in fixed pieces on all cores, each piece into its own
/// table, and the tables added in piece order: the same bits on any number of
/// threads (the pieces depend only on the input and the cell count).
fn cell_quadrics(
    mesh: &IndexedMesh,
    frame: &Frame,
    vertex_id: &[u32],
    cell_count: usize,
) -> Vec<Quadric> {
    let normalised = |v: u32| frame.to_normalized(DVec3::from_array(mesh.positions[v as usize]));
    let partial = |piece: &[[u32; 3]]| {
        let mut sums = vec![Quadric::ZERO; cell_count];
        for t in piece {
            let ids = t.map(|v| vertex_id[v as usize]);
            if ids == [NONE; 3] {
                continue;
            }
            let q = Quadric::from_triangle(normalised(t[0]), normalised(t[1]), normalised(t[2]));
            for k in 0..3 {
                if ids[k] != NONE && !ids[..k].contains(&ids[k]) {
                    sums[ids[k] as usize] += q;
                }
            }
        }
        sums
    };
    // A piece holds at least as many triangles as there are cells, so its table is no
    // larger than its share of the input; and only PIECES_AT_ONCE tables are held at
    // a time.
    let piece = QUADRIC_CHUNK.max(cell_count);
    let mut total: Option<Vec<Quadric>> = None;
    let pieces: Vec<&[[u32; 3]]> = mesh.triangles.chunks(piece).collect();
    for group in pieces.chunks(PIECES_AT_ONCE) {
        let sums: Vec<Vec<Quadric>> = group.par_iter().map(|p| partial(p)).collect();
        for sum in sums {
            match &mut total {
                None => total = Some(sum),
                Some(total) => total
                    .par_iter_mut()
                    .zip(sum.par_iter())
                    .for_each(|(t, q)| *t += *q),
            }
        }
    }
    total.unwrap_or_else(|| vec![Quadric::ZERO; cell_count])
}

/// Each output cell's mean vertex (of the input vertices in it that some triangle
/// uses), in input order.
fn cell_means(
    mesh: &IndexedMesh,
    frame: &Frame,
    used: &[bool],
    vertex_id: &[u32],
    cell_count: usize,
) -> Vec<DVec3> {
    let mut sums = vec![(DVec3::ZERO, 0u32); cell_count];
    for (v, p) in mesh.positions.iter().enumerate() {
        let id = vertex_id[v];
        if used[v] && id != NONE {
            let s = &mut sums[id as usize];
            s.0 += frame.to_normalized(DVec3::from_array(*p));
            s.1 += 1;
        }
    }
    sums.into_iter()
        .map(|(sum, n)| sum / f64::from(n.max(1)))
        .collect()
}

/// The weight of the pull toward a cell's mean vertex, per unit of the cell's plane
/// weight: far too faint to move the vertex along a direction the planes fix, strong
/// enough to settle the directions they leave free.
const MEAN_PULL: f64 = 1e-6;
