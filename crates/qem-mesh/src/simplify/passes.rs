//! The pass-based order ([`ContractionOrder::Passes`](super::super::ContractionOrder::Passes)):
//! the cheapest pairs contracted in batches instead of one at a time.
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
//!    first when the round may reach the target), each attempted like the greedy
//!    order's pairs (`attempt`); then the attempted edges
//!    and every edge at a moved vertex leave the batch, and the next round starts,
//!    until the batch is empty or the target is reached. Without locks, and far from
//!    the target, the pairs of a round whose neighbourhoods lie inside one block of
//!    vertex numbers are attempted first, the blocks on the thread pool, and the rest
//!    after them in order ([`crate::simplify::pass_blocks`]). With the orientation check on, a
//!    chunk of the pairs attempted in order may first be *speculated* on the thread pool
//!    (their placements and the check's quick tests, against the arrays as they are;
//!    when most recent attempts contracted), and the attempts take what still holds
//!    ([`Engine::speculate`] says why that is the sequential answer, bit for bit).
//!
//! Why it is faster than [`ContractionOrder::Greedy`](crate::simplify::ContractionOrder::Greedy):
//! no heap, each pair costed at most once per pass, the contractions walk the arrays
//! in order, and much of the work is on both cores. What it gives up: the strict
//! greedy order (a pair whose cost fell during a pass waits for the next one). Virtual
//! pairs are listed with the edges of their smaller end (and go to the sequential
//! attempts, not the blocks). Exact quadrics keep their planes as
//! [`crate::simplify::pass_exact`] describes. The orientation check runs last among the checks;
//! a pair it refuses is ranked at the waivers' penalty in later passes and then tried
//! without it ([`crate::simplify::waivers`]).
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

use super::*;

/// How many pairs of a round [`Engine::speculate`] handles at once: a bound on the
/// memory its answers hold, and on the work wasted past the target.
const SPECULATION_CHUNK: usize = 512;

/// Pairs per piece of work handed to another core by [`Engine::speculate`].
const SPECULATION_MIN_LEN: usize = 16;

/// Without the orientation check, a pass's batch also takes every edge whose cost is
/// within this factor of the cost of the last edge it needs (see
/// [`Engine::list_batch`]).
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

/// When a pass's batch had to grow (none of its cheapest pairs could be contracted),
/// the pass contracts the grown batch's pairs cheapest first and only up to this factor
/// times the cost of the first one it contracts; the rest wait for the next pass, which
/// costs them again.
///
/// Why: the batch grows fourfold at a time, and near the end of a stuck run that is
/// every pair left; contracting all of them in list order took whatever could move,
/// however costly, before the cheap pairs those contractions opened up. On ps_mk4_gantry
/// at ratio 0.01 (the ladder's merges, where a part worn down to a tetrahedron may
/// vanish), one grown pass took two rods as long as the model out (Hausdorff distance
/// 53% of the diagonal) while small parts were still there to go; the greedy order,
/// cheapest first, never did. The factor is [`BATCH_COST_FACTOR`]'s, for the same
/// reason: the pairs just above the cheapest are about as good.
const GROWN_BATCH_COST_FACTOR: f64 = BATCH_COST_FACTOR;

/// The order candidates are taken in: cost, then [`scatter`] of the index in the
/// pass's list. A total order (NaN costs are stored as +∞, see
/// [`Engine::cost_edges`]; `scatter` is a bijection).
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

/// What [`Engine::speculate`] found for a pair, in the order it is contracted.
#[derive(Debug)]
pub(super) struct Speculation {
    pub(super) placed: Placement,
    pub(super) quadric: Quadric,
    /// The moved faces that the orientation check's quick tests found to agree, in
    /// the order asked, up to the first they could not decide; empty when the check
    /// is off or was not reached.
    pub(super) faces: SmallVec<[FaceAgrees; 12]>,
}

/// A moved face of a speculated pair that agrees with the input surface.
#[derive(Clone, Copy, Debug)]
pub(super) struct FaceAgrees {
    pub(super) triangle: u32,
    /// The triangle to become its hint (`None`: keep the hint it has).
    pub(super) settled: Option<u32>,
}

impl Engine {
    /// Whether rounds are contracted block by block ([`crate::simplify::pass_blocks`]): not with
    /// locks (the lock check reads a locked neighbour's triangles, which may lie
    /// outside the block), and only with more than one block.
    fn uses_blocks(&self) -> bool {
        let hints_per_triangle = self
            .input_surface
            .as_ref()
            .is_none_or(|s| s.hint_count() == self.triangles.len());
        // (Nor where merges are allowed: a merge removes faces at the pair's neighbours,
        // and more than two triangles, which the blocks' bound on the target assumes.)
        // (Nor with attributes: their wedges are not split into blocks.)
        !self.settings.any_locked
            && !self.settings.allow_merges
            && self.wedges.is_none()
            && hints_per_triangle
            && self.world.len() > self.block_vertices as usize
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

    /// Contracts until `target` triangles are left, the error bound, no contraction
    /// is possible, or the observer stops it.
    pub(crate) fn run_passes(&mut self, target: usize, observer: &mut dyn Observer) -> StopReason {
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
        // Once the batch has grown (nothing in it could be contracted), the cost up to
        // which this pass contracts: set by its first contraction (see `GROWN_BATCH_COST_FACTOR`).
        let mut grown = false;
        let mut cost_cap = f64::INFINITY;
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
                grown = true;
                self.list_batch(take, &mut batch);
                let tried = &self.tried;
                batch.retain(|&i| !tried[i as usize]);
                continue;
            }
            self.select_local_minima(&batch, &mut selected);
            let may_reach_target = selected.len() * 2 >= live_count - target;
            if may_reach_target || grown {
                // The round may reach the target: the cheapest first, so that the
                // ones left out are the costliest, not the last in vertex order. (A
                // grown batch: the cheapest first, up to the cost cap.)
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
            let in_order = may_reach_target || grown;
            let attempts = if !in_order && self.uses_blocks() && blocks_in_order {
                #[cfg(test)]
                self.interior_first(&selected, &mut deferred);
                &deferred
            } else if !in_order && self.uses_blocks() {
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
                let Candidate { a, b, cost } = self.candidates[i as usize];
                if cost > cost_cap {
                    continue; // (in cost order: so is every pair after it in the round)
                }
                // A pair on no common triangle is attempted as a virtual pair only in
                // a run that has them: an edge whose faces a merge took earlier in the
                // round is none.
                let virtual_allowed = self.virtual_pairs.is_some();
                match self.try_contract(
                    a,
                    b,
                    [live_count, target],
                    virtual_allowed,
                    speculation,
                    observer,
                ) {
                    Attempt::Contracted { removed, .. } => {
                        live_count -= removed;
                        contracted += 1;
                        self.chunk_contracted += 1;
                        if grown && contracted == 1 {
                            cost_cap = cost.max(0.0) * GROWN_BATCH_COST_FACTOR;
                        }
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
        // Not where merges are allowed: a merge removes a face on both ends of a pair
        // of the same round, which changes that pair's exact quadric.
        // Nor with attributes: a seam may pin the merged vertex at either end, which
        // the speculated placement does not know.
        self.input_surface.is_some()
            && !self.settings.allow_merges
            && self.wedges.is_none()
            && self.chunk_contracted * 2 >= self.chunk_attempted
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
        let error = quadric.rms_distance(self.geometric_cost(&quadric, &placed));
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
        let positions = self.positions();
        let moved = self.frame.to_normalized(world);
        let mut neighbour_hint = None;
        for x in around.iter().flatten() {
            let corners = x.corners;
            if corners.contains(&a) && corners.contains(&b) {
                continue;
            }
            let new = moved_corners(&positions, corners, [a, b], moved);
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

    /// `selected` (a round, in list order) into `order` with the pairs
    /// interior to their block first, then the others, each in list order; found here
    /// independently of [`Slab::gather`], at the round's start (a contraction inside a
    /// block keeps its triangles' corners in the block, so a pair's standing cannot
    /// change during the round).
    #[cfg(test)]
    fn interior_first(&self, selected: &[u32], order: &mut Vec<u32>) {
        let layout_block = |v: u32| v / self.block_vertices;
        let n = self.world.len() as u32;
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
}
