//! The contraction loop: Garland–Heckbert pair contraction on any triangle input.
//!
//! validate → clean → build the store → face quadrics → vertex quadrics (+ border
//! planes) → candidate pairs (every edge, plus virtual pairs closer than t) → queue →
//! loop { pop the cheapest; skip it if stale; stop on the target or the error bound;
//! check it (locks, fold-over, topology); contract; merge the quadrics; re-cost the
//! pairs around the new vertex } → compact → report.
//!
//! Quadrics are computed in the normalised [`Frame`] of the cleaned input (coordinates
//! in `[-1, 1]`), while the store keeps world coordinates, so vertices that are never
//! moved come out bit for bit as they went in.
//!
//! Submodules, one job each: `options` (what a run may do), `report` (what it did),
//! `observer` (progress, cancellation, per-contraction events), `engine` (the loop),
//! `checks` (which contractions are allowed), `exact` (the inclusion–exclusion
//! bookkeeping of [`QuadricMode::Exact`]), `passes` (the pass-based order,
//! [`ContractionOrder::Passes`], on flat arrays instead of the store: the same checks
//! but no heap; [`SimplifyOptions::FAST`]), `pass_exact` (exact quadrics in that
//! order), `orientation` (the orientation check's index, both orders), `waivers`
//! (pairs the orientation check refused, in the pass-based order).

mod checks;
mod engine;
mod exact;
mod locality;
mod nth_key;
mod observer;
mod options;
mod orientation;
mod pass_blocks;
mod pass_exact;
mod passes;
mod report;
mod waivers;

pub use observer::{Contraction, NoObserver, Observer, Progress};
pub use options::{
    BoundaryMode, ContractionOrder, Length, PlacementMode, QuadricMode, SimplifyOptions, Target,
    VirtualPairs, Weighting, DEFAULT_BOUNDARY_WEIGHT, DEFAULT_MAX_NORMAL_ANGLE,
    DEFAULT_MIN_TRIANGLE_QUALITY, DEFAULT_WEIGHTING_MIX,
};
pub use report::{Simplified, SimplifyError, SimplifyReport, StopReason, Timings};

use crate::clean::{clean, CleanOptions, Cleaned};
use crate::store::build::kept_triangles;
use crate::store::{slot_index, BuildStats, FaceKey, MeshStore, SlotVec};
use crate::IndexedMesh;
use engine::{Counters, Engine};
use locality::{in_locality_order, in_original_order, Renumbered};
use passes::PassEngine;
use qem_core::{DVec3, Frame};
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
    let cleaned = clean(mesh, &options.clean);
    // Locked input vertices, renumbered like the cleaned mesh (unreferenced ones drop).
    let locked: Vec<u32> = options
        .locked_vertices
        .iter()
        .map(|&i| cleaned.vertex_map[i as usize])
        .filter(|&i| i != Cleaned::REMOVED)
        .collect();
    let cleanup = cleaned.report;
    if cleaned.mesh.triangles.is_empty() {
        return Err(SimplifyError::NothingLeftAfterCleaning {
            triangles_in: mesh.triangle_count(),
        });
    }
    timings.clean = clock.elapsed();

    let frame = Frame::from_points(cleaned.mesh.positions.iter().map(|p| DVec3::from_array(*p)));
    let mut run = match options.order {
        ContractionOrder::Greedy => {
            let (engine, numbers) = set_up_greedy(&cleaned, frame, &locked, options, &mut timings)?;
            Run::Greedy(engine, numbers)
        }
        ContractionOrder::Passes => {
            refuse_what_passes_lack(options, &frame)?;
            let clock = Instant::now();
            // As in the greedy setup: the orientation check's index on the other core.
            let (mut engine, input_surface) = rayon::join(
                || PassEngine::new(&cleaned.mesh, frame, &locked, options),
                || {
                    options
                        .orientation_check
                        .then(|| orientation::InputSurface::new(&cleaned.mesh, &frame))
                },
            );
            if let Some((surface, slots)) = input_surface {
                engine.set_input_surface(surface, &slots);
            }
            timings.setup = clock.elapsed();
            Run::Passes(engine)
        }
    };
    observer.cleaned(&cleaned.mesh, &frame);
    // The loop needs the cleaned mesh no more: gone before it starts (about 120 MB on
    // a 4M-triangle mesh), since it runs far longer than the setup and holds the most.
    drop(cleaned);

    let mut results = Vec::with_capacity(levels.len());
    let mut stopped_short: Option<StopReason> = None;
    for &level in levels {
        let target_triangles = target_count(level, mesh.triangle_count());
        let clock = Instant::now();
        let stop_reason = match stopped_short {
            Some(reason) => reason,
            None => run.run(target_triangles, options, observer)?,
        };
        if stop_reason != StopReason::TargetReached {
            stopped_short = Some(stop_reason);
        }
        timings.contract += clock.elapsed();

        let clock = Instant::now();
        let mut raw = run.to_mesh();
        // Zero area is judged in the loop's frame, not in the output's own (see
        // `Engine::is_zero_area`): the loop refused every contraction that would make a
        // face zero-area, so this drops only faces that came in so (cleaning passes off).
        let before = raw.triangles.len();
        raw.triangles
            .retain(|t| !run.is_zero_area(t.map(|i| raw.positions[i as usize])));
        let zero_area_dropped = before - raw.triangles.len();
        let final_clean = clean(&raw, &CleanOptions::OUTPUT.with_drop_zero_area(false));
        let out = final_clean.mesh;
        if out.triangles.is_empty() {
            return Err(SimplifyError::NothingLeftAfterCleaning {
                triangles_in: mesh.triangle_count(),
            });
        }
        timings.compact = clock.elapsed();

        let counters = run.counters();
        let report = SimplifyReport {
            triangles_in: mesh.triangle_count(),
            vertices_in: mesh.vertex_count(),
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
            rejected_degenerate: counters.rejected_degenerate,
            rejected_flip: counters.rejected_flip,
            rejected_sliver: counters.rejected_sliver,
            rejected_topology: counters.rejected_topology,
            rejected_locked: counters.rejected_locked,
            rejected_border: counters.rejected_border,
            rejected_merge: counters.rejected_merge,
            rejected_orientation: counters.rejected_orientation,
            locked_vertices: counters.locked_vertices,
            faces_flipped: run.flipped_faces(),
            timings,
        };
        results.push(Simplified { mesh: out, report });
    }
    Ok(results)
}

/// The greedy loop's store, quadrics, queue and (on the other core meanwhile) the
/// orientation check's index, built from the cleaned mesh in locality order (see
/// [`locality`]); and the cleaned number of each of the store's faces.
fn set_up_greedy(
    cleaned: &Cleaned,
    frame: Frame,
    locked: &[u32],
    options: &SimplifyOptions,
    timings: &mut Timings,
) -> Result<(Engine, CleanedNumbers), SimplifyError> {
    let clock = Instant::now();
    let Renumbered {
        mesh,
        vertex_from,
        vertex_to,
        triangle_from,
    } = in_locality_order(&cleaned.mesh, &frame);
    let (store, keys) = MeshStore::from_mesh(&mesh)?;
    timings.build = clock.elapsed();
    let locked: Vec<u32> = locked
        .iter()
        .filter_map(|&i| vertex_to.get(i as usize).copied())
        .collect();
    drop(vertex_to);

    // The store's faces are the triangles it kept, in order (it never adds one).
    let kept: Vec<u32> = if store.face_count() == mesh.triangles.len() {
        (0..mesh.triangles.len() as u32).collect()
    } else {
        kept_triangles(
            &mesh.triangles,
            mesh.positions.len(),
            &mut BuildStats::default(),
        )
    };
    let mut face_from = SlotVec::for_keys(store.faces(), u32::MAX);
    for (f, &t) in store.faces().zip(&kept) {
        face_from.set(f, triangle_from[t as usize]);
    }
    // The store holds its own copy: gone before the setup's peak.
    drop((mesh, kept));

    let mut engine = Engine::new(store, frame, options);
    let clock = Instant::now();
    // The orientation check's index is independent of the quadrics and queue: built on
    // the other core meanwhile (deterministic either way).
    let ((), input_surface) = rayon::join(
        || engine.initialise(&keys, &vertex_from, &locked, options),
        || {
            options
                .orientation_check
                .then(|| orientation::InputSurface::new(&cleaned.mesh, &frame))
        },
    );
    // Each face's search hint starts as its own input triangle.
    engine.input_surface = input_surface.map(|(mut surface, slots)| {
        surface.seed_hints(
            engine
                .store
                .faces()
                .map(|f| (slot_index(f), slots[*face_from.get(f) as usize])),
        );
        surface
    });
    timings.setup = clock.elapsed();
    let numbers = CleanedNumbers {
        vertex_count: cleaned.mesh.positions.len(),
        face_from,
    };
    Ok((engine, numbers))
}

/// What the greedy loop's output needs to be numbered back into the cleaned mesh's
/// numbers and order (its vertices carry their own, see `VertexState::index`).
struct CleanedNumbers {
    /// The cleaned mesh's vertex count.
    vertex_count: usize,
    /// The cleaned triangle each store face was made from.
    face_from: SlotVec<FaceKey, u32>,
}

/// [`SimplifyError::NotInPasses`] for the first option set that the pass-based order
/// does not implement.
fn refuse_what_passes_lack(options: &SimplifyOptions, frame: &Frame) -> Result<(), SimplifyError> {
    let lacking = if options.preserve_topology {
        Some("preserve_topology = true")
    } else if options.pair_threshold.normalized(frame) > 0.0 {
        Some("pair_threshold above zero (virtual pairs)")
    } else {
        None
    };
    match lacking {
        Some(option) => Err(SimplifyError::NotInPasses { option }),
        None => Ok(()),
    }
}

/// A run in either order, as the level loop of [`simplify_levels`] drives it.
// One value per run, made once: the size of the larger variant costs nothing.
#[allow(clippy::large_enum_variant)]
enum Run {
    /// The greedy loop, and how to number its output back.
    Greedy(Engine, CleanedNumbers),
    Passes(PassEngine),
}

impl Run {
    fn run(
        &mut self,
        target: usize,
        options: &SimplifyOptions,
        observer: &mut dyn Observer,
    ) -> Result<StopReason, SimplifyError> {
        match self {
            Run::Greedy(engine, _) => engine.run(target, options, observer),
            Run::Passes(engine) => Ok(engine.run(target, observer)),
        }
    }

    fn to_mesh(&self) -> IndexedMesh {
        match self {
            Run::Greedy(engine, numbers) => {
                let (mesh, keys) = engine.store.to_mesh_with_map();
                // Every live vertex has a state (its cleaned number).
                let vertex_from: Vec<u32> = keys.iter().map(|&v| engine.state[v].index).collect();
                let triangle_from: Vec<u32> = engine
                    .store
                    .faces()
                    .map(|f| *numbers.face_from.get(f))
                    .collect();
                in_original_order(mesh, numbers.vertex_count, &vertex_from, &triangle_from)
            }
            Run::Passes(engine) => engine.to_mesh(),
        }
    }

    /// Whether the loop counts a face with these world corners as zero-area (see
    /// `Engine::is_zero_area`).
    fn is_zero_area(&self, world_corners: [[f64; 3]; 3]) -> bool {
        match self {
            Run::Greedy(engine, _) => engine.is_zero_area(world_corners),
            Run::Passes(engine) => {
                checks::is_zero_area(&engine.frame, &engine.settings, world_corners)
            }
        }
    }

    fn counters(&self) -> Counters {
        match self {
            Run::Greedy(engine, _) => engine.counters,
            Run::Passes(engine) => engine.counters,
        }
    }

    fn flipped_faces(&self) -> usize {
        match self {
            Run::Greedy(engine, _) => engine.flipped_faces(),
            Run::Passes(engine) => engine.flipped_faces(),
        }
    }
}

/// The triangle count a target asks for, given the input's count as loaded.
fn target_count(target: Target, triangles_in: usize) -> usize {
    match target {
        Target::Triangles(n) => n,
        Target::Ratio(r) if r > 0.0 => (r.min(1.0) * triangles_in as f64).floor() as usize,
        Target::Ratio(_) => 0,
        Target::None => 0,
    }
}
