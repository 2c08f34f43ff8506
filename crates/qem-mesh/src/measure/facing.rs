//! The facing-away search of the orientation check: is there a triangle within a
//! radius of a point whose normal turns 90° or more from a given direction?
//!
//! It runs for every face a contraction moves (about 7 times per contraction on the
//! Stanford dragon) and almost always answers no: near the point every normal agrees
//! with the direction, so the search ends above the leaves, pruning whole subtrees by a
//! box of their normals. What it costs is the descent from the root, about 30 box tests
//! per query. So it walks its own copy of the [`TriangleBvh`]'s boxes, laid out for that
//! walk: four children per node (two levels of the binary tree at once), each child's
//! position box and normal box side by side in `f32`, by axis, so that one node is four
//! cache lines and its four tests are the same instructions on four lanes.
//!
//! Why `f32` cannot change an answer: every box is rounded outward, the query is a
//! cube around the ball (rounded outward too), and a subtree is skipped for its
//! normals only with a margin far above `f32` rounding. So the walk opens every node
//! the exact test would open (and perhaps a few more); the answer is decided at the
//! leaves, by the exact `f64` test on the triangles.

use super::PRUNE_FACTOR;
use super::{cross, dot, length, sub, triangle_distance2, NodeStack, TriangleBvh, P3};

/// Children per node of the [`FacingTree`].
const WIDTH: usize = 4;

/// How far above zero the `f32` lower bound of a dot product of unit vectors must be
/// before a whole subtree counts as facing the same way. The rounding of the unit
/// normals to `f32` and of the three products and two sums is below 1e-6; the margin is
/// ten times that, so rounding never hides a triangle at right angles.
const FACING_MARGIN: f32 = 1e-5;

/// The relative widening of the query cube before it is rounded to `f32`: 16 times
/// the conversion's rounding (2^-24), so the `f32` cube always holds the `f64` one.
const CUBE_WIDENING: f64 = 1e-6;

/// `x` rounded to an `f32` at or below it (−∞ and +∞ stay).
fn f32_below(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x {
        step_toward_negative(f)
    } else {
        f
    }
}

/// `x` rounded to an `f32` at or above it.
fn f32_above(x: f64) -> f32 {
    -f32_below(-x)
}

/// The next `f32` below `f` (finite or +∞). (`f32::next_down` is newer than the
/// workspace's minimum Rust version.)
fn step_toward_negative(f: f32) -> f32 {
    if f == 0.0 {
        -f32::from_bits(1)
    } else if f > 0.0 {
        f32::from_bits(f.to_bits() - 1)
    } else {
        f32::from_bits(f.to_bits() + 1)
    }
}

/// An axis-aligned box in `f32`, rounded outward from `f64` bounds.
#[derive(Clone, Copy, Debug)]
struct Box32 {
    lo: [f32; 3],
    hi: [f32; 3],
}

impl Box32 {
    /// Contains nothing: every test against it fails, and growing it by a box gives
    /// that box.
    const EMPTY: Box32 = Box32 {
        lo: [f32::INFINITY; 3],
        hi: [f32::NEG_INFINITY; 3],
    };

    fn around(lo: P3, hi: P3) -> Box32 {
        Box32 {
            lo: lo.map(f32_below),
            hi: hi.map(f32_above),
        }
    }

    fn grow(&mut self, other: &Box32) {
        for k in 0..3 {
            self.lo[k] = self.lo[k].min(other.lo[k]);
            self.hi[k] = self.hi[k].max(other.hi[k]);
        }
    }
}

/// One node: its (up to) four children's boxes, by axis then child, so that each
/// test reads four adjacent lanes.
#[derive(Clone, Debug)]
struct WideNode {
    /// Position boxes: `lo[k][i]` is the least `k` coordinate under child `i`.
    lo: [[f32; WIDTH]; 3],
    hi: [[f32; WIDTH]; 3],
    /// Boxes of the unit normals under each child (empty when all its triangles have
    /// zero area: such a child never needs opening for its normals).
    normal_lo: [[f32; WIDTH]; 3],
    normal_hi: [[f32; WIDTH]; 3],
    /// An inner child: its node's index. A leaf child: the first of its triangles.
    child: [u32; WIDTH],
    /// A leaf child: how many triangles (1..=LEAF_SIZE); an inner or unused child: 0.
    leaf_count: [u8; WIDTH],
}

impl WideNode {
    /// No children: every box empty, so no child is ever opened.
    const EMPTY: WideNode = WideNode {
        lo: [[f32::INFINITY; WIDTH]; 3],
        hi: [[f32::NEG_INFINITY; WIDTH]; 3],
        normal_lo: [[f32::INFINITY; WIDTH]; 3],
        normal_hi: [[f32::NEG_INFINITY; WIDTH]; 3],
        child: [u32::MAX; WIDTH],
        leaf_count: [0; WIDTH],
    };

    fn set_child(&mut self, i: usize, position: &Box32, normals: &Box32) {
        for k in 0..3 {
            self.lo[k][i] = position.lo[k];
            self.hi[k][i] = position.hi[k];
            self.normal_lo[k][i] = normals.lo[k];
            self.normal_hi[k][i] = normals.hi[k];
        }
    }
}

/// The boxes of a [`TriangleBvh`] (positions and unit normals), four children a node,
/// in `f32`, for [`TriangleBvh::any_facing_away`]. Built by
/// [`TriangleBvh::facing_tree`]; valid only with the index it was built from.
#[derive(Clone, Debug)]
pub struct FacingTree {
    nodes: Vec<WideNode>,
    /// The number of triangles of the index it was built from (a check that the two
    /// belong together).
    triangles: usize,
}

impl TriangleBvh {
    /// The [`FacingTree`] of this index, for
    /// [`any_facing_away`](Self::any_facing_away). Built in O(n): the normal boxes
    /// bottom-up over the binary tree, then each wide node from two of its levels.
    pub fn facing_tree(&self) -> FacingTree {
        let normal_boxes = self.unit_normal_boxes();
        let mut tree = FacingTree {
            nodes: Vec::new(),
            triangles: self.corners.len(),
        };
        if self.corners.is_empty() {
            return tree;
        }
        // The binary nodes a wide node's children stand for: the grandchildren of an
        // inner node (or a child itself, where it is a leaf).
        let children_of = |n: usize| -> ([usize; WIDTH], usize) {
            let mut out = [0; WIDTH];
            let mut len = 0;
            let node = &self.nodes[n];
            if node.count > 0 {
                // Only for a root that is a leaf: the tree is one node over it.
                out[0] = n;
                return (out, 1);
            }
            for c in [node.first as usize, node.first as usize + 1] {
                let child = &self.nodes[c];
                if child.count > 0 {
                    out[len] = c;
                    len += 1;
                } else {
                    out[len] = child.first as usize;
                    out[len + 1] = child.first as usize + 1;
                    len += 2;
                }
            }
            (out, len)
        };
        tree.nodes.push(WideNode::EMPTY);
        // (binary node, wide node standing for it)
        let mut stack = vec![(0usize, 0usize)];
        while let Some((n, w)) = stack.pop() {
            let (children, len) = children_of(n);
            let mut wide = WideNode::EMPTY;
            for (i, &c) in children[..len].iter().enumerate() {
                let node = &self.nodes[c];
                let position = Box32::around(node.bounds.lo, node.bounds.hi);
                wide.set_child(i, &position, &normal_boxes[c]);
                if node.count > 0 {
                    wide.child[i] = node.first;
                    wide.leaf_count[i] = node.count as u8;
                } else {
                    wide.child[i] = tree.nodes.len() as u32;
                    stack.push((c, tree.nodes.len()));
                    tree.nodes.push(WideNode::EMPTY);
                }
            }
            tree.nodes[w] = wide;
        }
        tree
    }

    /// The box of the unit normals under each node of the binary tree, rounded
    /// outward to `f32`. A triangle whose normal's length under- or overflows (or is
    /// NaN) counts as facing every way; a zero-area one has no direction and no say.
    fn unit_normal_boxes(&self) -> Vec<Box32> {
        let mut boxes = vec![Box32::EMPTY; self.nodes.len()];
        // Children always have higher indices than their parent (see `from_corners`),
        // so a reverse sweep sees both children before the parent.
        for n in (0..self.nodes.len()).rev() {
            let node = self.nodes[n];
            let mut bounds = Box32::EMPTY;
            if node.count > 0 {
                let start = node.first as usize;
                for [a, b, c] in &self.corners[start..start + node.count as usize] {
                    let normal = cross(sub(*b, *a), sub(*c, *a));
                    let length = length(normal);
                    if length > 0.0 && length.is_finite() {
                        let unit = normal.map(|x| x / length);
                        bounds.grow(&Box32::around(unit, unit));
                    } else if normal != [0.0; 3] {
                        bounds.grow(&Box32::around([-1.0; 3], [1.0; 3]));
                    }
                }
            } else {
                for child in [node.first as usize, node.first as usize + 1] {
                    bounds.grow(&boxes[child]);
                }
            }
            boxes[n] = bounds;
        }
        boxes
    }

    /// Whether some triangle within `radius` of `p` faces away from `normal`: its normal
    /// has a dot product ≤ 0 with `normal` (zero-area triangles excepted). A subtree
    /// whose normals all face the same way as `normal` (by `tree`, from
    /// [`facing_tree`](Self::facing_tree) of this index) is skipped whole, so on a
    /// smooth patch the search ends well above the leaves.
    ///
    /// May also answer true for a triangle a rounding error beyond `radius` (the box
    /// tests are widened, never narrowed); never answers false wrongly. A `tree` built
    /// from another index gets the answer "true" whenever there are triangles (the
    /// answer that sends a caller to its exact test).
    pub fn any_facing_away(
        &self,
        tree: &FacingTree,
        p: [f64; 3],
        radius: f64,
        normal: [f64; 3],
    ) -> bool {
        if self.corners.is_empty() || tree.triangles != self.corners.len() {
            return !self.corners.is_empty();
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
        // gives a NaN cube, which no box meets: no triangle is within a NaN distance
        // either.)
        let reach = radius2.sqrt();
        let widen = |x: f64| (x.abs() + reach) * CUBE_WIDENING + f64::from(f32::MIN_POSITIVE);
        let cube_lo = p.map(|x| (x - reach - widen(x)) as f32);
        let cube_hi = p.map(|x| (x + reach + widen(x)) as f32);
        let unit = unit_direction(normal);
        let mut stack = NodeStack::with_root();
        while let Some(w) = stack.pop() {
            let node = &tree.nodes[w as usize];
            let open = node.open(cube_lo, cube_hi, unit);
            for (i, &is_open) in open.iter().enumerate() {
                if !is_open {
                    continue;
                }
                let count = node.leaf_count[i] as usize;
                if count == 0 {
                    stack.push(node.child[i]);
                    continue;
                }
                let start = node.child[i] as usize;
                for [a, b, c] in &self.corners[start..start + count] {
                    let t = cross(sub(*b, *a), sub(*c, *a));
                    // "Not positive", NaN included, exactly as the caller's full test
                    // asks it (a zero normal has no say there either).
                    let d = dot(t, normal);
                    if (d <= 0.0 || d.is_nan())
                        && t != [0.0; 3]
                        && triangle_distance2(p, *a, *b, *c) <= radius2
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
    /// Which children the walk must open: their position box meets the cube, and
    /// (given a direction) not all of their normals face its way. Written lane by
    /// lane over plain arrays, with `&` and `|` rather than `&&` and `||` (no branch per
    /// lane), so that the compiler can test the four children at once.
    // Lane loops: the index form is the one that reads as lanes and vectorises.
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    fn open(&self, cube_lo: [f32; 3], cube_hi: [f32; 3], unit: Option<[f32; 3]>) -> [bool; WIDTH] {
        let mut meets = [true; WIDTH];
        for k in 0..3 {
            for i in 0..WIDTH {
                meets[i] &= (self.lo[k][i] <= cube_hi[k]) & (self.hi[k][i] >= cube_lo[k]);
            }
        }
        let Some(u) = unit else {
            return meets;
        };
        let mut least = [0.0f32; WIDTH];
        for k in 0..3 {
            for i in 0..WIDTH {
                let bound = if u[k] >= 0.0 {
                    self.normal_lo[k][i]
                } else {
                    self.normal_hi[k][i]
                };
                least[i] += u[k] * bound;
            }
        }
        let mut open = [false; WIDTH];
        for i in 0..WIDTH {
            // An empty normal box (zero-area triangles only) has nothing to say; its
            // products are NaN or infinite, so it is told apart first.
            let all_face =
                (self.normal_lo[0][i] > self.normal_hi[0][i]) | (least[i] > FACING_MARGIN);
            open[i] = meets[i] & !all_face;
        }
        open
    }
}

/// `v` scaled to unit length in `f32`, or `None` when its length is zero, NaN or
/// infinite (such a direction is never known to agree with a box of normals, so no
/// subtree is skipped for it).
fn unit_direction(v: P3) -> Option<[f32; 3]> {
    let length = length(v);
    (length > 0.0 && length.is_finite()).then(|| v.map(|x| (x / length) as f32))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Outward rounding never lands inside the value, and stays within one `f32` step.
    #[test]
    fn rounding_is_outward() {
        for x in [
            0.1,
            -0.1,
            1.0 / 3.0,
            -2.0 / 3.0,
            1e-40,
            1e39,
            -1e39,
            0.0,
            0.5,
        ] {
            let (lo, hi) = (f32_below(x), f32_above(x));
            assert!(f64::from(lo) <= x && x <= f64::from(hi), "{x}");
            // Within one step: the next value below `hi` is at or below `x`.
            assert!(
                f64::from(step_toward_negative(hi)) <= x,
                "{x}: {lo} .. {hi}"
            );
            assert!(
                f64::from(-step_toward_negative(-lo)) >= x,
                "{x}: {lo} .. {hi}"
            );
        }
        assert_eq!(f32_below(f64::INFINITY), f32::INFINITY);
        assert_eq!(f32_above(f64::NEG_INFINITY), f32::NEG_INFINITY);
        assert_eq!(f32_below(0.5), 0.5);
        assert_eq!(f32_below(1e300), f32::MAX);
        assert!(f32_below(-1e-300) < 0.0 && f32_above(1e-300) > 0.0);
        assert_eq!(f32_above(0.5), 0.5);
    }

    /// An empty normal box or an empty slot is never opened for its normals or its
    /// position; a full one is opened exactly when it meets the cube and faces away.
    #[test]
    fn children_open_only_when_they_meet_the_cube_and_may_face_away() {
        let mut node = WideNode::EMPTY;
        let unit_box = Box32::around([0.0; 3], [1.0; 3]);
        // Child 0: normals around +z only; child 1: normals every way; child 2: no
        // normals (zero-area triangles only); child 3 unused.
        node.set_child(
            0,
            &unit_box,
            &Box32::around([-0.1, -0.1, 0.9], [0.1, 0.1, 1.0]),
        );
        node.set_child(1, &unit_box, &Box32::around([-1.0; 3], [1.0; 3]));
        node.set_child(2, &unit_box, &Box32::EMPTY);
        let inside = ([0.4f32; 3], [0.6f32; 3]);
        let outside = ([2.0f32; 3], [3.0f32; 3]);
        assert_eq!(
            node.open(inside.0, inside.1, Some([0.0, 0.0, 1.0])),
            [false, true, false, false]
        );
        assert_eq!(
            node.open(inside.0, inside.1, Some([0.0, 0.0, -1.0])),
            [true, true, false, false]
        );
        assert_eq!(
            node.open(inside.0, inside.1, None),
            [true, true, true, false]
        );
        assert_eq!(
            node.open(outside.0, outside.1, Some([0.0, 0.0, -1.0])),
            [false; WIDTH]
        );
    }
}
