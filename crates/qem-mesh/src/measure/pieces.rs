//! Long thin triangles cut into pieces for the [`TriangleBvh`](super::TriangleBvh):
//! how many pieces each triangle gets, and the box of each piece.
//!
//! Why: a box tree is only as good as its boxes, and the box of a long triangle that
//! runs across the axes is mostly empty. CAD exports are full of them (a fan of
//! slivers from one vertex across an end face, walls one triangle high along a
//! diagonal), and every query near any part of such a box must open it. On
//! `mf_generic_twin_7081_left` (19,704 triangles, a fifth of them up to 4,700 units long
//! and 10 wide), the orientation check's facing-away search tested about 2,900
//! triangles per query, most of them in leaves that a sliver's box had stretched over
//! the query point; the simplification took about 7.3 s with the check (2.9 s with
//! pieces of a sixty-fourth of the diagonal, 4.1 s on a later build; 1.6 s with pieces
//! down to a thousandth, [`FINEST_FRACTION`]) and 0.08 s without.
//!
//! The cure is the one of Ernst and Greiner's early split clipping ("Early Split
//! Clipping for Bounding Volume Hierarchies", IEEE Symposium on Interactive Ray
//! Tracing 2007): the tree is built over pieces rather than whole triangles, a piece
//! being the part of a triangle within one slab of its box (equal slabs across the
//! box's longest axis), with the box of that part. A triangle is then found through
//! any of its pieces; the queries test whole triangles, so their answers do not
//! change.
//!
//! Which triangles: those whose box is both much larger than the triangle
//! ([`THIN_RATIO`]) and large against the whole mesh ([`PIECE_FRACTION`]). Why against
//! the mesh and not against its typical triangle: in a fan-capped cylinder or a cone,
//! half the triangles or all of them are the long thin ones. Ordinary meshes (scans,
//! fine CAD) have none, and their tree is the one built without pieces, bit for bit.

use super::{cross, length, sub, P3};
use rayon::prelude::*;

/// A triangle is cut only when the half surface of its box (the sum of the areas of
/// the box's three faces) is at least this many times its own area, per piece. Why
/// 8: a triangle across all three axes at 45° has a ratio of about 3.5, and cutting it
/// gains nothing; a sliver ten times longer than wide, laid diagonally, has about 10.
pub(super) const THIN_RATIO: f64 = 8.0;

/// Only a triangle whose box reaches more than about this fraction of the mesh's
/// diagonal (its box's half surface above the square of that) is cut, which no
/// triangle of a scan of more than a few thousand triangles is.
const PIECE_FRACTION: f64 = 1.0 / 64.0;

/// A triangle that is cut is cut into pieces that reach about this fraction of the
/// diagonal (their boxes' half surfaces about the square of that), or fewer when
/// [`THIN_RATIO`] asks for fewer.
///
/// Why so fine: the facing-away search's ball is far smaller than the triangles cut.
/// On `mf_generic_twin_7081_left` at ratio 0.1 it averaged 1.7e-4 of the diagonal
/// (2.9 units); with pieces of a sixty-fourth (265 units) a search still tested about
/// 1,285 leaf entries, most of them slivers facing away beyond the ball, and 274 with
/// pieces of a thousandth. The simplification took 4.1 s, then 1.6 s (the same output);
/// a 4,096th gained nothing more. The pieces count against the budget
/// ([`PIECES_PER_TRIANGLE`], [`EXTRA_PIECES`]).
const FINEST_FRACTION: f64 = 1.0 / 1024.0;

/// At most this many pieces per triangle (it fits the `u8` counts).
pub(super) const MAX_PIECES: usize = 255;

/// At most this many pieces in all, per triangle of the mesh: the memory bound. Each
/// piece costs a leaf entry (4 bytes) and a share of the nodes (about 18 bytes); if
/// the triangles ask for more, the largest counts are capped. Why 4: in a cylinder with
/// fan caps, half the triangles are slivers across the caps, and 7 pieces each (the
/// cap this gives) cut the box overlap near the rim about 7 times.
const PIECES_PER_TRIANGLE: usize = 4;

/// Pieces allowed beyond [`PIECES_PER_TRIANGLE`] a triangle, whatever the mesh's size:
/// at most about 23 MB more, where a small CAD mesh asks for many (the twin above
/// asks for about a million: with a quarter of that allowed, 3.0 s instead of 1.6 s).
const EXTRA_PIECES: usize = 1 << 20;

/// The half surface of the box of `corners` (0 for a point). `f64::min` and `max`
/// pass NaN over, so a NaN corner does not make it NaN: callers check the corners.
fn half_surface(corners: &[P3; 3]) -> f64 {
    let extent = box_extent(corners);
    extent[0] * extent[1] + extent[1] * extent[2] + extent[2] * extent[0]
}

fn box_extent(corners: &[P3; 3]) -> P3 {
    [0, 1, 2].map(|k| {
        let (a, b, c) = (corners[0][k], corners[1][k], corners[2][k]);
        a.max(b).max(c) - a.min(b).min(c)
    })
}

/// How many pieces each of the `n` triangles (triangle `t` has corners
/// `corners_of(t)`) is cut into (1: whole); `None` when no triangle is cut, which is
/// the common case. `diagonal` is the length of the diagonal of the box of all the
/// corners. Deterministic: a function of the corners alone.
pub(super) fn piece_counts(
    n: usize,
    corners_of: &(impl Fn(usize) -> [P3; 3] + Sync),
    diagonal: f64,
) -> Option<Vec<u8>> {
    // The pieces are numbered with u32 too (see `TriangleBvh::from_corners`).
    if n < 2 || n.saturating_mul(PIECES_PER_TRIANGLE) > u32::MAX as usize {
        return None;
    }
    // A triangle whose box is larger than `largest` is cut, into pieces of about
    // `finest` (by half surface).
    let largest = (diagonal * PIECE_FRACTION).powi(2);
    let finest = (diagonal * FINEST_FRACTION).powi(2);
    if !largest.is_finite() || largest <= 0.0 || finest <= 0.0 {
        return None;
    }
    let counts: Vec<u8> = (0..n)
        .into_par_iter()
        .map(|t| wanted_pieces(&corners_of(t), largest, finest))
        .collect();
    let wanted: usize = counts.iter().map(|&k| usize::from(k)).sum();
    if wanted == n {
        return None;
    }
    Some(within_budget(
        counts,
        n * PIECES_PER_TRIANGLE + EXTRA_PIECES,
    ))
}

/// The pieces `corners` asks for: none (1) when its box is within `largest`; else
/// enough that each piece's box is within [`THIN_RATIO`] of its area and within
/// `finest`, whichever needs fewer (cutting into `k` slabs shrinks each piece's box
/// about `k²` times and its area `k` times).
fn wanted_pieces(corners: &[P3; 3], largest: f64, finest: f64) -> u8 {
    // A triangle with a NaN or infinite corner stays whole: the searches never find it,
    // and pieces would only spend the budget (and could move a mesh off the whole-
    // triangle build for one bad triangle).
    if !corners.iter().flatten().all(|x| x.is_finite()) {
        return 1;
    }
    let box_area = half_surface(corners);
    if !box_area.is_finite() || box_area <= largest {
        return 1;
    }
    let [a, b, c] = *corners;
    let area = 0.5 * length(cross(sub(b, a), sub(c, a)));
    let by_shape = box_area / (THIN_RATIO * area);
    let by_size = (box_area / finest).sqrt();
    // A zero-area triangle (a needle) gives an infinite shape count: its size decides.
    let k = by_shape.min(by_size).floor();
    if k >= 2.0 {
        k.min(MAX_PIECES as f64) as u8
    } else {
        1
    }
}

/// `counts` with its largest values lowered to one cap, the highest that keeps the sum
/// within `budget` (which is at least the number of triangles).
fn within_budget(mut counts: Vec<u8>, budget: usize) -> Vec<u8> {
    let mut how_many = [0usize; MAX_PIECES + 1];
    for &k in &counts {
        how_many[usize::from(k)] += 1;
    }
    let total_under = |cap: usize| -> usize {
        how_many
            .iter()
            .enumerate()
            .map(|(k, &n)| k.min(cap) * n)
            .sum()
    };
    let cap = (1..=MAX_PIECES)
        .rev()
        .find(|&cap| total_under(cap) <= budget)
        .unwrap_or(1);
    for k in &mut counts {
        *k = (*k).min(cap as u8);
    }
    counts
}

/// The axis a triangle is cut across: the longest of its box (the first of equals).
fn cut_axis(corners: &[P3; 3]) -> usize {
    let e = box_extent(corners);
    if e[0] >= e[1] && e[0] >= e[2] {
        0
    } else if e[1] >= e[2] {
        1
    } else {
        2
    }
}

/// The bounds of slab `j` of `k` along the triangle's cut axis: the same expression
/// for the end of one slab and the start of the next, so the slabs tile the box
/// without a gap, and the first and last end exactly on the box.
fn slab(lo: f64, hi: f64, j: usize, k: usize) -> (f64, f64) {
    let at = |i: usize| {
        if i == 0 {
            lo
        } else if i == k {
            hi
        } else {
            lo + (hi - lo) * (i as f64 / k as f64)
        }
    };
    (at(j), at(j + 1))
}

/// The box of piece `j` of `k` of the triangle: the part of the triangle within the
/// slab, its box widened by far more than the rounding of the points where the edges
/// cross the slab's planes, and never beyond the triangle's own box. Every point of the
/// triangle lies in some piece's box (the slabs tile the triangle's box).
pub(super) fn piece_box(corners: &[P3; 3], j: usize, k: usize) -> (P3, P3) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    let mut grow = |p: P3| {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    };
    let whole_lo = [0, 1, 2].map(|i| corners.iter().map(|c| c[i]).fold(f64::INFINITY, f64::min));
    let whole_hi = [0, 1, 2].map(|i| {
        corners
            .iter()
            .map(|c| c[i])
            .fold(f64::NEG_INFINITY, f64::max)
    });
    if k <= 1 {
        return (whole_lo, whole_hi);
    }
    let axis = cut_axis(corners);
    let (s0, s1) = slab(whole_lo[axis], whole_hi[axis], j, k);
    for c in corners {
        if s0 <= c[axis] && c[axis] <= s1 {
            grow(*c);
        }
    }
    for (p, q) in [(0, 1), (1, 2), (2, 0)] {
        let (p, q) = (corners[p], corners[q]);
        let (low, high) = (p[axis].min(q[axis]), p[axis].max(q[axis]));
        for s in [s0, s1] {
            if low < s && s < high {
                let t = (s - p[axis]) / (q[axis] - p[axis]);
                let mut x = [0, 1, 2].map(|i| p[i] + t * (q[i] - p[i]));
                x[axis] = s;
                grow(x);
            }
        }
    }
    for i in 0..3 {
        if i == axis {
            // The slab's own bounds are exact: no rounding to cover.
            lo[i] = lo[i].max(s0);
            hi[i] = hi[i].min(s1);
            continue;
        }
        // The crossing points are off by a few units in the last place of the larger
        // corner coordinate (so by an amount that grows with the distance from the
        // origin, not with the triangle's size); 1e-12 of the triangle's reach covers
        // that many times over.
        let reach = whole_lo[i].abs().max(whole_hi[i].abs());
        let widen = reach * 1e-12 + f64::MIN_POSITIVE;
        lo[i] = (lo[i] - widen).max(whole_lo[i]);
        hi[i] = (hi[i] + widen).min(whole_hi[i]);
    }
    (lo, hi)
}

/// The point a piece is sorted by when the tree is built: the centre of its box.
pub(super) fn piece_centre(corners: &[P3; 3], j: usize, k: usize) -> P3 {
    let (lo, hi) = piece_box(corners, j, k);
    [0, 1, 2].map(|i| 0.5 * (lo[i] + hi[i]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A diagonal sliver is cut; a fat triangle and a small sliver are not.
    #[test]
    fn only_large_thin_triangles_are_cut() {
        let mut corners: Vec<[P3; 3]> = (0..100)
            .map(|i| {
                let x = f64::from(i);
                [[x, 0.0, 0.0], [x + 1.0, 0.0, 0.0], [x, 1.0, 0.0]]
            })
            .collect();
        // 100 long and 0.01 wide, along the diagonal of the x-y plane.
        corners.push([[0.0, 0.0, 1.0], [70.0, 70.0, 1.0], [70.0, 70.01, 1.0]]);
        // As thin, but only 1 long: no larger than the others.
        corners.push([[0.0, 0.0, 2.0], [0.7, 0.7, 2.0], [0.7, 0.71, 2.0]]);
        let diagonal = (101f64.powi(2) + 70.01f64.powi(2) + 4.0).sqrt();
        let counts_of =
            |corners: &[[P3; 3]]| piece_counts(corners.len(), &|t| corners[t], diagonal);
        let counts = counts_of(&corners).expect("the long sliver is cut");
        assert!(counts[..100].iter().all(|&k| k == 1));
        assert_eq!(counts[101], 1);
        // Cut down to about a thousandth of the diagonal (580 pieces), capped at
        // `MAX_PIECES`: more than the 4 a triangle of the budget's share, which
        // `EXTRA_PIECES` allows a small mesh.
        assert_eq!(usize::from(counts[100]), MAX_PIECES);
        // No thin triangle at all: nothing is cut.
        assert_eq!(counts_of(&corners[..100]), None);
        // The long sliver with a NaN corner stays whole.
        let mut with_nan = corners[..100].to_vec();
        with_nan.push([[f64::NAN, 0.0, 1.0], [70.0, 70.0, 1.0], [70.0, 70.01, 1.0]]);
        assert_eq!(counts_of(&with_nan), None);
    }

    /// The budget caps the largest counts and keeps the sum within it.
    #[test]
    fn the_budget_caps_the_largest_counts() {
        let counts = within_budget(vec![64, 64, 1, 1, 3, 1, 1, 1], 16);
        assert_eq!(counts, vec![4, 4, 1, 1, 3, 1, 1, 1]);
        assert_eq!(within_budget(vec![1, 2, 1], 4), vec![1, 2, 1]);
    }

    /// Neighbouring pieces meet exactly, and the points where the edges cross their
    /// common plane, however they are rounded, lie in both: near the origin and far
    /// from it.
    #[test]
    fn neighbouring_pieces_share_their_crossings() {
        for offset in [0.0, 1e6, -3e15] {
            let corners = [[0.1, -3.0, 0.2], [97.3, 51.7, 13.1], [97.2, 52.0, 13.0]]
                .map(|c| c.map(|x| x + offset));
            let axis = cut_axis(&corners);
            for k in [2, 7, 64] {
                let boxes: Vec<(P3, P3)> = (0..k).map(|j| piece_box(&corners, j, k)).collect();
                for j in 0..k - 1 {
                    let (_, hi) = boxes[j];
                    let (lo, _) = boxes[j + 1];
                    assert_eq!(hi[axis].to_bits(), lo[axis].to_bits(), "k {k}, j {j}");
                    let s = hi[axis];
                    for (p, q) in [(0, 1), (1, 2), (2, 0)] {
                        let (p, q) = (corners[p], corners[q]);
                        if !(p[axis].min(q[axis]) < s && s < p[axis].max(q[axis])) {
                            continue;
                        }
                        // The crossing from either end, plainly and fused.
                        for (a, b) in [(p, q), (q, p)] {
                            let t = (s - a[axis]) / (b[axis] - a[axis]);
                            for x in [
                                [0, 1, 2].map(|i| a[i] + t * (b[i] - a[i])),
                                [0, 1, 2].map(|i| t.mul_add(b[i] - a[i], a[i])),
                            ] {
                                for (lo, hi) in [boxes[j], boxes[j + 1]] {
                                    for i in (0..3).filter(|&i| i != axis) {
                                        assert!(
                                            lo[i] <= x[i] && x[i] <= hi[i],
                                            "offset {offset}, k {k}, j {j}, axis {i}"
                                        );
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    /// The pieces' boxes hold every point of the triangle, and each is much smaller
    /// than the whole box.
    #[test]
    fn pieces_cover_the_triangle() {
        let corners = [[0.1, -3.0, 0.2], [97.3, 51.7, 13.1], [97.2, 52.0, 13.0]];
        let k = 17;
        let boxes: Vec<(P3, P3)> = (0..k).map(|j| piece_box(&corners, j, k)).collect();
        let inside = |p: P3, (lo, hi): &(P3, P3)| (0..3).all(|i| lo[i] <= p[i] && p[i] <= hi[i]);
        let steps = 300;
        for u in 0..=steps {
            for v in 0..=steps - u {
                let (u, v) = (
                    f64::from(u) / f64::from(steps),
                    f64::from(v) / f64::from(steps),
                );
                let p = [0, 1, 2].map(|i| {
                    corners[0][i]
                        + u * (corners[1][i] - corners[0][i])
                        + v * (corners[2][i] - corners[0][i])
                });
                assert!(boxes.iter().any(|b| inside(p, b)), "{p:?} in no piece");
            }
        }
        for c in corners {
            assert!(boxes.iter().any(|b| inside(c, b)));
        }
        let whole = half_surface(&corners);
        for (lo, hi) in &boxes {
            let e = [0, 1, 2].map(|i| hi[i] - lo[i]);
            let piece = e[0] * e[1] + e[1] * e[2] + e[2] * e[0];
            assert!(piece < whole / 100.0, "{piece} of {whole}");
        }
    }
}
