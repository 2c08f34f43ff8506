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
//! until one of its ends moves; a pair refused by the orientation check is queued
//! again at the waivers' penalty.

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
            let virtual_allowed = greedy.virtual_ok[id as usize];
            match self.try_contract(a, b, live, virtual_allowed, None, observer) {
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
        greedy.pairs = PairSet::new(self.position.len(), ends);
        greedy.queue = PairQueue::new(candidates.len());
        for (id, c) in candidates.iter().enumerate() {
            greedy.queue.push(id as u32, c.cost);
        }
        greedy.filled = true;
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
        for &id in greedy.pairs.of(kept) {
            let [a, b] = greedy.pairs.ends(id);
            if [a, b] == GONE {
                continue;
            }
            let (placed, _) = self.place(a, b);
            let cost = if placed.cost.is_nan() {
                f64::INFINITY
            } else {
                placed.cost
            };
            greedy.queue.push(id, cost);
        }
    }
}
