//! [`QuadricMode::Exact`](super::QuadricMode::Exact), in both orders: the quadric of a
//! contracted pair is that of the *union* of the two plane sets, `Q_a + Q_b − Q_ab`
//! (inclusion–exclusion; Edelsbrunner, *Geometry and Topology for Mesh Generation*):
//! the plain sum counts every plane the two vertices share twice.
//!
//! Every input plane has a support: the input vertices it belongs to (a face plane:
//! its triangle's three corners; a border plane: its edge's two ends). `Q_ab` is the
//! sum of the planes whose support meets both `a`'s group and `b`'s, that is, whose
//! support's *current* vertices include both `a` and `b`. The engine keeps those
//! planes where it can find them from a pair:
//! - a live triangle holds its face plane, with its current corners;
//! - a plane whose support is down to two current vertices is a [`Segment`]: a border
//!   plane from the start, or the face plane of a triangle that collapsed (its two
//!   corners that merged are one vertex now, its third is the other end);
//! - a plane whose support is down to one vertex meets no pair's two groups again,
//!   and is forgotten.
//!
//! One exception: the two faces that a contraction merges away on the ladder of
//! relaxations ([`RelaxationStep::MergedFaces`](super::RelaxationStep::MergedFaces))
//! still have three current vertices in their supports, but no live triangle holds
//! them, so they drop out of every later `Q_ab` and count twice there, as summed
//! quadrics would. Only stuck runs merge faces; the brute-force tests run strict.
//!
//! So `Q_ab` = the face planes of the live triangles on both `a` and `b`, plus the
//! segments joining them. A contraction renames the removed vertex in its segments at
//! once and merges its list of segments into the kept vertex's ([`Incidence`]), so the
//! lists are always current; the pass-based order also rebuilds them at each pass, in
//! index order, so that the sum of a pair's segments has the same bits whichever end's
//! list is walked.

use super::incidence::Incidence;
use super::input_faces::InputFaces;
use qem_core::Quadric;

/// A plane supported by exactly two current vertices.
#[derive(Clone, Copy, Debug)]
struct Segment {
    /// Its two current ends (kept current by [`PassExact::contract`]).
    ends: [u32; 2],
    /// Its plane: a triangle index (the triangle's face plane, from [`InputFaces`]),
    /// or the triangle count plus an index into [`PassExact::border_planes`].
    source: u32,
}

/// A segment's ends once they are one vertex: it joins nothing any more.
const GONE: [u32; 2] = [u32::MAX, u32::MAX];

/// The bookkeeping of exact quadrics in a run (either order).
#[derive(Debug)]
pub(super) struct PassExact {
    /// How many input triangles there are (their face planes are [`InputFaces`]'):
    /// the first border plane's source number.
    triangle_count: usize,
    /// The border planes' quadrics, in the order they were added.
    border_planes: Vec<Quadric>,
    segments: Vec<Segment>,
    /// The segments by end (indices into `segments`): rebuilt in index order by
    /// [`start_pass`](Self::start_pass), merged by [`contract`](Self::contract).
    by_end: Incidence,
    vertex_count: usize,
}

impl PassExact {
    /// No segment yet, for `vertex_count` vertices and `triangle_count` input
    /// triangles.
    pub fn new(vertex_count: usize, triangle_count: usize) -> Self {
        let mut exact = PassExact {
            triangle_count,
            border_planes: Vec::new(),
            segments: Vec::new(),
            by_end: Incidence::default(),
            vertex_count,
        };
        exact.start_pass();
        exact
    }

    /// Records a border plane `q` on the edge `a b`.
    pub fn add_border_plane(&mut self, a: u32, b: u32, q: Quadric) {
        let source = (self.triangle_count + self.border_planes.len()) as u32;
        self.border_planes.push(q);
        self.add_segment([a, b], source);
    }

    fn add_segment(&mut self, ends: [u32; 2], source: u32) {
        let i = self.segments.len() as u32;
        self.segments.push(Segment { ends, source });
        for v in ends {
            self.by_end.push(v, i);
        }
    }

    /// Records the contraction of `b` into `a`, whose collapsed triangles are
    /// `collapsed` (each with its corner other than `a` and `b`): `b`'s segments are
    /// `a`'s now, those joining `a` and `b` join nothing, and each collapsed
    /// triangle's plane becomes a segment from `a` to its third corner.
    pub fn contract(&mut self, a: u32, b: u32, collapsed: impl Iterator<Item = (u32, u32)>) {
        for &i in self.by_end.of(b) {
            let s = &mut self.segments[i as usize];
            if s.ends.contains(&a) {
                s.ends = GONE;
            } else if s.ends != GONE {
                s.ends = s.ends.map(|v| if v == b { a } else { v });
            }
        }
        let segments = &self.segments;
        self.by_end
            .merge(a, b, |i| segments[i as usize].ends != GONE);
        for (t, x) in collapsed {
            self.add_segment([a, x], t);
        }
    }

    /// Forgets the segments that join nothing, and lists the rest by end again, each
    /// vertex's in increasing order (a counting sort): the start of a pass.
    pub fn start_pass(&mut self) {
        self.segments.retain(|s| s.ends != GONE);
        let segments = &self.segments;
        self.by_end.rebuild(self.vertex_count, || {
            segments
                .iter()
                .enumerate()
                .flat_map(|(i, s)| s.ends.map(|v| (v, i as u32)))
        });
    }

    /// The sum of the segments joining `a` and `b` (face planes from `faces`).
    ///
    /// Walks the shorter of the two ends' lists (a vertex that absorbed many others
    /// has a long one). After [`start_pass`](Self::start_pass) both list the segments
    /// in increasing order, so the sum is the same to the bit either way.
    #[inline]
    pub fn segments_between(&self, faces: &InputFaces, a: u32, b: u32) -> Quadric {
        let (walked, other) = self.by_end.shorter(a, b);
        let mut sum = Quadric::ZERO;
        for &i in self.by_end.of(walked) {
            let s = self.segments[i as usize];
            if s.ends.contains(&other) {
                sum += self.plane(faces, s.source);
            }
        }
        sum
    }

    /// Each segment at `v` that joins it to another vertex: that vertex and the
    /// segment's plane (face planes from `faces`).
    pub fn segments_at<'a>(
        &'a self,
        faces: &'a InputFaces,
        v: u32,
    ) -> impl Iterator<Item = (u32, Quadric)> + 'a {
        self.by_end.of(v).iter().filter_map(move |&i| {
            let s = self.segments[i as usize];
            (s.ends != GONE).then(|| {
                let other = if s.ends[0] == v { s.ends[1] } else { s.ends[0] };
                (other, self.plane(faces, s.source))
            })
        })
    }

    /// The quadric of a segment's plane.
    fn plane(&self, faces: &InputFaces, source: u32) -> Quadric {
        match (source as usize).checked_sub(self.triangle_count) {
            Some(border) => self.border_planes[border],
            None => faces.quadric(source),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simplify::checks::Facing;
    use qem_core::{DVec3, WeightedPlane};

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
        let mut e = PassExact::new(6, 2);
        let faces = InputFaces::kept(vec![Facing::NONE; 2], vec![plane(1.0), plane(2.0)], None);
        let face = |t| faces.quadric(t);
        let border = Quadric::from_plane(DVec3::X, -3.0);
        e.add_border_plane(4, 5, border);
        // Triangle 0 on 0 1 2 collapses as 1 goes into 0: a segment 0–2.
        e.contract(0, 1, [(0, 2)].into_iter());
        // Triangle 1 on 2 3 4 collapses as 3 goes into 2: a segment 2–4.
        e.contract(2, 3, [(1, 4)].into_iter());
        e.start_pass();
        assert_eq!(e.segments_between(&faces, 0, 2), face(0));
        assert_eq!(e.segments_between(&faces, 2, 0), face(0));
        assert_eq!(e.segments_between(&faces, 2, 4), face(1));
        assert_eq!(e.segments_between(&faces, 4, 5), border);
        assert_eq!(e.segments_between(&faces, 0, 4), Quadric::ZERO);
        // 5 into 4, then 4 into 2: the border plane now joins nothing (one vertex),
        // the segment 2–4 neither; 0–2 stays.
        e.contract(4, 5, std::iter::empty());
        e.contract(2, 4, std::iter::empty());
        e.start_pass();
        assert_eq!(e.segments.len(), 1);
        assert_eq!(e.segments_between(&faces, 0, 2), face(0));
        // Then 2 into 0: nothing left.
        e.contract(0, 2, std::iter::empty());
        e.start_pass();
        assert!(e.segments.is_empty());
    }
}
