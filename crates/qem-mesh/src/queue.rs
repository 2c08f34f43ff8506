//! The priority queue of candidate pairs, cheapest first, with lazy invalidation.
//!
//! A contraction changes the quadric of the surviving vertex, so every queued pair that
//! touches it is out of date. Instead of finding and removing those entries (a heap
//! cannot do that cheaply), each vertex carries a *stamp* that is bumped whenever its
//! quadric or position changes; an entry remembers the stamps of its two vertices when
//! it was pushed, and a popped entry whose stamps no longer match is simply dropped.
//!
//! The heap is 4-ary rather than binary (`std`'s `BinaryHeap`): half as many levels, and
//! the four children of a node are adjacent (128 bytes, two cache lines), so a pop that
//! sifts down through a heap far larger than the cache misses about half as often. Pop
//! order is fixed by [`Candidate`]'s total order alone (cost, then keys): entries that
//! compare equal name the same pair with the same cost, so which of them pops first
//! cannot change a run.

use crate::store::VertexKey;
use slotmap::Key;
use std::cmp::Ordering;

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
    /// Reversed, so that the max-heap pops the cheapest pair first; equal
    /// costs pop in increasing key order, which makes every run reproducible.
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .cost
            .total_cmp(&self.cost)
            .then_with(|| other.tie_key().cmp(&self.tie_key()))
    }
}

/// Children per node of the heap.
const ARITY: usize = 4;

/// Candidate pairs ordered by cost: a 4-ary max-heap under [`Candidate`]'s (reversed)
/// order, root at index 0, children of `i` at `ARITY * i + 1 ..= ARITY * i + ARITY`.
#[derive(Debug, Default)]
pub(crate) struct PairQueue {
    heap: Vec<Candidate>,
}

impl PairQueue {
    /// An empty queue with room for `capacity` entries.
    pub fn with_capacity(capacity: usize) -> Self {
        Self {
            heap: Vec::with_capacity(capacity),
        }
    }

    /// Queues a candidate.
    pub fn push(&mut self, candidate: Candidate) {
        self.heap.push(candidate);
        self.sift_up(self.heap.len() - 1);
    }

    /// Number of queued entries, stale ones included.
    pub fn len(&self) -> usize {
        self.heap.len()
    }

    /// Keeps only the entries for which `keep` is true (used to drop stale entries
    /// when they outnumber the live ones, so the heap stays proportional to the mesh).
    pub fn retain(&mut self, mut keep: impl FnMut(&Candidate) -> bool) {
        self.heap.retain(|c| keep(c));
        // Bottom-up heap construction: O(n).
        for i in (0..self.heap.len().div_ceil(ARITY)).rev() {
            self.sift_down(i);
        }
    }

    /// Removes and returns the cheapest candidate (stale or not).
    pub fn pop(&mut self) -> Option<Candidate> {
        let last = self.heap.pop()?;
        if self.heap.is_empty() {
            return Some(last);
        }
        let top = std::mem::replace(&mut self.heap[0], last);
        self.sift_down(0);
        Some(top)
    }

    /// Moves the entry at `i` up until its parent pops before it.
    fn sift_up(&mut self, mut i: usize) {
        let moving = self.heap[i];
        while i > 0 {
            let parent = (i - 1) / ARITY;
            if self.heap[parent] >= moving {
                break;
            }
            self.heap[i] = self.heap[parent];
            i = parent;
        }
        self.heap[i] = moving;
    }

    /// Moves the entry at `i` down until none of its children pops before it.
    fn sift_down(&mut self, mut i: usize) {
        let len = self.heap.len();
        let moving = self.heap[i];
        loop {
            let first = ARITY * i + 1;
            if first >= len {
                break;
            }
            let mut best = first;
            for child in first + 1..(first + ARITY).min(len) {
                if self.heap[child] > self.heap[best] {
                    best = child;
                }
            }
            if self.heap[best] <= moving {
                break;
            }
            self.heap[i] = self.heap[best];
            i = best;
        }
        self.heap[i] = moving;
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

    /// Many entries with repeated costs, some dropped by `retain` halfway: every pop
    /// is the smallest remaining entry in (cost, keys) order, as a sorted list says.
    #[test]
    fn pops_in_sorted_order_after_pushes_and_retain() {
        let mut keys: SlotMap<VertexKey, ()> = SlotMap::with_key();
        let v: Vec<VertexKey> = (0..50).map(|_| keys.insert(())).collect();
        let mut q = PairQueue::with_capacity(0);
        let mut model = Vec::new();
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) as usize
        };
        for round in 0..2 {
            for _ in 0..1000 {
                let c = Candidate {
                    cost: (next() % 20) as f64 * 0.5,
                    a: v[next() % 50],
                    b: v[next() % 50],
                    stamp_a: round,
                    stamp_b: 0,
                };
                q.push(c);
                model.push(c);
            }
            let keep = |c: &Candidate| c.a != v[7] && c.cost != 3.0;
            q.retain(keep);
            model.retain(keep);
            for _ in 0..300 {
                let popped = q.pop().map(|c| (c.cost, c.tie_key()));
                model.sort(); // cheapest last: the order is reversed
                let expected = model.pop().map(|c| (c.cost, c.tie_key()));
                assert_eq!(popped, expected);
            }
        }
        assert_eq!(q.len(), model.len());
        model.sort();
        while let Some(c) = q.pop() {
            let expected = model.pop().map(|c| (c.cost, c.tie_key()));
            assert_eq!(Some((c.cost, c.tie_key())), expected);
        }
        assert!(model.is_empty());
    }
}
