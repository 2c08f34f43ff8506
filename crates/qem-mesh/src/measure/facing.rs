//! The facing-away search of the orientation check: is there a triangle within a
//! radius of a point whose normal turns 90° or more from a given direction?
//!
//! It runs for every face a contraction moves (about 7 times per contraction on the
//! Stanford dragon) and almost always answers no: near the point every normal agrees
//! with the direction, so the search ends above the leaves, pruning whole subtrees by
//! the box of their normals that each node of the [`TriangleBvh`] keeps. What it costs
//! is the descent from the root, about 30 box tests per query, four at a time.
//!
//! Why `f32` cannot change an answer: every box is rounded outward, the query is a
//! cube around the ball (widened before it is rounded), and a subtree is skipped for
//! its normals only with a margin far above `f32` rounding. So the walk opens every
//! node an exact test would open (and perhaps a few more); the answer is decided at
//! the leaves, by the exact `f64` test on the triangles.

use super::bvh::{NodeStack, WideNode, NORMAL_STEPS, PRUNE_FACTOR, WIDTH};
use super::{cross, dot, length, sub, triangle_distance2, TriangleBvh, P3};

/// How far above zero the `f32` lower bound of a dot product of unit vectors must be
/// before a whole subtree counts as facing the same way. The rounding of the unit
/// normals to `f32`, of the boxes' steps back to `f32` (1/127 times a step count: one
/// rounding, below 1e-7) and of the three products and two sums is below 1e-6; the
/// margin is ten times that, so rounding never hides a triangle at right angles.
const FACING_MARGIN: f32 = 1e-5;

/// The shortest raw normal (of a query or of a triangle) that may skip a subtree by the
/// normal boxes. Why a floor: the leaves ask the sign of the raw dot product, which
/// underflows to 0 (counted as facing away) when both normals are tiny, even where the
/// unit normals agree; with both at least this long and the unit dot product above
/// [`FACING_MARGIN`], the raw one is at least 1e-205, far from underflow. (The
/// simplifier never asks about such faces: it refuses near-zero-area faces first.)
pub(super) const MIN_PRUNING_LENGTH: f64 = 1e-100;

/// The relative widening of the query cube before it is rounded to `f32`: 16 times
/// the conversion's rounding (2^-24), so the `f32` cube always holds the `f64` one.
const CUBE_WIDENING: f64 = 1e-6;

impl TriangleBvh {
    /// Whether some triangle within `radius` of `p` faces away from `normal`: its normal
    /// has a dot product ≤ 0 with `normal` (zero-area triangles excepted). A subtree
    /// whose normals all face the same way as `normal` is skipped whole, so on a smooth
    /// patch the search ends well above the leaves.
    ///
    /// May also answer true for a triangle a rounding error beyond `radius` (the box
    /// tests are widened, never narrowed); never answers false wrongly.
    pub fn any_facing_away(&self, p: [f64; 3], radius: f64, normal: [f64; 3]) -> bool {
        if self.corners.is_empty() {
            return false;
        }
        // A point that is not finite has no triangle within any finite distance (every
        // distance to it is infinite or NaN, and NaN is never "within").
        if !p.iter().all(|x| x.is_finite()) {
            return false;
        }
        let radius2 = radius * radius * PRUNE_FACTOR + self.slack2;
        // The cube around the ball, widened before it is rounded to f32: by far more
        // than the rounding of the f64 sums and of the conversion (each at most 2^-24
        // of |x| + reach), plus an absolute bit for a cube around 0. (A NaN radius
        // gives a NaN cube, which opens every child, see `open`; the leaves' exact
        // test then finds no triangle within a NaN distance.)
        let reach = radius2.sqrt();
        let widen = |x: f64| (x.abs() + reach) * CUBE_WIDENING + f64::from(f32::MIN_POSITIVE);
        // Relative to the boxes' origin (the leaves below take `p` itself); the
        // difference's rounding is far below `reach`, which holds `slack2`.
        let boxed = self.relative(p);
        let cube_lo = boxed.map(|x| (x - reach - widen(x)) as f32);
        let cube_hi = boxed.map(|x| (x + reach + widen(x)) as f32);
        let unit = unit_direction(normal);
        let mut stack = NodeStack::with(0u32);
        while let Some(w) = stack.pop() {
            let node = &self.nodes[w as usize];
            let mut open = node.open(cube_lo, cube_hi, unit);
            while open != 0 {
                let i = open.trailing_zeros() as usize;
                open &= open - 1;
                let count = node.leaf_count[i] as usize;
                if count == 0 {
                    stack.push(node.child[i]);
                    continue;
                }
                let start = node.child[i] as usize;
                for entry in start..start + count {
                    let [a, b, c] = self.corners.get(self.triangle_of(entry));
                    let t = cross(sub(b, a), sub(c, a));
                    // "Not positive", NaN included, exactly as the caller's full test
                    // asks it (a zero normal has no say there either).
                    let d = dot(t, normal);
                    if (d <= 0.0 || d.is_nan())
                        && t != [0.0; 3]
                        && triangle_distance2(p, a, b, c) <= radius2
                    {
                        return true;
                    }
                }
            }
        }
        false
    }
}

impl WideNode {
    /// Which children the walk must open, as a bit mask (bit `i`: child `i`): their
    /// position box meets the cube and (given a direction) not all of their normals
    /// face its way. Never a child with no normals (only zero-area triangles, which
    /// never face away) or an unused one.
    ///
    /// Written lane by lane over plain arrays, in arithmetic rather than `&&`: how far
    /// each box is from the cube along each axis (positive: apart), the largest of the
    /// six, then one comparison per lane, which the compiler turns into four-lane
    /// instructions. (`x - y ≤ 0` exactly when `x ≤ y`: subtraction is exact in sign,
    /// gradual underflow included. A NaN gap — `∞ − ∞` from an infinite cube against
    /// an unused child's empty box or a box beyond `f32`'s range, or a NaN cube — loses
    /// every comparison, so it never counts as apart: such a child is opened, which is
    /// always safe, and the lane mask closes unused ones.)
    // Lane loops: the index form is the one that reads as lanes and vectorises.
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    fn open(&self, cube_lo: [f32; 3], cube_hi: [f32; 3], unit: Option<[f32; 3]>) -> u32 {
        let mut apart = [f32::NEG_INFINITY; WIDTH];
        for k in 0..3 {
            for i in 0..WIDTH {
                let above = self.lo[k][i] - cube_hi[k];
                let below = cube_lo[k] - self.hi[k][i];
                let gap = if above > below { above } else { below };
                apart[i] = if gap > apart[i] { gap } else { apart[i] };
            }
        }
        let mut least = [f32::NEG_INFINITY; WIDTH];
        if let Some(u) = unit {
            least = [0.0; WIDTH];
            for k in 0..3 {
                for i in 0..WIDTH {
                    let steps = if u[k] >= 0.0 {
                        self.normal_lo[k][i]
                    } else {
                        self.normal_hi[k][i]
                    };
                    least[i] += u[k] * (f32::from(steps) / NORMAL_STEPS);
                }
            }
        }
        let mut mask = 0;
        for i in 0..WIDTH {
            // An empty normal box (zero-area triangles only) has nothing to say; its
            // bounds cross, so it is told apart first.
            let all_face =
                (self.normal_lo[0][i] > self.normal_hi[0][i]) | (least[i] > FACING_MARGIN);
            mask |= u32::from((apart[i] <= 0.0) & !all_face) << i;
        }
        mask & ((1 << self.lanes) - 1)
    }
}

/// `v` scaled to unit length in `f32`, or `None` when its length is NaN, infinite or
/// below [`MIN_PRUNING_LENGTH`] (such a direction is never known to agree with a box
/// of normals, so no subtree is skipped for it).
fn unit_direction(v: P3) -> Option<[f32; 3]> {
    let length = length(v);
    (length >= MIN_PRUNING_LENGTH && length.is_finite()).then(|| v.map(|x| (x / length) as f32))
}

#[cfg(test)]
mod tests {
    use super::super::bvh::{Box32, NormalBox};
    use super::*;

    /// Unused children, and children with no normals, are never opened; any other is
    /// opened exactly when it meets the cube and may face away.
    #[test]
    fn children_open_only_when_they_meet_the_cube_and_may_face_away() {
        let mut node =
            TriangleBvh::from_corners(vec![[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]])
                .0
                .nodes[0]
                .clone();
        let unit_box = Box32::around([0.0; 3], [1.0; 3]);
        // Child 0: normals around +z only; child 1: normals every way; child 2: no
        // normals (zero-area triangles only); child 3 unused (but with boxes set).
        let normals = |lo, hi| NormalBox::around(&Box32::around(lo, hi));
        node.set_child(0, &unit_box, &normals([-0.1, -0.1, 0.9], [0.1, 0.1, 1.0]));
        node.set_child(1, &unit_box, &normals([-1.0; 3], [1.0; 3]));
        node.set_child(2, &unit_box, &NormalBox::EMPTY);
        node.set_child(3, &unit_box, &normals([-1.0; 3], [1.0; 3]));
        node.lanes = 3;
        let inside = ([0.4f32; 3], [0.6f32; 3]);
        let outside = ([2.0f32; 3], [3.0f32; 3]);
        assert_eq!(node.open(inside.0, inside.1, Some([0.0, 0.0, 1.0])), 0b0010);
        assert_eq!(
            node.open(inside.0, inside.1, Some([0.0, 0.0, -1.0])),
            0b0011
        );
        // Without a direction, only the child of zero-area triangles stays closed
        // (they can never face away).
        assert_eq!(node.open(inside.0, inside.1, None), 0b0011);
        assert_eq!(node.open(outside.0, outside.1, Some([0.0, 0.0, -1.0])), 0);
        // Touching counts as meeting.
        assert_eq!(node.open([1.0; 3], [2.0; 3], None), 0b0011);
        // An infinite cube meets every box, yet the unused child stays closed.
        let everywhere = ([f32::NEG_INFINITY; 3], [f32::INFINITY; 3]);
        assert_eq!(node.open(everywhere.0, everywhere.1, None), 0b0011);
    }
}
