//! The greedy order ([`ContractionOrder::Greedy`](super::super::ContractionOrder::Greedy))
//! on the working mesh: Garland and Heckbert's loop, the cheapest pair first.
//!
//! Every pair (edge or virtual pair) is costed once (on both cores, as a pass costs
//! its edges) and queued ([`PairQueue`]); the cheapest is popped and attempted by the
//! same attempt sequence as the pass-based order's ([`Engine::try_contract`]: lock
//! order, placement, error bound, checks, orientation and waiver, contraction,
//! counters, event). After a contraction `b` → `a`, `b`'s triangles join `a`'s list
//! ([`Incidence::merge`]), `b`'s pairs become `a`'s ([`PairSet::contract`]), and every
//! pair at `a` is costed again and moved in the queue. A refused pair leaves the queue
//! until one of its ends moves (or the ladder of relaxations queues every pair again,
//! [`super::super::ladder`]); a pair refused by the orientation check is queued again at
//! the waivers' penalty.

use super::*;
use crate::simplify::pair_queue::PairQueue;
use crate::simplify::pair_set::{PairSet, GONE};

/// The greedy order's state, kept across the levels of a chain.
#[derive(Debug, Default)]
pub(super) struct Greedy {
    pairs: PairSet,
    queue: PairQueue,
    /// Per pair id, whether it may be contracted without a common triangle: a virtual
    /// pair, or a pair that took one's place.
    virtual_ok: Vec<bool>,
    /// Scratch of [`Engine::shared_planes_around`]: the sums, and per vertex its
    /// place among them (`u32::MAX`: none).
    shared: Vec<(u32, Quadric)>,
    shared_slot: Vec<u32>,
    /// Whether every pair has been queued (the first level's setup).
    filled: bool,
}

impl Engine {
    /// Contracts in the greedy order until `target` triangles are left, the error
    /// bound, no contraction is possible, or the observer stops it.
    pub(crate) fn run_greedy(&mut self, target: usize, observer: &mut dyn Observer) -> StopReason {
        let mut greedy = std::mem::take(&mut self.greedy);
        if !greedy.filled {
            self.queue_every_pair(&mut greedy);
        }
        let start = self.live.len();
        let mut live = start;
        let reason = loop {
            if live <= target {
                break StopReason::TargetReached;
            }
            let Some((id, cost)) = greedy.queue.pop() else {
                break StopReason::NoValidPair;
            };
            let [a, b] = greedy.pairs.ends(id);
            if self.settings.allow_merges {
                // Whether a pair makes a part vanish (priced by `place` while merges
                // are allowed) depends on its neighbours' triangles, which a
                // contraction elsewhere can change without costing the pair again: it
                // is costed again here, and queued again if it went up.
                let fresh = self.queue_cost(a, b);
                if fresh > cost {
                    greedy.queue.push(id, fresh);
                    continue;
                }
            }
            let virtual_allowed = greedy.virtual_ok[id as usize];
            match self.try_contract(a, b, [live, target], virtual_allowed, None, observer) {
                Attempt::Contracted {
                    removed,
                    kept,
                    gone,
                } => {
                    live -= removed;
                    self.after_greedy_contraction(&mut greedy, kept, gone);
                }
                // (An edge that lost its last triangle waits until it has one again.)
                Attempt::Refused | Attempt::NotAPair => {}
                // Queued again at the penalty (see `waivers`).
                Attempt::Waived => greedy
                    .queue
                    .push(id, penalised(cost, &self.merged_quadric(a, b))),
                // The cheapest pair is over the bound: so is every other.
                Attempt::OverErrorBound => break StopReason::MaxErrorReached,
            }
            if self.count_attempts(1, [live, start, target], observer) {
                break StopReason::Cancelled;
            }
        };
        self.greedy = greedy;
        self.drop_removed();
        observer.progress(Progress {
            triangles: self.live.len(),
            triangles_start: start,
            target,
        });
        reason
    }

    /// Queues again, at its current cost (a waived pair at the penalty), every pair
    /// that is not gone: those a check refused left the queue (see the module's doc),
    /// and the ladder of relaxations ([`super::super::ladder`]) asks them again under
    /// other checks.
    pub(crate) fn requeue_every_pair(&mut self) {
        let mut greedy = std::mem::take(&mut self.greedy);
        if greedy.filled {
            for id in 0..greedy.pairs.len() as u32 {
                let [a, b] = greedy.pairs.ends(id);
                if [a, b] == GONE {
                    continue;
                }
                greedy.queue.push(id, self.queue_cost(a, b));
            }
        }
        self.greedy = greedy;
    }

    /// The cost the pair `a b` is queued at now: its cost, and a waived pair's at the
    /// waivers' penalty, as a pass would rank it.
    fn queue_cost(&self, a: u32, b: u32) -> f64 {
        let cost = ranked(self.place(a, b).0.cost);
        if self.waivers.contains(a, b) {
            penalised(cost, &self.merged_quadric(a, b))
        } else {
            cost
        }
    }

    /// Lists and costs every pair (as a pass does) and queues it.
    fn queue_every_pair(&mut self, greedy: &mut Greedy) {
        self.list_edges();
        self.cost_edges();
        let candidates = std::mem::take(&mut self.candidates);
        let ends: Vec<[u32; 2]> = candidates.iter().map(|c| [c.a, c.b]).collect();
        // Virtual pairs are the listed pairs whose ends share no triangle.
        greedy.virtual_ok = ends
            .iter()
            .map(|&[a, b]| {
                let (walked, other) = self.incidence.shorter(a, b);
                !(self.incidence.of(walked).iter())
                    .any(|&t| self.triangles[t as usize].contains(&other))
            })
            .collect();
        greedy.pairs = PairSet::new(self.world.len(), ends);
        greedy.queue = PairQueue::new(candidates.len());
        for (id, c) in candidates.iter().enumerate() {
            greedy.queue.push(id as u32, c.cost);
        }
        greedy.filled = true;
        greedy.shared_slot = vec![u32::MAX; self.world.len()];
        // The pass-based lists are not used again: their memory goes back.
        self.listed_first = Vec::new();
        self.seen_with = Vec::new();
        self.virtual_pairs = None;
    }

    /// After `gone` was contracted into `kept`: `kept`'s triangles are both lists'
    /// live ones, `gone`'s pairs are `kept`'s, and every pair at `kept` is costed again.
    fn after_greedy_contraction(&mut self, greedy: &mut Greedy, kept: u32, gone: u32) {
        let triangles = &self.triangles;
        self.incidence
            .merge(kept, gone, |t| triangles[t as usize][0] != REMOVED);
        let (queue, virtual_ok) = (&mut greedy.queue, &mut greedy.virtual_ok);
        greedy.pairs.contract(kept, gone, |id, twin| {
            queue.remove(id);
            if let Some(twin) = twin {
                virtual_ok[twin as usize] |= virtual_ok[id as usize];
            }
        });
        let (shared, slot) = (&mut greedy.shared, &mut greedy.shared_slot);
        self.shared_planes_around(kept, shared, slot);
        for &id in greedy.pairs.of(kept) {
            let [a, b] = greedy.pairs.ends(id);
            if [a, b] == GONE {
                continue;
            }
            let other = if a == kept { b } else { a };
            let mut q = self.quadric[a as usize] + self.quadric[b as usize];
            if let Some(&(_, q_ab)) = shared.get(slot[other as usize] as usize) {
                q -= q_ab;
            }
            greedy
                .queue
                .push(id, ranked(self.place_with(a, b, q).0.cost));
        }
        for &(n, _) in greedy.shared.iter() {
            greedy.shared_slot[n as usize] = u32::MAX;
        }
    }

    /// With exact quadrics, `Q_ab` of `v` and each vertex `n` it shares planes with
    /// (the face planes of the live triangles on both, then the segments joining
    /// them; see [`super::super::pass_exact`]), in one walk of `v`'s lists, into
    /// `out`, with `slot[n]` the place of `n`'s sum (the caller resets `slot` to
    /// `u32::MAX` after use); empty with summed quadrics. (A slot per vertex rather
    /// than a search of `out`: at the centre of a fan of thousands of triangles, the
    /// search would be quadratic.)
    ///
    /// Why: after a contraction every pair at the new vertex is costed again, and
    /// finding each pair's shared planes on its own walked a list per pair (12% of the
    /// greedy defaults' time on the armadillo). The sums here add the same planes in
    /// another order than [`Engine::merged_quadric`] (the attempt's), so a queued cost
    /// may differ from the attempt's in its last bits; it only orders the queue.
    fn shared_planes_around(&self, v: u32, out: &mut Vec<(u32, Quadric)>, slot: &mut [u32]) {
        out.clear();
        let Some(exact) = &self.exact else {
            return;
        };
        let mut add = |n: u32, q: Quadric| match out.get_mut(slot[n as usize] as usize) {
            Some((_, sum)) => *sum += q,
            None => {
                slot[n as usize] = out.len() as u32;
                out.push((n, q));
            }
        };
        for &t in self.incidence.of(v) {
            let corners = self.triangles[t as usize];
            if corners[0] == REMOVED {
                continue;
            }
            let plane = self.input_faces.quadric(t);
            for c in corners {
                if c != v {
                    add(c, plane);
                }
            }
        }
        for (n, plane) in exact.segments_at(&self.input_faces, v) {
            add(n, plane);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::speculation_tests::thin_lens;
    use super::*;
    use crate::simplify::observer::NoObserver;
    use crate::simplify::ContractionOrder;

    /// When the ladder asks every pair again, a waived pair is queued at the waivers'
    /// penalty, as a pass would cost it: at its plain cost it would come up ahead of
    /// its penalised rank and be contracted without the orientation check.
    #[test]
    fn pairs_queued_again_keep_the_waivers_penalty() {
        let mesh = thin_lens(12, 24);
        let frame = Frame::from_points(mesh.positions.iter().map(|p| DVec3::from_array(*p)));
        let options = SimplifyOptions::default().with_order(ContractionOrder::Greedy);
        let mut engine = Engine::new(&mesh, frame, &[], &options, None);
        // A target of every live triangle: the pairs are queued, none is contracted.
        let live = engine.live.len();
        engine.run_greedy(live, &mut NoObserver);
        assert!(engine.greedy.filled);
        let waived: Vec<[u32; 2]> = (0..engine.greedy.pairs.len() as u32)
            .step_by(5)
            .map(|id| engine.greedy.pairs.ends(id))
            .filter(|&ends| ends != GONE)
            .collect();
        assert!(waived.len() > 10);
        for &[a, b] in &waived {
            engine.waivers.waive(a, b);
        }
        engine.requeue_every_pair();
        let mut queued = Vec::new();
        while let Some((id, cost)) = engine.greedy.queue.pop() {
            queued.push((engine.greedy.pairs.ends(id), cost));
        }
        assert_eq!(queued.len(), engine.greedy.pairs.len());
        for ([a, b], cost) in queued {
            let plain = ranked(engine.place(a, b).0.cost);
            let expected = if waived.contains(&[a, b]) {
                penalised(plain, &engine.merged_quadric(a, b))
            } else {
                plain
            };
            assert_eq!(cost.to_bits(), expected.to_bits(), "pair {a} {b}");
        }
    }
}
