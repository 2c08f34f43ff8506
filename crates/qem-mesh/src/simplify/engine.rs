//! The state of one run and the contraction loop itself.

use super::checks::Rejection;
use super::exact::ExactQuadrics;
use super::observer::{Contraction, Observer, Progress};
use super::options::{BoundaryMode, PlacementMode, QuadricMode, SimplifyOptions, VirtualPairs};
use super::orientation::InputSurface;
use super::report::{SimplifyError, StopReason};
use super::waivers::penalised;
use crate::clean::min_double_area;
use crate::pairs::grid::{virtual_pairs, GridOptions};
use crate::queue::PairQueue;
use crate::store::{slot_index, EdgeKey, FaceKey, MeshStore, SlotVec, VertexKey};
use qem_core::{
    endpoint_placement, optimal_placement, solve_first_placement, unit_normal_and_area, DVec3,
    Frame, Placement, PlacementRule, Quadric, WeightedPlane,
};
use rayon::prelude::*;
use slotmap::{Key, SecondaryMap};
use smallvec::SmallVec;
use std::collections::HashSet;

/// How often (in contractions) the observer's progress is called.
const OBSERVER_INTERVAL: usize = 4096;

/// The factor on the cost of a pair refused by the orientation check when it is queued
/// again. Why not refuse for good: at extreme ratios (1% of the triangles and below)
/// most remaining pairs fail the check, and refusing them all forced contractions ten
/// times costlier elsewhere (cgal_mannequin_devil at 0.01: Hausdorff 2.0% → 21% of the
/// diagonal, and the run stopped short of its target). At a penalty, a pair that turns
/// a face against the input is taken only once every alternative costs more.
///
/// Measured (qem measure, and a brute-force count of faces against the nearest input
/// face) on the 5 clean corpus scans that had such faces at ratio 0.1, plus 4 runs at
/// 0.01: with 8, cgal_mannequin_devil keeps one such face at 0.1 (0.04%); with 32 and
/// 128 none is left at 0.1; at 0.01 the mannequin's Hausdorff is 4.1% (32) and 3.9%
/// (128) against 2.0% with the check off, the other 0.01 runs within a few percent of
/// each other. 32 is the smallest factor tried that leaves none at 0.1.
pub(super) const ORIENTATION_PENALTY: f64 = 32.0;

/// The least cost a penalised pair is queued at, as a distance (normalised units, where
/// the model's diagonal is at most 2√3): `weight · d²` for the pair's quadric. Why: on a
/// flat region a pair costs exactly 0, and 32 × 0 would queue it right back at the
/// front, where it would pop again at once with the check waived; with the floor it
/// waits behind every pair that moves the surface by less than this.
pub(super) const PENALTY_FLOOR_DISTANCE: f64 = 1e-6;

/// A pair's two vertices, smaller key first: one spelling per pair.
fn ordered_pair(a: VertexKey, b: VertexKey) -> (VertexKey, VertexKey) {
    if a < b {
        (a, b)
    } else {
        (b, a)
    }
}

/// [`Engine::place`], from the parts of the engine it reads (so that the setup can
/// cost every edge while it walks the store's edges).
fn place(
    state: &VertexStates,
    exact: Option<&ExactQuadrics>,
    placement: PlacementMode,
    a: VertexKey,
    b: VertexKey,
    ab: Option<EdgeKey>,
) -> (Placement, Quadric) {
    let (sa, sb) = (&state[a], &state[b]);
    let mut q = sa.quadric + sb.quadric;
    if let Some(exact) = exact {
        q -= exact.edge(ab);
    }
    let ends = [(sa.position, sa.locked), (sb.position, sb.locked)];
    (place_merged(&q, ends, placement), q)
}

/// Where the merged vertex of a pair goes, given the merged quadric `q` and each end's
/// position and lock: a locked end stays put (the first, if both are), otherwise
/// `placement` decides.
pub(super) fn place_merged(
    q: &Quadric,
    [(pa, locked_a), (pb, locked_b)]: [(DVec3, bool); 2],
    placement: PlacementMode,
) -> Placement {
    let fixed = if locked_a {
        Some((pa, PlacementRule::FirstEnd))
    } else if locked_b {
        Some((pb, PlacementRule::SecondEnd))
    } else {
        None
    };
    if let Some((position, rule)) = fixed {
        let cost = q.evaluate(position).max(0.0);
        return Placement {
            position,
            cost,
            rule,
        };
    }
    match placement {
        PlacementMode::Optimal => optimal_placement(q, pa, pb),
        PlacementMode::EndpointOrMidpoint => endpoint_placement(q, pa, pb),
        PlacementMode::SolveFirst => solve_first_placement(q, pa, pb),
    }
}

/// The position of `v` in normalised units: its loop state's, or the store's converted
/// for a vertex without one. (A free function so that the setup can read positions
/// with the engine's fields borrowed apart.)
fn normalized_position(
    state: &VertexStates,
    frame: &Frame,
    store: &MeshStore,
    v: VertexKey,
) -> DVec3 {
    match state.get(v) {
        Some(s) => s.position,
        None => frame.to_normalized(DVec3::from_array(store.position(v))),
    }
}

/// Faces or edges handed to both cores at a time by [`Engine::initialise`]: large
/// enough that rayon's hand-off is noise (16k placements are about 10 M instructions,
/// at about 600 each under callgrind), small enough that the chunk's results (144 bytes
/// a face, 24 an edge) stay a few megabytes, not a copy per face of the mesh. (Small
/// enough, too, that `tests/threads.rs` runs several chunks.)
const SETUP_CHUNK: usize = 1 << 14;

/// What the loop keeps per vertex: what the placement and the checks read on every
/// pair, side by side. Why the position is here too (the store has it in world units):
/// one lookup instead of two, and no conversion per read; it is always exactly
/// `frame.to_normalized(store.position(v))`, so results are the same bit for bit.
#[derive(Clone, Debug, Default)]
pub(super) struct VertexState {
    pub quadric: Quadric,
    /// The position in normalised units.
    pub position: DVec3,
    /// Never moves, never disappears.
    pub locked: bool,
    /// Index in the cleaned mesh (for [`Contraction`] events).
    pub index: u32,
    /// How many pairs of this vertex are in [`Engine`]'s set of waived pairs (see
    /// [`Engine::unwaive`]); a pair can be there only when both its ends count it.
    waived_pairs: u32,
}

/// One vertex's state and the version of the key it belongs to (0: no vertex), padded
/// and aligned to exactly two cache lines. Why: `SecondaryMap`'s 120-byte slots start
/// anywhere in a line, so reading a quadric and position touched three lines about
/// half the time; the placement reads two vertices' states per queued pair and the
/// checks read the positions of every corner around a pair.
#[derive(Clone, Debug, Default)]
#[repr(align(64))]
struct StateSlot {
    state: VertexState,
    version: u32,
}

/// The [`VertexState`] of every live vertex, by the slot index of its key: the part of
/// `SecondaryMap`'s interface that the loop uses, over [`StateSlot`]s. A key whose
/// version does not match (a removed vertex) has no state, as in a `SecondaryMap`.
#[derive(Clone, Debug, Default)]
pub(super) struct VertexStates {
    slots: Vec<StateSlot>,
}

/// Slot index (the store's one definition, `slot_index`) and version of a key.
fn split_key(v: VertexKey) -> (usize, u32) {
    (slot_index(v), (v.data().as_ffi() >> 32) as u32)
}

impl VertexStates {
    pub fn with_capacity(capacity: usize) -> Self {
        VertexStates {
            slots: Vec::with_capacity(capacity + 1),
        }
    }

    pub fn get(&self, v: VertexKey) -> Option<&VertexState> {
        let (i, version) = split_key(v);
        self.slots
            .get(i)
            .filter(|s| s.version == version)
            .map(|s| &s.state)
    }

    pub fn get_mut(&mut self, v: VertexKey) -> Option<&mut VertexState> {
        let (i, version) = split_key(v);
        self.slots
            .get_mut(i)
            .filter(|s| s.version == version)
            .map(|s| &mut s.state)
    }

    pub fn contains_key(&self, v: VertexKey) -> bool {
        self.get(v).is_some()
    }

    pub fn insert(&mut self, v: VertexKey, state: VertexState) {
        let (i, version) = split_key(v);
        if self.slots.len() <= i {
            self.slots.resize_with(i + 1, StateSlot::default);
        }
        self.slots[i] = StateSlot { state, version };
    }

    pub fn remove(&mut self, v: VertexKey) {
        let (i, version) = split_key(v);
        if let Some(s) = self.slots.get_mut(i).filter(|s| s.version == version) {
            s.version = 0;
        }
    }

    /// The states of the live vertices, in slot order.
    pub fn values(&self) -> impl Iterator<Item = &VertexState> {
        self.slots
            .iter()
            .filter(|s| s.version != 0)
            .map(|s| &s.state)
    }
}

impl std::ops::Index<VertexKey> for VertexStates {
    type Output = VertexState;

    fn index(&self, v: VertexKey) -> &VertexState {
        match self.get(v) {
            Some(s) => s,
            None => panic!("no state for vertex {v:?}"),
        }
    }
}

impl std::ops::IndexMut<VertexKey> for VertexStates {
    fn index_mut(&mut self, v: VertexKey) -> &mut VertexState {
        match self.get_mut(v) {
            Some(s) => s,
            None => panic!("no state for vertex {v:?}"),
        }
    }
}

/// What the report counts, accumulated over the run.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Counters {
    pub edge_contractions: usize,
    pub virtual_contractions: usize,
    pub virtual_pairs: usize,
    pub virtual_pairs_capped: usize,
    /// The largest error contracted so far, normalised units.
    pub max_error: f64,
    pub rejected_degenerate: usize,
    pub rejected_flip: usize,
    pub rejected_sliver: usize,
    pub rejected_topology: usize,
    pub rejected_locked: usize,
    pub rejected_border: usize,
    pub rejected_merge: usize,
    pub rejected_orientation: usize,
    pub locked_vertices: usize,
}

impl Counters {
    /// Adds `other`'s counts of what happened to these and keeps the larger of the two
    /// largest errors (the counts of one block of a pass, see `pass_blocks`;
    /// `locked_vertices` is a property of the run, not counted there).
    pub(super) fn absorb(&mut self, other: &Counters) {
        self.edge_contractions += other.edge_contractions;
        self.virtual_contractions += other.virtual_contractions;
        self.virtual_pairs += other.virtual_pairs;
        self.virtual_pairs_capped += other.virtual_pairs_capped;
        self.max_error = self.max_error.max(other.max_error);
        self.rejected_degenerate += other.rejected_degenerate;
        self.rejected_flip += other.rejected_flip;
        self.rejected_sliver += other.rejected_sliver;
        self.rejected_topology += other.rejected_topology;
        self.rejected_locked += other.rejected_locked;
        self.rejected_border += other.rejected_border;
        self.rejected_merge += other.rejected_merge;
        self.rejected_orientation += other.rejected_orientation;
    }

    pub(super) fn reject(&mut self, why: Rejection) {
        let counter = match why {
            Rejection::Degenerate => &mut self.rejected_degenerate,
            Rejection::Flip => &mut self.rejected_flip,
            Rejection::Sliver => &mut self.rejected_sliver,
            Rejection::Topology => &mut self.rejected_topology,
            Rejection::Locked => &mut self.rejected_locked,
            Rejection::Border => &mut self.rejected_border,
            Rejection::Merge => &mut self.rejected_merge,
            Rejection::Orientation => &mut self.rejected_orientation,
        };
        *counter += 1;
    }
}

/// Bounding-box diagonals (model units) below which world-unit cross products may
/// underflow f64; see [`Settings::world_may_underflow`].
const WORLD_UNDERFLOW_DIAGONAL: f64 = 1e-140;

/// The options the loop reads, in the form it reads them.
#[derive(Clone, Copy, Debug)]
pub(super) struct Settings {
    pub placement: PlacementMode,
    /// The error bound in normalised units (infinite when there is none).
    pub max_error_bound: f64,
    /// The square of twice the area at or below which a face counts as zero-area
    /// (normalised units), to compare with a cross product's squared length.
    pub min_double_area_squared: f64,
    /// Whether world coordinates are so small that a proper triangle's cross product
    /// can underflow to zero in model units (see `clean::cross_underflows`); only then
    /// does the fold-over check also test faces in world units.
    pub world_may_underflow: bool,
    /// Cosine of the largest allowed normal turn; `None` when the check is off.
    pub min_normal_cos: Option<f64>,
    /// The sliver threshold; `None` when the check is off.
    pub min_quality: Option<f64>,
    pub preserve_topology: bool,
    /// Refuse contractions that pinch, close or remove a border loop (any
    /// [`BoundaryMode`] but `Free`).
    pub keep_border_loops: bool,
    /// Whether any vertex is locked (skips the lock checks entirely when not).
    pub any_locked: bool,
}

impl Settings {
    /// The settings of `options` for a run in `frame`.
    pub(super) fn new(options: &SimplifyOptions, frame: &Frame) -> Settings {
        let max_error_bound = options
            .max_error
            .map_or(f64::INFINITY, |e| e.normalized(frame));
        let angle = options.max_normal_angle.clamp(0.0, 180.0);
        Settings {
            placement: options.placement,
            max_error_bound,
            min_double_area_squared: min_double_area(frame.normalized_diagonal()).powi(2),
            // A cross product of edges of length L is about L²; f64 underflows below
            // ~1e-308, so only a model smaller than ~1e-150 can be affected.
            world_may_underflow: frame.world_diagonal() < WORLD_UNDERFLOW_DIAGONAL,
            min_normal_cos: (angle < 180.0).then(|| angle.to_radians().cos()),
            min_quality: (options.min_triangle_quality > 0.0)
                .then_some(options.min_triangle_quality),
            preserve_topology: options.preserve_topology,
            keep_border_loops: options.boundary != BoundaryMode::Free,
            any_locked: false,
        }
    }
}

/// The state of one run of the contraction loop.
pub(super) struct Engine {
    pub store: MeshStore,
    pub frame: Frame,
    pub state: VertexStates,
    queue: PairQueue,
    pub settings: Settings,
    pub counters: Counters,
    /// Intersection quadrics, with [`QuadricMode::Exact`] only.
    exact: Option<ExactQuadrics>,
    /// The (unnormalised) normal of every input face, for the fold-over check and
    /// [`Engine::flipped_faces`]; zero for a face without one (a zero normal's dot
    /// product is never negative, so it has no say).
    pub original_normals: SlotVec<FaceKey, DVec3>,
    /// Virtual-pair partners (vertices within t that share no edge) of the vertices
    /// that have any; kept apart from [`VertexState`] since most vertices have none.
    partners: SecondaryMap<VertexKey, SmallVec<[VertexKey; 4]>>,
    /// Reused buffer of the neighbours of a vertex and the edge to each.
    scratch: Vec<(VertexKey, Option<EdgeKey>)>,
    /// Reused buffer of the faces around a vertex.
    pub face_scratch: Vec<FaceKey>,
    /// Reused buffers of the faces around the two ends of the pair being checked.
    pub around_scratch: [Vec<FaceKey>; 2],
    /// The input surface for the orientation check; `None` when the check is off.
    pub input_surface: Option<InputSurface>,
    /// Pairs (smaller key first) that failed the orientation check and were queued
    /// again at [`ORIENTATION_PENALTY`], and not re-costed since: when one pops, the
    /// check is waived (its cost already carries the penalty). Only looked up, never
    /// iterated, so its order cannot matter; [`VertexState`] counts each vertex's pairs
    /// here so that most look-ups need no hashing.
    orientation_waived: HashSet<(VertexKey, VertexKey)>,
    /// Reused buffer of the edges of the vertex being removed.
    b_edges: Vec<EdgeKey>,
}

impl Engine {
    pub fn new(store: MeshStore, frame: Frame, options: &SimplifyOptions) -> Self {
        let settings = Settings::new(options, &frame);
        Engine {
            state: VertexStates::with_capacity(store.vertex_count()),
            queue: PairQueue::new(&store),
            exact: (options.quadrics == QuadricMode::Exact).then(|| ExactQuadrics::new(&store)),
            original_normals: SlotVec::for_keys(store.faces(), DVec3::ZERO),
            partners: SecondaryMap::new(),
            store,
            frame,
            settings,
            counters: Counters::default(),
            scratch: Vec::new(),
            face_scratch: Vec::new(),
            around_scratch: [Vec::new(), Vec::new()],
            input_surface: None,
            orientation_waived: HashSet::new(),
            b_edges: Vec::new(),
        }
    }

    pub fn normalized_position(&self, v: VertexKey) -> DVec3 {
        normalized_position(&self.state, &self.frame, &self.store, v)
    }

    /// Face quadrics summed into vertex quadrics, border planes or locks, locked
    /// vertices, virtual pairs, and the first queue. `keys[i]` is the store's key of
    /// vertex `i` of the mesh it was built from (the cleaned mesh in locality order),
    /// `numbers[i]` that vertex's number in the cleaned mesh (for [`Contraction`]
    /// events); `locked` lists vertex numbers of the mesh the store was built from.
    pub fn initialise(
        &mut self,
        keys: &[VertexKey],
        numbers: &[u32],
        locked: &[u32],
        options: &SimplifyOptions,
    ) {
        for (&v, &index) in keys.iter().zip(numbers) {
            self.state.insert(
                v,
                VertexState {
                    index,
                    position: self
                        .frame
                        .to_normalized(DVec3::from_array(self.store.position(v))),
                    ..VertexState::default()
                },
            );
        }
        let area_offset = options.weighting.area_offset(self.mean_face_area());
        self.sum_face_planes(area_offset);
        self.initialise_boundary(options, area_offset);
        for &i in locked {
            if let Some(s) = keys.get(i as usize).and_then(|&v| self.state.get_mut(v)) {
                s.locked = true;
            }
        }
        self.counters.locked_vertices = self.state.values().filter(|s| s.locked).count();
        self.settings.any_locked = self.counters.locked_vertices > 0;

        let threshold = if options.preserve_topology {
            0.0 // joining parts changes the topology
        } else {
            options.pair_threshold.normalized(&self.frame)
        };
        if threshold > 0.0 {
            self.initialise_virtual_pairs(keys, threshold, options);
        }

        self.queue_every_edge();
    }

    /// Records each face's input normal and its plane in the exact quadrics, and adds
    /// its quadric to its vertices' sums, with the weighting's `area_offset`.
    ///
    /// Reads the faces straight from the store, with its fields borrowed apart, rather
    /// than from a list of every face key first (32 MB on a 4M-triangle mesh, held at
    /// the setup's memory peak): a chunk of keys at a time, each face's normal, plane
    /// and quadric computed on both cores, then summed into its vertices and edges in
    /// face order (the order of the sums fixes their bits, so they are the same on any
    /// number of threads).
    fn sum_face_planes(&mut self, area_offset: Option<f64>) {
        let Engine {
            store,
            state,
            frame,
            original_normals,
            exact,
            ..
        } = self;
        let mut faces = store.faces();
        let mut chunk: Vec<FaceKey> = Vec::with_capacity(SETUP_CHUNK);
        let mut planes: Vec<(DVec3, WeightedPlane, Quadric)> = Vec::with_capacity(SETUP_CHUNK);
        loop {
            chunk.clear();
            chunk.extend(faces.by_ref().take(SETUP_CHUNK));
            if chunk.is_empty() {
                break;
            }
            let (shared_store, shared_state) = (&*store, &*state);
            chunk
                .par_iter()
                .map(|&f| {
                    let [pa, pb, pc] = shared_store
                        .face_vertices(f)
                        .map(|v| normalized_position(shared_state, frame, shared_store, v));
                    let plane = match area_offset {
                        Some(extra) => WeightedPlane::from_triangle_area_plus(pa, pb, pc, extra),
                        None => WeightedPlane::from_triangle_unweighted(pa, pb, pc),
                    };
                    ((pb - pa).cross(pc - pa), plane, plane.quadric())
                })
                .collect_into_vec(&mut planes);
            for (&f, &(normal, plane, q)) in chunk.iter().zip(&planes) {
                original_normals.set(f, normal);
                for v in store.face_vertices(f) {
                    if let Some(s) = state.get_mut(v) {
                        s.quadric += q;
                    }
                }
                if let Some(exact) = exact {
                    exact.add_face(f, store.face_edges(f), plane, q);
                }
            }
        }
    }

    /// Queues every edge as a pair, at its placement's cost: `push_pair` for every
    /// edge, read straight from the store (no list of every edge key first: 48 MB on a
    /// 4M-triangle mesh). No pair is waived yet, so there is nothing for `unwaive` to
    /// do. The placements of a chunk of edges are solved on both cores, then queued in
    /// edge order: the order of pushes gives equal costs their order (first in, first
    /// out), so it must not depend on the threads.
    fn queue_every_edge(&mut self) {
        let Engine {
            store,
            state,
            exact,
            settings,
            queue,
            ..
        } = self;
        let mut edges = store.edges();
        let mut chunk: Vec<EdgeKey> = Vec::with_capacity(SETUP_CHUNK);
        // Each edge's ends with its cost, so the queueing does not look the edge up again.
        let mut costed: Vec<(VertexKey, VertexKey, f64)> = Vec::with_capacity(SETUP_CHUNK);
        loop {
            chunk.clear();
            chunk.extend(edges.by_ref().take(SETUP_CHUNK));
            if chunk.is_empty() {
                break;
            }
            let (shared_store, shared_state, shared_exact) = (&*store, &*state, exact.as_ref());
            chunk
                .par_iter()
                .map(|&e| {
                    let [a, b] = shared_store.edge_vertices(e);
                    let (placed, _) = place(
                        shared_state,
                        shared_exact,
                        settings.placement,
                        a,
                        b,
                        Some(e),
                    );
                    (a, b, placed.cost)
                })
                .collect_into_vec(&mut costed);
            for (&e, &(a, b, cost)) in chunk.iter().zip(&costed) {
                queue.push(cost, a, b, Some(e));
            }
        }
    }

    /// The mean area of the store's faces in normalised units (degenerate faces count
    /// as 0), for [`Weighting::Mixed`](super::Weighting::Mixed); 0 when there are none.
    fn mean_face_area(&self) -> f64 {
        let count = self.store.face_count();
        if count == 0 {
            return 0.0;
        }
        let total: f64 = self
            .store
            .faces()
            .map(|f| {
                let [a, b, c] = self
                    .store
                    .face_vertices(f)
                    .map(|v| self.normalized_position(v));
                unit_normal_and_area(a, b, c).map_or(0.0, |(_, area)| area)
            })
            .sum();
        total / count as f64
    }

    /// Border planes ([`BoundaryMode::Planes`]) or border locks ([`BoundaryMode::Locked`]).
    /// `area_offset` is the weighting's constant added to face areas
    /// ([`Weighting::area_offset`](super::Weighting::area_offset); `None` = unit weights).
    fn initialise_boundary(&mut self, options: &SimplifyOptions, area_offset: Option<f64>) {
        let weight = match options.boundary {
            BoundaryMode::Free => return,
            BoundaryMode::Planes(w) if w > 0.0 && w.is_finite() => Some(w),
            BoundaryMode::Planes(_) => return,
            BoundaryMode::Locked => None,
        };
        let borders: Vec<EdgeKey> = self
            .store
            .edges()
            .filter(|&e| self.store.fan(e).len() == 1)
            .collect();
        for e in borders {
            let [a, b] = self.store.edge_vertices(e);
            let Some(w) = weight else {
                for v in [a, b] {
                    if let Some(s) = self.state.get_mut(v) {
                        s.locked = true;
                    }
                }
                continue;
            };
            let f = self.store.fan(e)[0];
            let [p0, p1, p2] = self
                .store
                .face_vertices(f)
                .map(|v| self.normalized_position(v));
            let normal = (p1 - p0).cross(p2 - p0).normalize_or_zero();
            let (pa, pb) = (self.normalized_position(a), self.normalized_position(b));
            let plane_weight = match area_offset {
                Some(extra) => w * (pa.distance_squared(pb) + extra),
                None => w,
            };
            let q = Quadric::boundary_constraint(pa, pb, normal, plane_weight);
            for v in [a, b] {
                if let Some(s) = self.state.get_mut(v) {
                    s.quadric += q;
                }
            }
            if let Some(exact) = &mut self.exact {
                exact.add_edge_plane(e, q);
            }
        }
    }

    /// Virtual pairs from the grid, filtered by [`VirtualPairs`], queued; `keys` lists
    /// every vertex (the grid numbers them by their place in it).
    fn initialise_virtual_pairs(
        &mut self,
        keys: &[VertexKey],
        threshold: f64,
        options: &SimplifyOptions,
    ) {
        let normalized: Vec<[f64; 3]> = keys
            .iter()
            .map(|&v| self.state[v].position.to_array())
            .collect();
        let labels = match options.virtual_pairs {
            VirtualPairs::Any => None,
            VirtualPairs::BetweenComponents => Some(self.store.component_labels()),
        };
        let store = &self.store;
        let grid =
            GridOptions::new(threshold).with_max_per_vertex(options.max_virtual_pairs_per_vertex);
        let found = virtual_pairs(&normalized, &grid, |i, j| {
            let (a, b) = (keys[i as usize], keys[j as usize]);
            let separate = labels.as_ref().is_none_or(|l| l.get(a) != l.get(b));
            separate && store.find_edge(a, b).is_none()
        });
        self.counters.virtual_pairs = found.pairs.len();
        self.counters.virtual_pairs_capped = found.capped;
        for (i, j) in found.pairs {
            let (a, b) = (keys[i as usize], keys[j as usize]);
            self.add_partner(a, b);
            self.add_partner(b, a);
            self.push_pair(a, b, None);
        }
    }

    /// Lists `p` among the virtual partners of `v`, if `v` is live.
    fn add_partner(&mut self, v: VertexKey, p: VertexKey) {
        if !self.state.contains_key(v) {
            return;
        }
        match self.partners.get_mut(v) {
            Some(list) => list.push(p),
            None => {
                self.partners.insert(v, SmallVec::from_slice(&[p]));
            }
        }
    }

    /// The merged quadric of `a` and `b` (joined by edge `ab`, if any), where the new
    /// vertex would go and its cost, in normalised units. A locked end stays put.
    fn place(&self, a: VertexKey, b: VertexKey, ab: Option<EdgeKey>) -> (Placement, Quadric) {
        place(
            &self.state,
            self.exact.as_ref(),
            self.settings.placement,
            a,
            b,
            ab,
        )
    }

    fn push_pair(&mut self, a: VertexKey, b: VertexKey, ab: Option<EdgeKey>) {
        let (placed, _) = self.place(a, b, ab);
        self.queue.push(placed.cost, a, b, ab);
        // Re-costed: a penalty from an earlier orientation refusal no longer applies.
        self.unwaive(a, b);
    }

    /// Lists the pair `a`, `b` (both live) as waived: queued again at a penalty after an
    /// orientation refusal.
    fn waive(&mut self, a: VertexKey, b: VertexKey) {
        if self.orientation_waived.insert(ordered_pair(a, b)) {
            self.state[a].waived_pairs += 1;
            self.state[b].waived_pairs += 1;
        }
    }

    /// Takes the pair `a`, `b` off the waived list; whether it was there (always false
    /// when either end is gone, as no such pair is ever asked about again).
    ///
    /// Why the per-vertex counts: this runs for every queued pair, and once any pair has
    /// been waived the set is never empty again, so without them every push hashed a
    /// pair (about 3% of the loop's instructions); the counts, read next to the quadric
    /// the placement just read, rule out almost every pair without hashing. Counts of a
    /// removed vertex's pairs stay on its neighbours: they only make the test ask the
    /// set, which answers the same.
    fn unwaive(&mut self, a: VertexKey, b: VertexKey) -> bool {
        let listed = |v| self.state.get(v).is_some_and(|s| s.waived_pairs > 0);
        if !listed(a) || !listed(b) {
            debug_assert!(
                !(self.state.contains_key(a)
                    && self.state.contains_key(b)
                    && self.orientation_waived.contains(&ordered_pair(a, b))),
                "a waived pair of live vertices that its counts do not show"
            );
            return false;
        }
        if !self.orientation_waived.remove(&ordered_pair(a, b)) {
            return false;
        }
        self.state[a].waived_pairs -= 1;
        self.state[b].waived_pairs -= 1;
        true
    }

    // Out of line (it runs once per level, so this costs nothing) so that profilers
    // can count the loop alone, e.g. `valgrind --toggle-collect='*Engine::run*'`.
    #[inline(never)]
    pub fn run(
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
            let (mut a, mut b) = (candidate.a, candidate.b);
            // Cheapest checks first: locks are two flags.
            let (locked_a, locked_b) = (self.state[a].locked, self.state[b].locked);
            if locked_a && locked_b {
                self.counters.reject(Rejection::Locked);
                continue;
            }
            if locked_b {
                // The locked vertex is the one that stays.
                std::mem::swap(&mut a, &mut b);
            }
            // The queue keeps every entry current (see `contract`), so the edge it
            // was queued with still joins the two.
            let ab = candidate.edge;
            debug_assert_eq!(ab, self.store.find_edge(a, b));
            // Never contract the last faces away: the output must keep a triangle.
            let shared_faces = ab.map_or(0, |e| self.store.fan(e).len());
            if shared_faces >= self.store.face_count() {
                continue;
            }
            let (placed, q) = self.place(a, b, ab);
            let error = q.rms_distance(placed.cost);
            if error > self.settings.max_error_bound {
                break StopReason::MaxErrorReached;
            }
            let world = if locked_a || locked_b {
                // Bit for bit where it was, not a round trip through the frame.
                DVec3::from_array(self.store.position(a))
            } else {
                self.world_position(&placed, a)
            };
            let waived = self.unwaive(a, b);
            if let Err(why) = self.check(a, b, ab, world, !waived) {
                self.counters.reject(why);
                if why == Rejection::Orientation {
                    // Not refused for good: queued again at a penalty, so it is taken
                    // only when every alternative costs more (see ORIENTATION_PENALTY).
                    // Same names in the same order, so the contraction keeps the
                    // vertex it would have kept.
                    self.waive(a, b);
                    self.queue.push(
                        penalised(placed.cost, &q),
                        candidate.a,
                        candidate.b,
                        candidate.edge,
                    );
                }
                continue;
            }
            let kept = self.state[a].index;
            let removed = self.state[b].index;
            self.contract(a, b, ab, world, q);
            self.counters.max_error = self.counters.max_error.max(error);
            observer.contracted(&Contraction {
                kept,
                removed,
                is_virtual: ab.is_none(),
                quadric: q,
                position: placed.position,
                cost: placed.cost,
            });
            if options.validate_each_contraction {
                self.store.validate().map_err(SimplifyError::Internal)?;
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

    /// Contracts `b` into `a` at `world`, merges their state, and queues the new pairs.
    fn contract(
        &mut self,
        a: VertexKey,
        b: VertexKey,
        ab: Option<EdgeKey>,
        world: DVec3,
        q: Quadric,
    ) {
        if ab.is_some() {
            self.counters.edge_contractions += 1;
        } else {
            self.counters.virtual_contractions += 1;
        }
        // The queue's pairs of `b` all go: its edges either move to `a` (and are re-queued
        // below under the same id) or merge away (removed after the contraction), and
        // its virtual pairs end with it. `a`'s virtual pairs are dropped too and the
        // current ones re-queued below, since merging partners may turn one into an edge.
        let mut b_edges = std::mem::take(&mut self.b_edges);
        b_edges.clear();
        b_edges.extend_from_slice(self.store.star(b));
        for v in [a, b] {
            if let Some(partners) = self.partners.get(v) {
                for &p in partners {
                    self.queue.remove_virtual(v, p);
                }
            }
        }
        // Both keys are live (the queue holds only pairs of live vertices) and distinct
        // (pairs are built from edges and from distinct grid points), so contraction
        // cannot fail.
        let contracted = match &mut self.exact {
            Some(exact) => exact.contract(&mut self.store, a, b, ab, world.to_array()),
            None => self
                .store
                .contract_along(a, b, ab, world.to_array(), None)
                .map(|_| ()),
        };
        if contracted.is_err() {
            self.b_edges = b_edges;
            return;
        }
        for &e in &b_edges {
            if !self.store.contains_edge(e) {
                self.queue.remove_edge(e);
            }
        }
        self.b_edges = b_edges;

        self.state.remove(b);
        if !self.partners.is_empty() {
            self.merge_partners(a, b);
        }
        let sa = &mut self.state[a];
        sa.quadric = q;
        sa.position = self.frame.to_normalized(world);

        // Re-cost every pair around the new vertex.
        let mut neighbours = std::mem::take(&mut self.scratch);
        neighbours.clear();
        neighbours.extend(
            self.store
                .star(a)
                .iter()
                .filter_map(|&e| self.store.other_vertex(e, a).map(|n| (n, Some(e)))),
        );
        if let Some(partners) = self.partners.get(a) {
            neighbours.extend(partners.iter().map(|&p| (p, None)));
        }
        for &(n, e) in &neighbours {
            self.push_pair(a, n, e);
        }
        self.scratch = neighbours;
    }

    /// Merges the virtual partners of `b` (just removed) into those of `a`, re-pointing
    /// the partners' lists, and drops the partners that are now joined to `a` by an edge
    /// (a virtual pair that became an edge is an edge from now on).
    fn merge_partners(&mut self, a: VertexKey, b: VertexKey) {
        let b_partners = self.partners.remove(b).unwrap_or_default();
        for &p in &b_partners {
            if let Some(ps) = self.partners.get_mut(p) {
                ps.retain(|x| *x != b);
            }
            if p != a && self.partners.get(p).is_none_or(|ps| !ps.contains(&a)) {
                self.add_partner(p, a);
            }
        }
        let mut partners = self.partners.remove(a).unwrap_or_default();
        partners.retain(|x| *x != b);
        for &p in &b_partners {
            if p != a && !partners.contains(&p) {
                partners.push(p);
            }
        }
        let store = &self.store;
        partners.retain(|p| store.contains_vertex(*p) && store.find_edge(a, *p).is_none());
        if !partners.is_empty() {
            self.partners.insert(a, partners);
        }
    }

    /// Faces whose normal now points more than 90° from the input face they descend
    /// from (a merged face counts as the face that was kept).
    pub fn flipped_faces(&self) -> usize {
        self.store
            .faces()
            .filter(|&f| {
                let [p0, p1, p2] = self
                    .store
                    .face_vertices(f)
                    .map(|v| self.normalized_position(v));
                let now = (p1 - p0).cross(p2 - p0);
                now.dot(*self.original_normals.get(f)) < 0.0
            })
            .count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use slotmap::SlotMap;

    /// `VertexStates` answers as a `SecondaryMap` would: by key, versions included, and
    /// each record is two whole cache lines.
    #[test]
    fn vertex_states_behave_like_a_secondary_map() {
        assert_eq!(std::mem::size_of::<StateSlot>(), 128);
        let mut keys: SlotMap<VertexKey, ()> = SlotMap::with_key();
        let v: Vec<VertexKey> = (0..4).map(|_| keys.insert(())).collect();
        let mut states = VertexStates::with_capacity(2);
        for (i, &k) in v.iter().enumerate().skip(1) {
            let state = VertexState {
                index: i as u32,
                ..VertexState::default()
            };
            states.insert(k, state);
        }
        assert!(!states.contains_key(v[0]));
        assert_eq!(states[v[2]].index, 2);
        states[v[2]].locked = true;
        assert!(states.get(v[2]).is_some_and(|s| s.locked));
        states.remove(v[1]);
        assert!(states.get(v[1]).is_none());
        let indices: Vec<u32> = states.values().map(|s| s.index).collect();
        assert_eq!(indices, vec![2, 3]);
        // A key of another version in a used slot has no state.
        keys.remove(v[3]);
        let reused = keys.insert(());
        assert!(states.get(reused).is_none());
        assert!(states.get_mut(reused).is_none());
    }
}
