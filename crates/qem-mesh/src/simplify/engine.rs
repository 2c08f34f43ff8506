//! The one engine: the working mesh (flat arrays), its setup, and what both orders
//! share (listing and costing pairs, placement, progress, compaction).
//!
//! The working mesh: world and normalised positions, quadrics and locks per vertex;
//! each input triangle's current corners ([`REMOVED`] once it is gone) and input
//! normal; the live triangles around each vertex ([`Incidence`]); exact quadrics'
//! planes ([`PassExact`]); the virtual pairs ([`PairSet`]); the orientation check's
//! index ([`InputSurface`]) and the waivers. A contraction of `b` into `a` renames
//! `b` to `a` in `b`'s triangles and removes the triangles on both.
//!
//! The orders are policies of this engine, each a child module: [`passes`] (the
//! cheapest independent pairs per pass, meshoptimizer's order) and [`greedy`]
//! (Garland–Heckbert's heap). Both attempt a pair by [`attempt`]'s one sequence: lock
//! order, placement, error bound, every check, the orientation check and its waiver,
//! the contraction, the counters and the observer's event.
//!
//! The arrays are numbered in locality order ([`super::locality`]: vertices along a
//! space-filling curve), so "in order" is also "near in space", whatever order the
//! input came in; the output and the observer get the cleaned mesh's numbers back.

use super::carried::{gather_in_place, is_carried, CarriedQuadrics};
use super::checks::{Facing, Rejection};
use super::counters::Counters;
use super::incidence::Incidence;
use super::input_faces::{weighted_plane, InputFaces};
use super::locality::{in_locality_order, in_original_order, Renumbered};
use super::nth_key::nth_key;
use super::observer::{Contraction, Observer, Progress};
use super::options::QuadricMode;
use super::options::VirtualPairs;
use super::options::{BoundaryMode, SimplifyOptions, Weighting, SEAM_PLANE_WEIGHT};
use super::orientation::{InputSurface, Quick};
use super::pair_set::PairSet;
use super::pass_blocks::{
    border_neighbours, contract_block, merging_faces, plain_checks, shared_planes, Around,
    BlockOutcome, Candidate, Fixed, Positions, Slab, WaiverChange, BLOCK_VERTICES, REMOVED,
};
use super::pass_exact::PassExact;
use super::placement::place_merged;
use super::relaxation::Ladder;
use super::report::StopReason;
use super::settings::Settings;
use super::waivers::{penalised, Waivers};
use super::wedges::{Pin, Wedges};
use crate::inspect::{find, union};
use crate::pairs::grid::{virtual_pairs, GridOptions};
use crate::store::build::kept_triangles;
use crate::store::BuildStats;
use crate::IndexedMesh;
use qem_core::{unit_normal_and_area, DVec3, Frame, Placement, Quadric, WeightedPlane};
use rayon::prelude::*;
use smallvec::SmallVec;
use std::cmp::Ordering;

/// A pair's cost as the orders rank it: a NaN cost (only from overflow) as +∞, so
/// that it comes last.
pub(super) fn ranked(cost: f64) -> f64 {
    if cost.is_nan() {
        f64::INFINITY
    } else {
        cost
    }
}

/// The cost, on the merged quadric `q`, of a contraction that makes a surface reaching
/// `radius` (normalised units) from the new vertex vanish (see
/// [`Engine::vanishing_radius`]): the cost at which `q`'s RMS distance
/// ([`Quadric::rms_distance`]) is that radius, so the order ranks it and the error
/// bound and the report count it like any other error.
pub(super) fn vanishing_cost(radius: f64, q: &Quadric) -> f64 {
    radius * radius * q.weight().max(0.0)
}

/// The largest distance from `at` to `corners` (vertex numbers; positions from
/// `positions`).
pub(super) fn farthest_corner(
    positions: &Positions,
    corners: impl Iterator<Item = u32>,
    at: DVec3,
) -> f64 {
    corners
        .map(|c| positions.position(c).distance(at))
        .fold(0.0, f64::max)
}

/// The geometric error (as a squared distance in the normalised frame, times the
/// quadric's weight) an attribute-weighted placement may always add: 1e-4 of the
/// frame's half-size, squared.
const GEOMETRY_SLACK: f64 = 1e-8;

/// How much an attribute-weighted placement may raise the geometric error above the
/// geometry's own best placement: meshoptimizer's bound on its attribute update (its
/// `solvePositions`), 1.5.
const GEOMETRY_GROWTH: f64 = 1.5;

/// How often (in attempted contractions) the observer's progress is called.
const OBSERVER_INTERVAL: usize = 4096;

/// The state of one pass-based run.
pub(super) struct Engine {
    pub frame: Frame,
    pub settings: Settings,
    pub counters: Counters,
    /// World positions: a vertex that never moves keeps its input bits. (Positions in
    /// the normalised frame are computed from them when read: [`Positions`].)
    world: Vec<[f64; 3]>,
    /// The engine's arrays are in locality order ([`super::locality`]): for each
    /// vertex, its number in the cleaned mesh (for the output and the observer).
    vertex_from: Vec<u32>,
    /// For each triangle, its number in the cleaned mesh.
    triangle_from: Vec<u32>,
    quadric: Vec<Quadric>,
    /// At the setup of a seeded run, which vertices' quadrics were carried in (the
    /// planes the setup sums are in them already); empty otherwise and afterwards.
    seeded: Vec<bool>,
    locked: Vec<bool>,
    /// Corners of every cleaned input triangle; [`REMOVED`] in the first corner once
    /// the triangle is gone.
    triangles: Vec<[u32; 3]>,
    /// The indices of the live triangles, in increasing order.
    live: Vec<u32>,
    /// Which way each input triangle faces (in the normalised frame), and its face
    /// plane.
    input_faces: InputFaces,
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
    /// The last pass's edges whose costs this pass may reuse, with their costs, in
    /// listing order, and where each vertex's start ([`Engine::keep_reusable_costs`]).
    last_listed: Vec<Candidate>,
    last_listed_first: Vec<u32>,
    /// Whether the costs of `last_listed` were computed with merges allowed (which
    /// price a part that vanishes: [`Engine::vanishing_radius`]).
    last_costed_with_merges: bool,
    /// The candidates whose cost this pass ranks at the waivers' penalty, with their
    /// costs before it (restored before the reusable ones are kept).
    unpenalised_costs: Vec<(u32, f64)>,
    /// Per vertex, the last vertex whose edges were listed with it (edge listing).
    seen_with: Vec<u32>,
    around: [Vec<Around>; 2],
    /// The number of the current chunk of a round (see [`Engine::speculate`]), and
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
    /// The ladder of relaxations' record ([`super::ladder`]).
    pub ladder: Ladder,
    /// The attributes' wedges ([`super::wedges`]); `None` for a mesh without
    /// attribute channels or materials, which pays nothing for them.
    pub(super) wedges: Option<Wedges>,
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
            input_faces: &$engine.input_faces,
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
            frame: &$engine.frame,
            world: &mut $engine.world,
            quadric: &mut $engine.quadric,
            moved_in: &mut $engine.moved_in,
            triangles: &mut $engine.triangles,
            hints: $hints,
        }
    };
}

impl Engine {
    /// Face quadrics summed into vertex quadrics, border planes or locks, locked
    /// vertices; `locked` lists cleaned-mesh indices. With the orientation check on,
    /// also its index (built on the other core meanwhile), from which the input faces
    /// are then read ([`InputFaces`]). The vertices that have a quadric in `seed` (by
    /// cleaned-mesh vertex, [`CarriedQuadrics`]) start from it instead of the planes
    /// around them; the seed becomes the quadric array, so it is never held twice.
    pub fn new(
        cleaned: &IndexedMesh,
        frame: Frame,
        locked: &[u32],
        options: &SimplifyOptions,
        seed: Option<CarriedQuadrics>,
    ) -> Self {
        // The orientation check's index is independent of the rest of the setup: built
        // on the other core meanwhile (deterministic either way).
        let ((mut engine, area_offset), surface) = rayon::join(
            || Engine::set_up(cleaned, frame, locked, options, seed),
            || {
                options
                    .orientation_check
                    .then(|| InputSurface::new(cleaned, &frame))
            },
        );
        match surface {
            Some((surface, slots)) => engine.set_input_surface(surface, &slots, area_offset),
            None => engine.input_faces = engine.kept_input_faces(area_offset),
        }
        engine
    }

    /// [`new`](Self::new) but for the orientation check's index and the input faces
    /// (left empty); also returns the constant the face planes' weighting adds to
    /// face areas.
    fn set_up(
        cleaned: &IndexedMesh,
        frame: Frame,
        locked: &[u32],
        options: &SimplifyOptions,
        seed: Option<CarriedQuadrics>,
    ) -> (Self, Option<f64>) {
        let Renumbered {
            mesh,
            vertex_from,
            vertex_to,
            triangle_from,
        } = in_locality_order(cleaned, &frame);
        let n = mesh.positions.len();
        let mesh_triangle_count = mesh.triangles.len();
        // The triangles the engine keeps: none with a repeated corner (it would
        // count as live while having no area), only the first of each vertex set (the
        // locality order keeps it first). Cleaning has dropped both when its passes
        // were on; the search (16 bytes a triangle, at the setup's memory peak) runs
        // only when they were off.
        let live = if options.clean.drop_repeated_index && options.clean.drop_duplicates {
            (0..mesh.triangles.len() as u32).collect()
        } else {
            kept_triangles(&mesh.triangles, n, &mut BuildStats::default())
        };
        let mut engine = Engine {
            settings: Settings::new(options, &frame),
            frame,
            counters: Counters::default(),
            world: mesh.positions,
            vertex_from,
            triangle_from,
            // Summed by `sum_face_planes` (a filled array made first was 80 bytes a
            // vertex of pages written twice), or a seed's (`take_seed`).
            quadric: Vec::new(),
            seeded: Vec::new(),
            locked: vec![false; n],
            triangles: mesh.triangles,
            live,
            // Set by `new`, once it knows whether the orientation check's index holds
            // the input.
            input_faces: InputFaces::kept(Vec::new(), Vec::new(), None),
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
            last_costed_with_merges: false,
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
            exact: (options.quadrics == QuadricMode::Exact)
                .then(|| PassExact::new(n, mesh_triangle_count)),
            block_vertices: BLOCK_VERTICES,
            block_triangles: Vec::new(),
            deferred: Vec::new(),
            greedy: greedy::Greedy::default(),
            virtual_pairs: None,
            ladder: Ladder::default(),
            wedges: None,
        };
        engine.set_block_vertices(BLOCK_VERTICES);
        if let Some(seed) = seed {
            engine.take_seed(seed, options.weighting);
        }
        // The incident lists first: the quadrics are summed along them.
        engine.list_incident_triangles();
        let area_offset = engine.sum_face_planes(options);
        engine.initialise_boundary(options, area_offset);
        engine.wedges = Wedges::new(
            &cleaned.attributes,
            &engine.triangles,
            &engine.triangle_from,
            &engine.positions(),
            &options.attribute_weights,
        );
        engine.add_seam_planes(options, area_offset);
        engine.seeded = Vec::new();
        for &i in locked {
            if let Some(&v) = vertex_to.get(i as usize) {
                engine.locked[v as usize] = true;
            }
        }
        engine.find_virtual_pairs(options);
        engine.counters.locked_vertices = engine.locked.iter().filter(|&&l| l).count();
        engine.settings.any_locked = engine.counters.locked_vertices > 0;
        (engine, area_offset)
    }

    /// Turns the orientation check on with `surface`, built from the same cleaned mesh
    /// (`slots` as [`InputSurface::new`] returned them): each triangle's first hint is
    /// its own input triangle. The input faces are read from its index (kept, when it
    /// does not hold every triangle), their planes weighted with `area_offset`.
    fn set_input_surface(
        &mut self,
        mut surface: InputSurface,
        slots: &[u32],
        area_offset: Option<f64>,
    ) {
        let slot: Vec<u32> = (self.triangle_from.iter())
            .map(|&cleaned_t| slots[cleaned_t as usize])
            .collect();
        surface.seed_hints(slot.iter().copied().enumerate());
        self.input_faces = match InputFaces::from_index(surface.index(), slot, area_offset) {
            Some(faces) => faces,
            None => self.kept_input_faces(area_offset),
        };
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
        let n = self.world.len();
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
        let positions = self.positions();
        let points: Vec<[f64; 3]> = (0..n as u32)
            .map(|v| positions.position(v).to_array())
            .collect();
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

    /// Every vertex's positions.
    pub(super) fn positions(&self) -> Positions<'_> {
        Positions::whole(&self.frame, &self.world)
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
        let blocks = (self.world.len() as u32).div_ceil(self.block_vertices);
        let triangles = &self.triangles;
        self.block_triangles = (0..=blocks)
            .map(|k| {
                let start = k.saturating_mul(self.block_vertices);
                triangles.partition_point(|t| t.iter().min().is_some_and(|&c| c < start)) as u32
            })
            .collect();
    }

    /// Vertex `v`'s position in the normalised frame.
    #[inline]
    pub(super) fn position(&self, v: u32) -> DVec3 {
        self.positions().position(v)
    }

    /// The corners of triangle `t` in the normalised frame.
    fn corners(&self, t: [u32; 3]) -> [DVec3; 3] {
        let positions = self.positions();
        t.map(|c| positions.position(c))
    }

    /// Each vertex's quadric, summed from the weighted planes of the triangles along
    /// its incident list (on the thread pool; each sum in a fixed order, so the bits do
    /// not depend on the thread count). Needs the incident lists. Returns the
    /// weighting's constant added to face areas (`None`: unit weights).
    fn sum_face_planes(&mut self, options: &SimplifyOptions) -> Option<f64> {
        // The areas on both cores, summed on one in the order of `live`: the bits of
        // that order, whatever the thread count.
        // In a seeded run, over the triangles with a corner the seed does not carry
        // only: the rest were simplified by an earlier run, their areas far above the
        // input's, while these are input faces still (the tiles' border strips,
        // `crate::tiles::budget`), and the planes summed here are theirs.
        let summed_here = |t: u32| {
            let corners = self.triangles[t as usize];
            self.seeded.is_empty() || corners.iter().any(|&c| !self.seeded[c as usize])
        };
        // 0 for the others rather than a filter: rayon collects a filtered iterator in
        // pieces and then copies them (8 MB more at the peak on a 1M-triangle sphere).
        // Adding 0 changes no bit of the sum.
        let areas: Vec<f64> = self
            .live
            .par_iter()
            .map(|&t| {
                let [a, b, c] = self.corners(self.triangles[t as usize]);
                let area = unit_normal_and_area(a, b, c).map_or(0.0, |(_, area)| area);
                if summed_here(t) {
                    area
                } else {
                    0.0
                }
            })
            .collect();
        let count = if self.seeded.is_empty() {
            self.live.len()
        } else {
            self.live.iter().filter(|&&t| summed_here(t)).count()
        };
        let areas: f64 = areas.iter().sum();
        let mean_area = if count == 0 {
            0.0
        } else {
            areas / count as f64
        };
        let area_offset = options.weighting.area_offset(mean_area);
        // Each vertex's quadric, summed over its live triangles in the order of
        // `live` (the order of its incident list): the bits the sum in that order gives,
        // whatever the thread count. Each plane is computed at each of its three
        // corners rather than once into an array: the array was 40 bytes a triangle at
        // the setup's memory peak, and with the orientation check on nothing keeps it
        // afterwards (`InputFaces` reads the planes from the check's index).
        // The fields, not `self.positions()`: the seeded case writes `self.quadric`.
        let positions = Positions::whole(&self.frame, &self.world);
        let (triangles, incidence) = (&self.triangles, &self.incidence);
        let sum = |v: u32| {
            let mut sum = Quadric::default();
            for &t in incidence.of(v) {
                let [pa, pb, pc] = triangles[t as usize].map(|c| positions.position(c));
                sum += weighted_plane(pa, pb, pc, area_offset).quadric();
            }
            sum
        };
        if self.seeded.is_empty() {
            self.quadric = (0..self.world.len() as u32)
                .into_par_iter()
                .map(sum)
                .collect();
        } else {
            // A seeded run: only the vertices the seed does not carry.
            (self.quadric.par_iter_mut().enumerate())
                .filter(|(_, q)| !is_carried(q))
                .for_each(|(v, q)| *q = sum(v as u32));
        }
        area_offset
    }

    /// Each input triangle's facing and, with exact quadrics, weighted face plane
    /// (with `area_offset`, as [`sum_face_planes`](Self::sum_face_planes) weighted
    /// them), kept: the input faces without the orientation check's index. Only
    /// before the run: it reads the triangles' current corners.
    fn kept_input_faces(&self, area_offset: Option<f64>) -> InputFaces {
        // By triangle index, on both cores; a triangle that is not live keeps a zero
        // normal and no plane (neither is ever read). Both arrays are written once, by
        // the threads that compute them: filled arrays made first were pages faulted
        // in and zeroed on one core (14% of the sphere:4M run's page faults), then
        // written again.
        let count = self.triangles.len();
        let is_live = (self.live.len() < count).then(|| {
            let mut is_live = vec![false; count];
            for &t in &self.live {
                is_live[t as usize] = true;
            }
            is_live
        });
        let (positions, triangles) = (self.positions(), &self.triangles);
        let skipped = |t: usize| is_live.as_ref().is_some_and(|live| !live[t]);
        let corners = |t: usize| triangles[t].map(|c| positions.position(c));
        let facing = (0..count)
            .into_par_iter()
            .map(|t| {
                if skipped(t) {
                    return Facing::NONE;
                }
                let [pa, pb, pc] = corners(t);
                Facing::of((pb - pa).cross(pc - pa))
            })
            .collect();
        let planes = match self.exact {
            None => Vec::new(),
            Some(_) => (0..count)
                .into_par_iter()
                .map(|t| {
                    if skipped(t) {
                        return WeightedPlane::NONE;
                    }
                    let [pa, pb, pc] = corners(t);
                    weighted_plane(pa, pb, pc, area_offset)
                })
                .collect(),
        };
        InputFaces::kept(facing, planes, area_offset)
    }
}

impl Engine {
    /// Lists the live triangles around every vertex, each vertex's in increasing
    /// triangle order (a counting sort of the live triangles' corners).
    fn list_incident_triangles(&mut self) {
        let (live, triangles) = (&self.live, &self.triangles);
        self.incidence.rebuild(self.world.len(), || {
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
    /// a border edge being an edge of exactly one triangle.
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
        let borders: Vec<(u32, u32, u32)> = (0..self.world.len() as u32)
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
            self.add_constraint_plane([v, x], t, w, area_offset);
        }
    }

    /// The constraint plane of the edge `v x` of triangle `t` (through the edge,
    /// perpendicular to the triangle), of weight `w` (times the edge's squared length
    /// plus `area_offset` with area weights), added to both ends' quadrics.
    fn add_constraint_plane(&mut self, [v, x]: [u32; 2], t: u32, w: f64, area_offset: Option<f64>) {
        let [p0, p1, p2] = self.corners(self.triangles[t as usize]);
        let normal = (p1 - p0).cross(p2 - p0).normalize_or_zero();
        let positions = self.positions();
        let (pa, pb) = (positions.position(v), positions.position(x));
        let plane_weight = match area_offset {
            Some(extra) => w * (pa.distance_squared(pb) + extra),
            None => w,
        };
        let q = Quadric::boundary_constraint(pa, pb, normal, plane_weight);
        for end in [v, x] {
            if !self.seeded.get(end as usize).is_some_and(|&s| s) {
                self.quadric[end as usize] += q;
            }
        }
        if let Some(exact) = &mut self.exact {
            exact.add_border_plane(v, x, q);
        }
    }

    /// Seam edges get constraint planes like the borders' (with [`BoundaryMode::Planes`]
    /// of a weight above 0), one for each triangle on the edge, so that a seam keeps
    /// its curve as a border does ([`super::wedges`]); their weight is
    /// [`SEAM_PLANE_WEIGHT`], not the borders'.
    fn add_seam_planes(&mut self, options: &SimplifyOptions, area_offset: Option<f64>) {
        let BoundaryMode::Planes(w) = options.boundary else {
            return;
        };
        let Some(wedges) = &self.wedges else {
            return;
        };
        if !(w > 0.0 && w.is_finite()) {
            return;
        }
        let seams = wedges.seam_edges(&self.incidence, &self.triangles, self.world.len());
        for (v, x, t) in seams {
            self.add_constraint_plane([v, x], t, SEAM_PLANE_WEIGHT, area_offset);
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

    /// Lists every edge of the live triangles once, as (smaller end, larger end), in
    /// order of the smaller end. Of the last pass's list, with its costs as computed
    /// (unpenalised), what this pass may reuse becomes `last_listed`.
    fn list_edges(&mut self) {
        // The unpenalised costs are put back in place rather than the list copied at
        // costing time (a copy was 16 bytes an edge a pass).
        for (i, cost) in self.unpenalised_costs.drain(..) {
            self.candidates[i as usize].cost = cost;
        }
        std::mem::swap(&mut self.candidates, &mut self.last_listed);
        std::mem::swap(&mut self.listed_first, &mut self.last_listed_first);
        self.keep_reusable_costs();
        self.seen_with.fill(u32::MAX);
        self.candidates.clear();
        self.listed_first.clear();
        for v in 0..self.world.len() as u32 {
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
                None => ranked(this.place(c.a, c.b).0.cost),
            };
        });
        self.candidates = candidates;
        self.last_costed_with_merges = self.settings.allow_merges;
        // Waived pairs are ranked at the waivers' penalty on their merged quadric.
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

    /// Keeps, of the last pass's list (`last_listed`), only the edges whose cost this
    /// pass may reuse ([`last_cost`](Self::last_cost): neither end moved in that pass,
    /// and it was costed without merges), and gives the memory of the rest back.
    ///
    /// Why: the last pass's list beside this one's, 16 bytes an edge each, was the
    /// largest item of the loop's memory peak (48 bytes an input triangle with this
    /// pass's, BENCHMARKS.md "The budget, array by array"), and the early passes,
    /// whose lists are the longest, move most vertices, so most of it was never read.
    /// (Kept whole, the lists' two buffers also each held the longest list they had
    /// ever held.)
    fn keep_reusable_costs(&mut self) {
        let last = self.pass.checked_sub(1).filter(|&p| p > 0);
        // (A list the greedy order took has nothing left to keep.)
        let whole =
            self.last_listed_first.last().map(|&end| end as usize) == Some(self.last_listed.len());
        let (list, first, moved_in) = (
            &mut self.last_listed,
            &mut self.last_listed_first,
            &self.moved_in,
        );
        match last {
            Some(last) if whole && !self.last_costed_with_merges => {
                let mut kept = 0;
                for v in 0..first.len() - 1 {
                    let range = first[v] as usize..first[v + 1] as usize;
                    first[v] = kept as u32;
                    for i in range {
                        let c = list[i];
                        if moved_in[c.a as usize] != last && moved_in[c.b as usize] != last {
                            list[kept] = c;
                            kept += 1;
                        }
                    }
                }
                *first.last_mut().expect("a whole list has an end") = kept as u32;
                list.truncate(kept);
            }
            _ => {
                list.clear();
                first.clear();
            }
        }
        list.shrink_to_fit();
    }

    /// The cost of the edge `a b` (`a < b`) in the last pass's list, when neither end
    /// moved in that pass. Never with merges allowed, nor when the last pass allowed
    /// them: whether a pair makes a part vanish depends on its neighbours' triangles too, and
    /// is priced only while merges are allowed.
    fn last_cost(&self, a: u32, b: u32) -> Option<f64> {
        if self.settings.allow_merges || self.last_costed_with_merges {
            return None;
        }
        let last = self.pass.checked_sub(1).filter(|&p| p > 0)?;
        if self.moved_in[a as usize] == last || self.moved_in[b as usize] == last {
            return None;
        }
        let start = *self.last_listed_first.get(a as usize)? as usize;
        let end = *self.last_listed_first.get(a as usize + 1)? as usize;
        self.last_listed[start..end]
            .iter()
            .find(|c| c.b == b)
            .map(|c| c.cost)
    }

    /// The merged quadric of `a` and `b`, where the new vertex would go and its cost;
    /// a locked end stays put.
    fn place(&self, a: u32, b: u32) -> (Placement, Quadric) {
        self.place_with(a, b, self.merged_quadric(a, b))
    }

    /// [`place`](Self::place) with the merged quadric `q` of `a` and `b` given.
    ///
    /// With attributes the placement weighs their error too (its cost is the
    /// geometric and the attribute error together, and a pair that would join a
    /// seam's sides costs +∞); the quadric returned is the geometric one.
    fn place_with(&self, a: u32, b: u32, q: Quadric) -> (Placement, Quadric) {
        let (mut placed, q) = self.place_on_quadrics(a, b, q);
        if self.settings.allow_merges {
            if let Some(radius) = self.vanishing_radius(a, b, placed.position) {
                placed.cost = placed.cost.max(vanishing_cost(radius, &q));
            }
        }
        (placed, q)
    }

    /// [`place_with`](Self::place_with) as the quadrics see it, without the cost of
    /// a part that vanishes.
    fn place_on_quadrics(&self, a: u32, b: u32, q: Quadric) -> (Placement, Quadric) {
        let mut ends = [
            (self.position(a), self.locked[a as usize]),
            (self.position(b), self.locked[b as usize]),
        ];
        let Some(wedges) = &self.wedges else {
            return (place_merged(&q, ends, self.settings.placement), q);
        };
        match wedges.merged_error(&self.incidence, &self.triangles, a, b) {
            Some((attributes, pin)) => {
                // A pinned end is placed like a locked one.
                match pin {
                    Pin::Free => {}
                    Pin::A => ends[0].1 = true,
                    Pin::B => ends[1].1 = true,
                }
                let total = q + attributes;
                let both = place_merged(&total, ends, self.settings.placement);
                if ends[0].1 || ends[1].1 {
                    // Placed at a locked or pinned end: there is no other place.
                    return (both, q);
                }
                // Where the attributes would pull the vertex off the geometry's best
                // place by more than GEOMETRY_GROWTH times its error, the geometry's
                // place wins: attribute fields that bend faster than the surface
                // (smooth normals across a crease) would otherwise trade shape for
                // shading (tm_fuze at 0.5: mean 0.318% without this bound, 0.106%
                // with it; BENCHMARKS.md, "Attributes").
                let geometric = place_merged(&q, ends, self.settings.placement);
                let allowed = GEOMETRY_GROWTH * geometric.cost + GEOMETRY_SLACK * q.weight();
                if q.evaluate(both.position) <= allowed {
                    (both, q)
                } else {
                    let cost = total.evaluate(geometric.position).max(0.0);
                    (Placement { cost, ..geometric }, q)
                }
            }
            None => {
                let mut placed = place_merged(&q, ends, self.settings.placement);
                placed.cost = f64::INFINITY;
                (placed, q)
            }
        }
    }

    /// With [`Settings::allow_merges`] (the ladder's merged faces), when contracting
    /// `b` into `a` would leave no live triangle at either end, each triangle there
    /// collapsing with the pair or merging with its twin (a closed part worn down to a
    /// tetrahedron vanishes): the largest distance from `at` (normalised units) to a
    /// corner of those triangles, the size of the surface that vanishes into that point.
    /// `None` when a triangle is left.
    ///
    /// Why: the quadrics measure distance to planes, not coverage. A long thin rod worn
    /// down to a sliver tetrahedron vanishes at the cost of a point on its axis, almost
    /// nothing: priced by the quadrics alone, the pass-based order took two rods the
    /// length of ps_mk4_gantry (1,850 units) out at a quadric error of 0.4% of the
    /// diagonal, for a Hausdorff distance of 53% (BENCHMARKS.md, "Never stuck").
    ///
    /// Why not every merge: pricing the faces any merge removes the same way (tried)
    /// left more damage, not less (ps_mk4_gantry at 0.01 went from 0.86% to 2.4%, and
    /// mf_offset1 from 31% to 41%, in the greedy order): the run then takes relaxed
    /// contractions that the quadrics misprice in other ways.
    ///
    /// Every twin is taken as merging; [`Engine::merged_away`] may keep one face of a
    /// pair (near the target, or a part's last face), so this can only over-price a
    /// pair for the order; the attempt prices what it removes.
    fn vanishing_radius(&self, a: u32, b: u32, at: DVec3) -> Option<f64> {
        let live = |v: u32| {
            self.incidence
                .of(v)
                .iter()
                .map(|&t| self.triangles[t as usize])
                .filter(|c| c[0] != REMOVED)
        };
        // Every triangle at `from` not on both ends has a twin at `to`: the triangle
        // with the same two other corners.
        let all_merge = |from: u32, to: u32| {
            live(from).all(|c| {
                c.contains(&to) || {
                    let mut others = c.into_iter().filter(|&x| x != from);
                    let (Some(x), Some(y)) = (others.next(), others.next()) else {
                        return false;
                    };
                    live(to).any(|d| !d.contains(&from) && d.contains(&x) && d.contains(&y))
                }
            })
        };
        if !(all_merge(a, b) && all_merge(b, a)) {
            return None;
        }
        let corners = live(a).chain(live(b)).flatten();
        Some(farthest_corner(&self.positions(), corners, at))
    }

    /// The geometric part of a placement's cost: the cost itself, or with attributes
    /// the geometric quadric `q` at the placed point (the error the report and the
    /// error bound speak of).
    pub(super) fn geometric_cost(&self, q: &Quadric, placed: &Placement) -> f64 {
        match self.wedges {
            None => placed.cost,
            Some(_) => q.evaluate(placed.position).max(0.0),
        }
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
        shared_planes(&self.incidence, triangles, exact, &self.input_faces, [a, b])
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
        let mut mesh = IndexedMesh::new(
            positions,
            self.live
                .iter()
                .map(|&t| self.triangles[t as usize].map(|c| number[c as usize]))
                .collect(),
        );
        if let Some(wedges) = &self.wedges {
            mesh.attributes = wedges.output(
                &self.live,
                &self.triangles,
                &self.triangle_from,
                &self.positions(),
            );
        }
        let triangle_from: Vec<u32> = self
            .live
            .iter()
            .map(|&t| self.triangle_from[t as usize])
            .collect();
        in_original_order(mesh, self.vertex_from.len(), &vertex_from, &triangle_from)
    }

    /// Makes `seed` (by cleaned-mesh vertex) the quadric array, in the engine's vertex
    /// order and frame, in place; [`sum_face_planes`](Self::sum_face_planes) fills the
    /// vertices it does not carry, and no border or seam plane is added to those it
    /// does (their quadrics hold them already). A seed of another length than the
    /// vertices is not taken (a caller's bug: the run then sums every quadric).
    fn take_seed(&mut self, seed: CarriedQuadrics, weighting: Weighting) {
        debug_assert!(self.exact.is_none(), "a seeded run sums its quadrics");
        let CarriedQuadrics {
            origin,
            quadrics: mut seed,
        } = seed;
        if !gather_in_place(&mut seed, &self.vertex_from) {
            debug_assert!(
                false,
                "a seed of {} for {} vertices",
                seed.len(),
                self.world.len()
            );
            return;
        }
        let (frame, area_weighted) = (self.frame, weighting.area_weighted());
        seed.par_iter_mut()
            .filter(|q| is_carried(q))
            .for_each(|q| *q = frame.quadric_to_normalized(q, origin, area_weighted));
        self.seeded = seed.iter().map(is_carried).collect();
        self.quadric = seed;
    }

    /// The quadrics of [`to_mesh`](Self::to_mesh)'s vertices, in its order, in world
    /// units about `origin`, their planes weighted by `weighting` (the run's).
    pub fn output_quadrics(&self, origin: DVec3, weighting: Weighting) -> Vec<Quadric> {
        let area_weighted = weighting.area_weighted();
        let mut used = vec![false; self.world.len()];
        for &t in &self.live {
            for c in self.triangles[t as usize] {
                used[c as usize] = true;
            }
        }
        // `to_mesh` orders its vertices by their cleaned-mesh numbers.
        let mut by_origin: Vec<(u32, u32)> = (0..self.world.len() as u32)
            .filter(|&v| used[v as usize])
            .map(|v| (self.vertex_from[v as usize], v))
            .collect();
        by_origin.sort_unstable();
        (by_origin.iter())
            .map(|&(_, v)| {
                let q = &self.quadric[v as usize];
                self.frame.quadric_to_world(q, origin, area_weighted)
            })
            .collect()
    }

    /// Live triangles whose normal points more than 90° away from the input triangle's.
    pub fn flipped_faces(&self) -> usize {
        self.live
            .iter()
            .filter(|&&t| {
                let [p0, p1, p2] = self.corners(self.triangles[t as usize]);
                (p1 - p0)
                    .cross(p2 - p0)
                    .dot(self.input_faces.facing(t).direction())
                    < 0.0
            })
            .count()
    }
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

use attempt::{moved_corners, Attempt};
use passes::Speculation;

#[path = "attempt.rs"]
mod attempt;
#[path = "greedy.rs"]
mod greedy;
#[path = "passes.rs"]
mod passes;
#[path = "turn_back.rs"]
mod turn_back;

#[cfg(test)]
#[path = "passes_speculation_tests.rs"]
mod speculation_tests;

#[cfg(test)]
#[path = "passes_blocks_tests.rs"]
mod blocks_tests;

#[cfg(test)]
mod input_faces_tests {
    use super::speculation_tests::thin_lens;
    use super::*;

    /// With the orientation check on, the engine reads every live triangle's facing and
    /// face plane from the check's index, and they have the bits the setup's own
    /// positions give (the kept faces): through the locality order, the index's leaf
    /// order and its slots, on a mesh whose triangles come shuffled.
    #[test]
    fn faces_read_from_the_index_have_the_kept_bits() {
        let mut mesh = thin_lens(12, 24);
        // A fixed shuffle (a multiplicative step through the triangles).
        let n = mesh.triangles.len();
        let step = (0..n).map(|k| (k * 7919) % n).collect::<Vec<_>>();
        assert!(n % 7919 != 0, "the step must be prime to the count");
        mesh.triangles = step.iter().map(|&k| mesh.triangles[k]).collect();
        let frame = Frame::from_points(mesh.positions.iter().map(|p| DVec3::from_array(*p)));
        let engine = Engine::new(&mesh, frame, &[], &SimplifyOptions::default(), None);
        assert!(engine.input_faces.reads_from_index());
        let kept = engine.kept_input_faces(engine.input_faces.area_offset());
        assert!(!kept.reads_from_index());
        let bits = |p: WeightedPlane| {
            let [x, y, z] = p.normal.to_array();
            [x, y, z, p.d, p.weight].map(f64::to_bits)
        };
        for &t in &engine.live {
            let (read, kept_facing) = (engine.input_faces.facing(t), kept.facing(t));
            assert_eq!(read, kept_facing, "facing of {t}");
            assert_eq!(
                bits(engine.input_faces.plane(t)),
                bits(kept.plane(t)),
                "plane of {t}"
            );
        }
        assert!(engine.live.len() > 100);
    }

    /// Of the last pass's list, exactly the edges with neither end moved in that pass
    /// are kept, and `last_cost` answers for every edge of the new list what a search
    /// of the whole last list under its rule would.
    #[test]
    fn the_last_list_keeps_exactly_the_reusable_costs() {
        let mesh = thin_lens(12, 24);
        let frame = Frame::from_points(mesh.positions.iter().map(|p| DVec3::from_array(*p)));
        let mut engine = Engine::new(&mesh, frame, &[], &SimplifyOptions::default(), None);
        engine.pass = 1;
        engine.list_edges();
        engine.cost_edges();
        let whole = engine.candidates.clone();
        // Every third vertex moved in pass 1 (nothing else changed, so the new list
        // is the same edges).
        for v in (0..engine.moved_in.len()).step_by(3) {
            engine.moved_in[v] = 1;
        }
        let moved = engine.moved_in.clone();
        let unmoved = |c: &Candidate| moved[c.a as usize] != 1 && moved[c.b as usize] != 1;
        let expected: Vec<(u32, u32, u64)> = (whole.iter().filter(|c| unmoved(c)))
            .map(|c| (c.a, c.b, c.cost.to_bits()))
            .collect();
        assert!(!expected.is_empty() && expected.len() < whole.len());
        engine.pass = 2;
        engine.list_edges();
        let kept: Vec<(u32, u32, u64)> = (engine.last_listed.iter())
            .map(|c| (c.a, c.b, c.cost.to_bits()))
            .collect();
        assert_eq!(kept, expected);
        assert_eq!(engine.candidates.len(), whole.len());
        for c in &engine.candidates {
            let searched = (whole.iter())
                .find(|x| x.a == c.a && x.b == c.b)
                .filter(|x| unmoved(x))
                .map(|x| x.cost.to_bits());
            assert_eq!(engine.last_cost(c.a, c.b).map(f64::to_bits), searched);
        }
    }
}
