//! [`CornerStore`]: the corners of an index's triangles, each point kept once.

use super::P3;
use rayon::prelude::*;

/// Not yet numbered, in [`CornerStore::gather`]'s renumbering.
const UNNUMBERED: u32 = u32::MAX;

/// The corners of the indexed triangles: each triangle as the numbers of its three
/// points, each point stored once.
///
/// Why not three corners per triangle: a closed mesh has about half as many vertices
/// as triangles, so corners repeated per triangle cost 72 bytes a triangle where the
/// numbers (12) and the shared points (about 12 a triangle) cost 24; on a 4M-triangle
/// mesh that was 192 MB more, the largest single item of the simplifier's peak (its
/// orientation check holds an index of the input for the whole run). The answers are
/// the same: a corner is the same point, bit for bit, whichever way it is stored.
///
/// Points are numbered in the order the triangles (in leaf order) first meet them, so
/// that the points of a leaf lie together in memory, as its corners did before.
#[derive(Clone, Debug)]
pub(super) struct CornerStore {
    triangles: Vec<[u32; 3]>,
    points: Vec<P3>,
}

impl CornerStore {
    /// The triangles `order` names, in that order: triangle `t` is made of points
    /// `points_of(t)` (each below `point_count`), point `v` being `point(v)`.
    ///
    /// `point` is asked once per point (from several threads); the numbering is done
    /// in one pass on one core, which keeps it the same with any number of threads.
    pub fn gather(
        order: impl ExactSizeIterator<Item = usize>,
        point_count: usize,
        points_of: impl Fn(usize) -> [u32; 3],
        point: impl Fn(u32) -> P3 + Sync,
    ) -> CornerStore {
        let mut number = vec![UNNUMBERED; point_count];
        // `old[n]`: the point given number n (at most every point, so sized once).
        let mut old: Vec<u32> = Vec::with_capacity(point_count.min(order.len() * 3));
        let mut triangles = Vec::with_capacity(order.len());
        for t in order {
            triangles.push(points_of(t).map(|v| {
                let slot = &mut number[v as usize];
                if *slot == UNNUMBERED {
                    // (Callers number at most u32::MAX / 3 triangles' points.)
                    debug_assert!(old.len() < UNNUMBERED as usize);
                    *slot = old.len() as u32;
                    old.push(v);
                }
                *slot
            }));
        }
        drop(number);
        let points = old.par_iter().map(|&v| point(v)).collect();
        CornerStore { triangles, points }
    }

    /// The corners of triangle `t`.
    #[inline(always)]
    pub fn get(&self, t: usize) -> [P3; 3] {
        self.triangles[t].map(|v| self.points[v as usize])
    }

    /// The corners of triangle `t`, `None` when there is no such triangle.
    #[inline]
    pub fn checked(&self, t: usize) -> Option<[P3; 3]> {
        let [a, b, c] = *self.triangles.get(t)?;
        Some([a, b, c].map(|v| self.points[v as usize]))
    }

    /// How many triangles there are.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_points_are_kept_once_and_numbered_as_first_met() {
        let points: [P3; 4] = [[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.5]];
        let triangles = [[0u32, 1, 2], [1, 3, 2]];
        let store = CornerStore::gather(
            [1, 0].into_iter(),
            4,
            |t| triangles[t],
            |v| points[v as usize],
        );
        assert_eq!(store.len(), 2);
        assert_eq!(store.points.len(), 4);
        // Triangle 1 comes first, so its points are numbered 0, 1, 2.
        assert_eq!(store.triangles, vec![[0, 1, 2], [3, 0, 2]]);
        assert_eq!(store.get(0), [points[1], points[3], points[2]]);
        assert_eq!(store.get(1), [points[0], points[1], points[2]]);
        assert_eq!(store.checked(1), Some(store.get(1)));
        assert_eq!(store.checked(2), None);
    }
}
