//! [`QuadricMode::Exact`](super::QuadricMode::Exact) in the pass-based order: the
//! quadric of a contracted pair is that of the *union* of the two plane sets,
//! `Q_a + Q_b − Q_ab` (see [`super::exact`] for the greedy loop's bookkeeping and the
//! argument).
//!
//! Every input plane has a support: the input vertices it belongs to (a face plane:
//! its triangle's three corners; a border plane: its edge's two ends). `Q_ab` is the
//! sum of the planes whose support meets both `a`'s group and `b`'s, that is, whose
//! support's *current* vertices include both `a` and `b`. The pass-based order keeps
//! those planes where it can find them from an edge:
//! - a live triangle holds its face plane, with its current corners;
//! - a plane whose support is down to two current vertices is a [`Segment`]: a border
//!   plane from the start, or the face plane of a triangle that collapsed (its two
//!   corners that merged are one vertex now, its third is the other end);
//! - a plane whose support is down to one vertex meets no pair's two groups again,
//!   and is forgotten.
//!
//! So `Q_ab` = the face planes of the live triangles on both `a` and `b`, plus the
//! segments joining them. Segments keep the ends they were made with; each pass
//! resolves them through the record of which vertex merged into which (so a segment
//! at a vertex that merged later follows it) and lists them by end. Within a pass, the
//! pairs asked about have both ends unmoved in that pass, and no segment's resolved
//! ends change without one of them moving, so the pass's list stays exact for them.

use qem_core::{Quadric, WeightedPlane};

/// A plane supported by exactly two current vertices.
#[derive(Clone, Copy, Debug)]
struct Segment {
    /// Its ends when it was made (resolved through [`PassExact::merged_into`] at the
    /// start of each pass).
    ends: [u32; 2],
    /// Its plane: a triangle index (the triangle's face plane), or the triangle count
    /// plus an index into [`PassExact::border_planes`].
    source: u32,
}

/// The bookkeeping of exact quadrics in a pass-based run.
#[derive(Debug)]
pub(super) struct PassExact {
    /// Each input triangle's weighted face plane (the one summed into its corners).
    face_planes: Vec<WeightedPlane>,
    /// The border planes' quadrics, in the order they were added.
    border_planes: Vec<Quadric>,
    segments: Vec<Segment>,
    /// Per vertex, the vertex it was contracted into, or itself while it lives.
    merged_into: Vec<u32>,
    /// The segments by end, as of the start of the pass:
    /// `by_end[first[v]..first[v + 1]]` are the indices of the segments at `v`.
    first: Vec<u32>,
    by_end: Vec<u32>,
}

impl PassExact {
    /// No plane yet, for `vertex_count` vertices (the face planes come with
    /// [`set_face_planes`](Self::set_face_planes)).
    pub fn new(vertex_count: usize) -> Self {
        PassExact {
            face_planes: Vec::new(),
            border_planes: Vec::new(),
            segments: Vec::new(),
            merged_into: (0..vertex_count as u32).collect(),
            first: Vec::new(),
            by_end: Vec::new(),
        }
    }

    /// Records every triangle's face plane, by triangle index; before any border plane
    /// is added (a border plane's source number counts the triangles).
    pub fn set_face_planes(&mut self, planes: Vec<WeightedPlane>) {
        debug_assert!(self.border_planes.is_empty());
        self.face_planes = planes;
    }

    /// The quadric of triangle `t`'s face plane.
    #[inline]
    pub fn face_quadric(&self, t: u32) -> Quadric {
        self.face_planes[t as usize].quadric()
    }

    /// Records a border plane `q` on the edge `a b`.
    pub fn add_border_plane(&mut self, a: u32, b: u32, q: Quadric) {
        let source = (self.face_planes.len() + self.border_planes.len()) as u32;
        self.border_planes.push(q);
        self.segments.push(Segment {
            ends: [a, b],
            source,
        });
    }

    /// Records the contraction of `b` into `a`, whose collapsed triangles are
    /// `collapsed` (each with its corner other than `a` and `b`).
    pub fn contract(&mut self, a: u32, b: u32, collapsed: impl Iterator<Item = (u32, u32)>) {
        self.merged_into[b as usize] = a;
        for (t, x) in collapsed {
            self.segments.push(Segment {
                ends: [a, x],
                source: t,
            });
        }
    }

    /// Resolves every segment's ends to current vertices, forgets those whose ends
    /// are one vertex now, and lists the rest by end (a counting sort).
    pub fn start_pass(&mut self) {
        let n = self.merged_into.len();
        let mut segments = std::mem::take(&mut self.segments);
        for s in &mut segments {
            s.ends = s.ends.map(|v| self.current(v));
        }
        segments.retain(|s| s.ends[0] != s.ends[1]);
        self.segments = segments;
        self.first.clear();
        self.first.resize(n + 1, 0);
        for s in &self.segments {
            for v in s.ends {
                self.first[v as usize + 1] += 1;
            }
        }
        for v in 0..n {
            self.first[v + 1] += self.first[v];
        }
        self.by_end.clear();
        self.by_end.resize(self.segments.len() * 2, 0);
        let mut cursor = self.first[..n].to_vec();
        for (i, s) in self.segments.iter().enumerate() {
            for v in s.ends {
                self.by_end[cursor[v as usize] as usize] = i as u32;
                cursor[v as usize] += 1;
            }
        }
    }

    /// The vertex `v` was merged into, through every later contraction (shortening
    /// the chain as it goes).
    fn current(&mut self, v: u32) -> u32 {
        let mut root = v;
        while self.merged_into[root as usize] != root {
            root = self.merged_into[root as usize];
        }
        let mut w = v;
        while self.merged_into[w as usize] != root {
            let next = self.merged_into[w as usize];
            self.merged_into[w as usize] = root;
            w = next;
        }
        root
    }

    /// The sum of the segments joining `a` and `b`, both unmoved in this pass.
    ///
    /// Walks the shorter of the two ends' lists (a vertex that absorbed many others
    /// has a long one); both list the segments in increasing order, so the sum is the
    /// same to the bit either way.
    #[inline]
    pub fn segments_between(&self, a: u32, b: u32) -> Quadric {
        let ((_, other), range) = shorter_list(&self.first, a, b);
        let mut sum = Quadric::ZERO;
        for &i in &self.by_end[range] {
            let s = self.segments[i as usize];
            if s.ends.contains(&other) {
                sum += self.plane(s.source);
            }
        }
        sum
    }

    /// The quadric of a segment's plane.
    fn plane(&self, source: u32) -> Quadric {
        let triangles = self.face_planes.len();
        match (source as usize).checked_sub(triangles) {
            Some(border) => self.border_planes[border],
            None => self.face_quadric(source),
        }
    }
}

/// Of two vertices with lists `by_vertex[first[v]..first[v + 1]]`, the one with the
/// shorter list (the first on a tie) and the other, and that list's range: the side
/// to walk when looking for what both share.
pub(super) fn shorter_list(first: &[u32], a: u32, b: u32) -> ((u32, u32), std::ops::Range<usize>) {
    let range = |v: u32| first[v as usize] as usize..first[v as usize + 1] as usize;
    if range(a).len() <= range(b).len() {
        ((a, b), range(a))
    } else {
        ((b, a), range(b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use qem_core::DVec3;

    fn plane(z: f64) -> WeightedPlane {
        WeightedPlane::from_triangle_unweighted(
            DVec3::new(0.0, 0.0, z),
            DVec3::new(1.0, 0.0, z),
            DVec3::new(0.0, 1.0, z),
        )
    }

    /// Segments follow their ends through later contractions, and one whose ends
    /// become one vertex is forgotten.
    #[test]
    fn segments_follow_merges_and_vanish_when_their_ends_meet() {
        let mut e = PassExact::new(6);
        e.set_face_planes(vec![plane(1.0), plane(2.0)]);
        let border = Quadric::from_plane(DVec3::X, -3.0);
        e.add_border_plane(4, 5, border);
        // Triangle 0 on 0 1 2 collapses as 1 goes into 0: a segment 0–2.
        e.contract(0, 1, [(0, 2)].into_iter());
        // Triangle 1 on 2 3 4 collapses as 3 goes into 2: a segment 2–4.
        e.contract(2, 3, [(1, 4)].into_iter());
        e.start_pass();
        assert_eq!(e.segments_between(0, 2), e.face_quadric(0));
        assert_eq!(e.segments_between(2, 0), e.face_quadric(0));
        assert_eq!(e.segments_between(2, 4), e.face_quadric(1));
        assert_eq!(e.segments_between(4, 5), border);
        assert_eq!(e.segments_between(0, 4), Quadric::ZERO);
        // 5 into 4, then 4 into 2: the border plane now joins nothing (one vertex),
        // the segment 2–4 neither; 0–2 stays.
        e.contract(4, 5, std::iter::empty());
        e.contract(2, 4, std::iter::empty());
        e.start_pass();
        assert_eq!(e.segments.len(), 1);
        assert_eq!(e.segments_between(0, 2), e.face_quadric(0));
        // Then 2 into 0: nothing left.
        e.contract(0, 2, std::iter::empty());
        e.start_pass();
        assert!(e.segments.is_empty());
    }
}
