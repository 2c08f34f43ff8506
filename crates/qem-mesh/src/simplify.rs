//! The contraction loop: Garland–Heckbert pair contraction on any triangle input.
//!
//! validate → clean → build the store → face quadrics → vertex quadrics → candidate
//! pairs (every edge, plus virtual pairs closer than t) → queue → loop { pop the
//! cheapest; skip it if stale; stop on the target or the error bound; contract; sum the
//! quadrics; re-cost the pairs around the new vertex } → compact → report.
//!
//! Quadrics are computed in the normalised [`Frame`] of the cleaned input (coordinates
//! in `[-1, 1]`), while the store keeps world coordinates, so vertices that are never
//! moved come out bit for bit as they went in.

use crate::clean::{clean, cross_underflows, min_double_area, CleanOptions, CleanReport};
use crate::pairs::grid::{virtual_pairs, GridOptions};
use crate::queue::{Candidate, PairQueue};
use crate::store::{FaceKey, MeshStore, StoreError, VertexKey};
use crate::{IndexedMesh, InputError};
use qem_core::{endpoint_placement, optimal_placement, DVec3, Frame, Placement, Quadric};
use slotmap::SecondaryMap;
use smallvec::SmallVec;
use std::fmt;
use std::time::{Duration, Instant};

/// A length given either relative to the input or in model units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Length {
    /// A fraction of the input's bounding-box diagonal (0.01 = 1% of the diagonal).
    DiagonalFraction(f64),
    /// A distance in the input's own units.
    Absolute(f64),
}

impl Length {
    /// This length in the normalised units of `frame`; negative or NaN becomes 0.
    fn normalized(self, frame: &Frame) -> f64 {
        let d = match self {
            Length::DiagonalFraction(f) => frame.diagonal_fraction_to_distance(f),
            Length::Absolute(d) => frame.distance_to_normalized(d),
        };
        if d > 0.0 {
            d
        } else {
            0.0
        }
    }
}

/// How many triangles to aim for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Target {
    /// Stop at or below this many triangles.
    Triangles(usize),
    /// Stop at or below this fraction of the input's triangles (as given, before
    /// cleaning), rounded down.
    Ratio(f64),
    /// No count target: contract until the error bound or until no pair is left.
    None,
}

/// How the new vertex of a contracted pair is placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlacementMode {
    /// The quadric's minimum, with Garland–Heckbert's fallback chain (segment, then
    /// ends and midpoint).
    Optimal,
    /// Only the cheapest of the two ends and the midpoint.
    EndpointOrMidpoint,
}

/// How face planes are weighted in the vertex quadrics.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Weighting {
    /// By triangle area (large faces count more than slivers).
    Area,
    /// Every face plane with weight 1.
    Unweighted,
}

/// Options of a simplification. Start from [`SimplifyOptions::DEFAULT`] and adjust
/// with the `with_*` setters.
///
/// ```
/// use qem_mesh::simplify::{Length, SimplifyOptions, Target};
/// let options = SimplifyOptions::DEFAULT
///     .with_target(Target::Ratio(0.1))
///     .with_max_error(Some(Length::DiagonalFraction(0.001)));
/// assert_eq!(options.target, Target::Ratio(0.1));
/// ```
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SimplifyOptions {
    /// The triangle count to reach. Default: `Target::Ratio(0.5)`.
    pub target: Target,
    /// Stop before the first contraction whose error would exceed this distance (see
    /// [`SimplifyReport::max_error`] for what the error measures). Default: `None`.
    pub max_error: Option<Length>,
    /// Vertex pairs closer than this that share no edge are candidates too ("virtual
    /// pairs"), so separate parts can merge; zero means edges only. Default:
    /// `Length::DiagonalFraction(0.0)`.
    pub pair_threshold: Length,
    /// At most this many virtual pairs per vertex, the nearest first. Default: 8.
    pub max_virtual_pairs_per_vertex: usize,
    /// Where the new vertex goes. Default: `PlacementMode::Optimal`.
    pub placement: PlacementMode,
    /// How face planes are weighted. Default: `Weighting::Area`.
    pub weighting: Weighting,
    /// The cleaning passes run before simplification. Default: `CleanOptions::DEFAULT`.
    pub clean: CleanOptions,
    /// Run the store's full invariant check ([`MeshStore::validate`]) after every
    /// contraction and fail with [`SimplifyError::Internal`] if it breaks. For tests:
    /// it costs O(n) per contraction. Default: `false`.
    pub validate_each_contraction: bool,
}

impl SimplifyOptions {
    /// The defaults listed on each field.
    pub const DEFAULT: SimplifyOptions = SimplifyOptions {
        target: Target::Ratio(0.5),
        max_error: None,
        pair_threshold: Length::DiagonalFraction(0.0),
        max_virtual_pairs_per_vertex: 8,
        placement: PlacementMode::Optimal,
        weighting: Weighting::Area,
        clean: CleanOptions::DEFAULT,
        validate_each_contraction: false,
    };

    /// Sets [`target`](Self::target).
    pub fn with_target(mut self, target: Target) -> Self {
        self.target = target;
        self
    }

    /// Sets [`max_error`](Self::max_error).
    pub fn with_max_error(mut self, max_error: Option<Length>) -> Self {
        self.max_error = max_error;
        self
    }

    /// Sets [`pair_threshold`](Self::pair_threshold).
    pub fn with_pair_threshold(mut self, threshold: Length) -> Self {
        self.pair_threshold = threshold;
        self
    }

    /// Sets [`max_virtual_pairs_per_vertex`](Self::max_virtual_pairs_per_vertex).
    pub fn with_max_virtual_pairs_per_vertex(mut self, k: usize) -> Self {
        self.max_virtual_pairs_per_vertex = k;
        self
    }

    /// Sets [`placement`](Self::placement).
    pub fn with_placement(mut self, placement: PlacementMode) -> Self {
        self.placement = placement;
        self
    }

    /// Sets [`weighting`](Self::weighting).
    pub fn with_weighting(mut self, weighting: Weighting) -> Self {
        self.weighting = weighting;
        self
    }

    /// Sets [`validate_each_contraction`](Self::validate_each_contraction).
    pub fn with_validate_each_contraction(mut self, on: bool) -> Self {
        self.validate_each_contraction = on;
        self
    }

    /// Sets [`clean`](Self::clean).
    pub fn with_clean(mut self, clean: CleanOptions) -> Self {
        self.clean = clean;
        self
    }
}

impl Default for SimplifyOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// Why the loop stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StopReason {
    /// The triangle count reached the target (or was already at or below it).
    TargetReached,
    /// The next contraction would have exceeded the error bound.
    MaxErrorReached,
    /// No candidate pair was left before the target.
    NoValidPair,
    /// The observer asked to stop.
    Cancelled,
}

impl StopReason {
    /// A short snake_case name, as used in JSON reports.
    pub fn as_str(self) -> &'static str {
        match self {
            StopReason::TargetReached => "target_reached",
            StopReason::MaxErrorReached => "max_error_reached",
            StopReason::NoValidPair => "no_valid_pair",
            StopReason::Cancelled => "cancelled",
        }
    }
}

impl fmt::Display for StopReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Wall time of each phase of a run.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timings {
    /// Validation and cleaning.
    pub clean: Duration,
    /// Building the store.
    pub build: Duration,
    /// Face and vertex quadrics, candidate pairs and the queue.
    pub setup: Duration,
    /// The contraction loop.
    pub contract: Duration,
    /// Compaction back to an [`IndexedMesh`].
    pub compact: Duration,
}

/// What a simplification did.
#[derive(Clone, Debug, PartialEq)]
pub struct SimplifyReport {
    /// Triangles in the input, as given.
    pub triangles_in: usize,
    /// Vertices in the input, as given.
    pub vertices_in: usize,
    /// Triangles in the output.
    pub triangles_out: usize,
    /// Vertices in the output.
    pub vertices_out: usize,
    /// The target the run aimed for, in triangles.
    pub target_triangles: usize,
    /// Contractions of pairs joined by an edge.
    pub edge_contractions: usize,
    /// Contractions of virtual pairs (no shared edge).
    pub virtual_contractions: usize,
    /// Virtual pairs found by the grid (after the per-vertex cap).
    pub virtual_pairs: usize,
    /// Virtual pairs the per-vertex cap left out.
    pub virtual_pairs_capped: usize,
    /// The largest contraction error, as a fraction of the input's bounding-box
    /// diagonal.
    ///
    /// The error of a contraction is a distance: `sqrt(cost / weight)`, the square root
    /// of the quadric cost at the new position divided by the quadric's total plane
    /// weight (its total area, with area weighting) — the RMS distance of the new vertex
    /// to the planes it has accumulated. So `0.001` means about 0.1% of the diagonal.
    pub max_error: f64,
    /// [`max_error`](Self::max_error) in model units.
    pub max_error_abs: f64,
    /// The input's bounding-box diagonal, in model units (after cleaning).
    pub bbox_diagonal: f64,
    /// Why the loop stopped.
    pub stop_reason: StopReason,
    /// What the cleaning passes removed or merged.
    pub cleanup: CleanReport,
    /// Faces of the result dropped at compaction because contraction left them with
    /// zero area.
    pub degenerate_faces_removed: usize,
    /// Contractions refused because they would have left a surviving face with zero
    /// area.
    pub rejected_degenerate: usize,
    /// Wall time per phase.
    pub timings: Timings,
}

/// Why a simplification could not run. Stopping short of the target is not an error
/// (see [`StopReason`]).
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum SimplifyError {
    /// The input failed validation.
    Input(InputError),
    /// Every triangle was degenerate or a duplicate: nothing is left to simplify.
    /// (With [`CleanOptions::drop_zero_area`] turned off, zero-area faces enter the
    /// loop; if only such faces are left at the end, this is the error too, since the
    /// output never has a zero-area face.)
    NothingLeftAfterCleaning {
        /// How many triangles the input had.
        triangles_in: usize,
    },
    /// A bug: the store broke an invariant (only detected with
    /// [`SimplifyOptions::validate_each_contraction`]).
    Internal(StoreError),
}

impl fmt::Display for SimplifyError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SimplifyError::Input(e) => e.fmt(f),
            SimplifyError::NothingLeftAfterCleaning { triangles_in } => write!(
                f,
                "all {triangles_in} triangles are degenerate (repeated vertex or zero area): \
                 nothing is left to simplify"
            ),
            SimplifyError::Internal(e) => write!(f, "internal error, please report: {e}"),
        }
    }
}

impl std::error::Error for SimplifyError {}

impl From<InputError> for SimplifyError {
    fn from(e: InputError) -> Self {
        SimplifyError::Input(e)
    }
}

/// Progress of the contraction loop, as given to an [`Observer`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// Triangles left now.
    pub triangles: usize,
    /// Triangles at the start of the loop.
    pub triangles_start: usize,
    /// The target.
    pub target: usize,
}

impl Progress {
    /// The fraction of the work done, between 0 and 1.
    pub fn fraction(&self) -> f64 {
        let total = self.triangles_start.saturating_sub(self.target);
        if total == 0 {
            return 1.0;
        }
        let done = self.triangles_start.saturating_sub(self.triangles);
        (done as f64 / total as f64).min(1.0)
    }
}

/// Receives progress and may cancel a run. Every method has a no-op default.
pub trait Observer {
    /// Called every few thousand contractions, and once at the end.
    fn progress(&mut self, _progress: Progress) {}
    /// Polled with [`progress`](Self::progress); returning `true` stops the run with
    /// [`StopReason::Cancelled`] (the partial result is still a valid mesh).
    fn should_stop(&mut self) -> bool {
        false
    }
}

/// The observer that does nothing.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoObserver;

impl Observer for NoObserver {}

/// How often (in contractions) the observer is called.
const OBSERVER_INTERVAL: usize = 4096;

/// The result of a simplification.
#[derive(Clone, Debug, PartialEq)]
pub struct Simplified {
    /// The simplified mesh.
    pub mesh: IndexedMesh,
    /// What happened.
    pub report: SimplifyReport,
}

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
    let cleaned = clean(mesh, &options.clean);
    let cleanup = cleaned.report;
    if cleaned.mesh.triangles.is_empty() {
        return Err(SimplifyError::NothingLeftAfterCleaning {
            triangles_in: mesh.triangle_count(),
        });
    }
    timings.clean = clock.elapsed();

    let clock = Instant::now();
    let (store, _keys) = MeshStore::from_mesh(&cleaned.mesh)?;
    timings.build = clock.elapsed();

    let frame = Frame::from_points(cleaned.mesh.positions.iter().map(|p| DVec3::from_array(*p)));
    let mut engine = Engine::new(store, frame, options);
    let clock = Instant::now();
    engine.initialise(&cleaned.mesh, options);
    timings.setup = clock.elapsed();

    let mut results = Vec::with_capacity(levels.len());
    let mut stopped_short: Option<StopReason> = None;
    for &level in levels {
        let target_triangles = target_count(level, mesh.triangle_count());
        let clock = Instant::now();
        let stop_reason = match stopped_short {
            Some(reason) => reason,
            None => engine.run(target_triangles, options, observer)?,
        };
        if stop_reason != StopReason::TargetReached {
            stopped_short = Some(stop_reason);
        }
        timings.contract += clock.elapsed();

        let clock = Instant::now();
        let mut raw = engine.store.to_mesh();
        // Zero-area faces are judged in the loop's frame, not in the output's own (which
        // is larger when a placement left the input's box, making the relative test
        // stricter): the loop refused every contraction that would make a face
        // zero-area, so this drops only faces that came in so (cleaning passes off).
        let before = raw.triangles.len();
        raw.triangles
            .retain(|t| !engine.is_zero_area(t.map(|i| raw.positions[i as usize])));
        let zero_area = before - raw.triangles.len();
        let final_clean = clean(&raw, &CleanOptions::OUTPUT.with_drop_zero_area(false));
        let out = final_clean.mesh;
        if out.triangles.is_empty() {
            return Err(SimplifyError::NothingLeftAfterCleaning {
                triangles_in: mesh.triangle_count(),
            });
        }
        timings.compact = clock.elapsed();

        let report = SimplifyReport {
            triangles_in: mesh.triangle_count(),
            vertices_in: mesh.vertex_count(),
            triangles_out: out.triangle_count(),
            vertices_out: out.vertex_count(),
            target_triangles,
            edge_contractions: engine.edge_contractions,
            virtual_contractions: engine.virtual_contractions,
            virtual_pairs: engine.virtual_pairs,
            virtual_pairs_capped: engine.virtual_pairs_capped,
            max_error: frame.distance_to_diagonal_fraction(engine.max_error),
            max_error_abs: frame.distance_to_world(engine.max_error),
            bbox_diagonal: frame.world_diagonal(),
            stop_reason,
            cleanup,
            degenerate_faces_removed: zero_area + final_clean.report.repeated_index_faces,
            rejected_degenerate: engine.rejected_degenerate,
            timings,
        };
        results.push(Simplified { mesh: out, report });
    }
    Ok(results)
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

/// When the queue holds more than this many entries per live pair, stale entries are
/// dropped. Why 2: a rebuild costs O(queue) and happens after at least as many pushes,
/// so it adds O(1) amortised per push while keeping the heap within 2x of minimal.
const STALE_REBUILD_FACTOR: usize = 2;

/// Whether a queued pair still describes the two vertices as they are now.
fn is_current(state: &SecondaryMap<VertexKey, VertexState>, c: &Candidate) -> bool {
    match (state.get(c.a), state.get(c.b)) {
        (Some(sa), Some(sb)) => sa.stamp == c.stamp_a && sb.stamp == c.stamp_b,
        _ => false,
    }
}

/// What the loop keeps per vertex.
#[derive(Clone, Debug, Default)]
struct VertexState {
    quadric: Quadric,
    /// Bumped whenever the quadric or position changes; see [`crate::queue`].
    stamp: u32,
    /// Virtual-pair partners (vertices within t that share no edge).
    partners: SmallVec<[VertexKey; 4]>,
}

/// The state of one run of the contraction loop.
struct Engine {
    store: MeshStore,
    frame: Frame,
    state: SecondaryMap<VertexKey, VertexState>,
    queue: PairQueue,
    placement: PlacementMode,
    /// The error bound in normalised units (infinite when there is none).
    max_error_bound: f64,
    /// The largest error contracted so far, normalised units.
    max_error: f64,
    edge_contractions: usize,
    virtual_contractions: usize,
    virtual_pairs: usize,
    virtual_pairs_capped: usize,
    /// Reused buffer of the neighbours of a vertex.
    scratch: Vec<VertexKey>,
    /// Reused buffer of the faces around a vertex.
    face_scratch: Vec<FaceKey>,
    /// Twice the area at or below which a face counts as zero-area (normalised units).
    min_double_area: f64,
    /// Contractions refused because they would leave a zero-area face.
    rejected_degenerate: usize,
}

impl Engine {
    fn new(store: MeshStore, frame: Frame, options: &SimplifyOptions) -> Self {
        let max_error_bound = options
            .max_error
            .map_or(f64::INFINITY, |e| e.normalized(&frame));
        Engine {
            state: SecondaryMap::with_capacity(store.vertex_count()),
            queue: PairQueue::with_capacity(store.edge_count() * 2),
            store,
            frame,
            placement: options.placement,
            max_error_bound,
            max_error: 0.0,
            edge_contractions: 0,
            virtual_contractions: 0,
            virtual_pairs: 0,
            virtual_pairs_capped: 0,
            scratch: Vec::new(),
            face_scratch: Vec::new(),
            min_double_area: min_double_area(frame.normalized_diagonal()),
            rejected_degenerate: 0,
        }
    }

    fn normalized_position(&self, v: VertexKey) -> DVec3 {
        self.frame
            .to_normalized(DVec3::from_array(self.store.position(v)))
    }

    /// Face quadrics summed into vertex quadrics, virtual pairs, and the first queue.
    fn initialise(&mut self, cleaned: &IndexedMesh, options: &SimplifyOptions) {
        let vertices: Vec<VertexKey> = self.store.vertices().collect();
        for &v in &vertices {
            self.state.insert(v, VertexState::default());
        }
        let faces: Vec<_> = self.store.faces().collect();
        for f in faces {
            let [a, b, c] = self.store.face_vertices(f);
            let (pa, pb, pc) = (
                self.normalized_position(a),
                self.normalized_position(b),
                self.normalized_position(c),
            );
            let q = match options.weighting {
                Weighting::Area => Quadric::from_triangle(pa, pb, pc),
                Weighting::Unweighted => Quadric::from_triangle_unweighted(pa, pb, pc),
            };
            for v in [a, b, c] {
                if let Some(s) = self.state.get_mut(v) {
                    s.quadric += q;
                }
            }
        }

        let threshold = options.pair_threshold.normalized(&self.frame);
        if threshold > 0.0 {
            // The cleaned mesh's vertex i is the store's vertices[i]: from_mesh creates
            // them in order.
            let normalized: Vec<[f64; 3]> = cleaned
                .positions
                .iter()
                .map(|p| self.frame.to_normalized(DVec3::from_array(*p)).to_array())
                .collect();
            let store = &self.store;
            let grid = GridOptions::new(threshold)
                .with_max_per_vertex(options.max_virtual_pairs_per_vertex);
            let found = virtual_pairs(&normalized, &grid, |i, j| {
                store
                    .find_edge(vertices[i as usize], vertices[j as usize])
                    .is_none()
            });
            self.virtual_pairs = found.pairs.len();
            self.virtual_pairs_capped = found.capped;
            for (i, j) in found.pairs {
                let (a, b) = (vertices[i as usize], vertices[j as usize]);
                if let Some(s) = self.state.get_mut(a) {
                    s.partners.push(b);
                }
                if let Some(s) = self.state.get_mut(b) {
                    s.partners.push(a);
                }
                self.push_pair(a, b);
            }
        }

        let edges: Vec<_> = self.store.edges().collect();
        for e in edges {
            let [a, b] = self.store.edge_vertices(e);
            self.push_pair(a, b);
        }
    }

    /// Where the pair would go, and its cost, in normalised units.
    fn place(&self, a: VertexKey, b: VertexKey) -> (Placement, Quadric) {
        let q = self.state[a].quadric + self.state[b].quadric;
        let (pa, pb) = (self.normalized_position(a), self.normalized_position(b));
        let placed = match self.placement {
            PlacementMode::Optimal => optimal_placement(&q, pa, pb),
            PlacementMode::EndpointOrMidpoint => endpoint_placement(&q, pa, pb),
        };
        (placed, q)
    }

    fn push_pair(&mut self, a: VertexKey, b: VertexKey) {
        let (placed, _) = self.place(a, b);
        self.queue.push(Candidate {
            cost: placed.cost,
            a,
            b,
            stamp_a: self.state[a].stamp,
            stamp_b: self.state[b].stamp,
        });
    }

    fn is_current(&self, c: &Candidate) -> bool {
        is_current(&self.state, c)
    }

    fn run(
        &mut self,
        target: usize,
        options: &SimplifyOptions,
        observer: &mut dyn Observer,
    ) -> Result<StopReason, SimplifyError> {
        let start = self.store.face_count();
        let mut since_report = 0usize;
        let reason = loop {
            if self.store.face_count() <= target {
                break StopReason::TargetReached;
            }
            let Some(candidate) = self.queue.pop() else {
                break StopReason::NoValidPair;
            };
            if !self.is_current(&candidate) {
                continue;
            }
            let (a, b) = (candidate.a, candidate.b);
            // Never contract the last faces away: the output must keep a triangle.
            let shared_faces = self
                .store
                .find_edge(a, b)
                .map_or(0, |e| self.store.fan(e).len());
            if shared_faces >= self.store.face_count() {
                continue;
            }
            let (placed, q) = self.place(a, b);
            let error = q.rms_distance(placed.cost);
            if error > self.max_error_bound {
                break StopReason::MaxErrorReached;
            }
            let world = self.world_position(&placed, a);
            if self.would_degenerate(a, b, world) {
                self.rejected_degenerate += 1;
                continue;
            }
            self.contract(a, b, world, q);
            self.max_error = self.max_error.max(error);
            if options.validate_each_contraction {
                self.store.validate().map_err(SimplifyError::Internal)?;
            }

            // Each contraction queues a fresh entry per neighbour and leaves the old
            // ones stale; once stale entries dominate, drop them in one O(n) pass so
            // the heap (and every pop) stays proportional to the live pairs.
            if self.queue.len()
                > STALE_REBUILD_FACTOR * (self.store.edge_count() + self.virtual_pairs) + 1024
            {
                let state = &self.state;
                self.queue.retain(|c| is_current(state, c));
            }

            since_report += 1;
            if since_report == OBSERVER_INTERVAL {
                since_report = 0;
                observer.progress(Progress {
                    triangles: self.store.face_count(),
                    triangles_start: start,
                    target,
                });
                if observer.should_stop() {
                    break StopReason::Cancelled;
                }
            }
        };
        observer.progress(Progress {
            triangles: self.store.face_count(),
            triangles_start: start,
            target,
        });
        Ok(reason)
    }

    /// The world position of a placement; a non-finite one (possible only when the
    /// mesh spans nearly all of f64) falls back to `a`'s position.
    fn world_position(&self, placed: &Placement, a: VertexKey) -> DVec3 {
        let world = self.frame.to_world(placed.position);
        if world.is_finite() {
            world
        } else {
            DVec3::from_array(self.store.position(a))
        }
    }

    /// Whether a triangle with these world corners is (numerically) zero-area for the
    /// loop: its double area in the normalised frame is at most `min_double_area` (or
    /// NaN), or its cross product underflows in world units. The same test decides
    /// which contractions are refused and which faces are dropped at output, so a face
    /// the loop kept is never dropped afterwards.
    fn is_zero_area(&self, world_corners: [[f64; 3]; 3]) -> bool {
        let [p0, p1, p2] = world_corners.map(|c| self.frame.to_normalized(DVec3::from_array(c)));
        let double_area = (p1 - p0).cross(p2 - p0).length();
        double_area.is_nan()
            || double_area <= self.min_double_area
            || cross_underflows(world_corners)
    }

    /// Whether moving `a` and `b` to `world` would leave a surviving face of either
    /// with (numerically) zero area — such a face would be dropped at output, and if
    /// it were the last one the output would be empty.
    fn would_degenerate(&mut self, a: VertexKey, b: VertexKey, world: DVec3) -> bool {
        let mut faces = std::mem::take(&mut self.face_scratch);
        let mut degenerate = false;
        for v in [a, b] {
            self.store.faces_of_vertex(v, &mut faces);
            for &f in &faces {
                let corners = self.store.face_vertices(f);
                if corners.contains(&a) && corners.contains(&b) {
                    continue; // collapses with the pair
                }
                let world_corners = corners.map(|c| {
                    if c == a || c == b {
                        world.to_array()
                    } else {
                        self.store.position(c)
                    }
                });
                if self.is_zero_area(world_corners) {
                    degenerate = true;
                    break;
                }
            }
            if degenerate {
                break;
            }
        }
        self.face_scratch = faces;
        degenerate
    }

    /// Contracts `b` into `a` at `placed`, merges their state, and queues the new pairs.
    fn contract(&mut self, a: VertexKey, b: VertexKey, world: DVec3, q: Quadric) {
        if self.store.find_edge(a, b).is_some() {
            self.edge_contractions += 1;
        } else {
            self.virtual_contractions += 1;
        }
        // Both keys are live (checked by is_current) and distinct (pairs are built from
        // edges and from distinct grid points), so contraction cannot fail.
        if self.store.contract(a, b, world.to_array()).is_err() {
            return;
        }

        // Merge b's virtual partners into a's, re-pointing the partners' lists.
        let b_state = self.state.remove(b).unwrap_or_default();
        for &p in &b_state.partners {
            if let Some(ps) = self.state.get_mut(p) {
                ps.partners.retain(|x| *x != b);
                if p != a && !ps.partners.contains(&a) {
                    ps.partners.push(a);
                }
            }
        }
        let mut partners = std::mem::take(&mut self.state[a].partners);
        partners.retain(|x| *x != b);
        for &p in &b_state.partners {
            if p != a && !partners.contains(&p) {
                partners.push(p);
            }
        }
        // A virtual pair that became an edge is an edge from now on.
        let store = &self.store;
        partners.retain(|p| store.contains_vertex(*p) && store.find_edge(a, *p).is_none());
        let sa = &mut self.state[a];
        sa.partners = partners;
        sa.quadric = q;
        sa.stamp = sa.stamp.wrapping_add(1);

        // Re-cost every pair around the new vertex.
        let mut neighbours = std::mem::take(&mut self.scratch);
        neighbours.clear();
        neighbours.extend(
            self.store
                .star(a)
                .iter()
                .filter_map(|&e| self.store.other_vertex(e, a)),
        );
        neighbours.extend(self.state[a].partners.iter().copied());
        for &n in &neighbours {
            self.push_pair(a, n);
        }
        self.scratch = neighbours;
    }
}
