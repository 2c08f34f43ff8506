//! The working mesh (flat arrays), its setup, the one attempt of a pair, and the
//! pass-based order ([`ContractionOrder::Passes`](super::ContractionOrder::Passes)):
//! the cheapest pairs contracted in batches instead of one at a time. (The greedy
//! order, [`greedy`], runs on the same mesh with the same attempt.)
//!
//! Each pass:
//! 1. lists, for every vertex, the live triangles around it (one counting sort);
//! 2. lists every edge once, and costs it (on both cores: each cost reads only its two
//!    ends, so the results do not depend on the thread count; an edge whose ends did
//!    not move in the last pass keeps its cost);
//! 3. makes a batch of the cheapest edges, as many as the contractions still needed,
//!    by cost, ties broken by a scatter of the index in the list (a total order; see
//!    [`scatter`] for why not the index itself), and without the orientation check
//!    every other edge whose cost is within [`BATCH_COST_FACTOR`] of the last of
//!    those (many of the batch's edges go stale as their neighbours move, so a batch
//!    of exactly the needed size falls well short of it);
//! 4. contracts in rounds: each round takes the batch's *local minima*, the edges
//!    that are the batch's cheapest at both of their ends (so no two share a vertex),
//!    in list order (by first vertex, so the arrays are walked in order; the cheapest
//!    first when the round may reach the target), each checked like the greedy loop's
//!    pairs (fold-over, merged faces, border loops, locks); then the attempted edges
//!    and every edge at a moved vertex leave the batch, and the next round starts,
//!    until the batch is empty or the target is reached. Without locks, and far from
//!    the target, the pairs of a round whose neighbourhoods lie inside one block of
//!    vertex numbers are attempted first, the blocks on the thread pool, and the rest
//!    after them in order ([`super::pass_blocks`]). With the orientation check on, a
//!    chunk of the pairs attempted in order may first be *speculated* on the thread pool
//!    (their placements and the check's quick tests, against the arrays as they are;
//!    when most recent attempts contracted), and the attempts take what still holds
//!    ([`PassEngine::speculate`] says why that is the sequential answer, bit for bit).
//!
//! Why it is faster than [`ContractionOrder::Greedy`](super::ContractionOrder::Greedy):
//! no heap, each pair costed at most once per pass, the contractions walk the arrays
//! in order, and much of the work is on both cores. What it gives up: the strict
//! greedy order (a pair whose cost fell during a pass waits for the next one). Virtual
//! pairs are listed with the edges of their smaller end (and go to the sequential
//! attempts, not the blocks). Exact quadrics keep their planes as
//! [`super::pass_exact`] describes. The orientation check runs last among the checks;
//! a pair it refuses is ranked at the waivers' penalty in later passes and then tried
//! without it ([`super::waivers`]).
//!
//! The arrays are numbered in locality order ([`super::locality`]: vertices along a
//! space-filling curve), so "in order" is also "near in space", whatever order the
//! input came in; the output and the observer get the cleaned mesh's numbers back.
//!
//! If a pass contracts nothing, its batch grows fourfold (without the pairs already
//! refused) until every edge has been tried; a pass that still contracts nothing ends
//! the run.
//!
//! Why the pass's view stays exact: a contraction of `b` into `a` changes only the
//! triangles around `b` (renamed to `a` at once) and those around both (removed).
//! Every edge at `a` or `b` then leaves the batch, so the list of `a`'s triangles,
//! which is now short of `b`'s, is not read again in the pass by the checks of a pair
//! (the one exception, the lock check's look at a locked neighbour, can only see too
//! few triangles there, and so only refuse more); every other vertex has the
//! triangles it had at the pass's start, minus the removed ones.

use super::checks::Rejection;
use super::counters::Counters;
use super::incidence::Incidence;
use super::locality::{in_locality_order, in_original_order, Renumbered};
use super::nth_key::nth_key;
use super::observer::{Contraction, Observer, Progress};
use super::options::QuadricMode;
use super::options::VirtualPairs;
use super::options::{BoundaryMode, SimplifyOptions};
use super::orientation::{InputSurface, Quick};
use super::pair_set::PairSet;
use super::pass_blocks::{
    border_neighbours, contract_block, plain_checks, shared_planes, Around, BlockOutcome,
    Candidate, Corners, Fixed, Slab, WaiverChange, BLOCK_VERTICES, REMOVED,
};
use super::pass_exact::PassExact;
use super::placement::place_merged;
use super::report::StopReason;
use super::settings::Settings;
use super::waivers::{penalised, Waivers};
use crate::inspect::{find, union};
use crate::pairs::grid::{virtual_pairs, GridOptions};
use crate::store::build::kept_triangles;
use crate::store::BuildStats;
use crate::IndexedMesh;
use qem_core::{unit_normal_and_area, DVec3, Frame, Placement, Quadric, WeightedPlane};
use rayon::prelude::*;
use smallvec::SmallVec;
use std::cmp::Ordering;

/// How many pairs of a round [`PassEngine::speculate`] handles at once: a bound on the
/// memory its answers hold, and on the work wasted past the target.
const SPECULATION_CHUNK: usize = 512;

/// Pairs per piece of work handed to another core by [`PassEngine::speculate`].
const SPECULATION_MIN_LEN: usize = 16;

/// Without the orientation check, a pass's batch also takes every edge whose cost is
/// within this factor of the cost of the last edge it needs (see
/// [`PassEngine::list_batch`]).
///
/// meshoptimizer's simplifier bounds each pass's errors the same way and with the same
/// factor (`kPassErrorBound = 1.5` in its `simplifier.cpp`, applied to the error of the
/// collapse at the pass's goal), since many collapses of a pass are locked out by their
/// neighbours. Measured here (`--fast` at ratio 0.1, against a batch of exactly the
/// needed size): the dragon in 6 passes instead of 12, contraction 913 -> 754 ms
/// (median of 5); over the 49 corpus meshes, Hausdorff distance 0.944x and mean
/// distance 1.022x (geometric means); with exact quadrics and the orientation check,
/// 1.004x and 1.001x. A factor of 2 was barely faster (721 ms) and the mean distance
/// 1.034x.
///
/// Why not with the orientation check: there the peers' harness counted faces facing
/// away at ratio 0.1 on one of issue 5's 9 clean scans (cgal_mannequin_devil, 0.19%;
/// none without the factor) and the Hausdorff distance at most the best peer's in 16
/// of 27 cases (18 without it; BENCHMARKS.md, "The batch's cost bound"). What that
/// costs: the dragon's contraction phase with every default quality option in passes
/// took 1,696 and 1,840 ms without the factor, 1,484 and 1,756 ms with it (medians of
/// 5, alternating); the check's promise is worth more.
pub(super) const BATCH_COST_FACTOR: f64 = 1.5;

/// How often (in attempted contractions) the observer's progress is called.
const OBSERVER_INTERVAL: usize = 4096;

/// The order candidates are taken in: cost, then [`scatter`] of the index in the
/// pass's list. A total order (NaN costs are stored as +∞, see
/// [`PassEngine::cost_edges`]; `scatter` is a bijection).
fn cheaper((x, i): (&Candidate, u32), (y, j): (&Candidate, u32)) -> Ordering {
    by_cost((x.cost, i), (y.cost, j))
}

/// [`cheaper`] on (cost, index) keys.
fn by_cost((x, i): (f64, u32), (y, j): (f64, u32)) -> Ordering {
    x.total_cmp(&y).then(scatter(i).cmp(&scatter(j)))
}

/// A bijection of `u32` that scatters consecutive indices (a multiplication by an odd
/// constant, then an xor-shift, each invertible), used to break ties between equal
/// costs.
///
/// Why not the index itself: the list is in vertex order, so on a flat region, where
/// every cost is exactly 0, ties by index put the whole batch around the first few
/// vertices, of which few edges can be local minima at once. Measured in review on a
/// flat 300x300 grid at ratio 0.1: 253 passes (1.19 s) by index, 18 (0.27 s) scattered;
/// on a flat fan of 20,000 triangles with free borders, 9,999 passes of one contraction
/// each (13.6 s, quadratic) against 39 (0.05 s). A noisy grid, without ties, ran the same.
fn scatter(i: u32) -> u32 {
    let x = i.wrapping_mul(0x9E37_79B1);
    x ^ (x >> 16)
}

/// Whether the pass ended for a reason that ends the run.
enum PassEnd {
    /// Ran out of candidates (or reached the target); `contracted` in this pass, and
    /// `waived` refused by the orientation check, to be tried without it next pass.
    Done { contracted: usize, waived: usize },
    /// Nothing was contracted, and at least one candidate's error was above the
    /// bound.
    MaxErrorReached,
    /// The observer asked to stop.
    Cancelled,
}

/// The state of one pass-based run.
pub(super) struct PassEngine {
    pub frame: Frame,
    pub settings: Settings,
    pub counters: Counters,
    /// World positions: a vertex that never moves keeps its input bits.
    world: Vec<[f64; 3]>,
    /// The engine's arrays are in locality order ([`super::locality`]): for each
    /// vertex, its number in the cleaned mesh (for the output and the observer).
    vertex_from: Vec<u32>,
    /// For each triangle, its number in the cleaned mesh.
    triangle_from: Vec<u32>,
    /// Positions in the normalised frame.
    position: Vec<DVec3>,
    quadric: Vec<Quadric>,
    locked: Vec<bool>,
    /// Corners of every cleaned input triangle; [`REMOVED`] in the first corner once
    /// the triangle is gone.
    triangles: Vec<[u32; 3]>,
    /// The indices of the live triangles, in increasing order.
    live: Vec<u32>,
    /// Each input triangle's (unnormalised) normal in the normalised frame.
    original_normals: Vec<DVec3>,
    /// The pass in which each vertex last moved or was removed.
    moved_in: Vec<u32>,
    pass: u32,
    /// The live triangles around each vertex: rebuilt at each pass in the pass-based
    /// order, merged at each contraction in the greedy order.
    incidence: Incidence,
    candidates: Vec<Candidate>,
    /// Scratch of the batch selection: the batch's candidate indices, the cheapest at
    /// each vertex, and the selected edges.
    batch: Vec<u32>,
    keys: Vec<(f64, u32)>,
    /// Whether each candidate was attempted in this pass.
    tried: Vec<bool>,
    best: Vec<u32>,
    selected: Vec<u32>,
    /// Where each vertex's edges (as the smaller end) start in `candidates`, as listed.
    listed_first: Vec<u32>,
    /// The last pass's edges and costs in listing order, and where each vertex's start.
    last_listed: Vec<Candidate>,
    last_listed_first: Vec<u32>,
    /// The candidates whose cost this pass ranks at the waivers' penalty, with their
    /// costs before it (restored before the list becomes `last_listed`).
    unpenalised_costs: Vec<(u32, f64)>,
    /// Per vertex, the last vertex whose edges were listed with it (edge listing).
    seen_with: Vec<u32>,
    around: [Vec<Around>; 2],
    /// The number of the current chunk of a round (see [`PassEngine::speculate`]), and
    /// per vertex the chunk in which it last moved or was removed.
    chunk: u32,
    moved_in_chunk: Vec<u32>,
    /// The pairs attempted and contracted since the last chunk began (for
    /// `speculating`).
    chunk_attempted: usize,
    chunk_contracted: usize,
    /// What the tests of speculation and blocks set and read (test builds only).
    #[cfg(test)]
    probes: Probes,
    since_report: usize,
    /// The input surface for the orientation check; `None` when the check is off.
    input_surface: Option<InputSurface>,
    /// Pairs refused by the orientation check, ranked at a penalty and then tried
    /// without it ([`super::waivers`] says when a waiver ends).
    waivers: Waivers,
    /// The planes of exact quadrics; `None` with summed quadrics.
    exact: Option<PassExact>,
    /// Vertices per block of [`super::pass_blocks`], and where each block's triangles
    /// start (the last entry is the triangle count).
    block_vertices: u32,
    block_triangles: Vec<u32>,
    /// Scratch: the pairs of a round the blocks left to the sequential attempts.
    deferred: Vec<u32>,
    /// The greedy order's pairs and queue (empty in the pass-based order).
    greedy: greedy::Greedy,
    /// The virtual pairs not yet contracted (`None` without them; the greedy order
    /// takes them into its own pairs).
    virtual_pairs: Option<PairSet>,
}

/// A [`Fixed`] borrowing the fields of the engine `$engine`, with the orientation
/// check's index `$nearest`. A macro rather than a method so that it can borrow those
/// fields beside mutable borrows of the engine's others (the [`Slab`]).
macro_rules! fixed_of {
    ($engine:expr, $nearest:expr) => {
        Fixed {
            frame: &$engine.frame,
            settings: &$engine.settings,
            incidence: &$engine.incidence,
            original_normals: &$engine.original_normals,
            vertex_from: &$engine.vertex_from,
            pass: $engine.pass,
            exact: $engine.exact.as_ref(),
            has_virtual_pairs: $engine.virtual_pairs.is_some(),
            nearest: $nearest,
            waivers: &$engine.waivers,
        }
    };
}

/// The whole mesh of the engine `$engine` as one [`Slab`], with the orientation
/// check's hints `$hints`. A macro for the same reason as [`fixed_of`]: the slab's
/// mutable borrows sit beside the [`Fixed`]'s shared ones.
macro_rules! whole_slab_of {
    ($engine:expr, $hints:expr) => {
        Slab {
            first_vertex: 0,
            first_triangle: 0,
            position: &mut $engine.position,
            world: &mut $engine.world,
            quadric: &mut $engine.quadric,
            moved_in: &mut $engine.moved_in,
            triangles: &mut $engine.triangles,
            hints: $hints,
        }
    };
}

impl PassEngine {
    /// Face quadrics summed into vertex quadrics, border planes or locks, locked
    /// vertices; `locked` lists cleaned-mesh indices.
    pub fn new(
        cleaned: &IndexedMesh,
        frame: Frame,
        locked: &[u32],
        options: &SimplifyOptions,
    ) -> Self {
        let Renumbered {
            mesh,
            vertex_from,
            vertex_to,
            triangle_from,
        } = in_locality_order(cleaned, &frame);
        let n = mesh.positions.len();
        let position: Vec<DVec3> = mesh
            .positions
            .par_iter()
            .map(|p| frame.to_normalized(DVec3::from_array(*p)))
            .collect();
        // The triangles the store would keep: none with a repeated corner (it would
        // count as live while having no area), only the first of each vertex set (the
        // locality order keeps it first). Cleaning has dropped both when its passes
        // were on; the search (16 bytes a triangle, at the setup's memory peak) runs
        // only when they were off.
        let live = if options.clean.drop_repeated_index && options.clean.drop_duplicates {
            (0..mesh.triangles.len() as u32).collect()
        } else {
            kept_triangles(&mesh.triangles, n, &mut BuildStats::default())
        };
        let mut engine = PassEngine {
            settings: Settings::new(options, &frame),
            frame,
            counters: Counters::default(),
            world: mesh.positions,
            vertex_from,
            triangle_from,
            // Summed by `sum_face_planes` (a filled array made first was 80 bytes a
            // vertex of pages written twice).
            quadric: Vec::new(),
            locked: vec![false; n],
            triangles: mesh.triangles,
            live,
            original_normals: Vec::new(),
            moved_in: vec![0; n],
            pass: 0,
            incidence: Incidence::default(),
            candidates: Vec::new(),
            batch: Vec::new(),
            keys: Vec::new(),
            tried: Vec::new(),
            best: vec![u32::MAX; n],
            selected: Vec::new(),
            listed_first: Vec::new(),
            last_listed: Vec::new(),
            last_listed_first: Vec::new(),
            unpenalised_costs: Vec::new(),
            seen_with: vec![u32::MAX; n],
            around: [Vec::new(), Vec::new()],
            chunk: 0,
            moved_in_chunk: vec![0; n],
            chunk_attempted: 0,
            chunk_contracted: 0,
            #[cfg(test)]
            probes: Probes::default(),
            since_report: 0,
            input_surface: None,
            waivers: Waivers::new(n),
            exact: (options.quadrics == QuadricMode::Exact).then(|| PassExact::new(n)),
            position,
            block_vertices: BLOCK_VERTICES,
            block_triangles: Vec::new(),
            deferred: Vec::new(),
            greedy: greedy::Greedy::default(),
            virtual_pairs: None,
        };
        engine.set_block_vertices(BLOCK_VERTICES);
        // The incident lists first: the quadrics are summed along them.
        engine.list_incident_triangles();
        let area_offset = engine.sum_face_planes(options);
        engine.initialise_boundary(options, area_offset);
        for &i in locked {
            if let Some(&v) = vertex_to.get(i as usize) {
                engine.locked[v as usize] = true;
            }
        }
        engine.find_virtual_pairs(options);
        engine.counters.locked_vertices = engine.locked.iter().filter(|&&l| l).count();
        engine.settings.any_locked = engine.counters.locked_vertices > 0;
        engine
    }

    /// Turns the orientation check on with `surface`, built from the same cleaned mesh
    /// (`slots` as [`InputSurface::new`] returned them): each triangle's first hint is
    /// its own input triangle.
    pub fn set_input_surface(&mut self, mut surface: InputSurface, slots: &[u32]) {
        let hints = (self.triangle_from.iter().enumerate())
            .map(|(t, &cleaned_t)| (t, slots[cleaned_t as usize]));
        surface.seed_hints(hints);
        self.input_surface = Some(surface);
    }

    /// The virtual pairs: vertices closer than the pair threshold and not joined by
    /// an edge (only between different parts with [`VirtualPairs::BetweenComponents`]),
    /// at most the nearest few per vertex (see [`GridOptions`]).
    fn find_virtual_pairs(&mut self, options: &SimplifyOptions) {
        let threshold = self.settings.virtual_pair_threshold;
        if threshold.is_nan() || threshold <= 0.0 {
            return;
        }
        let n = self.position.len();
        let part = (options.virtual_pairs == VirtualPairs::BetweenComponents).then(|| {
            let mut parent: Vec<usize> = (0..n).collect();
            for &t in &self.live {
                let [x, y, z] = self.triangles[t as usize].map(|c| c as usize);
                union(&mut parent, x, y);
                union(&mut parent, x, z);
            }
            (0..n)
                .map(|v| find(&mut parent, v) as u32)
                .collect::<Vec<u32>>()
        });
        let points: Vec<[f64; 3]> = self.position.iter().map(|p| p.to_array()).collect();
        let grid =
            GridOptions::new(threshold).with_max_per_vertex(options.max_virtual_pairs_per_vertex);
        let (incidence, triangles) = (&self.incidence, &self.triangles);
        let found = virtual_pairs(&points, &grid, |i, j| {
            let separate = part.as_ref().is_none_or(|p| p[i as usize] != p[j as usize]);
            let joined = || {
                let (walked, other) = incidence.shorter(i, j);
                (incidence.of(walked).iter()).any(|&t| triangles[t as usize].contains(&other))
            };
            separate && !joined()
        });
        self.counters.virtual_pairs = found.pairs.len();
        self.counters.virtual_pairs_capped = found.capped;
        if !found.pairs.is_empty() {
            let ends = found.pairs.into_iter().map(|(i, j)| [i, j]).collect();
            self.virtual_pairs = Some(PairSet::new(n, ends));
        }
    }

    /// What no contraction of the pass changes, for the shared pieces of an attempt
    /// ([`super::pass_blocks`]).
    fn fixed(&self) -> Fixed<'_> {
        fixed_of!(self, None)
    }

    /// Every vertex's positions, for the fold-over check.
    fn corners_view(&self) -> Corners<'_> {
        Corners {
            first_vertex: 0,
            position: &self.position,
            world: &self.world,
        }
    }

    /// The whole mesh as one [`Slab`] (for the sequential attempts), and what does not
    /// change.
    fn split(&mut self) -> (Slab<'_>, Fixed<'_>) {
        let slab = whole_slab_of!(self, &mut []);
        let fixed = fixed_of!(self, None);
        (slab, fixed)
    }

    /// Sets the vertices per block of [`super::pass_blocks`] (tests use small blocks
    /// on small meshes). Only before the run: the triangles' numbers are by lowest
    /// corner then, which is what makes each block's triangles one run.
    pub(super) fn set_block_vertices(&mut self, block_vertices: u32) {
        debug_assert_eq!(self.pass, 0);
        self.block_vertices = block_vertices.max(1);
        let blocks = (self.position.len() as u32).div_ceil(self.block_vertices);
        let triangles = &self.triangles;
        self.block_triangles = (0..=blocks)
            .map(|k| {
                let start = k.saturating_mul(self.block_vertices);
                triangles.partition_point(|t| t.iter().min().is_some_and(|&c| c < start)) as u32
            })
            .collect();
    }

    /// Whether rounds are contracted block by block ([`super::pass_blocks`]): not with
    /// locks (the lock check reads a locked neighbour's triangles, which may lie
    /// outside the block), and only with more than one block.
    fn uses_blocks(&self) -> bool {
        let hints_per_triangle = self
            .input_surface
            .as_ref()
            .is_none_or(|s| s.hint_count() == self.triangles.len());
        !self.settings.any_locked
            && hints_per_triangle
            && self.position.len() > self.block_vertices as usize
    }

    /// Contracts the pairs of `selected` (a round, in list order) that are interior to
    /// their block, the blocks on the thread pool, and leaves the others in
    /// `deferred`, in order. The contractions reach the observer and the counters in
    /// block order, as if the blocks had run one after another.
    fn contract_blocks(
        &mut self,
        selected: &[u32],
        deferred: &mut Vec<u32>,
        observer: &mut dyn Observer,
    ) -> BlockOutcome {
        let watch = observer.wants_contractions();
        let block_vertices = self.block_vertices;
        let (nearest, hints) = match &mut self.input_surface {
            Some(surface) => {
                let (nearest, hints) = surface.parts();
                (Some(nearest), hints)
            }
            None => (None, &mut [][..]),
        };
        let fixed = fixed_of!(self, nearest);
        let whole = whole_slab_of!(self, hints);
        let (candidates, block_triangles) = (&self.candidates, &self.block_triangles);
        let mut slabs: Vec<Option<Slab>> = whole
            .into_blocks(block_vertices, block_triangles)
            .into_iter()
            .map(Some)
            .collect();
        // The list is in order of the smaller end, so each block's pairs are one run.
        let block_of = |i: u32| candidates[i as usize].a / block_vertices;
        // (A second run for the same block cannot happen: `selected` is in list order.
        // Were it to, its pairs would go to the sequential attempts, in order.)
        let mut strays = Vec::new();
        let mut jobs: Vec<(Slab, &[u32])> = Vec::new();
        for pairs in selected.chunk_by(|&x, &y| block_of(x) == block_of(y)) {
            match slabs[block_of(pairs[0]) as usize].take() {
                Some(slab) => jobs.push((slab, pairs)),
                None => strays.extend_from_slice(pairs),
            }
        }
        debug_assert!(strays.is_empty(), "a round's pairs out of list order");
        let outcomes: Vec<BlockOutcome> = jobs
            .into_par_iter()
            .map(|(mut slab, pairs)| contract_block(&mut slab, &fixed, candidates, pairs, watch))
            .collect();
        drop(slabs);
        // In block order, as if the blocks had run one after another.
        deferred.clear();
        deferred.extend_from_slice(&strays);
        let mut total = BlockOutcome::default();
        for outcome in outcomes {
            deferred.extend_from_slice(&outcome.deferred);
            for change in &outcome.waiver_changes {
                match *change {
                    WaiverChange::Take(a, b) => {
                        self.waivers.take(a, b);
                    }
                    WaiverChange::Waive(a, b) => self.waivers.waive(a, b),
                    WaiverChange::Forget(v) => self.waivers.forget(v),
                }
            }
            if let Some(pairs) = &mut self.virtual_pairs {
                for &[kept, removed] in &outcome.merges {
                    pairs.contract(kept, removed, |_, _| {});
                }
            }
            if let Some(exact) = &mut self.exact {
                for change in &outcome.exact_changes {
                    let collapsed = change.collapsed.iter().copied();
                    exact.contract(change.kept, change.removed, collapsed);
                }
            }
            for contraction in &outcome.contractions {
                observer.contracted(contraction);
            }
            self.counters.absorb(&outcome.counters);
            total.contracted += outcome.contracted;
            total.removed += outcome.removed;
            total.attempted += outcome.attempted;
            total.waived += outcome.waived;
            total.over_bound |= outcome.over_bound;
        }
        if !strays.is_empty() {
            // Candidate indices are the list order.
            deferred.sort_unstable();
        }
        total
    }

    /// The corners of triangle `t` in the normalised frame.
    fn corners(&self, t: [u32; 3]) -> [DVec3; 3] {
        t.map(|c| self.position[c as usize])
    }

    /// Each face's normal and plane, and each vertex's quadric summed along its incident
    /// list (both on the thread pool; each sum in a fixed order, so the bits do not
    /// depend on the thread count). Needs the incident lists. Returns the weighting's
    /// constant added to face areas (`None`: unit weights).
    fn sum_face_planes(&mut self, options: &SimplifyOptions) -> Option<f64> {
        // The areas on both cores, summed on one in the order of `live`: the bits of
        // that order, whatever the thread count.
        let areas: Vec<f64> = self
            .live
            .par_iter()
            .map(|&t| {
                let [a, b, c] = self.corners(self.triangles[t as usize]);
                unit_normal_and_area(a, b, c).map_or(0.0, |(_, area)| area)
            })
            .collect();
        let areas: f64 = areas.iter().sum();
        let mean_area = if self.live.is_empty() {
            0.0
        } else {
            areas / self.live.len() as f64
        };
        let area_offset = options.weighting.area_offset(mean_area);
        // Each triangle's normal and weighted plane, by triangle index, on both cores;
        // a triangle that is not live keeps a zero normal (never read) and no plane.
        // Planes rather than quadrics kept (40 bytes a triangle instead of 80, at the
        // setup's memory peak); with exact quadrics the planes are kept for the run.
        // Both arrays are written once, by the threads that compute them: filled
        // arrays made first were 64 bytes a triangle of pages faulted in and zeroed on
        // one core (14% of the sphere:4M run's page faults), then written again.
        let count = self.triangles.len();
        let is_live = (self.live.len() < count).then(|| {
            let mut is_live = vec![false; count];
            for &t in &self.live {
                is_live[t as usize] = true;
            }
            is_live
        });
        let (position, triangles) = (&self.position, &self.triangles);
        let (mut normals, mut planes) = (Vec::new(), Vec::new());
        (0..count)
            .into_par_iter()
            .map(|t| {
                if is_live.as_ref().is_some_and(|live| !live[t]) {
                    return (DVec3::ZERO, WeightedPlane::NONE);
                }
                let [pa, pb, pc] = triangles[t].map(|c| position[c as usize]);
                let plane = match area_offset {
                    Some(extra) => WeightedPlane::from_triangle_area_plus(pa, pb, pc, extra),
                    None => WeightedPlane::from_triangle_unweighted(pa, pb, pc),
                };
                ((pb - pa).cross(pc - pa), plane)
            })
            .unzip_into_vecs(&mut normals, &mut planes);
        // Each vertex's quadric, summed over its live triangles in the order of
        // `live` (the order of its incident list): the bits the sum in that order gives,
        // whatever the thread count. (Made from the plane at each corner rather than
        // kept per triangle: 80 bytes a triangle saved.)
        let incidence = &self.incidence;
        self.quadric = (0..self.position.len() as u32)
            .into_par_iter()
            .map(|v| {
                let mut sum = Quadric::default();
                for &t in incidence.of(v) {
                    sum += planes[t as usize].quadric();
                }
                sum
            })
            .collect();
        self.original_normals = normals;
        if let Some(exact) = &mut self.exact {
            exact.set_face_planes(planes);
        }
        area_offset
    }
}

impl PassEngine {
    /// Lists the live triangles around every vertex, each vertex's in increasing
    /// triangle order (a counting sort of the live triangles' corners).
    fn list_incident_triangles(&mut self) {
        let (live, triangles) = (&self.live, &self.triangles);
        self.incidence.rebuild(self.position.len(), || {
            live.iter()
                .flat_map(move |&t| triangles[t as usize].map(move |c| (c, t)))
        });
    }

    /// The live triangles around `v`, with their current corners, into `out`.
    fn gather(&self, v: u32, out: &mut Vec<Around>) {
        out.clear();
        for &t in self.incidence.of(v) {
            let corners = self.triangles[t as usize];
            if corners[0] != REMOVED {
                out.push(Around {
                    triangle: t,
                    corners,
                });
            }
        }
    }

    /// Border planes ([`BoundaryMode::Planes`]) or border locks ([`BoundaryMode::Locked`]),
    /// as the greedy loop adds them: a border edge is an edge of exactly one triangle.
    ///
    /// The border edges are found on the thread pool, each vertex's from its smaller
    /// end by [`border_neighbours`], in the order of the vertex's triangles; then added
    /// on one core in vertex order, so the sums, and their bits, are the same whatever
    /// the thread count. (The search on one core, with a table of counts indexed by
    /// vertex, was 53 of the 178 ms of the dragon's `--fast` setup.)
    fn initialise_boundary(&mut self, options: &SimplifyOptions, area_offset: Option<f64>) {
        let weight = match options.boundary {
            BoundaryMode::Free => return,
            BoundaryMode::Planes(w) if w > 0.0 && w.is_finite() => Some(w),
            BoundaryMode::Planes(_) => return,
            BoundaryMode::Locked => None,
        };
        // (smaller end, larger end, the edge's triangle)
        let borders: Vec<(u32, u32, u32)> = (0..self.position.len() as u32)
            .into_par_iter()
            .map_init(Vec::new, |around, v| {
                self.gather(v, around);
                let ends = border_neighbours(v, around);
                let mut found = SmallVec::<[(u32, u32, u32); 4]>::new();
                if ends.last().is_some_and(|&last| last > v) {
                    for x in around.iter() {
                        for c in x.corners {
                            if c > v && ends.binary_search(&c).is_ok() {
                                found.push((v, c, x.triangle));
                            }
                        }
                    }
                }
                found
            })
            .flat_map_iter(|found| found)
            .collect();
        for (v, x, t) in borders {
            let Some(w) = weight else {
                self.locked[v as usize] = true;
                self.locked[x as usize] = true;
                continue;
            };
            let [p0, p1, p2] = self.corners(self.triangles[t as usize]);
            let normal = (p1 - p0).cross(p2 - p0).normalize_or_zero();
            let (pa, pb) = (self.position[v as usize], self.position[x as usize]);
            let plane_weight = match area_offset {
                Some(extra) => w * (pa.distance_squared(pb) + extra),
                None => w,
            };
            let q = Quadric::boundary_constraint(pa, pb, normal, plane_weight);
            self.quadric[v as usize] += q;
            self.quadric[x as usize] += q;
            if let Some(exact) = &mut self.exact {
                exact.add_border_plane(v, x, q);
            }
        }
    }

    /// Contracts until `target` triangles are left, the error bound, no contraction
    /// is possible, or the observer stops it.
    pub fn run(&mut self, target: usize, observer: &mut dyn Observer) -> StopReason {
        let start = self.live.len();
        let reason = loop {
            if self.live.len() <= target {
                break StopReason::TargetReached;
            }
            match self.pass(target, start, observer) {
                // A pair waived in this pass is tried without the check in the next.
                PassEnd::Done {
                    contracted: 0,
                    waived: 0,
                } => break StopReason::NoValidPair,
                PassEnd::Done { .. } => {}
                PassEnd::MaxErrorReached => break StopReason::MaxErrorReached,
                PassEnd::Cancelled => break StopReason::Cancelled,
            }
        };
        observer.progress(Progress {
            triangles: self.live.len(),
            triangles_start: start,
            target,
        });
        reason
    }

    /// One pass (see the module's doc). `start` is the run's triangle count, for
    /// progress.
    fn pass(&mut self, target: usize, start: usize, observer: &mut dyn Observer) -> PassEnd {
        self.pass += 1;
        // The segments of exact quadrics are listed on one core while the triangles
        // and edges are listed on the other: neither reads what the other writes.
        let mut exact = self.exact.take();
        rayon::join(
            || {
                if let Some(exact) = &mut exact {
                    exact.start_pass();
                }
            },
            || {
                if self.pass > 1 {
                    self.list_incident_triangles();
                }
                self.list_edges();
            },
        );
        self.exact = exact;
        self.cost_edges();
        // Each contraction of an interior edge removes two triangles. (The batch is
        // larger, see `list_batch`; the rounds stop at the target, cheapest first.)
        let needed = self.live.len() - target;
        let edges = self.candidates.len();
        let mut take = needed.div_ceil(2).clamp(1, edges.max(1));
        let mut live_count = self.live.len();
        let mut contracted = 0;
        let mut waived = 0;
        let mut end = None;
        let mut over_bound = false;
        let mut selected = std::mem::take(&mut self.selected);
        let mut speculations = Vec::new();
        let mut batch = std::mem::take(&mut self.batch);
        let mut deferred = std::mem::take(&mut self.deferred);
        self.list_batch(take, &mut batch);
        self.tried.clear();
        self.tried.resize(edges, false);
        // Rounds: the local minima of the batch are contracted (or refused), then the
        // batch loses them and every edge at a vertex that moved, and the local minima
        // of what is left go next, until none is left. If the whole pass contracts
        // nothing, a batch four times larger, and so on (nothing has changed).
        'rounds: loop {
            // A contraction can remove more triangles than were still needed (a
            // vertex of a non-manifold fan), so the target can be passed mid-round.
            if live_count <= target {
                break;
            }
            if batch.is_empty() {
                if contracted > 0 || take == edges {
                    break;
                }
                take = take.saturating_mul(4).min(edges);
                self.list_batch(take, &mut batch);
                let tried = &self.tried;
                batch.retain(|&i| !tried[i as usize]);
                continue;
            }
            self.select_local_minima(&batch, &mut selected);
            let may_reach_target = selected.len() * 2 >= live_count - target;
            if may_reach_target {
                // The round may reach the target: the cheapest first, so that the
                // ones left out are the costliest, not the last in vertex order.
                let candidates = &self.candidates;
                selected.sort_unstable_by(|&x, &y| {
                    cheaper((&candidates[x as usize], x), (&candidates[y as usize], y))
                });
            }
            // Far from the target, the pairs interior to their block go first, on the
            // thread pool; the others follow in order (see `pass_blocks`). Each
            // interior contraction removes at most two triangles, so the target
            // cannot be passed among them.
            #[cfg(test)]
            let blocks_in_order = self.probes.blocks_in_order;
            #[cfg(not(test))]
            let blocks_in_order = false;
            let attempts = if !may_reach_target && self.uses_blocks() && blocks_in_order {
                #[cfg(test)]
                self.interior_first(&selected, &mut deferred);
                &deferred
            } else if !may_reach_target && self.uses_blocks() {
                let blocks = self.contract_blocks(&selected, &mut deferred, observer);
                live_count -= blocks.removed;
                contracted += blocks.contracted;
                waived += blocks.waived;
                #[cfg(test)]
                {
                    self.probes.block_contractions += blocks.contracted;
                    self.probes.block_deferrals += deferred.len();
                }
                over_bound |= blocks.over_bound;
                if self.count_attempts(blocks.attempted, [live_count, start, target], observer) {
                    end = Some(PassEnd::Cancelled);
                    break 'rounds;
                }
                &deferred
            } else {
                &selected
            };
            for (k, &i) in attempts.iter().enumerate() {
                if live_count <= target {
                    break 'rounds;
                }
                if k % SPECULATION_CHUNK == 0 {
                    speculations.clear();
                    if self.speculating() {
                        let end = attempts.len().min(k + SPECULATION_CHUNK);
                        // Not past the edges the target can still take (two triangles
                        // each), with room for refusals.
                        let wanted = (live_count - target).div_ceil(2) + SPECULATION_CHUNK / 8;
                        let end = end.min(k + wanted);
                        self.speculate(&attempts[k..end], &mut speculations);
                    }
                    (self.chunk_attempted, self.chunk_contracted) = (0, 0);
                }
                self.chunk_attempted += 1;
                let speculation = speculations
                    .get(k % SPECULATION_CHUNK)
                    .and_then(Option::as_ref);
                let Candidate { a, b, .. } = self.candidates[i as usize];
                match self.try_contract(a, b, live_count, true, speculation, observer) {
                    Attempt::Contracted { removed, .. } => {
                        live_count -= removed;
                        contracted += 1;
                        self.chunk_contracted += 1;
                    }
                    Attempt::Refused | Attempt::NotAPair => {}
                    Attempt::Waived => waived += 1,
                    // Never contracted; the pass goes on with the pairs under the bound.
                    Attempt::OverErrorBound => over_bound = true,
                }
                if self.count_attempts(1, [live_count, start, target], observer) {
                    end = Some(PassEnd::Cancelled);
                    break 'rounds;
                }
            }
            // Attempted edges leave the batch (a refused one is asked again next
            // pass), and so do edges at a moved vertex (their cost is stale).
            for &i in &selected {
                self.tried[i as usize] = true;
            }
            let (candidates, moved_in, pass, tried) =
                (&self.candidates, &self.moved_in, self.pass, &self.tried);
            batch.retain(|&i| {
                let c = &candidates[i as usize];
                moved_in[c.a as usize] != pass
                    && moved_in[c.b as usize] != pass
                    && !tried[i as usize]
            });
        }
        self.batch = batch;
        self.selected = selected;
        self.deferred = deferred;
        self.drop_removed();
        match end {
            Some(end) => end,
            None if contracted == 0 && waived == 0 && over_bound => PassEnd::MaxErrorReached,
            None => PassEnd::Done { contracted, waived },
        }
    }

    /// Counts `attempted` more attempts and, every [`OBSERVER_INTERVAL`] of them, tells
    /// the observer the live triangle count (of the run's `start`, towards `target`) and
    /// asks whether to stop: `true` when it says so.
    fn count_attempts(
        &mut self,
        attempted: usize,
        [live, start, target]: [usize; 3],
        observer: &mut dyn Observer,
    ) -> bool {
        self.since_report += attempted;
        if self.since_report < OBSERVER_INTERVAL {
            return false;
        }
        self.since_report = 0;
        observer.progress(Progress {
            triangles: live,
            triangles_start: start,
            target,
        });
        observer.should_stop()
    }

    /// The indices of this pass's batch into `batch`, in listing order: the `take`
    /// cheapest edges, and without the orientation check every edge whose cost is
    /// within [`BATCH_COST_FACTOR`] of the `take`-th cheapest's.
    fn list_batch(&mut self, take: usize, batch: &mut Vec<u32>) {
        let candidates = &self.candidates;
        batch.clear();
        if take >= candidates.len() {
            batch.extend(0..candidates.len() as u32);
            return;
        }
        // The batch's largest key, the `take`-th cheapest (see `cheaper`).
        let by_key = |x: &(f64, u32), y: &(f64, u32)| by_cost(*x, *y);
        let key = |i: usize| (candidates[i].cost, i as u32);
        let bound = nth_key(candidates.len(), take - 1, key, by_key, &mut self.keys);
        // (A cost at or below 0 only gains its ties at the bound.) On both cores; the
        // batch keeps the list's order.
        let within = if self.input_surface.is_some() {
            f64::NEG_INFINITY
        } else {
            bound.0 * BATCH_COST_FACTOR
        };
        batch.par_extend((0..candidates.len() as u32).into_par_iter().filter(|&i| {
            let cost = candidates[i as usize].cost;
            cost <= within || by_key(&(cost, i), &bound).is_le()
        }));
    }

    /// The edges of `batch` that are the cheapest of `batch` at both of their ends,
    /// into `selected`, in the batch's order. No two of them share a vertex, and an
    /// edge with a cheaper one next to it waits, as it would in the greedy order.
    fn select_local_minima(&mut self, batch: &[u32], selected: &mut Vec<u32>) {
        let candidates = &self.candidates;
        for &i in batch {
            let c = &candidates[i as usize];
            for end in [c.a, c.b] {
                let best = &mut self.best[end as usize];
                if *best == u32::MAX
                    || cheaper((c, i), (&candidates[*best as usize], *best)).is_lt()
                {
                    *best = i;
                }
            }
        }
        selected.clear();
        selected.extend(batch.iter().copied().filter(|&i| {
            let c = &candidates[i as usize];
            self.best[c.a as usize] == i && self.best[c.b as usize] == i
        }));
        for &i in batch {
            let c = &candidates[i as usize];
            self.best[c.a as usize] = u32::MAX;
            self.best[c.b as usize] = u32::MAX;
        }
    }

    /// Lists every edge of the live triangles once, as (smaller end, larger end), in
    /// order of the smaller end. The last pass's list, with its costs as computed
    /// (unpenalised), becomes `last_listed`, and the list before it is overwritten.
    fn list_edges(&mut self) {
        // Handed over rather than copied at costing time: the copy was 16 bytes an edge
        // a pass, the first pass's onto fresh pages.
        for (i, cost) in self.unpenalised_costs.drain(..) {
            self.candidates[i as usize].cost = cost;
        }
        std::mem::swap(&mut self.candidates, &mut self.last_listed);
        std::mem::swap(&mut self.listed_first, &mut self.last_listed_first);
        self.seen_with.fill(u32::MAX);
        self.candidates.clear();
        self.listed_first.clear();
        for v in 0..self.position.len() as u32 {
            self.listed_first.push(self.candidates.len() as u32);
            for &t in self.incidence.of(v) {
                for c in self.triangles[t as usize] {
                    if c > v && self.seen_with[c as usize] != v {
                        self.seen_with[c as usize] = v;
                        self.candidates.push(Candidate {
                            a: v,
                            b: c,
                            cost: 0.0,
                        });
                    }
                }
            }
            // Then its virtual pairs that are not edges (yet), each once.
            if let Some(pairs) = &self.virtual_pairs {
                for &id in pairs.of(v) {
                    let [x, c] = pairs.ends(id);
                    if x == v && self.seen_with[c as usize] != v {
                        self.seen_with[c as usize] = v;
                        self.candidates.push(Candidate {
                            a: v,
                            b: c,
                            cost: 0.0,
                        });
                    }
                }
            }
        }
        self.listed_first.push(self.candidates.len() as u32);
    }

    /// Costs every candidate, on both cores (each cost reads only its two ends). A NaN
    /// cost (only from overflow) is stored as +∞, so that it comes last.
    ///
    /// An edge whose ends did not move in the last pass existed then (a new edge
    /// always has a moved end) and has the same quadrics and positions, so its cost is
    /// taken from the last pass's list instead of solved again: the same value, bit
    /// for bit. Late passes re-cost only a few percent of their edges this way.
    fn cost_edges(&mut self) {
        // Written in place (the list taken out so the rest of `self` can be read
        // meanwhile): a fresh list of costs each pass was 8 bytes per edge of new
        // pages to fault in and then copy over.
        let mut candidates = std::mem::take(&mut self.candidates);
        let this = &*self;
        candidates.par_iter_mut().for_each(|c| {
            c.cost = match this.last_cost(c.a, c.b) {
                Some(cost) => cost,
                None => {
                    let (placed, _) = this.place(c.a, c.b);
                    if placed.cost.is_nan() {
                        f64::INFINITY
                    } else {
                        placed.cost
                    }
                }
            };
        });
        self.candidates = candidates;
        // Waived pairs are ranked at the greedy loop's penalty on their merged quadric.
        // (Few: a pass lists them first, then reads their quadrics.)
        if self.waivers.is_empty() {
            return;
        }
        let waived: Vec<usize> = (0..self.candidates.len())
            .filter(|&i| {
                let c = &self.candidates[i];
                self.waivers.contains(c.a, c.b)
            })
            .collect();
        // The unpenalised costs are the ones a later pass may reuse: kept aside.
        for i in waived {
            let Candidate { a, b, cost } = self.candidates[i];
            self.unpenalised_costs.push((i as u32, cost));
            self.candidates[i].cost = penalised(cost, &self.merged_quadric(a, b));
        }
    }

    /// The cost of the edge `a b` (`a < b`) in the last pass's list, when neither end
    /// moved in that pass.
    fn last_cost(&self, a: u32, b: u32) -> Option<f64> {
        let last = self.pass.checked_sub(1).filter(|&p| p > 0)?;
        if self.moved_in[a as usize] == last || self.moved_in[b as usize] == last {
            return None;
        }
        let range = self.last_listed_first[a as usize] as usize
            ..self.last_listed_first[a as usize + 1] as usize;
        self.last_listed[range]
            .iter()
            .find(|c| c.b == b)
            .map(|c| c.cost)
    }

    /// The merged quadric of `a` and `b`, where the new vertex would go and its cost;
    /// a locked end stays put.
    fn place(&self, a: u32, b: u32) -> (Placement, Quadric) {
        let q = self.merged_quadric(a, b);
        let (a, b) = (a as usize, b as usize);
        let ends = [
            (self.position[a], self.locked[a]),
            (self.position[b], self.locked[b]),
        ];
        (place_merged(&q, ends, self.settings.placement), q)
    }

    /// The quadric of `a` and `b` merged: `Q_a + Q_b`, less `Q_ab` with exact quadrics.
    fn merged_quadric(&self, a: u32, b: u32) -> Quadric {
        let mut q = self.quadric[a as usize] + self.quadric[b as usize];
        if let Some(exact) = &self.exact {
            q -= self.shared_planes(exact, a, b);
        }
        q
    }

    /// `Q_ab` of exact quadrics for `a` and `b` ([`shared_planes`]).
    fn shared_planes(&self, exact: &PassExact, a: u32, b: u32) -> Quadric {
        let triangles = (0, &self.triangles[..]);
        shared_planes(&self.incidence, triangles, exact, [a, b])
    }

    /// Checks and contracts the edge `a b` (both unmoved in this pass); `live` is the
    /// live triangle count.
    ///
    /// `speculation` is what [`speculate`](Self::speculate) found for the pair.
    ///
    /// A pair on no common triangle is a virtual pair: attempted only when
    /// `virtual_allowed` (the greedy order's edges that lost their last triangle are
    /// not).
    fn try_contract(
        &mut self,
        a: u32,
        b: u32,
        live: usize,
        virtual_allowed: bool,
        speculation: Option<&Speculation>,
        observer: &mut dyn Observer,
    ) -> Attempt {
        let mut around = std::mem::take(&mut self.around);
        self.gather(a, &mut around[0]);
        self.gather(b, &mut around[1]);
        let shared = around[0].iter().filter(|x| x.corners.contains(&b)).count();
        if shared == 0 && !virtual_allowed {
            self.around = around;
            return Attempt::NotAPair;
        }
        let Some((kept, _)) = self.kept_first(a, b) else {
            self.around = around;
            self.counters.reject(Rejection::Locked);
            return Attempt::Refused;
        };
        let (a, b) = if kept == a {
            (a, b)
        } else {
            around.swap(0, 1);
            (b, a)
        };
        // Never contract the last faces away: the output must keep a triangle.
        let attempt = if shared >= live {
            Attempt::Refused
        } else {
            self.check_and_contract(a, b, shared, &around, speculation, observer)
        };
        self.around = around;
        attempt
    }

    /// The pair `a b` in the order it is contracted (the second end into the first):
    /// a locked end is the one that stays; `None` when both are locked.
    fn kept_first(&self, a: u32, b: u32) -> Option<(u32, u32)> {
        match (self.locked[a as usize], self.locked[b as usize]) {
            (true, true) => None,
            (false, true) => Some((b, a)),
            _ => Some((a, b)),
        }
    }

    /// Where contracting `b` into `a` puts the vertex, in model units: `placed`, or
    /// `a`'s position when an end is locked or `placed` does not map to a finite point.
    fn world_position(&self, a: u32, placed: &Placement, any_locked: bool) -> DVec3 {
        if any_locked {
            // Bit for bit where it was, not a round trip through the frame.
            return DVec3::from_array(self.world[a as usize]);
        }
        let world = self.frame.to_world(placed.position);
        if world.is_finite() {
            world
        } else {
            DVec3::from_array(self.world[a as usize])
        }
    }

    /// For each pair of `selected` (the next edges of a round, in order), what its
    /// attempt will need that a contraction of another pair cannot change, computed
    /// against the current arrays on both cores, into `out` (one entry per pair; `None`
    /// when both ends are locked). Starts a new chunk: every vertex that moves from now
    /// on is marked with it, so that the attempts can tell which answers still hold.
    ///
    /// Why: the orientation check's quick tests (see [`InputSurface::agrees`]) and the
    /// placements were most of a round's sequential work, and the pairs of a round
    /// share no vertex. What a contraction of
    /// `d` into `c` changes: the position of `c`, and the triangles around `d` (renamed
    /// to `c`) and around both (removed). So for a pair `a b` of the same round (`a`,
    /// `b`, `c`, `d` distinct):
    /// - its merged quadric and placement are unchanged: they read the quadrics and
    ///   positions of `a` and `b`, and the planes of the triangles on both `a` and `b`
    ///   and of the segments joining them; a triangle on both never holds `c` and `d`
    ///   together, and renaming `d` to `c` neither adds nor removes `a` or `b` from a
    ///   triangle;
    /// - a moved face's orientation verdict is a function of its corners' positions
    ///   (the hints change the work, not the answer), so a face found to agree still
    ///   does when none of its current corners moved since the speculation (a renamed
    ///   or collapsed face has `c` among its corners, or is gone).
    ///
    /// Everything else (the fold-over, merge, border-loop and lock checks) is asked
    /// again at the attempt, in order, so a pair's outcome is the one the sequential
    /// order gives, bit for bit, with any number of threads. Debug builds check the
    /// placement against a fresh one.
    fn speculate(&mut self, selected: &[u32], out: &mut Vec<Option<Speculation>>) {
        self.chunk += 1;
        let this = &*self;
        selected
            .par_iter()
            .with_min_len(SPECULATION_MIN_LEN)
            .map_init(
                || [Vec::new(), Vec::new()],
                |around, &i| {
                    let Candidate { a, b, .. } = this.candidates[i as usize];
                    this.speculate_one(a, b, around)
                },
            )
            .collect_into_vec(out);
    }

    /// Whether this pass's attempts are speculated (see [`speculate`](Self::speculate)):
    /// with the orientation check on, whose quick tests are the work it spreads, and
    /// when at least half the pairs attempted since the last chunk began were
    /// contracted.
    ///
    /// Why not always: without the check, the placements alone did not pay for
    /// handing them over (on the dragon at ratio 0.1 with `--fast`, the contractions
    /// took 7% longer). And where the other checks refuse most pairs, the quick tests
    /// speculated for them are wasted: on the CAD mesh ps_mk4_gantry (190,000
    /// refusals for 22,500 contractions) the contractions took 2x as long, and 17%
    /// longer still with those checks asked first in the speculation. The rule changes
    /// only the work: the outputs are the same either way.
    fn speculating(&self) -> bool {
        #[cfg(test)]
        if !self.probes.speculate_chunks {
            return false;
        }
        self.input_surface.is_some() && self.chunk_contracted * 2 >= self.chunk_attempted
    }

    /// [`speculate`](Self::speculate) for one pair; `around` is scratch.
    fn speculate_one(&self, a: u32, b: u32, around: &mut [Vec<Around>; 2]) -> Option<Speculation> {
        let (a, b) = self.kept_first(a, b)?;
        let (placed, quadric) = self.place(a, b);
        let mut speculation = Speculation {
            placed,
            quadric,
            faces: SmallVec::new(),
        };
        let error = quadric.rms_distance(placed.cost);
        let Some(surface) = &self.input_surface else {
            return Some(speculation);
        };
        if error > self.settings.max_error_bound || self.waivers.contains(a, b) {
            return Some(speculation);
        }
        let any_locked = self.locked[a as usize] || self.locked[b as usize];
        let world = self.world_position(a, &placed, any_locked);
        self.gather(a, &mut around[0]);
        self.gather(b, &mut around[1]);
        // The other checks are not asked first: in a pass that speculates, they refuse
        // few pairs (see `speculating`), and asking them here too would double their
        // cost for all.
        let moved = self.frame.to_normalized(world);
        let mut neighbour_hint = None;
        for x in around.iter().flatten() {
            let corners = x.corners;
            if corners.contains(&a) && corners.contains(&b) {
                continue;
            }
            let new = moved_corners(&self.position, corners, [a, b], moved);
            // Only the quick tests: a full search here would start from the hints as
            // they were, which the attempts before this one may have moved on (on CAD
            // meshes, where full searches are common and dear, asking them here made
            // the run twice as slow); the attempt asks it with the hints of its time.
            let Quick::Agrees { settled } =
                surface.agrees_quickly(x.triangle as usize, new, &mut neighbour_hint)
            else {
                break;
            };
            speculation.faces.push(FaceAgrees {
                triangle: x.triangle,
                settled,
            });
        }
        Some(speculation)
    }

    /// [`try_contract`](Self::try_contract) with `around` = the live triangles of `a`
    /// and of `b`, `shared` of which are on both.
    fn check_and_contract(
        &mut self,
        a: u32,
        b: u32,
        shared: usize,
        around: &[Vec<Around>; 2],
        speculation: Option<&Speculation>,
        observer: &mut dyn Observer,
    ) -> Attempt {
        let any_locked = self.locked[a as usize] || self.locked[b as usize];
        let (placed, q) = match speculation {
            Some(s) => {
                debug_assert!({
                    let (placed, q) = self.place(a, b);
                    placed.position.to_array().map(f64::to_bits)
                        == s.placed.position.to_array().map(f64::to_bits)
                        && placed.cost.to_bits() == s.placed.cost.to_bits()
                        && q.entries().map(f64::to_bits) == s.quadric.entries().map(f64::to_bits)
                });
                (s.placed, s.quadric)
            }
            None => self.place(a, b),
        };
        let error = q.rms_distance(placed.cost);
        if error > self.settings.max_error_bound {
            return Attempt::OverErrorBound;
        }
        let world = self.world_position(a, &placed, any_locked);
        if let Err(why) = self.check(a, b, world, shared, around) {
            self.counters.reject(why);
            return Attempt::Refused;
        }
        // Last, as in the greedy loop: the only check that searches outside the
        // neighbourhood. A waived pair (refused before, ranked at a penalty since) is
        // taken without it.
        let waived = self.waivers.take(a, b);
        if !waived && !self.faces_agree_with_input(a, b, world, around, speculation) {
            self.counters.reject(Rejection::Orientation);
            self.waivers.waive(a, b);
            return Attempt::Waived;
        }
        // The contraction itself.
        self.waivers.forget(a);
        self.waivers.forget(b);
        self.moved_in_chunk[a as usize] = self.chunk;
        self.moved_in_chunk[b as usize] = self.chunk;
        if let Some(exact) = &mut self.exact {
            // Each collapsed triangle's plane joins `a` and its third corner now.
            let collapsed = around[0].iter().filter(|x| x.corners.contains(&b));
            exact.contract(
                a,
                b,
                collapsed.filter_map(|x| {
                    let third = x.corners.into_iter().find(|&c| c != a && c != b)?;
                    Some((x.triangle, third))
                }),
            );
        }
        if let Some(pairs) = &mut self.virtual_pairs {
            pairs.contract(a, b, |_, _| {});
        }
        let (mut slab, fixed) = self.split();
        let removed = slab.contract(&fixed, [a, b], world, q, around);
        let is_virtual = shared == 0;
        if is_virtual {
            self.counters.virtual_contractions += 1;
        } else {
            self.counters.edge_contractions += 1;
        }
        self.counters.max_error = self.counters.max_error.max(error);
        observer.contracted(&Contraction {
            kept: self.vertex_from[a as usize],
            removed: self.vertex_from[b as usize],
            is_virtual,
            quadric: q,
            position: placed.position,
            world: world.to_array(),
            cost: placed.cost,
        });
        Attempt::Contracted {
            removed,
            kept: a,
            gone: b,
        }
    }

    /// Every check of contracting `b` into `a` at `world`, the greedy loop's rules on
    /// the pass's arrays: fold-over (degenerate, flipped, sliver), merged faces, border
    /// loops, locks.
    fn check(
        &self,
        a: u32,
        b: u32,
        world: DVec3,
        shared: usize,
        around: &[Vec<Around>; 2],
    ) -> Result<(), Rejection> {
        plain_checks(
            &self.corners_view(),
            &self.fixed(),
            [a, b],
            world,
            shared,
            around,
        )?;
        if self.settings.any_locked && self.locked_vertex_would_vanish(a, b, around) {
            return Err(Rejection::Locked);
        }
        Ok(())
    }

    /// Whether every triangle that contracting `b` into `a` at `world` moves faces the
    /// same way as the input surface nearest to its new centroid (see
    /// [`super::orientation`]); true when the check is off. Triangles on both `a` and
    /// `b` collapse and are not asked.
    ///
    /// A face that `speculation` found to agree is taken as agreeing when none of its
    /// corners has moved since (see [`speculate`](Self::speculate)); the others are
    /// asked now.
    fn faces_agree_with_input(
        &mut self,
        a: u32,
        b: u32,
        world: DVec3,
        around: &[Vec<Around>; 2],
        speculation: Option<&Speculation>,
    ) -> bool {
        let Some(surface) = self.input_surface.as_mut() else {
            return true;
        };
        let known = speculation.map_or(&[][..], |s| &s.faces[..]);
        let (chunk, moved_in_chunk) = (self.chunk, &self.moved_in_chunk);
        let (mut reused, mut asked_again) = (0, 0);
        let still_holds = |x: &Around| {
            x.corners
                .iter()
                .all(|&c| moved_in_chunk[c as usize] != chunk)
        };
        for f in known {
            if let Some(t) = f.settled {
                surface.set_hint(f.triangle as usize, t);
            }
        }
        let moved = self.frame.to_normalized(world);
        // A triangle seen for the first time borrows the hint of the one checked before.
        let mut neighbour_hint = None;
        let agrees = around.iter().flatten().all(|x| {
            let corners = x.corners;
            if corners.contains(&a) && corners.contains(&b) {
                return true;
            }
            if known.iter().any(|f| f.triangle == x.triangle) {
                if still_holds(x) {
                    reused += 1;
                    return true;
                }
                asked_again += 1;
            }
            let new = moved_corners(&self.position, corners, [a, b], moved);
            surface.agrees(x.triangle as usize, new, &mut neighbour_hint)
        });
        #[cfg(test)]
        {
            self.probes.verdicts_reused += reused;
            self.probes.verdicts_asked_again += asked_again;
        }
        #[cfg(not(test))]
        let _ = (reused, asked_again);
        agrees
    }

    /// Whether contracting `b` into `a` would leave a locked vertex without a triangle:
    /// `a` itself, or a locked common neighbour whose triangles all collapse or merge.
    /// A neighbour that moved in this pass may list too few triangles, which can only
    /// make this refuse.
    fn locked_vertex_would_vanish(&self, a: u32, b: u32, around: &[Vec<Around>; 2]) -> bool {
        if self.locked[a as usize] {
            let left = around[0]
                .iter()
                .chain(&around[1])
                .filter(|x| !(x.corners.contains(&a) && x.corners.contains(&b)))
                .count();
            if left == 0 {
                return true;
            }
        }
        let mut of_w = Vec::new();
        for x in &around[0] {
            for w in x.corners {
                if w == a || w == b || !self.locked[w as usize] {
                    continue;
                }
                if !around[1].iter().any(|y| y.corners.contains(&w)) {
                    continue; // not a common neighbour
                }
                // Merges were refused before this check (`would_merge_faces`), so `w`
                // keeps every triangle but those on both `a` and `b`.
                self.gather(w, &mut of_w);
                if of_w
                    .iter()
                    .all(|y| y.corners.contains(&a) && y.corners.contains(&b))
                {
                    return true;
                }
            }
        }
        false
    }

    /// `selected` (a round, in list order) into `order` with the pairs
    /// interior to their block first, then the others, each in list order; found here
    /// independently of [`Slab::gather`], at the round's start (a contraction inside a
    /// block keeps its triangles' corners in the block, so a pair's standing cannot
    /// change during the round).
    #[cfg(test)]
    fn interior_first(&self, selected: &[u32], order: &mut Vec<u32>) {
        let layout_block = |v: u32| v / self.block_vertices;
        let n = self.position.len() as u32;
        let interior = |i: u32| {
            let Candidate { a, b, .. } = self.candidates[i as usize];
            let k = layout_block(a);
            let vertices = k * self.block_vertices..((k + 1) * self.block_vertices).min(n);
            let triangles = self.block_triangles[k as usize]..self.block_triangles[k as usize + 1];
            let mut shared = 0;
            for v in [a, b] {
                for &t in self.incidence.of(v) {
                    if !triangles.contains(&t) {
                        return false;
                    }
                    let corners = self.triangles[t as usize];
                    if corners[0] == REMOVED {
                        continue;
                    }
                    if !corners.iter().all(|c| vertices.contains(c)) {
                        return false;
                    }
                    if v == a && corners.contains(&b) {
                        shared += 1;
                    }
                }
            }
            shared <= 2
        };
        order.clear();
        order.extend(selected.iter().copied().filter(|&i| interior(i)));
        order.extend(selected.iter().copied().filter(|&i| !interior(i)));
    }

    /// Takes the removed triangles off the live list, ending the pass.
    fn drop_removed(&mut self) {
        let triangles = &self.triangles;
        self.live.retain(|&t| triangles[t as usize][0] != REMOVED);
    }

    /// The live triangles and the vertices they use, in model units, numbered and
    /// ordered as in the cleaned mesh.
    ///
    /// Only the used vertices: after a tenfold reduction nine in ten are unused, and
    /// the caller's cleaning of the output walks every vertex it is given (on one core,
    /// for most of its steps). What it drops is the same either way: unused vertices
    /// are dropped without a trace, and the used ones keep their order.
    pub fn to_mesh(&self) -> IndexedMesh {
        let mut number = vec![u32::MAX; self.world.len()];
        for &t in &self.live {
            for c in self.triangles[t as usize] {
                number[c as usize] = 0;
            }
        }
        let mut positions = Vec::new();
        let mut vertex_from = Vec::new();
        for (v, new) in number.iter_mut().enumerate() {
            if *new == 0 {
                *new = positions.len() as u32;
                positions.push(self.world[v]);
                vertex_from.push(self.vertex_from[v]);
            }
        }
        let mesh = IndexedMesh {
            positions,
            triangles: self
                .live
                .iter()
                .map(|&t| self.triangles[t as usize].map(|c| number[c as usize]))
                .collect(),
        };
        let triangle_from: Vec<u32> = self
            .live
            .iter()
            .map(|&t| self.triangle_from[t as usize])
            .collect();
        in_original_order(mesh, self.vertex_from.len(), &vertex_from, &triangle_from)
    }

    /// Live triangles whose normal points more than 90° away from the input triangle's.
    pub fn flipped_faces(&self) -> usize {
        self.live
            .iter()
            .filter(|&&t| {
                let [p0, p1, p2] = self.corners(self.triangles[t as usize]);
                (p1 - p0)
                    .cross(p2 - p0)
                    .dot(self.original_normals[t as usize])
                    < 0.0
            })
            .count()
    }
}

/// What [`PassEngine::try_contract`] did.
pub(super) enum Attempt {
    /// Contracted `gone` into `kept`, removing `removed` triangles.
    Contracted {
        removed: usize,
        kept: u32,
        gone: u32,
    },
    /// Refused by a check (counted) or to keep the last triangles.
    Refused,
    /// Refused by the orientation check (counted), and waived: ranked at a penalty
    /// next pass, and tried then without the check.
    Waived,
    /// The pair's error is above the bound: not contracted.
    OverErrorBound,
    /// Not attempted: the ends share no triangle, and virtual pairs were not allowed.
    NotAPair,
}

/// What [`PassEngine::speculate`] found for a pair, in the order it is contracted.
#[derive(Debug)]
struct Speculation {
    placed: Placement,
    quadric: Quadric,
    /// The moved faces that the orientation check's quick tests found to agree, in
    /// the order asked, up to the first they could not decide; empty when the check
    /// is off or was not reached.
    faces: SmallVec<[FaceAgrees; 12]>,
}

/// A moved face of a speculated pair that agrees with the input surface.
#[derive(Clone, Copy, Debug)]
struct FaceAgrees {
    triangle: u32,
    /// The triangle to become its hint (`None`: keep the hint it has).
    settled: Option<u32>,
}

/// What the tests of speculation and blocks set and read on a run (test builds only:
/// release builds have neither the switches nor the counts).
#[cfg(test)]
#[derive(Debug)]
struct Probes {
    /// Whether chunks may be speculated (the tests compare outputs with and without).
    speculate_chunks: bool,
    /// Instead of the blocks, attempt a round's interior pairs and then the others in
    /// order, all by the sequential attempts (the order the blocks must give the
    /// result of; see `interior_first`).
    blocks_in_order: bool,
    /// Moved faces' orientation verdicts taken from a speculation, and asked again
    /// because a corner had moved since.
    verdicts_reused: usize,
    verdicts_asked_again: usize,
    /// Pairs the blocks contracted, and left to the sequential attempts.
    block_contractions: usize,
    block_deferrals: usize,
}

#[cfg(test)]
impl Default for Probes {
    fn default() -> Self {
        Probes {
            speculate_chunks: true,
            blocks_in_order: false,
            verdicts_reused: 0,
            verdicts_asked_again: 0,
            block_contractions: 0,
            block_deferrals: 0,
        }
    }
}

/// The positions of a triangle's `corners` once the pair `ends` is contracted to
/// `moved` (normalised units): either end goes to `moved`, the others stay.
fn moved_corners(
    position: &[DVec3],
    corners: [u32; 3],
    ends: [u32; 2],
    moved: DVec3,
) -> [DVec3; 3] {
    corners.map(|c| {
        if ends.contains(&c) {
            moved
        } else {
            position[c as usize]
        }
    })
}

#[path = "greedy.rs"]
mod greedy;

#[cfg(test)]
#[path = "passes_speculation_tests.rs"]
mod speculation_tests;

#[cfg(test)]
#[path = "passes_blocks_tests.rs"]
mod blocks_tests;
