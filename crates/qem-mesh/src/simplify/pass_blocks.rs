//! The pass-based order's contractions, block by block on both cores, and the pieces
//! of a contraction that the block workers and the sequential attempts share.
//!
//! The engine's vertices are in locality order ([`super::locality`]), so a run of
//! [`BLOCK_VERTICES`] consecutive numbers is a patch of the surface, and its triangles
//! (numbered by their lowest corner) are a run of consecutive numbers too. A pair of a
//! round is *interior* to its block when every live triangle around either end lies
//! in the block's run of triangles and has all three corners in the block's run of
//! vertices. What a contraction of an interior pair reads and writes (the triangles
//! around its ends, their corners' positions, its ends' quadrics, the orientation
//! check's hints of those triangles) then belongs to that block alone, so the interior
//! pairs of different blocks can be contracted at the same time: each block gets its
//! own slices of the arrays ([`Slab`]). What the blocks share they only read during
//! the round: the pass's lists, the input surface's index, exact quadrics' planes as of
//! the pass's start (a pass reads only those; see [`super::pass_exact`]) and the
//! waivers as of the round's start (see [`WaiverChange`] for why that is enough); their
//! changes to the last two are made after the blocks, in block order.
//!
//! Not with locked vertices: the lock check looks at a locked neighbour's triangles,
//! which may lie outside the block. (Nor, with the orientation check, if the hints
//! were not one per triangle, which seeding them always makes them.)
//!
//! The order is fixed by the numbers, not by the threads: in a round, the interior
//! pairs of each block are attempted in the round's order, blocks one after another as
//! far as the result is concerned (they cannot see each other), and then the pairs
//! that were not interior, in the round's order, by the sequential attempts. The
//! output is therefore the same with any number of threads.
//!
//! Measured before this existed, on the dragon at ratio 0.1: with `--fast`, the rounds'
//! sequential attempts were about 600 ms of the 960 ms contraction phase; with every
//! default quality option, the attempts (0.88 s) and their speculation on both cores
//! (0.87 s) were most of 2.6 s. With blocks of 16,384 vertices, 89–93% of the pairs of
//! the first round of passes 1-3 were interior (counted in a scratch build). (BENCHMARKS.md,
//! "Rounds block by block".)

use super::checks::{moved_face_verdict, Rejection};
use super::counters::Counters;
use super::incidence::Incidence;
use super::input_faces::InputFaces;
use super::observer::Contraction;
use super::orientation::Nearest;
use super::pass_exact::PassExact;
use super::placement::place_merged;
use super::settings::Settings;
use super::waivers::Waivers;
use crate::clean::cross_underflows;
use qem_core::{DVec3, Frame, Quadric};
use smallvec::SmallVec;

/// Vertices per block. A constant, not a share of the thread count: the blocks decide
/// which pairs are interior, so they decide the order, and so the output.
pub(super) const BLOCK_VERTICES: u32 = 16_384;

/// Marks a removed triangle (its first corner).
pub(super) const REMOVED: u32 = u32::MAX;

/// An edge of the current pass and its cost (normalised units).
#[derive(Clone, Copy, Debug)]
pub(super) struct Candidate {
    pub a: u32,
    pub b: u32,
    pub cost: f64,
}

/// A live triangle around a vertex: its index and its current corners.
#[derive(Clone, Copy, Debug)]
pub(super) struct Around {
    pub triangle: u32,
    pub corners: [u32; 3],
}

/// What a contraction reads and no contraction of the pass changes.
pub(super) struct Fixed<'a> {
    pub frame: &'a Frame,
    pub settings: &'a Settings,
    /// The live triangles around each vertex at the pass's start.
    pub incidence: &'a Incidence,
    /// Which way each input triangle faces (normalised frame), and its face plane.
    pub input_faces: &'a InputFaces,
    /// Each engine vertex's number in the cleaned mesh (for the observer).
    pub vertex_from: &'a [u32],
    pub pass: u32,
    /// Exact quadrics' planes as of the pass's start (`None`: summed quadrics). A
    /// contraction's changes to them wait in [`BlockOutcome::exact_changes`].
    pub exact: Option<&'a PassExact>,
    /// Whether there are virtual pairs, whose ends a contraction renames (the
    /// contractions wait in [`BlockOutcome::merges`]).
    pub has_virtual_pairs: bool,
    /// The orientation check's index (`None`: the check is off); the hints are the
    /// slab's.
    pub nearest: Option<Nearest<'a>>,
    /// The waivers as of the round's start; changes wait in
    /// [`BlockOutcome::waiver_changes`].
    pub waivers: &'a Waivers,
}

/// The positions of a run of vertices, read-only: what the fold-over check reads.
///
/// Only world positions are kept; a vertex's position in the normalised frame is
/// computed from its world one when read. Why: the engine wrote both from the same
/// world point, so the normalised one was always `frame.to_normalized(world)`, bit for
/// bit, and keeping it cost 24 bytes a vertex (12 a triangle) for the whole run.
#[derive(Clone, Copy)]
pub(super) struct Positions<'a> {
    pub first_vertex: u32,
    pub frame: &'a Frame,
    pub world: &'a [[f64; 3]],
}

impl<'a> Positions<'a> {
    /// Every vertex's positions: `world` holds them from vertex 0 on.
    pub fn whole(frame: &'a Frame, world: &'a [[f64; 3]]) -> Self {
        Positions {
            first_vertex: 0,
            frame,
            world,
        }
    }

    /// Vertex `v`'s position in the normalised frame.
    #[inline]
    pub fn position(&self, v: u32) -> DVec3 {
        self.frame.to_normalized(DVec3::from_array(
            self.world[(v - self.first_vertex) as usize],
        ))
    }

    fn world(&self, v: u32) -> [f64; 3] {
        self.world[(v - self.first_vertex) as usize]
    }

    /// The fold-over check of contracting the
    /// pair `a b` to `world` (model units): every triangle of `around` that moves and
    /// does not collapse, but the `unchecked` ones: the merged faces of a part that
    /// vanishes, which leave nothing to fold (of two merging faces `a x y` and `b x y`
    /// on a closed part, the second moved onto the first faces the other way, so the
    /// check refused every tetrahedron's last contraction on ps_mk4_gantry).
    pub fn fold_over(
        &self,
        fixed: &Fixed,
        [a, b]: [u32; 2],
        world: DVec3,
        around: &[Vec<Around>; 2],
        unchecked: &[u32],
    ) -> Result<(), Rejection> {
        let moved = fixed.frame.to_normalized(world);
        for x in around.iter().flatten() {
            let corners = x.corners;
            if corners.contains(&a) && corners.contains(&b) {
                continue; // collapses with the pair
            }
            if unchecked.contains(&x.triangle) {
                continue; // merged away with the part it belonged to
            }
            let old = corners.map(|c| self.position(c));
            let new = std::array::from_fn::<_, 3, _>(|i| {
                if corners[i] == a || corners[i] == b {
                    moved
                } else {
                    old[i]
                }
            });
            moved_face_verdict(
                fixed.settings,
                old,
                new,
                || fixed.input_faces.facing(x.triangle).direction(),
                || {
                    cross_underflows(corners.map(|c| {
                        if c == a || c == b {
                            world.to_array()
                        } else {
                            self.world(c)
                        }
                    }))
                },
            )?;
        }
        Ok(())
    }
}

/// The state that contractions change, for the vertices from `first_vertex` on and
/// the triangles from `first_triangle` on, as many as the slices hold: all of them for
/// the sequential attempts, one block's for a block worker.
pub(super) struct Slab<'a> {
    pub first_vertex: u32,
    pub first_triangle: u32,
    /// The normalised frame: positions in it are computed from the world ones
    /// ([`Positions`]).
    pub frame: &'a Frame,
    pub world: &'a mut [[f64; 3]],
    pub quadric: &'a mut [Quadric],
    /// The pass in which each vertex last moved or was removed.
    pub moved_in: &'a mut [u32],
    /// Corners of each triangle; [`REMOVED`] in the first once it is gone.
    pub triangles: &'a mut [[u32; 3]],
    /// The orientation check's hint of each triangle (empty when the check is off, or
    /// for the sequential attempts, which use the engine's).
    pub hints: &'a mut [u32],
}

impl<'a> Slab<'a> {
    /// Vertex `v`'s place in the slices, if it is in the slab.
    fn vertex_slot(&self, v: u32) -> Option<usize> {
        let i = v.checked_sub(self.first_vertex)? as usize;
        (i < self.world.len()).then_some(i)
    }

    /// Triangle `t`'s place in `triangles`, if it is in the slab.
    fn triangle_slot(&self, t: u32) -> Option<usize> {
        let i = t.checked_sub(self.first_triangle)? as usize;
        (i < self.triangles.len()).then_some(i)
    }

    /// The slab's vertex positions, read-only (what the fold-over check reads).
    pub fn positions(&self) -> Positions<'_> {
        Positions {
            first_vertex: self.first_vertex,
            frame: self.frame,
            world: self.world,
        }
    }

    /// The live triangles around `v`, with their current corners, into `out`; `false`
    /// (and `out` incomplete) when one of them or one of their corners is outside the
    /// slab. Reads no triangle outside the slab.
    pub fn gather(&self, fixed: &Fixed, v: u32, out: &mut Vec<Around>) -> bool {
        out.clear();
        for &t in fixed.incidence.of(v) {
            let Some(slot) = self.triangle_slot(t) else {
                return false;
            };
            let corners = self.triangles[slot];
            if corners[0] == REMOVED {
                continue;
            }
            if corners.iter().any(|&c| self.vertex_slot(c).is_none()) {
                return false;
            }
            out.push(Around {
                triangle: t,
                corners,
            });
        }
        true
    }

    /// Contracts `b` into `a`, which moves to `world` (model units) with quadric `q`;
    /// `around` holds the live triangles of `a` and of `b`, and `merged` the faces that
    /// the contraction merges and that go with it (see `Engine::merged_away`).
    /// Returns how many triangles were removed. (Exact quadrics' planes and the
    /// orientation check's state are the caller's.)
    pub fn contract(
        &mut self,
        fixed: &Fixed,
        [a, b]: [u32; 2],
        world: DVec3,
        q: Quadric,
        around: &[Vec<Around>; 2],
        merged: &[u32],
    ) -> usize {
        let (sa, sb) = (self.slot_of(a), self.slot_of(b));
        self.moved_in[sa] = fixed.pass;
        self.moved_in[sb] = fixed.pass;
        self.world[sa] = world.to_array();
        self.quadric[sa] = q;
        let mut removed = 0;
        for x in &around[0] {
            if x.corners.contains(&b) {
                let slot = self.triangle_slot_of(x.triangle);
                self.triangles[slot][0] = REMOVED;
                removed += 1;
            }
        }
        // `b`'s other triangles are `a`'s now: renamed at once, so that every triangle
        // read later in the pass has its current corners.
        for x in &around[1] {
            if !x.corners.contains(&a) {
                let slot = self.triangle_slot_of(x.triangle);
                self.triangles[slot] = x.corners.map(|c| if c == b { a } else { c });
            }
        }
        // Faces merged by the contraction (only where the ladder allows merges; see
        // `Settings::allow_merges`). Their other corners count as moved: their
        // triangles changed.
        for &t in merged {
            let slot = self.triangle_slot_of(t);
            for c in self.triangles[slot] {
                if let Some(v) = self.vertex_slot(c) {
                    self.moved_in[v] = fixed.pass;
                }
            }
            self.triangles[slot][0] = REMOVED;
            removed += 1;
        }
        removed
    }

    /// The orientation check (see `Engine::faces_agree_with_input`) of moving `a`
    /// and `b` to `moved` (normalised units), with the slab's hints; `near` is
    /// scratch.
    fn faces_agree(
        &mut self,
        nearest: Nearest,
        near: &mut Vec<u32>,
        [a, b]: [u32; 2],
        moved: DVec3,
        around: &[Vec<Around>; 2],
    ) -> bool {
        // A triangle seen for the first time borrows the hint of the one checked before.
        let mut neighbour_hint = None;
        around.iter().flatten().all(|x| {
            let corners = x.corners;
            if corners.contains(&a) && corners.contains(&b) {
                return true;
            }
            let new = corners.map(|c| {
                if c == a || c == b {
                    moved
                } else {
                    let world = self.world[(c - self.first_vertex) as usize];
                    self.frame.to_normalized(DVec3::from_array(world))
                }
            });
            let slot = (x.triangle - self.first_triangle) as usize;
            nearest.agrees(&mut self.hints[slot], near, new, &mut neighbour_hint)
        })
    }

    /// The slab cut into blocks of `block_vertices` vertices, the `k`-th block with
    /// the triangles from `triangle_starts[k]` to `triangle_starts[k + 1]` (one entry
    /// per block and one more; relative to the whole mesh, so only for a slab of all of
    /// it). The hints, when there are any, are one per triangle and split likewise.
    pub fn into_blocks(self, block_vertices: u32, triangle_starts: &[u32]) -> Vec<Slab<'a>> {
        debug_assert_eq!((self.first_vertex, self.first_triangle), (0, 0));
        let Slab {
            frame,
            mut world,
            mut quadric,
            mut moved_in,
            mut triangles,
            mut hints,
            ..
        } = self;
        let mut blocks = Vec::with_capacity(triangle_starts.len().saturating_sub(1));
        for (k, bounds) in triangle_starts.windows(2).enumerate() {
            let first_vertex = k as u32 * block_vertices;
            let count = (block_vertices as usize).min(world.len());
            let (this_world, rest) = std::mem::take(&mut world).split_at_mut(count);
            world = rest;
            let (this_quadric, rest) = std::mem::take(&mut quadric).split_at_mut(count);
            quadric = rest;
            let (this_moved_in, rest) = std::mem::take(&mut moved_in).split_at_mut(count);
            moved_in = rest;
            let triangle_count = (bounds[1] - bounds[0]) as usize;
            let (this_triangles, rest) =
                std::mem::take(&mut triangles).split_at_mut(triangle_count);
            triangles = rest;
            let hint_count = if hints.is_empty() { 0 } else { triangle_count };
            let (this_hints, rest) = std::mem::take(&mut hints).split_at_mut(hint_count);
            hints = rest;
            blocks.push(Slab {
                first_vertex,
                first_triangle: bounds[0],
                frame,
                world: this_world,
                quadric: this_quadric,
                moved_in: this_moved_in,
                triangles: this_triangles,
                hints: this_hints,
            });
        }
        blocks
    }

    /// [`vertex_slot`](Self::vertex_slot) of a vertex known to be in the slab.
    fn slot_of(&self, v: u32) -> usize {
        (v - self.first_vertex) as usize
    }

    /// [`triangle_slot`](Self::triangle_slot) of a triangle known to be in the slab.
    fn triangle_slot_of(&self, t: u32) -> usize {
        (t - self.first_triangle) as usize
    }
}

/// What one block's worker did with its share of a round.
#[derive(Default)]
pub(super) struct BlockOutcome {
    /// The pairs (indices in the candidate list) that were not interior, or that more
    /// than two triangles hold, in the round's order: left to the sequential attempts.
    pub deferred: Vec<u32>,
    /// The contractions made, in order (empty when the observer does not watch them).
    pub contractions: Vec<Contraction>,
    pub counters: Counters,
    pub contracted: usize,
    pub removed: usize,
    pub attempted: usize,
    /// Whether a pair was left for its error being above the bound.
    pub over_bound: bool,
    /// Pairs the orientation check refused (each waived: see [`super::waivers`]).
    pub waived: usize,
    /// The changes to the waivers, in order, for the caller to make.
    pub waiver_changes: Vec<WaiverChange>,
    /// Each contraction's changes to exact quadrics' planes, in order.
    pub exact_changes: Vec<ExactChange>,
    /// Each contraction (kept, removed), in order, when there are virtual pairs.
    pub merges: Vec<[u32; 2]>,
}

/// A contraction's change to exact quadrics' planes, for the caller to make with
/// `PassExact::contract`: `removed` merged into `kept`, and each collapsed triangle
/// with its third corner (at most two: a block defers pairs that more triangles hold).
#[derive(Clone, Debug)]
pub(super) struct ExactChange {
    pub kept: u32,
    pub removed: u32,
    pub collapsed: SmallVec<[(u32, u32); 2]>,
}

/// A change to the waivers that a block's worker leaves for the caller.
///
/// Why they can wait: a pair's waiver is read only at its own attempt, a round's pairs
/// share no vertex, and each change touches only the waivers of its own pair's ends
/// (and drops those ends from their partners' lists), so no attempt of the same round
/// reads what another's changes; and the changes of different pairs commute.
#[derive(Clone, Copy, Debug)]
pub(super) enum WaiverChange {
    /// The waived pair was contracted without the check (`Waivers::take`).
    Take(u32, u32),
    /// The pair was refused by the check (`Waivers::waive`).
    Waive(u32, u32),
    /// The vertex moved or was removed (`Waivers::forget`).
    Forget(u32),
}

/// Attempts `pairs` (indices into `candidates`, in the round's order) on `slab`, one
/// block; a pair that is not interior to it is deferred.
///
/// The attempt is the sequential one (`Engine::check_and_contract`) for a run
/// without locks (the only one that uses blocks): the merged quadric (less the shared
/// planes with exact quadrics), placement, the error bound, fold-over, merged faces,
/// border loops, the orientation check unless the pair is waived, then the
/// contraction. The changes to what the blocks share (waivers, exact quadrics' planes)
/// wait in the outcome. A pair more than two triangles hold (a non-manifold edge) is
/// deferred, so that the round's interior contractions remove at most two triangles
/// each and cannot pass the target (the caller uses blocks only when twice the
/// round's size is short of it).
pub(super) fn contract_block(
    slab: &mut Slab,
    fixed: &Fixed,
    candidates: &[Candidate],
    pairs: &[u32],
    watch_contractions: bool,
) -> BlockOutcome {
    let mut out = BlockOutcome::default();
    let mut around = [Vec::new(), Vec::new()];
    let mut near = Vec::new();
    for &i in pairs {
        let Candidate { a, b, .. } = candidates[i as usize];
        if !slab.gather(fixed, a, &mut around[0]) || !slab.gather(fixed, b, &mut around[1]) {
            out.deferred.push(i);
            continue;
        }
        let shared = around[0].iter().filter(|x| x.corners.contains(&b)).count();
        // Virtual pairs (no triangle on both) go to the sequential attempts, which
        // count them apart.
        if shared > 2 || shared == 0 {
            out.deferred.push(i);
            continue;
        }
        out.attempted += 1;
        let (sa, sb) = (slab.slot_of(a), slab.slot_of(b));
        let mut q = slab.quadric[sa] + slab.quadric[sb];
        if let Some(exact) = fixed.exact {
            let triangles = (slab.first_triangle, &*slab.triangles);
            q -= shared_planes(fixed.incidence, triangles, exact, fixed.input_faces, [a, b]);
        }
        let positions = slab.positions();
        let ends = [
            (positions.position(a), false),
            (positions.position(b), false),
        ];
        let placed = place_merged(&q, ends, fixed.settings.placement);
        let error = q.rms_distance(placed.cost);
        if error > fixed.settings.max_error_bound {
            out.over_bound = true;
            continue;
        }
        let world = {
            let world = fixed.frame.to_world(placed.position);
            if world.is_finite() {
                world
            } else {
                DVec3::from_array(slab.world[sa])
            }
        };
        if let Err(why) = plain_checks(
            &slab.positions(),
            fixed,
            [a, b],
            world,
            shared,
            &around,
            &[],
        ) {
            out.counters.reject(why);
            continue;
        }
        // Last, as in the sequential attempts; a waived pair is taken without it.
        let waived = fixed.waivers.contains(a, b);
        if waived {
            out.waiver_changes.push(WaiverChange::Take(a, b));
        } else if let Some(nearest) = fixed.nearest {
            let moved = fixed.frame.to_normalized(world);
            if !slab.faces_agree(nearest, &mut near, [a, b], moved, &around) {
                out.counters.reject(Rejection::Orientation);
                out.waiver_changes.push(WaiverChange::Waive(a, b));
                out.waived += 1;
                continue;
            }
        }
        for v in [a, b] {
            if fixed.waivers.involves(v) {
                out.waiver_changes.push(WaiverChange::Forget(v));
            }
        }
        if fixed.exact.is_some() {
            // Each collapsed triangle's plane joins `a` and its third corner now.
            let collapsed = around[0]
                .iter()
                .filter(|x| x.corners.contains(&b))
                .filter_map(|x| {
                    let third = x.corners.into_iter().find(|&c| c != a && c != b)?;
                    Some((x.triangle, third))
                })
                .collect();
            out.exact_changes.push(ExactChange {
                kept: a,
                removed: b,
                collapsed,
            });
        }
        if fixed.has_virtual_pairs {
            out.merges.push([a, b]);
        }
        let removed = slab.contract(fixed, [a, b], world, q, &around, &[]);
        out.removed += removed;
        out.contracted += 1;
        out.counters.edge_contractions += 1;
        out.counters.max_error = out.counters.max_error.max(error);
        if watch_contractions {
            out.contractions.push(Contraction {
                kept: fixed.vertex_from[a as usize],
                removed: fixed.vertex_from[b as usize],
                is_virtual: false,
                quadric: q,
                position: placed.position,
                world: world.to_array(),
                triangles_removed: removed,
                cost: placed.cost,
            });
        }
    }
    out
}

/// The checks every contraction passes, in both orders and in the block workers:
/// fold-over (degenerate, flipped, sliver; but not of the `unchecked` faces, see
/// [`Positions::fold_over`]), merged faces, border loops, topology. (The lock check and
/// the orientation check are the sequential attempts' own.)
pub(super) fn plain_checks(
    positions: &Positions,
    fixed: &Fixed,
    [a, b]: [u32; 2],
    world: DVec3,
    shared: usize,
    around: &[Vec<Around>; 2],
    unchecked: &[u32],
) -> Result<(), Rejection> {
    positions.fold_over(fixed, [a, b], world, around, unchecked)?;
    if !fixed.settings.allow_merges && would_merge_faces(a, b, around) {
        return Err(Rejection::Merge);
    }
    // A virtual pair (no triangle on both) joins parts or closes a gap: it pinches
    // no border loop of its own, which is what it is for.
    if fixed.settings.keep_border_loops && shared > 0 && !keeps_border_loops(a, b, shared, around) {
        return Err(Rejection::Border);
    }
    if fixed.settings.preserve_topology && !keeps_topology(a, b, shared, around) {
        return Err(Rejection::Topology);
    }
    Ok(())
}

/// Whether a vertex's star (`around`, its live triangles) is one fan of triangles
/// joined edge to edge, every edge at the vertex on one or two of them: `Some(true)`
/// when the fan is open (the vertex is on a border), `Some(false)` when it is closed,
/// `None` for any other star (non-manifold, or no triangle).
fn manifold_star(v: u32, around: &[Around]) -> Option<bool> {
    if around.is_empty() {
        return None;
    }
    // (neighbour, triangle's place in `around`), sorted: each run is one edge at `v`.
    let mut ends: SmallVec<[(u32, u32); 24]> = SmallVec::new();
    for (i, x) in around.iter().enumerate() {
        for c in x.corners {
            if c != v {
                ends.push((c, i as u32));
            }
        }
    }
    ends.sort_unstable();
    let mut group: SmallVec<[u32; 12]> = (0..around.len() as u32).collect();
    let root = |group: &mut SmallVec<[u32; 12]>, mut i: u32| {
        while group[i as usize] != i {
            group[i as usize] = group[group[i as usize] as usize];
            i = group[i as usize];
        }
        i
    };
    let mut border_edges = 0;
    for run in ends.chunk_by(|p, q| p.0 == q.0) {
        match run {
            [_] => border_edges += 1,
            [(_, i), (_, j)] => {
                let (ri, rj) = (root(&mut group, *i), root(&mut group, *j));
                group[ri.max(rj) as usize] = ri.min(rj);
            }
            _ => return None,
        }
    }
    let one_fan = (0..around.len() as u32).all(|i| root(&mut group, i) == 0);
    match (one_fan, border_edges) {
        (true, 0) => Some(false),
        (true, 2) => Some(true),
        _ => None,
    }
}

/// The link condition of Dey, Edelsbrunner, Guha and Nekhayev ("Topology preserving
/// edge contraction", 1999) for the edge `a b` (on `shared` triangles) of a 2-manifold
/// with border, and a refusal elsewhere (a virtual pair, a non-manifold edge or star).
///
/// `Lk a ∩ Lk b = Lk ab`: the vertices joined to both `a` and `b` are exactly the
/// third corners of the triangles on `a b`, and no edge `x y` is in both links (two
/// triangles `a x y` and `b x y`; such a pair would merge, which `would_merge_faces`
/// refuses). For a border, their extension cones the border off with a dummy vertex ω
/// (a triangle `x y ω` for every border edge `x–y`): ω is a common neighbour when both
/// ends are on a border, so `a b` must be a border edge itself; and `x ω` is a common
/// link edge when `a–x` and `b–x` are both border edges, which would close a border
/// loop of three edges (or collapse a lone triangle).
fn keeps_topology(a: u32, b: u32, shared: usize, around: &[Vec<Around>; 2]) -> bool {
    if !(1..=2).contains(&shared) {
        return false;
    }
    let (Some(a_border), Some(b_border)) =
        (manifold_star(a, &around[0]), manifold_star(b, &around[1]))
    else {
        return false;
    };
    if a_border && b_border && shared != 1 {
        return false;
    }
    let neighbours = |v: u32, star: &[Around]| {
        let mut n: SmallVec<[u32; 16]> = star
            .iter()
            .flat_map(|x| x.corners)
            .filter(|&c| c != v)
            .collect();
        n.sort_unstable();
        n.dedup();
        n
    };
    let (of_a, of_b) = (neighbours(a, &around[0]), neighbours(b, &around[1]));
    let opposite: SmallVec<[u32; 2]> = around[0]
        .iter()
        .filter(|x| x.corners.contains(&b))
        .filter_map(|x| x.corners.into_iter().find(|&c| c != a && c != b))
        .collect();
    let common_beyond_the_edge = of_a
        .iter()
        .any(|&x| x != b && of_b.binary_search(&x).is_ok() && !opposite.contains(&x));
    if common_beyond_the_edge {
        return false;
    }
    !(a_border && b_border) || keeps_border_loops(a, b, shared, around)
}

/// The neighbours of `v` joined to it by a border edge (exactly one triangle of
/// `around`, the triangles of `v`, holds both), in increasing order. Live triangles
/// have distinct corners, so that is a neighbour listed once among the corners.
///
/// Found by sorting the corners other than `v`: for a usual star (up to
/// [`SMALL_STAR`] triangles), a dozen numbers on the stack, about half the
/// instructions of the search of the other triangles per corner that this replaced;
/// for a vertex with thousands of triangles (a fan), k log k steps, not k².
pub(super) fn border_neighbours(v: u32, around: &[Around]) -> SmallVec<[u32; 8]> {
    if around.len() > SMALL_STAR {
        let mut ends: Vec<u32> = around
            .iter()
            .flat_map(|x| x.corners)
            .filter(|&c| c != v)
            .collect();
        return listed_once(&mut ends);
    }
    let mut ends = [0u32; 3 * SMALL_STAR];
    let mut n = 0;
    for x in around {
        for c in x.corners {
            if c != v {
                ends[n] = c;
                n += 1;
            }
        }
    }
    listed_once(&mut ends[..n])
}

/// The numbers that occur exactly once in `ends` (sorted in place), in increasing
/// order.
fn listed_once(ends: &mut [u32]) -> SmallVec<[u32; 8]> {
    ends.sort_unstable();
    let mut single = SmallVec::new();
    for run in ends.chunk_by(|p, q| p == q) {
        if let [only] = run {
            single.push(*only);
        }
    }
    single
}

/// The star size up to which [`border_neighbours`] sorts on the stack.
const SMALL_STAR: usize = 16;

/// Whether contracting the edge `a b` would merge a triangle `a x y` with a triangle
/// `b x y` (two faces on the same three vertices after it).
fn would_merge_faces(a: u32, b: u32, around: &[Vec<Around>; 2]) -> bool {
    !merging_faces(a, b, around).is_empty()
}

/// The faces that contracting `b` into `a` would merge, as pairs (a triangle `b x y`,
/// a triangle `a x y`), each triangle in at most one pair; `around` holds the live
/// triangles of `a` and of `b`.
pub(super) fn merging_faces(
    a: u32,
    b: u32,
    around: &[Vec<Around>; 2],
) -> SmallVec<[(u32, u32); 2]> {
    let mut pairs: SmallVec<[(u32, u32); 2]> = SmallVec::new();
    for y in &around[1] {
        if y.corners.contains(&a) {
            continue; // collapses with the pair
        }
        let mut others = y.corners.into_iter().filter(|&c| c != b);
        let (Some(p), Some(q)) = (others.next(), others.next()) else {
            continue;
        };
        let twin = around[0].iter().find(|x| {
            !x.corners.contains(&b)
                && x.corners.contains(&p)
                && x.corners.contains(&q)
                && !pairs.iter().any(|&(_, t)| t == x.triangle)
        });
        if let Some(x) = twin {
            pairs.push((y.triangle, x.triangle));
        }
    }
    pairs
}

/// Whether contracting the edge `a b` (held by `shared` triangles) keeps every border
/// loop: when both ends are on a border, `a b` must
/// be a border edge, and no third vertex may be joined to both by border edges.
fn keeps_border_loops(a: u32, b: u32, shared: usize, around: &[Vec<Around>; 2]) -> bool {
    let a_border = border_neighbours(a, &around[0]);
    if a_border.is_empty() {
        return true;
    }
    let b_border = border_neighbours(b, &around[1]);
    if b_border.is_empty() {
        return true;
    }
    if shared != 1 {
        return false;
    }
    !a_border
        .iter()
        .any(|&x| x != b && b_border.binary_search(&x).is_ok())
}

/// `Q_ab` of exact quadrics (see [`super::pass_exact`]) for `a` and `b`, both unmoved in
/// this pass: the face planes of the live triangles on both, then the segments joining
/// them (face planes from `faces`). `incidence` lists the triangles around each vertex;
/// `triangles` holds the triangles from the number it is paired with on, which must
/// include every triangle around `a` and `b`.
///
/// Walks the shorter of the two ends' lists: at a fan's centre, walking its own list
/// for each of its edges was quadratic (found in review: a cylinder with
/// 80,000-segment fan caps, 16.7 s against 0.5 s with summed quadrics). Either list
/// holds the triangles on both ends in increasing order, so the sum is the same to the
/// bit whichever is walked.
pub(super) fn shared_planes(
    incidence: &Incidence,
    (first_triangle, triangles): (u32, &[[u32; 3]]),
    exact: &PassExact,
    faces: &InputFaces,
    [a, b]: [u32; 2],
) -> Quadric {
    let (walked, other) = incidence.shorter(a, b);
    let mut sum = Quadric::ZERO;
    for &t in incidence.of(walked) {
        let corners = triangles[(t - first_triangle) as usize];
        if corners[0] != REMOVED && corners.contains(&other) {
            sum += faces.quadric(t);
        }
    }
    sum + exact.segments_between(faces, a, b)
}
