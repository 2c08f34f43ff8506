//! The greedy order's priority queue of pairs, cheapest first, one entry per pair id.
//!
//! A contraction changes the quadric of the surviving vertex, so every queued pair at
//! it must be costed again, and the pairs that went must leave. The queue is
//! *addressable*: it records where each id sits, and a re-costed pair moves in place
//! instead of being queued a second time. Why not lazy invalidation (stamps checked at
//! pop, stale entries dropped): measured on the armadillo at ratio 0.1, a binary heap
//! of stale and live entries took 38% of the run's samples, nearly all of it cache
//! misses of its sifts through a heap several times the live pairs.
//!
//! Pop order is fixed by the key alone, `(cost, stamp)`, costs compared as
//! `f64::total_cmp` and the stamp counting the pushes: among pairs of equal cost, the
//! one queued or re-costed longest ago pops first. Two live entries never share a
//! stamp, so the heap's layout cannot change which pair pops next.
//!
//! Why first in, first out on ties rather than by the vertices' numbers: ties are
//! common exactly where the surface is flat (every pair inside a plane costs 0), and a
//! fixed order by number lets one vertex win every tie around it, absorbing its
//! neighbours one after another into a hub whose re-costed pairs come straight back to
//! the top to be refused by the fold-over check again. A pair re-costed by a
//! contraction waits behind every older pair of its cost, so a flat region thins
//! evenly.
//!
//! The heap is 4-ary: half the levels of a binary heap, and the four children of a
//! node fill exactly one cache line (16-byte entries, aligned), so a sift through a
//! heap larger than the cache misses at most once per level.

/// Children per node of the heap.
const ARITY: usize = 4;

/// Marks an id that is not in the heap.
const ABSENT: u32 = u32::MAX;

/// `cost` as an integer whose unsigned order is `f64::total_cmp`'s order.
fn cost_bits(cost: f64) -> u64 {
    let bits = cost.to_bits();
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | 1 << 63
    }
}

/// The inverse of [`cost_bits`].
fn cost_from_bits(bits: u64) -> f64 {
    if bits >> 63 == 1 {
        f64::from_bits(bits & !(1 << 63))
    } else {
        f64::from_bits(!bits)
    }
}

/// One heap entry, 16 bytes.
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    /// [`cost_bits`] of the cost.
    cost: u64,
    /// The queue's push counter when it was pushed; unique among live entries.
    stamp: u32,
    id: u32,
}

impl Entry {
    fn before(&self, other: &Entry) -> bool {
        (self.cost, self.stamp) < (other.cost, other.stamp)
    }
}

/// The four children of one node, aligned to a cache line: the heap is stored three
/// entries late, so that the children `4i + 1 ..= 4i + 4` of node `i` are exactly
/// line `i + 1`.
#[derive(Clone, Copy, Debug, Default)]
#[repr(align(64))]
struct Line([Entry; ARITY]);

/// Pair ids ordered by cost (see the module's doc).
#[derive(Debug, Default)]
pub(super) struct PairQueue {
    lines: Vec<Line>,
    len: usize,
    /// Heap index of each id, [`ABSENT`] when not queued.
    position: Vec<u32>,
    next_stamp: u32,
}

impl PairQueue {
    /// An empty queue for ids below `ids`.
    pub fn new(ids: usize) -> Self {
        PairQueue {
            lines: Vec::with_capacity(ids.div_ceil(ARITY) + 1),
            len: 0,
            position: vec![ABSENT; ids],
            next_stamp: 0,
        }
    }

    /// The number of queued ids.
    #[cfg(test)]
    fn len(&self) -> usize {
        self.len
    }

    fn get(&self, i: usize) -> Entry {
        let j = i + ARITY - 1;
        self.lines[j / ARITY].0[j % ARITY]
    }

    fn set(&mut self, i: usize, entry: Entry) {
        let j = i + ARITY - 1;
        if j / ARITY >= self.lines.len() {
            self.lines.push(Line::default());
        }
        self.lines[j / ARITY].0[j % ARITY] = entry;
        self.position[entry.id as usize] = i as u32;
    }

    /// The next stamp. When the counter runs out, every live entry is restamped in
    /// its current order (the heap's order is kept, so the layout stays valid).
    fn stamp(&mut self) -> u32 {
        if self.next_stamp == u32::MAX {
            let mut entries: Vec<Entry> = (0..self.len).map(|i| self.get(i)).collect();
            let mut order: Vec<usize> = (0..entries.len()).collect();
            order.sort_unstable_by_key(|&i| entries[i].stamp);
            for (rank, &i) in order.iter().enumerate() {
                entries[i].stamp = rank as u32;
            }
            for (i, e) in entries.into_iter().enumerate() {
                self.set(i, e);
            }
            self.next_stamp = self.len as u32;
        }
        let stamp = self.next_stamp;
        self.next_stamp += 1;
        stamp
    }

    /// Queues `id` at `cost`, or moves it there if it is queued (with a new stamp).
    pub fn push(&mut self, id: u32, cost: f64) {
        let entry = Entry {
            cost: cost_bits(cost),
            stamp: self.stamp(),
            id,
        };
        match self.position[id as usize] {
            ABSENT => {
                self.len += 1;
                self.sift_up(self.len - 1, entry);
            }
            at => self.replace(at as usize, entry),
        }
    }

    /// Takes `id` out of the queue, if it is there.
    pub fn remove(&mut self, id: u32) {
        let at = self.position[id as usize];
        if at != ABSENT {
            self.position[id as usize] = ABSENT;
            self.remove_at(at as usize);
        }
    }

    /// The cheapest id and its cost.
    pub fn pop(&mut self) -> Option<(u32, f64)> {
        if self.len == 0 {
            return None;
        }
        let top = self.get(0);
        self.position[top.id as usize] = ABSENT;
        self.remove_at(0);
        Some((top.id, cost_from_bits(top.cost)))
    }

    fn remove_at(&mut self, i: usize) {
        self.len -= 1;
        if i == self.len {
            return;
        }
        let last = self.get(self.len);
        self.replace(i, last);
    }

    /// Puts `entry` at `i` (whose entry leaves) and restores the heap order.
    fn replace(&mut self, i: usize, entry: Entry) {
        if i > 0 && entry.before(&self.get((i - 1) / ARITY)) {
            self.sift_up(i, entry);
        } else {
            self.sift_down(i, entry);
        }
    }

    fn sift_up(&mut self, mut i: usize, moving: Entry) {
        while i > 0 {
            let parent = (i - 1) / ARITY;
            let p = self.get(parent);
            if !moving.before(&p) {
                break;
            }
            self.set(i, p);
            i = parent;
        }
        self.set(i, moving);
    }

    fn sift_down(&mut self, mut i: usize, moving: Entry) {
        loop {
            let first = ARITY * i + 1;
            if first >= self.len {
                break;
            }
            let last = (first + ARITY).min(self.len);
            let mut best = first;
            let mut best_entry = self.get(first);
            for c in first + 1..last {
                let e = self.get(c);
                if e.before(&best_entry) {
                    best = c;
                    best_entry = e;
                }
            }
            if !best_entry.before(&moving) {
                break;
            }
            self.set(i, best_entry);
            i = best;
        }
        self.set(i, moving);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn four_entries_fill_one_cache_line() {
        assert_eq!(std::mem::size_of::<Entry>(), 16);
        assert_eq!(std::mem::size_of::<Line>(), 64);
    }

    #[test]
    fn cost_bits_keep_the_total_order() {
        let costs = [
            f64::NEG_INFINITY,
            -1.0,
            -0.0,
            0.0,
            1e-300,
            1.0,
            f64::INFINITY,
        ];
        for w in costs.windows(2) {
            assert!(cost_bits(w[0]) < cost_bits(w[1]));
            assert_eq!(cost_from_bits(cost_bits(w[0])).to_bits(), w[0].to_bits());
        }
    }

    /// When the push counter runs out, the live entries are restamped in their order:
    /// ties still pop oldest first.
    #[test]
    fn stamps_running_out_keep_the_order() {
        let mut queue = PairQueue::new(4);
        queue.next_stamp = u32::MAX - 2;
        for id in [2, 0, 3, 1] {
            queue.push(id, 1.0);
        }
        let order: Vec<u32> = std::iter::from_fn(|| queue.pop().map(|(id, _)| id)).collect();
        assert_eq!(order, vec![2, 0, 3, 1]);
    }

    /// Through pushes, re-costs and removals, pops come out as a sorted model says:
    /// by cost, then oldest push first.
    #[test]
    fn matches_a_sorted_model_through_updates_and_removals() {
        let ids = 200u32;
        let mut queue = PairQueue::new(ids as usize);
        // The model: id -> (cost, stamp).
        let mut model: Vec<Option<(f64, u32)>> = vec![None; ids as usize];
        let mut stamp = 0u32;
        let mut state = 99u64;
        let mut next = |m: u64| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 33) % m
        };
        for step in 0..5000 {
            let id = next(ids as u64) as u32;
            match next(4) {
                0 | 1 => {
                    let cost = (next(20) as f64) * 0.5;
                    queue.push(id, cost);
                    model[id as usize] = Some((cost, stamp));
                    stamp += 1;
                }
                2 => {
                    queue.remove(id);
                    model[id as usize] = None;
                }
                _ => {
                    let expected = (0..ids)
                        .filter_map(|i| model[i as usize].map(|(c, s)| (c, s, i)))
                        .min_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
                    let popped = queue.pop();
                    assert_eq!(popped, expected.map(|(c, _, i)| (i, c)), "step {step}");
                    if let Some((i, _)) = popped {
                        model[i as usize] = None;
                    }
                }
            }
            assert_eq!(queue.len(), model.iter().flatten().count());
        }
    }
}
