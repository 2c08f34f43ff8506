//! The priority queue of candidate pairs, cheapest first, with lazy invalidation.
//!
//! A contraction changes the quadric of the surviving vertex, so every queued pair that
//! touches it is out of date. Instead of finding and removing those entries (a heap
//! cannot do that cheaply), each vertex carries a *stamp* that is bumped whenever its
//! quadric or position changes; an entry remembers the stamps of its two vertices when
//! it was pushed, and a popped entry whose stamps no longer match is simply dropped.

use crate::store::VertexKey;
use slotmap::Key;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// One queued pair: its cost when pushed and the stamps that make it current.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Candidate {
    /// The quadric cost of contracting the pair (normalised units).
    pub cost: f64,
    /// First vertex (the one that survives).
    pub a: VertexKey,
    /// Second vertex (the one that is removed).
    pub b: VertexKey,
    /// Stamp of `a` when pushed.
    pub stamp_a: u32,
    /// Stamp of `b` when pushed.
    pub stamp_b: u32,
}

impl Candidate {
    /// The deterministic tie-break: the slot keys of the two vertices.
    fn tie_key(&self) -> (u64, u64) {
        (self.a.data().as_ffi(), self.b.data().as_ffi())
    }
}

impl PartialEq for Candidate {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Candidate {}

impl PartialOrd for Candidate {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Candidate {
    /// Reversed, so that `BinaryHeap` (a max-heap) pops the cheapest pair first; equal
    /// costs pop in increasing key order, which makes every run reproducible.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .cost
            .total_cmp(&self.cost)
            .then_with(|| other.tie_key().cmp(&self.tie_key()))
    }
}

/// Candidate pairs ordered by cost.
#[derive(Debug, Default)]
pub(crate) struct PairQueue {
    heap: BinaryHeap<Candidate>,
}

impl PairQueue {
    /// An empty queue with room for `capacity` entries.
    pub fn with_capacity(capacity: usize) -> Self {
        Self {
            heap: BinaryHeap::with_capacity(capacity),
        }
    }

    /// Queues a candidate.
    pub fn push(&mut self, candidate: Candidate) {
        self.heap.push(candidate);
    }

    /// Number of queued entries, stale ones included.
    pub fn len(&self) -> usize {
        self.heap.len()
    }

    /// Keeps only the entries for which `keep` is true (used to drop stale entries
    /// when they outnumber the live ones, so the heap stays proportional to the mesh).
    pub fn retain(&mut self, keep: impl FnMut(&Candidate) -> bool) {
        self.heap.retain(keep);
    }

    /// Removes and returns the cheapest candidate (stale or not).
    pub fn pop(&mut self) -> Option<Candidate> {
        self.heap.pop()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use slotmap::SlotMap;

    #[test]
    fn pops_cheapest_first_with_key_tie_break() {
        let mut keys: SlotMap<VertexKey, ()> = SlotMap::with_key();
        let v: Vec<VertexKey> = (0..4).map(|_| keys.insert(())).collect();
        let mut q = PairQueue::with_capacity(4);
        let c = |cost, a: VertexKey, b: VertexKey| Candidate {
            cost,
            a,
            b,
            stamp_a: 0,
            stamp_b: 0,
        };
        q.push(c(2.0, v[0], v[1]));
        q.push(c(1.0, v[2], v[3]));
        q.push(c(1.0, v[1], v[2]));
        q.push(c(0.5, v[3], v[0]));
        let order: Vec<(f64, VertexKey)> = std::iter::from_fn(|| q.pop())
            .map(|c| (c.cost, c.a))
            .collect();
        assert_eq!(
            order,
            vec![(0.5, v[3]), (1.0, v[1]), (1.0, v[2]), (2.0, v[0])]
        );
    }
}
