//! Lists of items per vertex (the live triangles around each vertex, the segments of
//! exact quadrics at each end) that a contraction can merge: the working mesh's one
//! model of "what is at a vertex", for both orders.
//!
//! Each vertex's list is a run `items[start[v]..start[v] + len[v]]`. Built in one
//! counting sort ([`Incidence::rebuild`]), every list in increasing item order, one
//! after another. Contracting `b` into `a` writes `a`'s list followed by `b`'s at the
//! end of `items` (without the items the caller no longer wants) and empties `b`'s:
//! the pass-based order never merges (it rebuilds at each pass), the greedy order
//! merges at every contraction. The runs left behind are garbage; once they are more
//! than half of `items`, every live run is copied to a fresh array in vertex order
//! ([`Incidence::compact`]), so the array stays within about twice the items it holds
//! and a merge costs the two lists' lengths (amortised).

/// Per-vertex lists of `u32` items (see the module's doc).
#[derive(Debug, Default)]
pub(super) struct Incidence {
    start: Vec<u32>,
    len: Vec<u32>,
    items: Vec<u32>,
    /// The sum of `len`: the items in live runs.
    held: usize,
}

impl Incidence {
    /// The lists of `vertex_count` vertices, from `entries`: for each item, in
    /// increasing item order, the vertices it belongs to. Each vertex's list holds its
    /// items in that order. `entries` is walked twice (count, then fill).
    pub fn rebuild<I, E>(&mut self, vertex_count: usize, entries: E)
    where
        E: Fn() -> I,
        I: Iterator<Item = (u32, u32)>,
    {
        self.start.clear();
        self.start.resize(vertex_count, 0);
        self.len.clear();
        self.len.resize(vertex_count, 0);
        for (v, _) in entries() {
            self.len[v as usize] += 1;
        }
        let mut total = 0u32;
        for v in 0..vertex_count {
            self.start[v] = total;
            total += self.len[v];
        }
        self.items.clear();
        self.items.resize(total as usize, 0);
        // `len` doubles as the fill cursor, counted up again from zero.
        self.len.fill(0);
        for (v, item) in entries() {
            let v = v as usize;
            self.items[(self.start[v] + self.len[v]) as usize] = item;
            self.len[v] += 1;
        }
        self.held = total as usize;
    }

    /// The list of `v`.
    #[inline]
    pub fn of(&self, v: u32) -> &[u32] {
        let start = self.start[v as usize] as usize;
        &self.items[start..start + self.len[v as usize] as usize]
    }

    /// The number of items in `v`'s list.
    #[inline]
    pub fn len_of(&self, v: u32) -> usize {
        self.len[v as usize] as usize
    }

    /// Of `a` and `b`, the one with the shorter list (the first on a tie) and the
    /// other: the side to walk when looking for what both share.
    #[inline]
    pub fn shorter(&self, a: u32, b: u32) -> (u32, u32) {
        if self.len_of(a) <= self.len_of(b) {
            (a, b)
        } else {
            (b, a)
        }
    }

    /// `a`'s list becomes `a`'s then `b`'s items, each kept only when `keep` says so
    /// (in their order); `b`'s list becomes empty.
    pub fn merge(&mut self, a: u32, b: u32, keep: impl Fn(u32) -> bool) {
        self.reserve_for_merge(a, b);
        let new_start = self.items.len();
        for v in [a, b] {
            let start = self.start[v as usize] as usize;
            for i in start..start + self.len[v as usize] as usize {
                let item = self.items[i];
                if keep(item) {
                    self.items.push(item);
                }
            }
        }
        self.held -= self.len_of(a) + self.len_of(b);
        let new_len = self.items.len() - new_start;
        self.held += new_len;
        self.start[a as usize] = new_start as u32;
        self.len[a as usize] = new_len as u32;
        self.len[b as usize] = 0;
    }

    /// Adds `item` at the end of `v`'s list.
    pub fn push(&mut self, v: u32, item: u32) {
        let (start, len) = (self.start[v as usize] as usize, self.len_of(v));
        if start + len == self.items.len() && len > 0 {
            // The last run: it grows in place.
            self.items.push(item);
        } else {
            self.reserve_for_merge(v, v);
            let start = self.start[v as usize] as usize;
            let new_start = self.items.len();
            self.items.extend_from_within(start..start + len);
            self.items.push(item);
            self.start[v as usize] = new_start as u32;
        }
        self.len[v as usize] += 1;
        self.held += 1;
    }

    /// Compacts first when a merge of `a` and `b` would leave more garbage than live
    /// items.
    fn reserve_for_merge(&mut self, a: u32, b: u32) {
        let extra = self.len_of(a) + if a == b { 1 } else { self.len_of(b) };
        if self.items.len() + extra > 2 * (self.held + extra) + 64 {
            self.compact();
        }
    }

    /// Copies every list to a fresh array, in vertex order.
    fn compact(&mut self) {
        let mut items = Vec::with_capacity(2 * self.held + 64);
        for v in 0..self.start.len() {
            let start = self.start[v] as usize;
            let len = self.len[v] as usize;
            self.start[v] = items.len() as u32;
            items.extend_from_slice(&self.items[start..start + len]);
        }
        self.items = items;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lists(inc: &Incidence, n: u32) -> Vec<Vec<u32>> {
        (0..n).map(|v| inc.of(v).to_vec()).collect()
    }

    /// Rebuild sorts by vertex, keeping item order; merges and pushes behave like
    /// `Vec`s, through many compactions.
    #[test]
    fn matches_a_model_of_vecs_through_merges_pushes_and_compactions() {
        let n = 50u32;
        let entries: Vec<(u32, u32)> = (0..300u32).map(|i| ((i * 7) % n, i)).collect();
        let mut inc = Incidence::default();
        inc.rebuild(n as usize, || entries.iter().copied());
        let mut model: Vec<Vec<u32>> = vec![Vec::new(); n as usize];
        for &(v, i) in &entries {
            model[v as usize].push(i);
        }
        assert_eq!(lists(&inc, n), model);
        let mut state = 12345u64;
        let mut next = |m: u32| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) % m as u64) as u32
        };
        for step in 0..2000u32 {
            let (a, b) = (next(n), next(n));
            if step % 3 == 0 {
                inc.push(a, 1000 + step);
                model[a as usize].push(1000 + step);
            } else if a != b {
                let keep = |x: u32| x % 5 != 0;
                inc.merge(a, b, keep);
                let mut merged: Vec<u32> = model[a as usize].clone();
                merged.extend_from_slice(&model[b as usize]);
                merged.retain(|&x| keep(x));
                model[a as usize] = merged;
                model[b as usize].clear();
            }
            assert_eq!(lists(&inc, n), model, "step {step}");
        }
        let held: usize = model.iter().map(Vec::len).sum();
        assert!(inc.items.len() <= 2 * held + 64 + 2 * 300);
    }
}
