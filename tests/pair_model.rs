//! The documented rule of [`virtual_pairs`](qem_mesh::pairs::virtual_pairs), computed by
//! brute force over all pairs of points. Used by the `grid_pairs` property test and the
//! `grid_pairs` fuzz target, so both compare the grid with the same reference.

use qem_mesh::pairs::VirtualPairs;

/// Every pair `(i, j)`, `i < j`, of `points` closer than `t` (squared distance below
/// `t * t`) with `allowed(i, j)`, kept when it is among the `k` nearest allowed
/// candidates of `i` or of `j` (ties broken by the lower index); `capped` counts the
/// close allowed pairs left out. O(n²) distance tests and O(n² log n) sorting.
pub fn brute_force_pairs(
    points: &[[f64; 3]],
    t: f64,
    k: usize,
    allowed: impl Fn(u32, u32) -> bool,
) -> VirtualPairs {
    if !(t > 0.0 && t.is_finite()) || k == 0 {
        return VirtualPairs::default();
    }
    let n = points.len() as u32;
    let d2 = |i: u32, j: u32| {
        let (p, q) = (points[i as usize], points[j as usize]);
        (0..3).map(|a| (p[a] - q[a]) * (p[a] - q[a])).sum::<f64>()
    };
    let close = |i: u32, j: u32| i != j && d2(i, j) < t * t && allowed(i.min(j), i.max(j));
    let nearest_of = |i: u32| {
        let mut c: Vec<(f64, u32)> = (0..n)
            .filter(|&j| close(i, j))
            .map(|j| (d2(i, j), j))
            .collect();
        c.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        c.truncate(k);
        c.into_iter().map(|(_, j)| j).collect::<Vec<_>>()
    };
    let lists: Vec<Vec<u32>> = (0..n).map(nearest_of).collect();
    let mut pairs = Vec::new();
    let mut total = 0;
    for i in 0..n {
        for j in i + 1..n {
            if close(i, j) {
                total += 1;
                if lists[i as usize].contains(&j) || lists[j as usize].contains(&i) {
                    pairs.push((i, j));
                }
            }
        }
    }
    VirtualPairs {
        capped: total - pairs.len(),
        pairs,
    }
}
