//! The priority queue of candidate pairs, cheapest first, with one entry per live pair.
//!
//! A contraction changes the quadric of the surviving vertex, so every queued pair that
//! touches it must be re-costed, and every pair of the removed vertex must go. The queue
//! is *addressable*: each pair has an id (an edge's slot index, or an id handed out for
//! a virtual pair), the heap records where each id sits, and a re-costed pair is moved
//! in place instead of being queued a second time. Why not lazy invalidation (stamps,
//! stale entries dropped at pop): the stale entries doubled the heap, every pop sifted
//! through a heap far larger than the cache, and a periodic pass had to sweep them out.
//!
//! Pop order is fixed by the key alone, `(cost, stamp)` compared as (`f64::total_cmp`,
//! then the stamp), where the stamp counts the pushes: among pairs of equal cost, the
//! one queued or re-costed longest ago pops first. Two live entries never have equal
//! stamps, so the heap's layout, which depends on the order of pushes, updates and
//! removals, cannot change which pair pops next.
//!
//! Why first-in first-out on ties rather than by the vertices' names: ties are common
//! exactly where the surface is flat (every pair inside a plane costs 0), and a fixed
//! order by name let one vertex win every tie around it: it absorbed its neighbours one
//! after another into a hub of 100 and more faces, whose re-costed pairs came straight
//! back to the top of the queue to be refused by the fold-over check again. A flat
//! 121x121 grid took 8.2 s (704,850 refusals for 13,122 contractions). A pair re-costed
//! by a contraction now waits behind every older pair of its cost, so a flat region
//! thins evenly, round after round, as a pass-based simplifier would thin it.
//!
//! The heap is 4-ary: half the levels of a binary heap, and the four children of a node
//! fill exactly one cache line (16-byte entries, aligned), so a sift through a heap
//! larger than the cache misses at most once per level.

use crate::store::{EdgeKey, MeshStore, VertexKey};
use slotmap::{Key, KeyData};
use std::collections::HashMap;

/// Children per node of the heap.
const ARITY: usize = 4;

/// Marks an id that is not in the heap.
const ABSENT: u32 = u32::MAX;

// The slot index of a key (the one definition, next to `SlotVec`): unique among live
// keys, and stable for as long as the key lives (the loop never inserts into the store,
// so slots are not reused under it).
use crate::store::slot_index as slot;

/// Slot keys as dense 32-bit numbers, and back. (In `as_ffi` order, which the queue's
/// tie-break once used; the order no longer matters, only that the numbers are dense.)
///
/// A store fresh from [`MeshStore::from_mesh`] has never removed anything, so all its
/// keys share one version and the slot index alone is such a number (no table at
/// all). Otherwise the keys are ranked once, and two tables convert.
#[derive(Debug)]
enum Numbering<K> {
    /// Every key has this version: a key's number is its slot index.
    OneVersion(u32),
    /// The number of the key in each slot, and the key of each number.
    Ranked { number: Vec<u32>, keys: Vec<K> },
}

impl<K: Key> Numbering<K> {
    fn new(keys: impl Iterator<Item = K>) -> Self {
        let mut keys: Vec<K> = keys.collect();
        let version = |k: &K| (k.data().as_ffi() >> 32) as u32;
        match keys.first().map(version) {
            None => return Numbering::OneVersion(1),
            Some(v) if keys.iter().all(|k| version(k) == v) => {
                return Numbering::OneVersion(v);
            }
            Some(_) => {}
        }
        keys.sort_unstable_by_key(|k| k.data().as_ffi());
        let slots = keys.iter().map(|&k| slot(k) + 1).max().unwrap_or(0);
        let mut number = vec![0; slots];
        for (n, &k) in keys.iter().enumerate() {
            number[slot(k)] = n as u32;
        }
        Numbering::Ranked { number, keys }
    }

    #[inline]
    fn number(&self, key: K) -> u32 {
        match self {
            Numbering::OneVersion(_) => slot(key) as u32,
            Numbering::Ranked { number, .. } => number[slot(key)],
        }
    }

    #[inline]
    fn key(&self, number: u32) -> K {
        match self {
            Numbering::OneVersion(version) => {
                KeyData::from_ffi(u64::from(*version) << 32 | u64::from(number)).into()
            }
            Numbering::Ranked { keys, .. } => keys[number as usize],
        }
    }
}

impl<K> Default for Numbering<K> {
    fn default() -> Self {
        Numbering::OneVersion(1)
    }
}

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

/// One heap entry: the cost, the push's stamp and the pair's id, 16 bytes, so that the
/// four children of a node fill one cache line (see [`Line`]). The two vertices are in
/// the id's [`Slot`], read only at pop.
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    /// [`cost_bits`] of the cost.
    cost: u64,
    /// When the entry was pushed: the queue's push counter at the time (see
    /// [`PairQueue::next_stamp`]). Unique among live entries.
    stamp: u32,
    /// The pair's id: an edge's slot index, or a virtual pair's id past the edges.
    id: u32,
}

/// What the queue keeps per id, 12 bytes: where its entry is and its two vertices.
#[derive(Clone, Copy, Debug)]
struct Slot {
    /// Heap index of the entry, [`ABSENT`] when not queued.
    position: u32,
    /// The [`Numbering`] of the vertex the push named first.
    first: u32,
    /// The [`Numbering`] of the vertex the push named second.
    second: u32,
}

const NO_SLOT: Slot = Slot {
    position: ABSENT,
    first: 0,
    second: 0,
};

/// The four children of one node, aligned to a cache line: the heap is stored three
/// entries late, so that the children `4i + 1 ..= 4i + 4` of node `i` are exactly
/// line `i + 1` and a sift down reads one line per level.
#[derive(Clone, Copy, Debug, Default)]
#[repr(align(64))]
struct Line([Entry; ARITY]);

/// A popped pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Popped {
    /// The cost it was queued with (normalised units).
    pub cost: f64,
    /// The vertex the push named first.
    pub a: VertexKey,
    /// The other vertex.
    pub b: VertexKey,
    /// The edge joining them, `None` for a virtual pair.
    pub edge: Option<EdgeKey>,
}

/// Candidate pairs ordered by cost: a 4-ary min-heap, root at index 0, children of `i`
/// at `ARITY * i + 1 ..= ARITY * i + ARITY` (stored in [`Line`]s), with the heap index
/// of every id.
///
/// Vertices are kept as their [`Numbering`] (the store gains no vertex while the queue
/// lives, so the numbering stays valid): 4 bytes instead of a key's 8.
#[derive(Debug, Default)]
pub(crate) struct PairQueue {
    /// The heap, three entries late (see [`Line`]).
    lines: Vec<Line>,
    /// Number of entries in the heap.
    len: usize,
    /// Position and both vertices of every id.
    slots: Vec<Slot>,
    /// Vertex numbers, to keep a pair's vertices in 4 bytes each.
    vertices: Numbering<VertexKey>,
    /// The stamp the next push gets.
    next_stamp: u32,
    /// The edge of each edge id (= its slot index, which is also its number here).
    edges: Numbering<EdgeKey>,
    /// Ids below this are edges.
    edge_slots: usize,
    /// Ids of the virtual pairs, by their two vertex keys (`as_ffi`, smaller first).
    /// Only ever looked up, never iterated, so its hash order cannot reach an output.
    virtual_ids: HashMap<(u64, u64), u32>,
    /// Virtual-pair ids free for reuse.
    free_ids: Vec<u32>,
}

impl PairQueue {
    /// An empty queue for the pairs of `store`'s vertices and edges.
    pub fn new(store: &MeshStore) -> Self {
        let edge_slots = store.edges().map(|e| slot(e) + 1).max().unwrap_or(0);
        let mut edges = Numbering::new(store.edges());
        if let Numbering::Ranked { keys, .. } = &mut edges {
            // Edge numbers are slot indices, not ranks: the id of an edge is its slot.
            let mut by_slot = vec![EdgeKey::null(); edge_slots];
            for &e in keys.iter() {
                by_slot[slot(e)] = e;
            }
            *keys = by_slot;
        }
        PairQueue {
            lines: Vec::with_capacity(store.edge_count() / ARITY + 2),
            len: 0,
            slots: vec![NO_SLOT; edge_slots],
            vertices: Numbering::new(store.vertices()),
            next_stamp: 0,
            edges,
            edge_slots,
            virtual_ids: HashMap::new(),
            free_ids: Vec::new(),
        }
    }

    /// Number of queued pairs.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.len
    }

    /// The entry at heap index `i`.
    #[inline]
    fn get(&self, i: usize) -> Entry {
        let p = i + ARITY - 1;
        self.lines[p / ARITY].0[p % ARITY]
    }

    /// Writes the entry at heap index `i` and records its position.
    #[inline]
    fn set(&mut self, i: usize, entry: Entry) {
        let p = i + ARITY - 1;
        self.lines[p / ARITY].0[p % ARITY] = entry;
        self.slots[entry.id as usize].position = i as u32;
    }

    /// Whether `x` pops before `y` (two entries of different pairs).
    #[inline]
    fn before(&self, x: &Entry, y: &Entry) -> bool {
        // Field by field rather than a tuple's `cmp` (an `Ordering` per field, then a
        // match): the same order, about 1.3% fewer of the loop's instructions.
        if x.cost != y.cost {
            return x.cost < y.cost;
        }
        x.stamp < y.stamp
    }

    /// A stamp later than every live entry's. When the counter runs out (after 2^32
    /// pushes), the live entries are stamped again `0..len` in their order, which
    /// keeps the order and frees the rest of the range.
    fn stamp(&mut self) -> u32 {
        if self.next_stamp == u32::MAX {
            self.restamp();
        }
        let stamp = self.next_stamp;
        self.next_stamp += 1;
        stamp
    }

    /// Stamps the live entries `0..len` in their stamp order. Costs are untouched and
    /// the stamps' order is kept, so the heap stays valid where it is.
    fn restamp(&mut self) {
        let mut order: Vec<(u32, usize)> = (0..self.len).map(|i| (self.get(i).stamp, i)).collect();
        order.sort_unstable();
        for (new, &(_, i)) in order.iter().enumerate() {
            let p = i + ARITY - 1;
            // At most `len` ≤ u32::MAX - 1 live entries: ids are u32 and one is ABSENT.
            self.lines[p / ARITY].0[p % ARITY].stamp = new as u32;
        }
        self.next_stamp = self.len as u32;
    }

    /// The id of the pair `a`–`b` joined by `edge`, or of the virtual pair `a`–`b`
    /// (handed out on first use).
    fn id(&mut self, a: VertexKey, b: VertexKey, edge: Option<EdgeKey>) -> u32 {
        if let Some(e) = edge {
            debug_assert_eq!(self.edges.key(slot(e) as u32), e);
            return slot(e) as u32;
        }
        let next = self.slots.len() as u32;
        let free = &mut self.free_ids;
        let slots = &mut self.slots;
        *self
            .virtual_ids
            .entry(virtual_key(a, b))
            .or_insert_with(|| {
                free.pop().unwrap_or_else(|| {
                    slots.push(NO_SLOT);
                    next
                })
            })
    }

    /// Queues the pair `a`–`b` (joined by `edge`, or virtual) at `cost`, or, when it is
    /// queued already, gives it this cost and names `a` first from now on.
    pub fn push(&mut self, cost: f64, a: VertexKey, b: VertexKey, edge: Option<EdgeKey>) {
        let id = self.id(a, b, edge);
        let entry = Entry {
            cost: cost_bits(cost),
            stamp: self.stamp(),
            id,
        };
        let (first, second) = (self.vertices.number(a), self.vertices.number(b));
        let slot = &mut self.slots[id as usize];
        slot.first = first;
        slot.second = second;
        match slot.position {
            ABSENT => {
                self.len += 1;
                if (self.len + ARITY - 2) / ARITY >= self.lines.len() {
                    self.lines.push(Line::default());
                }
                self.sift_up(self.len - 1, entry);
            }
            i => self.replace(i as usize, entry),
        }
    }

    /// Takes the pair joined by `edge` out of the queue, if it is there.
    pub fn remove_edge(&mut self, edge: EdgeKey) {
        let id = slot(edge);
        debug_assert_eq!(self.edges.key(id as u32), edge);
        self.remove_id(id);
    }

    /// Takes the virtual pair `a`–`b` out of the queue, if it is there, and frees its id.
    pub fn remove_virtual(&mut self, a: VertexKey, b: VertexKey) {
        if let Some(id) = self.virtual_ids.remove(&virtual_key(a, b)) {
            self.remove_id(id as usize);
            self.free_ids.push(id);
        }
    }

    /// Removes and returns the cheapest pair.
    pub fn pop(&mut self) -> Option<Popped> {
        if self.len == 0 {
            return None;
        }
        let top = self.get(0);
        self.remove_at(0);
        let slot = self.slots[top.id as usize];
        Some(Popped {
            cost: cost_from_bits(top.cost),
            a: self.vertices.key(slot.first),
            b: self.vertices.key(slot.second),
            edge: ((top.id as usize) < self.edge_slots).then(|| self.edges.key(top.id)),
        })
    }

    fn remove_id(&mut self, id: usize) {
        match self.slots[id].position {
            ABSENT => {}
            i => self.remove_at(i as usize),
        }
    }

    /// Removes the entry at heap index `i`.
    fn remove_at(&mut self, i: usize) {
        let removed = self.get(i).id;
        self.len -= 1;
        if i < self.len {
            let last = self.get(self.len);
            self.replace(i, last);
        }
        self.slots[removed as usize].position = ABSENT;
    }

    /// Puts `entry` at heap index `i` in place of what was there, then restores the
    /// heap order.
    fn replace(&mut self, i: usize, entry: Entry) {
        if self.before(&entry, &self.get(i)) {
            self.sift_up(i, entry);
        } else {
            self.sift_down(i, entry);
        }
    }

    /// Places `moving` at or above the hole at `i`, until its parent pops before it.
    fn sift_up(&mut self, mut i: usize, moving: Entry) {
        while i > 0 {
            let parent = (i - 1) / ARITY;
            let above = self.get(parent);
            if !self.before(&moving, &above) {
                break;
            }
            self.set(i, above);
            i = parent;
        }
        self.set(i, moving);
    }

    /// Places `moving` at or below the hole at `i`, until no child pops before it.
    fn sift_down(&mut self, mut i: usize, moving: Entry) {
        let len = self.len;
        loop {
            let first = ARITY * i + 1;
            if first >= len {
                break;
            }
            // The children are line i + 1.
            let children = &self.lines[i + 1].0;
            let count = (len - first).min(ARITY);
            let mut best = 0;
            for c in 1..count {
                if self.before(&children[c], &children[best]) {
                    best = c;
                }
            }
            let below = children[best];
            if !self.before(&below, &moving) {
                break;
            }
            self.set(i, below);
            i = first + best;
        }
        self.set(i, moving);
    }
}

/// The map key of the virtual pair `a`–`b`, the same either way round.
fn virtual_key(a: VertexKey, b: VertexKey) -> (u64, u64) {
    let (a, b) = (a.data().as_ffi(), b.data().as_ffi());
    (a.min(b), a.max(b))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::IndexedMesh;

    #[test]
    fn four_entries_fill_one_cache_line() {
        assert_eq!(std::mem::size_of::<Entry>(), 16);
        assert_eq!(std::mem::size_of::<Line>(), 64);
        assert_eq!(std::mem::align_of::<Line>(), 64);
    }

    #[test]
    fn cost_bits_keep_the_total_order() {
        let costs = [
            f64::NEG_INFINITY,
            -1.0,
            -0.0,
            0.0,
            1e-300,
            0.5,
            1.0,
            f64::INFINITY,
            f64::NAN,
        ];
        for x in costs {
            assert_eq!(cost_from_bits(cost_bits(x)).to_bits(), x.to_bits());
            for y in costs {
                assert_eq!(cost_bits(x).cmp(&cost_bits(y)), x.total_cmp(&y), "{x} {y}");
            }
        }
    }

    /// Keys of several versions (a slot freed and taken again) are ranked in `as_ffi`
    /// order; keys of one version are numbered by slot. Both convert back.
    #[test]
    fn numbering_follows_the_key_order() {
        let mut map: slotmap::SlotMap<VertexKey, ()> = slotmap::SlotMap::with_key();
        let first: Vec<VertexKey> = (0..5).map(|_| map.insert(())).collect();
        let one = Numbering::new(map.keys());
        assert!(matches!(one, Numbering::OneVersion(1)));
        for &k in &first {
            let n = one.number(k);
            assert_eq!(n as usize, slot(k));
            assert_eq!(one.key(n), k);
        }
        assert!(first
            .windows(2)
            .all(|w| one.number(w[0]) < one.number(w[1])));
        map.remove(first[1]);
        map.remove(first[3]);
        let again = map.insert(()); // slot 3, version 3
        let keys: Vec<VertexKey> = map.keys().collect();
        let ranked = Numbering::new(keys.iter().copied());
        assert!(matches!(ranked, Numbering::Ranked { .. }));
        let mut sorted = keys.clone();
        sorted.sort_by_key(|k| k.data().as_ffi());
        assert_eq!(sorted.last(), Some(&again));
        for (n, &k) in sorted.iter().enumerate() {
            assert_eq!(ranked.number(k), n as u32);
            assert_eq!(ranked.key(n as u32), k);
        }
    }

    /// A strip of `n` triangles: vertices `0..n + 2`, edges between neighbours.
    fn strip(n: u32) -> (MeshStore, Vec<VertexKey>) {
        let positions = (0..n + 2)
            .map(|i| [f64::from(i / 2), f64::from(i % 2), 0.0])
            .collect();
        let faces = (0..n).map(|i| [i, i + 1, i + 2]).collect();
        let mesh = IndexedMesh::new(positions, faces);
        MeshStore::from_mesh(&mesh).expect("a valid strip")
    }

    #[test]
    fn pops_cheapest_first_then_oldest_first() {
        let (store, v) = strip(2);
        let e = |a: usize, b: usize| store.find_edge(v[a], v[b]);
        let mut q = PairQueue::new(&store);
        q.push(2.0, v[0], v[1], e(0, 1));
        q.push(1.0, v[2], v[3], e(2, 3));
        q.push(1.0, v[1], v[2], e(1, 2));
        q.push(0.5, v[3], v[0], None);
        let order: Vec<(f64, VertexKey)> = std::iter::from_fn(|| q.pop())
            .map(|c| (c.cost, c.a))
            .collect();
        assert_eq!(
            order,
            vec![(0.5, v[3]), (1.0, v[2]), (1.0, v[1]), (2.0, v[0])]
        );
    }

    /// A pair re-costed to the same cost goes behind the pairs of that cost that were
    /// queued before its update: the tie-break that keeps a vertex from winning every
    /// tie around it (see the module's doc).
    #[test]
    fn a_recosted_pair_waits_behind_older_ties() {
        let (store, v) = strip(2);
        let e = |a: usize, b: usize| store.find_edge(v[a], v[b]);
        let mut q = PairQueue::new(&store);
        q.push(0.0, v[0], v[1], e(0, 1));
        q.push(0.0, v[1], v[2], e(1, 2));
        q.push(0.0, v[2], v[3], e(2, 3));
        q.push(0.0, v[0], v[1], e(0, 1));
        let order: Vec<VertexKey> = std::iter::from_fn(|| q.pop()).map(|c| c.a).collect();
        assert_eq!(order, vec![v[1], v[2], v[0]]);
    }

    /// Running out of stamps renumbers the live entries without changing their order.
    #[test]
    fn stamps_running_out_keep_the_order() {
        let (store, _) = strip(6);
        let edges: Vec<EdgeKey> = store.edges().collect();
        let mut q = PairQueue::new(&store);
        q.next_stamp = u32::MAX - 3;
        // Before the wrap, costs 1, 1, 0: the 0 sifts to the root and moves the oldest
        // 1 below the newer one, so stamps given in heap order would pop the two ties
        // the wrong way round. Then more ties of both costs across the wrap.
        let costs = [1.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0];
        assert!(edges.len() >= costs.len());
        for (&edge, &cost) in edges.iter().zip(&costs) {
            let [a, b] = store.edge_vertices(edge);
            q.push(cost, a, b, Some(edge));
        }
        assert!(q.next_stamp < 100, "the stamps were renumbered");
        let popped: Vec<EdgeKey> = std::iter::from_fn(|| q.pop())
            .filter_map(|c| c.edge)
            .collect();
        let mut expected: Vec<(f64, usize)> = costs.iter().copied().zip(0..).collect();
        expected.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let expected: Vec<EdgeKey> = expected.iter().map(|&(_, k)| edges[k]).collect();
        assert_eq!(popped, expected);
    }

    /// Pushes (new pairs and updates, either way round), removals of edges and of
    /// virtual pairs, and pops, against a model that keeps one `(cost, stamp, a, b)` per
    /// pair (the stamp counting pushes) and pops the smallest `(cost, stamp)`: every pop
    /// agrees, and so does the final length.
    #[test]
    fn matches_a_sorted_model_through_updates_and_removals() {
        let (store, v) = strip(60);
        let edges: Vec<EdgeKey> = store.edges().collect();
        let mut q = PairQueue::new(&store);
        // Model: pair name -> (cost, push number, a, b); a pair is an edge index or a
        // virtual (i, j).
        type Name = (usize, usize, bool);
        type Queued = (f64, u64, VertexKey, VertexKey);
        let mut model: std::collections::BTreeMap<Name, Queued> = Default::default();
        let mut pushes = 0u64;
        let mut seed = 12345u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 33) as usize
        };
        for _ in 0..5000 {
            match next() % 6 {
                0..=2 => {
                    let cost = (next() % 20) as f64 * 0.25;
                    if next() % 3 == 0 {
                        let (i, j) = (next() % v.len(), next() % v.len());
                        if i == j || store.find_edge(v[i], v[j]).is_some() {
                            continue;
                        }
                        let (a, b) = if next() % 2 == 0 {
                            (v[i], v[j])
                        } else {
                            (v[j], v[i])
                        };
                        q.push(cost, a, b, None);
                        pushes += 1;
                        model.insert((i.min(j), i.max(j), true), (cost, pushes, a, b));
                    } else {
                        let k = next() % edges.len();
                        let [x, y] = store.edge_vertices(edges[k]);
                        let (a, b) = if next() % 2 == 0 { (x, y) } else { (y, x) };
                        q.push(cost, a, b, Some(edges[k]));
                        pushes += 1;
                        model.insert((k, 0, false), (cost, pushes, a, b));
                    }
                }
                3 => {
                    let k = next() % edges.len();
                    q.remove_edge(edges[k]);
                    model.remove(&(k, 0, false));
                }
                4 => {
                    let (i, j) = (next() % v.len(), next() % v.len());
                    q.remove_virtual(v[j], v[i]);
                    model.remove(&(i.min(j), i.max(j), true));
                }
                _ => {
                    let expected = model
                        .iter()
                        .min_by(|x, y| x.1 .0.total_cmp(&y.1 .0).then(x.1 .1.cmp(&y.1 .1)))
                        .map(|(name, c)| (*name, *c));
                    let popped = q.pop();
                    match (expected, popped) {
                        (None, None) => {}
                        (Some((name, (cost, _, a, b))), Some(p)) => {
                            assert_eq!((p.cost, p.a, p.b), (cost, a, b));
                            let edge = (!name.2).then(|| edges[name.0]);
                            assert_eq!(p.edge, edge);
                            model.remove(&name);
                        }
                        (e, p) => panic!("model {e:?}, queue {p:?}"),
                    }
                }
            }
            assert_eq!(q.len(), model.len());
        }
    }
}
