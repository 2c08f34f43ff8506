//! Virtual pairs from a uniform spatial grid of cell size t.
//!
//! Every point goes into the cell `floor(p / s)` with `s` slightly larger than `t`
//! (so that rounding in the division can never put two points closer than `t` more
//! than one cell apart). Pairs closer than `t` are then in the same or adjacent cells:
//! each point looks at 27 cells. Cells live in a sorted vector, not a dense array (whose
//! size would follow the bounding box, not the point count) nor a hash map (whose
//! iteration order would make results depend on hashing).
//!
//! Cost: O(n log n) for the sort plus the number of points in neighbouring cells. For a
//! mesh-like point set and a small t that is near linear. A t comparable to the whole
//! model puts every point in a few cells and costs O(n²) distance tests; the per-vertex
//! cap bounds the output (at most n·k pairs) but not those tests.

use rayon::prelude::*;

/// Why 1e-9: the cell coordinate `p / s` is rounded to within a few ulps (relative
/// 1e-16 each); enlarging the cell by 1e-9 keeps two points closer than `t` at most one
/// cell apart with a margin of many orders of magnitude, while adding a negligible
/// number of extra distance tests.
const CELL_MARGIN: f64 = 1e-9;

/// Options of the virtual-pair search.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct GridOptions {
    /// Pairs at distance strictly less than this are found. Zero, negative or
    /// non-finite means none. No default: it is the argument of [`GridOptions::new`].
    pub threshold: f64,
    /// Keep a pair only if it is among the `max_per_vertex` nearest candidates of at
    /// least one of its two points (ties broken by the lower index). Default:
    /// `usize::MAX` (no cap).
    pub max_per_vertex: usize,
}

impl GridOptions {
    /// Pairs closer than `threshold`, with no cap.
    pub fn new(threshold: f64) -> Self {
        Self {
            threshold,
            max_per_vertex: usize::MAX,
        }
    }

    /// Sets [`max_per_vertex`](Self::max_per_vertex).
    pub fn with_max_per_vertex(mut self, k: usize) -> Self {
        self.max_per_vertex = k;
        self
    }
}

/// The pairs found.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct VirtualPairs {
    /// Pairs `(i, j)` with `i < j`, sorted, without duplicates.
    pub pairs: Vec<(u32, u32)>,
    /// Allowed pairs closer than the threshold that the cap left out.
    pub capped: usize,
}

/// Every pair of `points` closer than the threshold for which `allowed(i, j)` (called
/// with `i < j`, possibly more than once per pair and from several threads) is true,
/// subject to the cap. Points must be finite. The work is shared among rayon's
/// threads; the result does not depend on their number.
///
/// ```
/// use qem_mesh::pairs::{virtual_pairs, GridOptions};
/// let points = [[0.0, 0.0, 0.0], [0.05, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.09, 0.0]];
/// let found = virtual_pairs(&points, &GridOptions::new(0.1), |_, _| true);
/// assert_eq!(found.pairs, vec![(0, 1), (0, 3)]);
/// // (1, 3) is 0.103 apart: not closer than 0.1.
/// ```
pub fn virtual_pairs(
    points: &[[f64; 3]],
    options: &GridOptions,
    allowed: impl Fn(u32, u32) -> bool + Sync,
) -> VirtualPairs {
    let t = options.threshold;
    if !(t > 0.0 && t.is_finite()) || options.max_per_vertex == 0 || points.len() < 2 {
        return VirtualPairs::default();
    }
    let size = t * (1.0 + CELL_MARGIN);
    // `as i64` saturates, so far-away points share the extreme cells: more tests, never
    // a wrong answer, because every candidate is checked by its true distance.
    let cell_of = |p: &[f64; 3]| p.map(|c| (c / size).floor() as i64);
    // (cell, index) pairs are distinct: the parallel unstable sort has one result.
    let mut sorted: Vec<([i64; 3], u32)> = points
        .par_iter()
        .enumerate()
        .map(|(i, p)| (cell_of(p), i as u32))
        .collect();
    sorted.par_sort_unstable();

    let t2 = t * t;
    let k = options.max_per_vertex;
    // Each point gathers its own nearest allowed candidates (distance², other index),
    // at most k, looking at every partner on both sides. A pair is thus examined from
    // both ends — twice the distance tests of a one-sided scan — but every point is
    // independent, so the points are shared among threads and the lists do not depend
    // on how. `total` counts each allowed close pair once, from its lower index.
    let per_point: Vec<_> = sorted
        .par_iter()
        .map(|&(cell, i)| {
            let p = points[i as usize];
            let mut list = Vec::new();
            let mut above = 0usize;
            for key in neighbour_cells(cell) {
                let start = sorted.partition_point(|(c, _)| *c < key);
                for (c, j) in &sorted[start..] {
                    if *c != key {
                        break;
                    }
                    if *j == i {
                        continue;
                    }
                    let d2 = squared_distance(p, points[*j as usize]);
                    if d2 < t2 && allowed(i.min(*j), i.max(*j)) {
                        above += usize::from(*j > i);
                        offer(&mut list, (d2, *j), k);
                    }
                }
            }
            (i, list, above)
        })
        .collect();
    let total: usize = per_point.iter().map(|(_, _, above)| above).sum();
    let mut pairs: Vec<(u32, u32)> = per_point
        .iter()
        .flat_map(|(i, list, _)| list.iter().map(move |&(_, j)| ((*i).min(j), (*i).max(j))))
        .collect();
    pairs.par_sort_unstable();
    pairs.dedup();
    let capped = total - pairs.len();
    VirtualPairs { pairs, capped }
}

/// The cells around `cell` (itself included): 27, fewer at the edges of i64, where
/// offsets that would leave the range are skipped. Why not saturate: a saturated
/// offset repeats the edge cell, which then was visited twice, so each pair in it was
/// counted twice and offered twice to the nearest-k lists, crowding out others (a
/// `grid_pairs` fuzz finding). Points beyond the range all share the edge cell, so
/// skipping loses nothing.
pub(crate) fn neighbour_cells(cell: [i64; 3]) -> impl Iterator<Item = [i64; 3]> {
    let around = |c: i64| (-1..=1i64).filter_map(move |d| c.checked_add(d));
    around(cell[0]).flat_map(move |x| {
        around(cell[1]).flat_map(move |y| around(cell[2]).map(move |z| [x, y, z]))
    })
}

/// Squared Euclidean distance.
pub(crate) fn squared_distance(p: [f64; 3], q: [f64; 3]) -> f64 {
    (0..3).map(|a| (p[a] - q[a]) * (p[a] - q[a])).sum()
}

/// Inserts `candidate` into `list`, kept sorted by (distance², index) and at most `k`
/// long.
fn offer(list: &mut Vec<(f64, u32)>, candidate: (f64, u32), k: usize) {
    let before = |a: &(f64, u32), b: &(f64, u32)| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1));
    let at = list.partition_point(|x| before(x, &candidate).is_lt());
    if at < k {
        list.insert(at, candidate);
        list.truncate(k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // The comparison with a brute-force reference, over random points, is in the
    // workspace tests crate (`tests/tests/suite/grid_pairs.rs`), shared with the fuzz target.

    #[test]
    fn no_threshold_no_pairs() {
        let p = [[0.0; 3], [0.0; 3]];
        for t in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(
                virtual_pairs(&p, &GridOptions::new(t), |_, _| true),
                VirtualPairs::default()
            );
        }
    }

    #[test]
    fn coincident_points_all_pair_up_to_the_cap() {
        let p = vec![[3.0; 3]; 6];
        let all = virtual_pairs(&p, &GridOptions::new(1e-12), |_, _| true);
        assert_eq!(all.pairs.len(), 15);
        let capped = virtual_pairs(
            &p,
            &GridOptions::new(1e-12).with_max_per_vertex(1),
            |_, _| true,
        );
        // Every point's nearest is the lowest other index (all distances tie): 0 for
        // points 1..5, and 1 for point 0.
        assert_eq!(capped.pairs, vec![(0, 1), (0, 2), (0, 3), (0, 4), (0, 5)]);
        assert_eq!(capped.capped, 10);
    }

    #[test]
    fn extreme_scales_do_not_panic() {
        let p = [[1e30, -1e30, 0.0], [1e30, -1e30, 1e-30], [-1e30, 1e30, 5.0]];
        // Cell coordinates saturate at i64::MAX here; the true distances still decide.
        let tiny = virtual_pairs(&p, &GridOptions::new(1e-29), |_, _| true);
        assert_eq!(tiny.pairs, vec![(0, 1)]);
        let huge = virtual_pairs(&p, &GridOptions::new(1e300), |_, _| true);
        assert_eq!(huge.pairs, vec![(0, 1), (0, 2), (1, 2)]);
    }
}
