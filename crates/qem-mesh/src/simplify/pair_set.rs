//! A set of vertex pairs that follows contractions: the greedy order's candidates
//! (every edge and virtual pair), and the virtual pairs of the pass-based order.
//!
//! Each pair has a fixed id and two current ends; each vertex lists the ids of its
//! pairs ([`Incidence`]). Contracting `b` into `a` renames `b` to `a` in `b`'s pairs
//! and merges the lists; the pair `a b` itself joins nothing any more, and where `a`
//! and `b` both had a pair with the same vertex `n`, the one of `b` goes (one pair per
//! two vertices). No new pair can arise: `a`'s neighbours after the contraction are
//! `a`'s and `b`'s before it.

use super::incidence::Incidence;

/// A pair's ends once it is gone.
pub(super) const GONE: [u32; 2] = [u32::MAX, u32::MAX];

/// Pairs of vertices with stable ids (see the module's doc).
#[derive(Debug, Default)]
pub(super) struct PairSet {
    ends: Vec<[u32; 2]>,
    by_end: Incidence,
    /// Scratch of [`contract`](Self::contract): per vertex, the last vertex whose
    /// pairs were marked with it, and the id of that vertex's pair with it.
    marked_by: Vec<(u32, u32)>,
}

impl PairSet {
    /// The pairs `ends` (distinct vertices, no pair twice) among `vertex_count`
    /// vertices; pair `i` has id `i`.
    pub fn new(vertex_count: usize, ends: Vec<[u32; 2]>) -> Self {
        let mut by_end = Incidence::default();
        by_end.rebuild(vertex_count, || {
            ends.iter()
                .enumerate()
                .flat_map(|(i, e)| e.map(|v| (v, i as u32)))
        });
        PairSet {
            ends,
            by_end,
            marked_by: vec![(u32::MAX, u32::MAX); vertex_count],
        }
    }

    /// How many pairs there were (ids run from 0 to this, gone ones included).
    pub fn len(&self) -> usize {
        self.ends.len()
    }

    /// The current ends of pair `id` ([`GONE`] once it is gone).
    #[inline]
    pub fn ends(&self, id: u32) -> [u32; 2] {
        self.ends[id as usize]
    }

    /// The ids of the pairs at `v`; it may still list pairs gone since its last
    /// contraction (their ends are [`GONE`]).
    #[inline]
    pub fn of(&self, v: u32) -> &[u32] {
        self.by_end.of(v)
    }

    /// Records the contraction of `b` into `a` (see the module's doc); `gone` is told
    /// each id that goes, with the id of `a`'s pair that it duplicated (`None` for the
    /// pair `a b` itself).
    pub fn contract(&mut self, a: u32, b: u32, mut gone: impl FnMut(u32, Option<u32>)) {
        for &i in self.by_end.of(a) {
            let [x, y] = self.ends[i as usize];
            if [x, y] != GONE {
                let other = if x == a { y } else { x };
                self.marked_by[other as usize] = (a, i);
            }
        }
        for &i in self.by_end.of(b) {
            let e = &mut self.ends[i as usize];
            if *e == GONE {
                continue;
            }
            let other = if e[0] == b { e[1] } else { e[0] };
            let (marker, twin) = self.marked_by[other as usize];
            if other == a {
                *e = GONE;
                gone(i, None);
            } else if marker == a {
                *e = GONE;
                gone(i, Some(twin));
            } else {
                *e = [a.min(other), a.max(other)];
            }
        }
        // Cleared, so that a mark never outlives its contraction.
        for &i in self.by_end.of(a) {
            let [x, y] = self.ends[i as usize];
            if [x, y] != GONE {
                let other = if x == a { y } else { x };
                self.marked_by[other as usize] = (u32::MAX, u32::MAX);
            }
        }
        let ends = &self.ends;
        self.by_end.merge(a, b, |i| ends[i as usize] != GONE);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A path 0-1-2 and a pair 0-2: contracting 1 into 0 removes 0-1 and the
    /// duplicate 0-2 (from 1-2), keeping the older 0-2.
    #[test]
    fn contraction_drops_the_pair_itself_and_duplicates() {
        let mut set = PairSet::new(4, vec![[0, 1], [1, 2], [0, 2], [1, 3]]);
        let mut gone = Vec::new();
        set.contract(0, 1, |i, twin| gone.push((i, twin)));
        gone.sort_unstable();
        assert_eq!(gone, vec![(0, None), (1, Some(2))]);
        assert_eq!(set.ends(2), [0, 2]);
        assert_eq!(set.ends(3), [0, 3]);
        let mut at_0 = set.of(0).to_vec();
        at_0.sort_unstable();
        assert_eq!(at_0, vec![2, 3]);
        assert!(set.of(1).is_empty());
        assert_eq!(set.of(3), &[3]);
        // Then 3 into 2: 0-3 becomes a duplicate of 0-2.
        let mut gone = Vec::new();
        set.contract(2, 3, |i, twin| gone.push((i, twin)));
        assert_eq!(gone, vec![(3, Some(2))]);
        let live_at = |v: u32| -> Vec<u32> {
            (set.of(v).iter().copied())
                .filter(|&i| set.ends(i) != GONE)
                .collect()
        };
        assert_eq!(live_at(0), vec![2]);
        assert_eq!(set.of(2), &[2]);
    }
}
