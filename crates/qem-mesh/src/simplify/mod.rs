//! The contraction engine: Garland–Heckbert pair contraction on any triangle input.
//!
//! validate → clean → the working mesh in locality order (flat arrays: positions,
//! quadrics, triangles, the live triangles around each vertex) → face quadrics →
//! vertex quadrics (+ border planes or locks) → virtual pairs (closer than t) → the
//! order's loop { the next pair; its one attempt (lock order, placement, error bound,
//! checks, orientation and waiver, contraction, counters, event) }, and when no pair
//! passes every check, the ladder of relaxations ([`RelaxationStep`]) → compact →
//! report.
//!
//! The order is a policy of the one engine ([`ContractionOrder`]): `greedy` (a heap of
//! every pair, the cheapest first, the pairs at the new vertex re-costed) or `passes`
//! (each pass costs every pair and contracts the cheapest independent ones). Both run
//! the same attempt of a pair, the same checks and the same bookkeeping, and every
//! option works in both.
//!
//! Quadrics are computed in the normalised [`Frame`] of the cleaned input (coordinates
//! in `[-1, 1]`), while the engine keeps world coordinates (and computes a vertex's
//! normalised position from them when it reads one), so vertices that are never moved
//! come out bit for bit as they went in.
//!
//! Submodules, one job each: `options` (what a run may do), `settings` (options become
//! what the engine reads, in one place), `report` and `counters` (what it did),
//! `observer` (progress, cancellation, per-contraction events), `engine` (the working
//! mesh and its setup) with its children `attempt` (the one attempt sequence),
//! `passes` and `greedy` (the two orders), `pass_blocks` (the checks on the working
//! mesh, and the pass-based order's block workers), `incidence` (per-vertex lists that contractions merge),
//! `pair_set` and `pair_queue` (pairs that follow contractions, and the greedy queue),
//! `placement` (where a merged vertex goes), `pass_exact` (the bookkeeping of
//! [`QuadricMode::Exact`]), `checks` (the fold-over rules), `ladder` (the relaxations
//! when no pair passes every check) and `relaxation` (its steps and what the report
//! says of them), `orientation` (the
//! orientation check's index), `waivers` (pairs the orientation check refused),
//! `locality` (the vertex order), `nth_key` (the batch bound), `replay` (the store as
//! the engine's oracle).

mod carried;
mod checks;
mod counters;
mod engine;
mod incidence;
mod input_faces;
mod ladder;
mod locality;
mod nth_key;
mod observer;
mod options;
mod orientation;
mod pair_queue;
mod pair_set;
mod pass_blocks;
mod pass_exact;
mod placement;
mod relaxation;
mod replay;
mod report;
mod settings;
mod waivers;
mod wedges;

pub use observer::{Contraction, EdgeFlip, NoObserver, Observer, Phase, Progress};
pub use options::{
    AttributeWeights, BoundaryMode, ContractionOrder, Length, Method, PlacementMode, QuadricMode,
    SimplifyOptions, Target, VirtualPairs, Weighting, DEFAULT_BOUNDARY_WEIGHT,
    DEFAULT_MAX_NORMAL_ANGLE, DEFAULT_MIN_TRIANGLE_QUALITY, DEFAULT_WEIGHTING_MIX,
    SEAM_PLANE_WEIGHT,
};
pub use relaxation::{Constraint, Relaxation, RelaxationStep};
pub use replay::StoreReplay;
pub use report::{Refusals, Simplified, SimplifyError, SimplifyReport, StopReason, Timings};

#[cfg(all(test, feature = "io"))]
pub(crate) use carried::is_carried;
pub(crate) use carried::CarriedQuadrics;
#[cfg(feature = "io")]
pub(crate) use carried::NOT_CARRIED;

use crate::clean::{clean, CleanOptions, Cleaned};
use crate::IndexedMesh;
use carried::by_cleaned_vertex;
use engine::Engine;
use qem_core::{DVec3, Frame};
use std::borrow::Cow;
use std::time::Instant;

/// Simplifies `mesh` with `options`.
///
/// The output is always valid: every index in range, no face with a repeated vertex,
/// no zero-area face, finite coordinates, never more triangles than the input; and the
/// same input and options give the same output bit for bit.
///
/// ```
/// use qem_mesh::simplify::{simplify, SimplifyOptions, Target, StopReason};
/// use qem_mesh::IndexedMesh;
/// // A square pyramid without its base: 4 triangles around an apex.
/// let mesh = IndexedMesh::new(
///     vec![[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]],
///     vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
/// );
/// let out = simplify(&mesh, &SimplifyOptions::DEFAULT.with_target(Target::Triangles(2)))?;
/// assert!(out.mesh.triangle_count() <= 2);
/// assert_eq!(out.report.stop_reason, StopReason::TargetReached);
/// # Ok::<(), qem_mesh::simplify::SimplifyError>(())
/// ```
pub fn simplify(
    mesh: &IndexedMesh,
    options: &SimplifyOptions,
) -> Result<Simplified, SimplifyError> {
    simplify_observed(mesh, options, &mut NoObserver)
}

/// [`simplify`] with an observer for progress and cancellation.
pub fn simplify_observed(
    mesh: &IndexedMesh,
    options: &SimplifyOptions,
    observer: &mut dyn Observer,
) -> Result<Simplified, SimplifyError> {
    let mut levels = simplify_levels(mesh, options, &[options.target], observer)?;
    // One target in, one level out (simplify_levels returns one result per target).
    levels.pop().ok_or(SimplifyError::NothingLeftAfterCleaning {
        triangles_in: mesh.triangle_count(),
    })
}

/// [`simplify_observed`] for a caller that needs its mesh no more: the mesh is
/// dropped as soon as it is cleaned, before the setup and the loop (which hold the
/// most), where a borrowed mesh stays until the caller drops it: the input's positions
/// and triangles less at the peak, about 24 bytes a triangle (93 MB less on a
/// 4M-triangle sphere, BENCHMARKS.md "The whole process"). Same output, bit for bit.
/// (With [`Method::Clustering`] the mesh is held to the end: each level clusters the
/// input.)
///
/// ```
/// use qem_mesh::simplify::{simplify_observed, simplify_owned, NoObserver, SimplifyOptions, Target};
/// use qem_mesh::IndexedMesh;
/// let mesh = IndexedMesh::new(
///     vec![[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]],
///     vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
/// );
/// let options = SimplifyOptions::DEFAULT.with_target(Target::Triangles(2));
/// let borrowed = simplify_observed(&mesh, &options, &mut NoObserver)?;
/// let owned = simplify_owned(mesh, &options, &mut NoObserver)?;
/// assert_eq!(owned.mesh, borrowed.mesh);
/// # Ok::<(), qem_mesh::simplify::SimplifyError>(())
/// ```
pub fn simplify_owned(
    mesh: IndexedMesh,
    options: &SimplifyOptions,
    observer: &mut dyn Observer,
) -> Result<Simplified, SimplifyError> {
    let triangles_in = mesh.triangle_count();
    let (mut levels, _) = levels_of(
        Cow::Owned(mesh),
        options,
        &[options.target],
        observer,
        Carry::NONE,
    )?;
    levels
        .pop()
        .ok_or(SimplifyError::NothingLeftAfterCleaning { triangles_in })
}

/// What a run takes and gives of [`CarriedQuadrics`].
struct Carry {
    /// One per input vertex, replacing what the run would sum for it.
    seed: Option<CarriedQuadrics>,
    /// The origin the run hands its output vertices' quadrics back about, if it does.
    hand_back: Option<DVec3>,
}

impl Carry {
    const NONE: Carry = Carry {
        seed: None,
        hand_back: None,
    };
}

/// [`simplify_owned`] carrying vertex quadrics: `seed` (one per input vertex) replaces
/// the quadrics the run would sum from the faces, and the result comes with each output
/// vertex's quadric, in world units about `origin` (a point near the mesh). With a seed
/// the quadrics are summed ([`QuadricMode::Sum`]): the planes behind a carried quadric
/// are not known, so the planes a pair shares cannot be taken out of its merged
/// quadric. Not with [`Method::Clustering`], which has no vertex quadrics to hand
/// back (the tiles and the memory budget refuse it before any run).
// Outside the tests only the tile jobs call it, and they need `io`.
#[cfg_attr(not(feature = "io"), allow(dead_code))]
pub(crate) fn simplify_carrying(
    mesh: IndexedMesh,
    options: &SimplifyOptions,
    seed: Option<CarriedQuadrics>,
    origin: DVec3,
    observer: &mut dyn Observer,
) -> Result<(Simplified, CarriedQuadrics), SimplifyError> {
    debug_assert_ne!(options.method, Method::Clustering);
    let triangles_in = mesh.triangle_count();
    let options = match seed {
        Some(_) => Cow::Owned(options.clone().with_quadrics(QuadricMode::Sum)),
        None => Cow::Borrowed(options),
    };
    let carry = Carry {
        seed,
        hand_back: Some(origin),
    };
    let (mut levels, mut quadrics) = levels_of(
        Cow::Owned(mesh),
        &options,
        &[options.target],
        observer,
        carry,
    )?;
    match (levels.pop(), quadrics.pop()) {
        (Some(level), Some(quadrics)) => Ok((level, quadrics)),
        _ => Err(SimplifyError::NothingLeftAfterCleaning { triangles_in }),
    }
}

/// [`simplify_levels`] for a caller that needs its mesh no more, dropped as soon as
/// it is cleaned (see [`simplify_owned`]).
pub fn simplify_levels_owned(
    mesh: IndexedMesh,
    options: &SimplifyOptions,
    levels: &[Target],
    observer: &mut dyn Observer,
) -> Result<Vec<Simplified>, SimplifyError> {
    levels_of(Cow::Owned(mesh), options, levels, observer, Carry::NONE).map(|(levels, _)| levels)
}

/// A chain of levels of detail from one run: the loop contracts down to `levels[0]`,
/// takes a copy of the mesh, then *continues* from there to `levels[1]`, and so on, so
/// each level is a simplification of the previous one and the whole chain costs about
/// as much as the coarsest level alone. `options.target` is ignored; every other option
/// applies to every level.
///
/// Returns one [`Simplified`] per entry of `levels`, in order. Each level's report
/// describes the run up to that level: contraction counts and `max_error` are
/// cumulative, `timings.contract` is the loop time so far and `timings.compact` that
/// level's copy. Levels whose target is above the count already reached repeat the
/// previous mesh (with [`StopReason::TargetReached`]); once the loop stops short
/// (error bound, no pair, cancelled), the later levels repeat the last mesh with the
/// same stop reason.
///
/// ```
/// use qem_mesh::simplify::{simplify_levels, NoObserver, SimplifyOptions, Target};
/// use qem_mesh::IndexedMesh;
/// // A 4x4 grid of squares, 32 triangles.
/// let n = 5;
/// let positions = (0..n * n).map(|i| [(i % n) as f64, (i / n) as f64, ((i * 7) % 3) as f64]).collect();
/// let mut triangles = Vec::new();
/// for y in 0..n - 1 {
///     for x in 0..n - 1 {
///         let v = (y * n + x) as u32;
///         triangles.push([v, v + 1, v + n as u32]);
///         triangles.push([v + 1, v + n as u32 + 1, v + n as u32]);
///     }
/// }
/// let mesh = IndexedMesh::new(positions, triangles);
/// let levels = [Target::Ratio(0.5), Target::Ratio(0.25)];
/// let out = simplify_levels(&mesh, &SimplifyOptions::DEFAULT, &levels, &mut NoObserver)?;
/// assert_eq!(out.len(), 2);
/// assert!(out[0].mesh.triangle_count() <= 16);
/// assert!(out[1].mesh.triangle_count() <= out[0].mesh.triangle_count());
/// # Ok::<(), qem_mesh::simplify::SimplifyError>(())
/// ```
pub fn simplify_levels(
    mesh: &IndexedMesh,
    options: &SimplifyOptions,
    levels: &[Target],
    observer: &mut dyn Observer,
) -> Result<Vec<Simplified>, SimplifyError> {
    levels_of(Cow::Borrowed(mesh), options, levels, observer, Carry::NONE).map(|(levels, _)| levels)
}

/// [`simplify_levels`] on a borrowed or a handed-over mesh, with each level's output
/// vertices' quadrics when `carry` asks for them (else none).
fn levels_of(
    mesh: Cow<'_, IndexedMesh>,
    options: &SimplifyOptions,
    levels: &[Target],
    observer: &mut dyn Observer,
    carry: Carry,
) -> Result<(Vec<Simplified>, Vec<CarriedQuadrics>), SimplifyError> {
    if options.method == Method::Clustering {
        return Ok((cluster_levels(&mesh, options, levels)?, Vec::new()));
    }
    let mut timings = Timings::default();
    let clock = Instant::now();
    mesh.validate()?;
    if let Some(&index) = options
        .locked_vertices
        .iter()
        .find(|&&i| i as usize >= mesh.vertex_count())
    {
        return Err(SimplifyError::LockedVertexOutOfRange {
            index,
            vertex_count: mesh.vertex_count(),
        });
    }
    observer.phase(Phase::Cleaning);
    let cleaned = clean(&mesh, &options.clean);
    // Locked input vertices, renumbered like the cleaned mesh (unreferenced ones drop).
    let locked: Vec<u32> = options
        .locked_vertices
        .iter()
        .map(|&i| cleaned.vertex_map[i as usize])
        .filter(|&i| i != Cleaned::REMOVED)
        .collect();
    let cleanup = cleaned.report;
    let (triangles_in, vertices_in) = (mesh.triangle_count(), mesh.vertex_count());
    // A mesh handed over is needed no more: gone before the setup and the loop.
    drop(mesh);
    if cleaned.mesh.triangles.is_empty() {
        return Err(SimplifyError::NothingLeftAfterCleaning { triangles_in });
    }
    timings.clean = clock.elapsed();
    if observer.should_stop() {
        return Err(SimplifyError::Cancelled {
            after: Phase::Cleaning,
        });
    }

    let frame = Frame::from_points(cleaned.mesh.positions.iter().map(|p| DVec3::from_array(*p)));
    let clock = Instant::now();
    observer.phase(Phase::SettingUp);
    let seed = (carry.seed)
        .map(|seed| by_cleaned_vertex(seed, &cleaned.vertex_map, cleaned.mesh.vertex_count()));
    let mut engine = Engine::new(&cleaned.mesh, frame, &locked, options, seed);
    timings.setup = clock.elapsed();
    if observer.should_stop() {
        return Err(SimplifyError::Cancelled {
            after: Phase::SettingUp,
        });
    }
    observer.cleaned(&cleaned.mesh, &frame);
    // The loop needs the cleaned mesh no more: gone before it starts (about 120 MB on
    // a 4M-triangle mesh), since it runs far longer than the setup and holds the most.
    drop(cleaned);

    let mut results = Vec::with_capacity(levels.len());
    let mut quadrics = Vec::new();
    let mut stopped_short: Option<StopReason> = None;
    for (level_number, &level) in levels.iter().enumerate() {
        let target_triangles = level.triangles_for(triangles_in);
        let clock = Instant::now();
        observer.phase(Phase::Contracting);
        let stop_reason = match stopped_short {
            Some(reason) => reason,
            None => engine.run_order_with_ladder(options, target_triangles, observer),
        };
        // After the last level only: a later level's exact quadrics take a live
        // triangle's input plane to belong to its corners, and the greedy order keeps
        // its pairs from level to level; a flip changes both.
        if level_number + 1 == levels.len() {
            engine.turn_back_faces(observer);
        }
        if stop_reason != StopReason::TargetReached {
            stopped_short = Some(stop_reason);
        }
        timings.contract += clock.elapsed();

        let clock = Instant::now();
        observer.phase(Phase::Compacting);
        let mut raw = engine.to_mesh();
        let raw_quadrics = (carry.hand_back)
            .map(|origin| (origin, engine.output_quadrics(origin, options.weighting)));
        // Zero area is judged in the loop's frame, not in the output's own (see
        // `checks::is_zero_area`): the loop refused every contraction that would make a
        // face zero-area, so this drops only faces that came in so (cleaning passes off).
        let before = raw.triangles.len();
        let zero_area = |t: &[u32; 3]| {
            checks::is_zero_area(
                &engine.frame,
                &engine.settings,
                t.map(|i| raw.positions[i as usize]),
            )
        };
        if raw.attributes.is_empty() {
            raw.triangles.retain(|t| !zero_area(t));
        } else {
            // The attributes go with their faces.
            let kept: Vec<u32> = (0..before as u32)
                .filter(|&t| !zero_area(&raw.triangles[t as usize]))
                .collect();
            raw.triangles = kept.iter().map(|&t| raw.triangles[t as usize]).collect();
            raw.attributes = raw.attributes.for_faces(&kept);
        }
        let zero_area_dropped = before - raw.triangles.len();
        let final_clean = clean(&raw, &CleanOptions::OUTPUT.with_drop_zero_area(false));
        let out = final_clean.mesh;
        if out.triangles.is_empty() {
            return Err(SimplifyError::NothingLeftAfterCleaning { triangles_in });
        }
        timings.compact = clock.elapsed();

        let counters = engine.counters;
        let report = SimplifyReport {
            triangles_in,
            vertices_in,
            triangles_out: out.triangle_count(),
            vertices_out: out.vertex_count(),
            target_triangles,
            edge_contractions: counters.edge_contractions,
            virtual_contractions: counters.virtual_contractions,
            virtual_pairs: counters.virtual_pairs,
            virtual_pairs_capped: counters.virtual_pairs_capped,
            max_error: frame.distance_to_diagonal_fraction(counters.max_error),
            max_error_abs: frame.distance_to_world(counters.max_error),
            bbox_diagonal: frame.world_diagonal(),
            stop_reason,
            cleanup,
            degenerate_faces_removed: zero_area_dropped + final_clean.report.repeated_index_faces,
            rejected: counters.rejected,
            relaxations: engine.ladder.relaxations(),
            stopped_by: (stop_reason == StopReason::NoValidPair)
                .then_some(engine.ladder.stopped_by.unwrap_or(Constraint::NoPairs)),
            locked_vertices: counters.locked_vertices,
            faces_flipped: engine.flipped_faces(),
            faces_turned_back: counters.faces_turned_back,
            timings,
        };
        if let Some((origin, quadrics_of_raw)) = raw_quadrics {
            let of_raw = CarriedQuadrics {
                origin,
                quadrics: quadrics_of_raw,
            };
            let n = out.vertex_count();
            quadrics.push(by_cleaned_vertex(of_raw, &final_clean.vertex_map, n));
        }
        results.push(Simplified { mesh: out, report });
    }
    Ok((results, quadrics))
}

/// [`simplify_levels`] with [`Method::Clustering`]: each level clustered from the
/// input, reported in the engine's terms (no contraction, no cleaning pass; the
/// setup's time is the grid's search, the loop's the clustering itself).
fn cluster_levels(
    mesh: &IndexedMesh,
    options: &SimplifyOptions,
    levels: &[Target],
) -> Result<Vec<Simplified>, SimplifyError> {
    let refused = if options.preserve_topology {
        Some("preserve_topology")
    } else if !options.locked_vertices.is_empty() {
        Some("locked_vertices")
    } else if options.boundary == BoundaryMode::Locked {
        Some("boundary: Locked")
    } else if options.max_error.is_some() {
        Some("max_error")
    } else if levels.contains(&Target::None) {
        Some("target: None")
    } else {
        None
    };
    if let Some(option) = refused {
        return Err(SimplifyError::NotWithClustering { option });
    }
    let mut results = Vec::with_capacity(levels.len());
    for &level in levels {
        let target_triangles = level.triangles_for(mesh.triangle_count());
        let clustered = crate::cluster::cluster(mesh, target_triangles)?;
        let r = clustered.report;
        if clustered.mesh.triangles.is_empty() {
            return Err(SimplifyError::NothingLeftAfterCleaning {
                triangles_in: mesh.triangle_count(),
            });
        }
        let report = SimplifyReport {
            triangles_in: r.triangles_in,
            vertices_in: r.vertices_in,
            triangles_out: r.triangles_out,
            vertices_out: r.vertices_out,
            target_triangles,
            edge_contractions: 0,
            virtual_contractions: 0,
            virtual_pairs: 0,
            virtual_pairs_capped: 0,
            max_error: r.max_error,
            max_error_abs: r.max_error_abs,
            bbox_diagonal: r.bbox_diagonal,
            stop_reason: StopReason::TargetReached,
            cleanup: crate::clean::CleanReport::default(),
            degenerate_faces_removed: 0,
            rejected: Refusals::default(),
            relaxations: Vec::new(),
            stopped_by: None,
            locked_vertices: 0,
            faces_flipped: 0,
            faces_turned_back: 0,
            timings: Timings {
                setup: r.search,
                contract: r.build,
                ..Timings::default()
            },
        };
        results.push(Simplified {
            mesh: clustered.mesh,
            report,
        });
    }
    Ok(results)
}
