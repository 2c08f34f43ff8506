//! [`TriangleBvh`]: a bounding-volume hierarchy over the triangles of one mesh, for
//! exact nearest-triangle queries (Metro sampling, the orientation check).
//!
//! Split as a binary tree would be (at median centroids), but stored as a 4-wide tree:
//! each node holds its (up to) four children's boxes side by side, by axis (position
//! boxes in `f32`, normal boxes in steps of 1/127: [`NormalBox`]), two binary levels at
//! once. Why: a walk reads one node (three cache lines) where it read four binary nodes
//! in as many places, tests four boxes with the same instructions, and a node costs 36
//! bytes per child instead of 56 for a binary node plus 48 for its normal box.
//!
//! Long thin triangles are indexed in pieces (see [`pieces`]): a
//! leaf entry is then a piece, which names its triangle, and a triangle may be met
//! more than once in a walk. Meshes without such triangles have no pieces, and their
//! tree is the one a leaf entry per triangle gives.
//!
//! Why `f32` boxes change no answer: every box is rounded outward, so the distance to
//! it is never more than the distance to the exact box, and a subtree is skipped only
//! when it is farther than the pruning bound; the answers themselves come from the
//! exact `f64` triangle distances at the leaves.
//!
//! The boxes are kept relative to an origin near the mesh ([`TriangleBvh::origin`])
//! when the mesh lies far from zero. Why: `f32` has 24 bits, so at 5e6 (a scan in UTM
//! coordinates) its steps are 0.5 units, and a model a few units across had every box
//! rounded out to nearly the whole model: `qem measure` of a 86k-triangle armadillo
//! moved by 5e6 took 623 s instead of 2.3 s, every search visiting most of the tree.

use super::corner_store::CornerStore;
use super::facing::MIN_PRUNING_LENGTH;
use super::pieces;
use super::{cross, length, sub, triangle_distance2, P3};
use crate::input::IndexedMesh;
use rayon::prelude::*;

/// Entries (triangles, or pieces of them) per leaf: small leaves keep the exact tests few, large enough to keep the
/// tree shallow.
const LEAF_SIZE: usize = 4;

/// Children per node of the stored tree.
pub(super) const WIDTH: usize = 4;

/// A node is skipped only when its box is farther than the best squared distance by more
/// than this factor (plus [`TriangleBvh::slack2`]): a margin far above the rounding of
/// either computation, so rounding can never skip the node that holds the triangle a
/// brute-force search would pick. It costs a handful of extra box tests.
pub(super) const PRUNE_FACTOR: f64 = 1.0 + 1e-9;

/// An axis-aligned box in `f64`, for the build.
#[derive(Clone, Copy, Debug)]
struct Aabb {
    lo: P3,
    hi: P3,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        lo: [f64::INFINITY; 3],
        hi: [f64::NEG_INFINITY; 3],
    };

    fn grow(&mut self, p: P3) {
        for (k, &x) in p.iter().enumerate() {
            self.lo[k] = self.lo[k].min(x);
            self.hi[k] = self.hi[k].max(x);
        }
    }

    /// Grows the box to hold `other` (nothing, when `other` is empty).
    fn add(&mut self, other: &Aabb) {
        for k in 0..3 {
            self.lo[k] = self.lo[k].min(other.lo[k]);
            self.hi[k] = self.hi[k].max(other.hi[k]);
        }
    }
}

/// `x` rounded to an `f32` at or below it (−∞ and +∞ stay).
pub(super) fn f32_below(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x {
        step_toward_negative(f)
    } else {
        f
    }
}

/// `x` rounded to an `f32` at or above it.
pub(super) fn f32_above(x: f64) -> f32 {
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
pub(super) struct Box32 {
    pub lo: [f32; 3],
    pub hi: [f32; 3],
}

impl Box32 {
    /// Contains nothing: every test against it fails, and growing it by a box gives
    /// that box.
    pub const EMPTY: Box32 = Box32 {
        lo: [f32::INFINITY; 3],
        hi: [f32::NEG_INFINITY; 3],
    };

    pub fn around(lo: P3, hi: P3) -> Box32 {
        Box32 {
            lo: lo.map(f32_below),
            hi: hi.map(f32_above),
        }
    }

    /// The box from `lo` to `hi` relative to `origin` ([`TriangleBvh::origin`]),
    /// rounded outward. Along an axis where `origin` is not zero, the `f64`
    /// differences (rounded to nearest) are first moved outward by a unit in their
    /// last place, so the `f32` box still holds the exact one; where it is zero the
    /// bounds are [`around`](Self::around)'s, bit for bit.
    pub fn relative(lo: P3, hi: P3, origin: P3) -> Box32 {
        let outward = |x: f64, o: f64, sign: f64| {
            if o == 0.0 {
                x
            } else {
                let d = x - o;
                d + sign * (d.abs() * f64::EPSILON + f64::MIN_POSITIVE)
            }
        };
        Box32::around(
            [0, 1, 2].map(|k| outward(lo[k], origin[k], -1.0)),
            [0, 1, 2].map(|k| outward(hi[k], origin[k], 1.0)),
        )
    }

    fn grow(&mut self, other: &Box32) {
        for k in 0..3 {
            self.lo[k] = self.lo[k].min(other.lo[k]);
            self.hi[k] = self.hi[k].max(other.hi[k]);
        }
    }
}

/// A box of unit normals in steps of 1/127 ([`NORMAL_STEPS`]), rounded outward from
/// [`Box32`] bounds: `lo > hi` when empty.
///
/// Why so coarse: the facing-away search only asks whether all the normals under a
/// child face a query's way with a margin ([`super::facing`]); a box a step wider
/// opens a node a little sooner, never skips one an exact box would open, so no answer
/// changes. A wide node's normal boxes take 24 bytes instead of 96 (its size 144 bytes
/// instead of 216; the orientation check's index holds one node for about six input
/// triangles for the whole run, so this saves 12.6 bytes a triangle, the nodes now
/// costing about 25: BENCHMARKS.md "The budget, array by array").
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct NormalBox {
    pub lo: [i8; 3],
    pub hi: [i8; 3],
}

/// The steps of [`NormalBox`] per unit.
pub(super) const NORMAL_STEPS: f32 = 127.0;

impl NormalBox {
    /// Holds nothing; growing it by a box gives that box.
    pub const EMPTY: NormalBox = NormalBox {
        lo: [i8::MAX; 3],
        hi: [i8::MIN; 3],
    };

    /// The least box of steps holding `bounds` (unit normals' bounds: each component
    /// is `x / length` with `length ≥ |x|`, and rounding a value within ±1 outward to
    /// `f32` keeps it within ±1, so no bound needs the clamp; were a high bound above 1,
    /// it would clamp to 1, inside the facing test's margin). The product by 127 is
    /// exact in `f64` (24 + 7 bits), so the floor and ceiling round outward exactly.
    pub fn around(bounds: &Box32) -> NormalBox {
        let step = |x: f32, round: fn(f64) -> f64| {
            round(f64::from(x) * f64::from(NORMAL_STEPS)).clamp(-128.0, 127.0) as i8
        };
        NormalBox {
            lo: bounds.lo.map(|x| step(x, f64::floor)),
            hi: bounds.hi.map(|x| step(x, f64::ceil)),
        }
    }

    fn grow(&mut self, other: &NormalBox) {
        for k in 0..3 {
            self.lo[k] = self.lo[k].min(other.lo[k]);
            self.hi[k] = self.hi[k].max(other.hi[k]);
        }
    }
}

/// A node of the stored tree: its (up to) four children's boxes, by axis then child,
/// so that each test reads four adjacent lanes.
#[derive(Clone, Debug)]
pub(super) struct WideNode {
    /// Position boxes: `lo[k][i]` is the least `k` coordinate under child `i`.
    pub lo: [[f32; WIDTH]; 3],
    pub hi: [[f32; WIDTH]; 3],
    /// Boxes of the unit normals under each child ([`NormalBox`]'s steps), for the
    /// orientation check's facing-away search (empty when all its triangles have zero
    /// area).
    pub normal_lo: [[i8; WIDTH]; 3],
    pub normal_hi: [[i8; WIDTH]; 3],
    /// An inner child: its node's index. A leaf child: its first leaf entry.
    pub child: [u32; WIDTH],
    /// A leaf child: how many entries (1..=LEAF_SIZE); an inner child: 0.
    pub leaf_count: [u8; WIDTH],
    /// How many children are used (the first ones); the others have empty boxes.
    pub lanes: u8,
}

impl WideNode {
    /// No children: every box empty.
    const EMPTY: WideNode = WideNode {
        lo: [[f32::INFINITY; WIDTH]; 3],
        hi: [[f32::NEG_INFINITY; WIDTH]; 3],
        normal_lo: [[i8::MAX; WIDTH]; 3],
        normal_hi: [[i8::MIN; WIDTH]; 3],
        child: [u32::MAX; WIDTH],
        leaf_count: [0; WIDTH],
        lanes: 0,
    };

    /// The leaf entries of child `i`, when it is a leaf child.
    fn leaf_entries(&self, i: usize) -> Option<std::ops::Range<usize>> {
        let count = usize::from(self.leaf_count[i]);
        let first = self.child[i] as usize;
        (count > 0).then(|| first..first + count)
    }

    pub(super) fn set_child(&mut self, i: usize, position: &Box32, normals: &NormalBox) {
        for k in 0..3 {
            self.lo[k][i] = position.lo[k];
            self.hi[k][i] = position.hi[k];
            self.normal_lo[k][i] = normals.lo[k];
            self.normal_hi[k][i] = normals.hi[k];
        }
    }

    /// Squared distance from `p` to child `i`'s box (0 inside), in `f64` on the
    /// outward-rounded bounds: a lower bound on the distance to anything under it.
    /// Plain comparisons rather than `f64::max` (which must pass NaN over, at a few
    /// instructions each): a NaN coordinate still gives 0 (every comparison with NaN
    /// is false), so a NaN point prunes nothing, as before.
    #[inline(always)]
    fn lane_distance2(&self, i: usize, p: P3) -> f64 {
        let mut s = 0.0;
        for (k, &x) in p.iter().enumerate() {
            let below = f64::from(self.lo[k][i]) - x;
            let above = x - f64::from(self.hi[k][i]);
            let outside = if below > above { below } else { above };
            let d = if outside > 0.0 { outside } else { 0.0 };
            s += d * d;
        }
        s
    }
}

/// A stack of node indices (with a key, for the nearest-first walks) for the tree
/// walks. Why a plain array: `SmallVec`'s push and pop (its inline-or-spilled checks)
/// were 12% of the contraction loop's instructions through the orientation check's
/// quick test. Why 64 is enough: the binary tree splits at the median, so a node `d`
/// levels down holds at most `n / 2^d + 1` triangles and its depth stays below 33 for
/// any `n < 2^32`; the wide tree is then at most 17 deep, and a walk pushes at most
/// four children per node it pops: at most 3 × 17 + 1 = 52 entries.
pub(super) struct NodeStack<T> {
    items: [T; 64],
    len: usize,
}

impl<T: Copy + Default> NodeStack<T> {
    pub fn with(root: T) -> NodeStack<T> {
        let mut items = [T::default(); 64];
        items[0] = root;
        NodeStack { items, len: 1 }
    }

    #[inline]
    pub fn push(&mut self, item: T) {
        self.items[self.len] = item;
        self.len += 1;
    }

    #[inline]
    pub fn pop(&mut self) -> Option<T> {
        self.len = self.len.checked_sub(1)?;
        Some(self.items[self.len])
    }
}

/// A bounding-volume hierarchy over the triangles of one mesh, for exact closest-point
/// queries: a node is skipped only when its box is farther than the best distance found
/// so far, so the answer is the true minimum over all triangles.
///
/// Built top-down by splitting the leaf entries (triangles, or pieces of long thin
/// ones) at the median centroid along the longest axis of the centroids' box (ties
/// broken by entry number, so the tree is deterministic), then stored four children a
/// node (see the module docs).
#[derive(Clone, Debug)]
pub struct TriangleBvh {
    /// The wide tree; node 0 is the root. Empty when there are no triangles.
    pub(super) nodes: Vec<WideNode>,
    /// Triangle corners, numbered in the order the leaves first meet them: without
    /// pieces, a leaf's triangles are contiguous.
    pub(super) corners: CornerStore,
    /// The triangle of each leaf entry, when some triangle is indexed in pieces (see
    /// the module docs); `None` when every leaf entry is its own triangle, in order.
    pub(super) pieces: Option<Vec<u32>>,
    /// Absolute part of the pruning margin (squared): rounding of coordinates at the
    /// scale of the whole tree.
    pub(super) slack2: f64,
    /// What the boxes are relative to: a box bound is `f32` of the coordinate minus
    /// this, rounded outward, and a query point is moved by it before it meets a box
    /// (the exact tests at the leaves take the points as they are). Zero along each
    /// axis on which the mesh's box reaches zero or lies nearer to it than its own
    /// length, so that the boxes of such a mesh (the simplifier's, in its normalised
    /// frame) are the bits they were before there was an origin.
    pub(super) origin: P3,
}

impl TriangleBvh {
    /// Builds the hierarchy over every triangle of `mesh` (degenerate ones included:
    /// their points are still on the surface). The mesh must pass
    /// [`IndexedMesh::validate`]; an index out of range would otherwise be skipped.
    pub fn new(mesh: &IndexedMesh) -> TriangleBvh {
        Self::with_slots(mesh).0
    }

    /// [`new`](Self::new), and where each triangle went: `slots[i]` is the index (for
    /// [`corners`](Self::corners)) of the `i`-th triangle of `mesh` with valid indices.
    pub fn with_slots(mesh: &IndexedMesh) -> (TriangleBvh, Vec<u32>) {
        Self::from_triangles(mesh, |p| p)
    }

    /// The index over the triangles of `mesh` with valid indices, each corner mapped
    /// through `to_index` first (which should be cheap: it runs several times per
    /// corner), and where each triangle went (as [`with_slots`](Self::with_slots)).
    ///
    /// Why from the mesh rather than a list of corners: the index keeps each shared
    /// vertex once (`CornerStore`), numbered in leaf order once the tree's order
    /// is known, where a list would hold every corner three times over first.
    pub fn from_triangles(
        mesh: &IndexedMesh,
        to_index: impl Fn(P3) -> P3 + Sync,
    ) -> (TriangleBvh, Vec<u32>) {
        let n = mesh.positions.len();
        let all_valid = mesh
            .triangles
            .par_iter()
            .all(|t| t.iter().all(|&i| (i as usize) < n));
        if all_valid {
            let (triangles, positions) = (&mesh.triangles, &mesh.positions);
            Self::from_points(
                triangles.len(),
                n,
                |t| triangles[t],
                |v| to_index(positions[v as usize]),
            )
        } else {
            // Left out, as documented; a validated mesh never comes this way.
            let corners: Vec<[P3; 3]> = mesh
                .triangles
                .iter()
                .filter_map(|t| {
                    let p = |i: u32| mesh.positions.get(i as usize).map(|&p| to_index(p));
                    Some([p(t[0])?, p(t[1])?, p(t[2])?])
                })
                .collect();
            Self::from_corners(corners)
        }
    }

    /// The index over these triangles (given by their corners), and where each went:
    /// `slots[i]` is the index (for [`corners`](Self::corners)) of `corners[i]`.
    /// Corners are numbered with `u32`: at most `u32::MAX / 3` triangles are indexed
    /// (about 100 GB of corners), the rest are left out. Corners should be finite (as a
    /// validated mesh's are): a triangle with a NaN corner is never found by the
    /// searches. (The index holds its own copy of the corners; a mesh is better given
    /// to [`from_triangles`](Self::from_triangles), whose shared vertices the index
    /// then stores once.)
    pub fn from_corners(corners: Vec<[P3; 3]>) -> (TriangleBvh, Vec<u32>) {
        let count = corners.len().min(u32::MAX as usize / 3);
        Self::from_points(
            count,
            3 * count,
            |t| {
                let first = 3 * t as u32;
                [first, first + 1, first + 2]
            },
            |v| corners[v as usize / 3][v as usize % 3],
        )
    }

    /// The index over `count` triangles, triangle `t` made of points `points_of(t)`
    /// (each below `point_count`), point `v` being `point(v)` (asked several times per
    /// point, from several threads: it must give the same bits each time), and where
    /// each triangle went (as [`from_corners`](Self::from_corners)).
    fn from_points(
        count: usize,
        point_count: usize,
        points_of: impl Fn(usize) -> [u32; 3] + Sync,
        point: impl Fn(u32) -> P3 + Sync,
    ) -> (TriangleBvh, Vec<u32>) {
        let count = count.min(u32::MAX as usize);
        let source = Source {
            count,
            point_count,
            points_of,
            point,
        };
        let (nodes, corners, slots, root, pieces, origin) = build(&source);
        let scale = (0..3)
            .map(|k| root.lo[k].abs().max(root.hi[k].abs()))
            .fold(0.0, f64::max);
        let slack = if scale.is_finite() {
            1e-12 * scale
        } else {
            0.0
        };
        (
            TriangleBvh {
                nodes,
                corners,
                pieces,
                slack2: slack * slack,
                origin,
            },
            slots,
        )
    }

    /// `p` relative to the boxes' [`origin`](Self::origin), for the box tests only.
    /// Rounded to nearest: off by at most half a unit in the last place of the
    /// coordinates, far below the pruning margin's `slack2`, which is taken at the
    /// scale of the coordinates themselves (so no box that could hold the answer is
    /// skipped for it).
    #[inline(always)]
    pub(super) fn relative(&self, p: P3) -> P3 {
        sub(p, self.origin)
    }

    /// The triangle of leaf entry `entry` (an index for [`corners`](Self::corners)).
    #[inline(always)]
    pub(super) fn triangle_of(&self, entry: usize) -> usize {
        match &self.pieces {
            None => entry,
            Some(pieces) => pieces[entry] as usize,
        }
    }

    /// Visits node `w` of a nearest-first walk: tests the triangles of its leaf
    /// children, nearest child first, and pushes its inner children with their box
    /// distances, farthest first (so the nearest is popped next). `p` is the query
    /// point relative to the boxes ([`relative`](Self::relative)). `prune` gives the
    /// current bound on squared distances and `leaf` takes the triangle (index) of each
    /// entry of a leaf child within it (a triangle in pieces may come more than once).
    #[inline(always)]
    fn visit_nearest_first(
        &self,
        w: u32,
        p: P3,
        stack: &mut NodeStack<(u32, f64)>,
        prune: &mut impl FnMut() -> f64,
        leaf: &mut impl FnMut(usize),
    ) {
        let node = &self.nodes[w as usize];
        let lanes = usize::from(node.lanes);
        // Unused children sort last and are skipped by their lane number.
        let mut by_distance = [(f64::INFINITY, WIDTH); WIDTH];
        for (i, slot) in by_distance[..lanes].iter_mut().enumerate() {
            *slot = (node.lane_distance2(i, p), i);
        }
        // Nearest first, by a fixed network of five exchanges (a library sort of four
        // was 14% of `qem measure`'s instructions). Not stable, but fixed: the same
        // distances give the same order on every run. (Only the walk's speed depends on
        // the order: every child within the bound is visited, and the answers are
        // ranked by distance and index.)
        for (x, y) in [(0, 1), (2, 3), (0, 2), (1, 3), (1, 2)] {
            if by_distance[y].0 < by_distance[x].0 {
                by_distance.swap(x, y);
            }
        }
        for &(d2, i) in by_distance.iter().filter(|x| x.1 < WIDTH) {
            let count = usize::from(node.leaf_count[i]);
            if count == 0 || d2 > prune() {
                continue;
            }
            let start = node.child[i] as usize;
            for entry in start..start + count {
                leaf(self.triangle_of(entry));
            }
        }
        for &(d2, i) in by_distance.iter().rev().filter(|x| x.1 < WIDTH) {
            if node.leaf_count[i] == 0 && d2 <= prune() {
                stack.push((node.child[i], d2));
            }
        }
    }

    /// The exact distance from `p` to the nearest triangle, or `None` when there are no
    /// triangles.
    pub fn distance(&self, p: [f64; 3]) -> Option<f64> {
        if self.corners.is_empty() {
            return None;
        }
        let boxed = self.relative(p);
        let best = std::cell::Cell::new(f64::INFINITY);
        let mut prune = || best.get() * PRUNE_FACTOR + self.slack2;
        let mut leaf = |t: usize| {
            let [a, b, c] = self.corners.get(t);
            best.set(best.get().min(triangle_distance2(p, a, b, c)));
        };
        let mut stack = NodeStack::with((0u32, 0.0f64));
        while let Some((w, d2)) = stack.pop() {
            if d2 > prune() {
                continue;
            }
            self.visit_nearest_first(w, boxed, &mut stack, &mut prune, &mut leaf);
        }
        Some(best.get().sqrt())
    }

    /// The triangles nearest to `p`: of the triangles whose distance to `p` is at most
    /// `factor` times the distance of the nearest one plus `margin` (both distances, not
    /// squares), the `max_count` nearest (by squared distance, then by index), as indices
    /// for [`corners`](Self::corners) in ascending index order. `out` is cleared first;
    /// it is empty when there are no triangles (or `max_count` is 0). Returns the
    /// nearest triangle (the lowest index among those at the least squared distance),
    /// `None` when there are no triangles.
    ///
    /// Why several: a point equally near two triangles (on their shared edge, say) has
    /// no single nearest one, and a caller asking "which way does the surface face here"
    /// must hear from all of them. Why a count: above a finely cut region the ball can
    /// hold hundreds of triangles, and the count keeps the search's cost bounded (the
    /// pruning radius shrinks to the `max_count`-th distance). `factor` below 1 counts
    /// as 1, and a negative (or NaN) `margin` as 0.
    pub fn nearest_triangles(
        &self,
        p: [f64; 3],
        factor: f64,
        margin: f64,
        max_count: usize,
        out: &mut Vec<u32>,
    ) -> Option<u32> {
        self.nearest_triangles_within(p, f64::INFINITY, factor, margin, max_count, out)
    }

    /// [`nearest_triangles`](Self::nearest_triangles) for a caller that already
    /// knows a triangle at squared distance `known2` from `p` (the distance of some
    /// triangle of this index, as [`distance_squared_to`](Self::distance_squared_to)
    /// gives it; `f64::INFINITY` when none is known). The answer is the same; the
    /// search prunes by that distance from the start instead of from its first leaf.
    pub fn nearest_triangles_within(
        &self,
        p: [f64; 3],
        known2: f64,
        factor: f64,
        margin: f64,
        max_count: usize,
        out: &mut Vec<u32>,
    ) -> Option<u32> {
        out.clear();
        if self.corners.is_empty() {
            return None;
        }
        let factor = factor.max(1.0);
        // A negative margin would make the bound smaller than the nearest distance
        // itself (and the answer empty); NaN counts as 0 too.
        let margin = margin.max(0.0);
        // The bound a triangle must meet, from the best squared distance so far.
        let bound = |best2: f64| {
            let d = best2.sqrt() * factor + margin;
            d * d * PRUNE_FACTOR + self.slack2
        };
        // Why starting from `known2` changes nothing: it is a true squared distance, so
        // `best2` never drops below the nearest triangle's squared distance, and every
        // pruning bound stays at or above it; the nearest triangle's node is never
        // skipped, and `best2` ends at its distance from either start.
        let best2 = std::cell::Cell::new(if known2 >= 0.0 { known2 } else { f64::INFINITY });
        // The nearest found so far, sorted by (squared distance, index), at most
        // `max_count` long (and at least 1, to know the nearest).
        let keep = max_count.max(1);
        let candidates: std::cell::RefCell<smallvec::SmallVec<[(f64, u32); 16]>> =
            std::cell::RefCell::new(smallvec::SmallVec::new());
        let mut prune = || {
            let b = bound(best2.get());
            let candidates = candidates.borrow();
            if candidates.len() == keep {
                b.min(candidates[keep - 1].0 * PRUNE_FACTOR + self.slack2)
            } else {
                b
            }
        };
        let mut leaf = |i: usize| {
            let [a, b, c] = self.corners.get(i);
            let d2 = triangle_distance2(p, a, b, c);
            best2.set(best2.get().min(d2));
            // A NaN distance (a NaN corner or point) makes no candidate: it would sort
            // among the nearest under `total_cmp` and could take a slot.
            if d2.is_nan() || d2 > bound(best2.get()) {
                return;
            }
            let entry = (d2, i as u32);
            let mut candidates = candidates.borrow_mut();
            let at =
                candidates.partition_point(|x| x.0.total_cmp(&d2).then(x.1.cmp(&entry.1)).is_lt());
            // A triangle met again through another of its pieces: the same distance,
            // already there.
            let again = candidates
                .get(at)
                .is_some_and(|x| x.1 == entry.1 && x.0.to_bits() == d2.to_bits());
            if at < keep && !again {
                candidates.insert(at, entry);
                candidates.truncate(keep);
            }
        };
        let boxed = self.relative(p);
        let mut stack = NodeStack::with((0u32, 0.0f64));
        while let Some((w, d2)) = stack.pop() {
            if d2 > prune() {
                continue;
            }
            self.visit_nearest_first(w, boxed, &mut stack, &mut prune, &mut leaf);
        }
        let candidates = candidates.into_inner();
        let best2 = best2.get();
        // Compared as distances, not squares: squaring the limit back can round it
        // below `best2` itself and drop the nearest triangle.
        let limit = best2.sqrt() * factor + margin;
        out.extend(
            candidates
                .iter()
                .take(max_count)
                .filter(|&&(d2, _)| d2.sqrt() <= limit)
                .map(|&(_, i)| i),
        );
        out.sort_unstable();
        candidates.first().map(|&(_, i)| i)
    }

    /// The squared distance from `p` to triangle `i` (an index for
    /// [`corners`](Self::corners)); `None` when `i` is out of range.
    pub fn distance_squared_to(&self, p: [f64; 3], i: u32) -> Option<f64> {
        let [a, b, c] = self.corners.checked(i as usize)?;
        Some(triangle_distance2(p, a, b, c))
    }

    /// Number of indexed triangles (those of the mesh with valid indices); indices for
    /// [`corners`](Self::corners) run below it.
    pub fn triangle_count(&self) -> usize {
        self.corners.len()
    }

    /// The corners of triangle `i` (an index from
    /// [`nearest_triangles`](Self::nearest_triangles)), in their input order.
    #[inline]
    pub fn corners(&self, i: u32) -> [[f64; 3]; 3] {
        self.corners.get(i as usize)
    }
}

/// What [`build`] returns: the nodes, the corners in leaf order, where each triangle
/// went, the root's box, the pieces' triangles (when there are pieces) and the boxes'
/// origin.
type Built = (
    Vec<WideNode>,
    CornerStore,
    Vec<u32>,
    Aabb,
    Option<Vec<u32>>,
    P3,
);

/// The tree over the triangles of `source` (their corners returned in leaf order, see
/// [`TriangleBvh::corners`]), node 0 the root,
/// every node after its parent; where each triangle went (`slots[i]` is the
/// new index of the triangle that was at `i`); the box of all the corners; and the
/// triangle of each leaf entry when some triangle is indexed in pieces (see
/// [`pieces`]).
///
/// The splits are those of a binary tree: a range of more than [`LEAF_SIZE`] entries
/// is split at its median centroid along the longest axis of its centroids' box (ties
/// broken by entry number, so the tree is deterministic). A node stands for one such
/// split and its two halves' splits: its children are the four quarter ranges (or a
/// half, where the half is a leaf). Built straight into wide nodes, so the build never
/// holds a binary node per range (56 bytes each, about 134 MB on the 4M sphere).
///
/// Four steps, so that none reads corners out of order: [`partition`] puts every
/// entry in its leaf (on both cores), the corners are gathered in leaf order (points
/// numbered on one core, then fetched on both: [`CornerStore::gather`]), [`wide_nodes`]
/// lays out the nodes (which needs only the range sizes), and
/// [`fill_boxes`] fills in the boxes bottom-up. Why: building top-down with each
/// range's box computed as its split was made read every triangle's 72 bytes of
/// corners at random, once per level; that was most of the index build, then the
/// longer half of the simplifier's setup.
fn build(source: &Source<impl PointsOf, impl PointAt>) -> Built {
    let count = source.count;
    let corners_of = &|t| source.corners(t);
    let mut root_bounds = Aabb::EMPTY;
    for t in 0..count {
        for corner in corners_of(t) {
            root_bounds.grow(corner);
        }
    }
    let extent = sub(root_bounds.hi, root_bounds.lo);
    let origin = box_origin(&root_bounds);
    let (nodes, corners, slots, pieces) =
        match pieces::piece_counts(count, corners_of, length(extent)) {
            None => {
                let (nodes, corners, slots) = build_whole(source, origin);
                (nodes, corners, slots, None)
            }
            Some(counts) => {
                let (nodes, corners, slots, pieces) = build_in_pieces(source, &counts, origin);
                (nodes, corners, slots, Some(pieces))
            }
        };
    (nodes, corners, slots, root_bounds, pieces, origin)
}

/// The boxes' origin for a mesh whose box is `bounds` ([`TriangleBvh::origin`]): along
/// each axis, the box's centre when the box lies farther from zero than it is long,
/// else zero (also for an empty or non-finite box).
fn box_origin(bounds: &Aabb) -> P3 {
    [0, 1, 2].map(|k| {
        let (lo, hi) = (bounds.lo[k], bounds.hi[k]);
        let centre = lo / 2.0 + hi / 2.0;
        let far = lo > 0.0 && lo > hi - lo || hi < 0.0 && -hi > hi - lo;
        if far && centre.is_finite() {
            centre
        } else {
            0.0
        }
    })
}

/// Which points make triangle `t`, for [`Source`].
trait PointsOf: Fn(usize) -> [u32; 3] + Sync {}
impl<F: Fn(usize) -> [u32; 3] + Sync> PointsOf for F {}

/// Point `v`, for [`Source`].
trait PointAt: Fn(u32) -> P3 + Sync {}
impl<F: Fn(u32) -> P3 + Sync> PointAt for F {}

/// The triangles an index is built over: `count` of them, triangle `t` made of points
/// `points_of(t)` (each below `point_count`), point `v` being `point(v)`.
struct Source<T, P> {
    count: usize,
    point_count: usize,
    points_of: T,
    point: P,
}

impl<T: PointsOf, P: PointAt> Source<T, P> {
    /// The corners of triangle `t`.
    #[inline]
    fn corners(&self, t: usize) -> [P3; 3] {
        (self.points_of)(t).map(|v| (self.point)(v))
    }

    /// The corners of the triangles `order` names, in that order, each point stored
    /// once.
    fn gather(&self, order: impl ExactSizeIterator<Item = usize>) -> CornerStore {
        CornerStore::gather(order, self.point_count, &self.points_of, &self.point)
    }
}

/// A NaN coordinate (from infinite or NaN corners, which callers should not pass)
/// becomes the one canonical NaN: the split's `total_cmp` orders NaNs by their bits,
/// which arithmetic does not fix, and the tree must not depend on them.
fn canonical(p: P3) -> P3 {
    p.map(|x| if x.is_nan() { f64::NAN } else { x })
}

/// [`build`] with a leaf entry per triangle: the nodes, the corners in leaf order and
/// where each triangle went.
fn build_whole(
    source: &Source<impl PointsOf, impl PointAt>,
    origin: P3,
) -> (Vec<WideNode>, CornerStore, Vec<u32>) {
    // The centroids, kept for the split only: recomputing them inside the median
    // selection's comparisons made the dragon's index build about 0.3 s slower.
    let mut order: Vec<Split> = (0..source.count)
        .into_par_iter()
        .map(|entry| {
            let c = source.corners(entry);
            Split {
                centroid: canonical([0, 1, 2].map(|k| (c[0][k] + c[1][k] + c[2][k]) / 3.0)),
                entry: entry as u32,
            }
        })
        .collect();
    partition(&mut order);
    let corners = source.gather(order.iter().map(|split| split.entry as usize));
    let mut slots = vec![0u32; order.len()];
    for (slot, split) in order.iter().enumerate() {
        slots[split.entry as usize] = slot as u32;
    }
    drop(order);
    let mut nodes = wide_nodes(corners.len());
    fill_boxes(&mut nodes, origin, |entry| {
        let c = corners.get(entry);
        (c, pieces::piece_box(&c, 0, 1))
    });
    (nodes, corners, slots)
}

/// [`build`] with triangle `t` cut into `counts[t]` pieces: a leaf entry per piece.
/// Triangles are numbered in the order the leaves first meet them. Returns the nodes,
/// the corners in that order, where each triangle went and each leaf entry's triangle.
fn build_in_pieces(
    source: &Source<impl PointsOf, impl PointAt>,
    counts: &[u8],
    origin: P3,
) -> (Vec<WideNode>, CornerStore, Vec<u32>, Vec<u32>) {
    // first[t]: the number of triangle t's first piece; pieces are numbered triangle
    // by triangle (u32: the budget keeps their count within PIECES_PER_TRIANGLE times the triangles').
    let mut first = Vec::with_capacity(counts.len() + 1);
    let mut total = 0u32;
    for &k in counts {
        first.push(total);
        total += u32::from(k);
    }
    first.push(total);
    let triangle_and_piece = |entry: u32| {
        let t = first.partition_point(|&f| f <= entry) - 1;
        (t, (entry - first[t]) as usize, usize::from(counts[t]))
    };
    let mut splits: Vec<Split> = (0..total)
        .into_par_iter()
        .map(|entry| {
            let (t, j, k) = triangle_and_piece(entry);
            let c = source.corners(t);
            let centroid = canonical(if k == 1 {
                [0, 1, 2].map(|i| (c[0][i] + c[1][i] + c[2][i]) / 3.0)
            } else {
                pieces::piece_centre(&c, j, k)
            });
            Split { centroid, entry }
        })
        .collect();
    partition(&mut splits);
    let order: Vec<u32> = splits.iter().map(|split| split.entry).collect();
    drop(splits);
    let mut slots = vec![u32::MAX; counts.len()];
    // by_slot[s]: the triangle numbered s, the inverse of `slots`.
    let mut by_slot = Vec::with_capacity(counts.len());
    let mut leaf_triangles = Vec::with_capacity(order.len());
    for &entry in &order {
        let (t, _, _) = triangle_and_piece(entry);
        if slots[t] == u32::MAX {
            slots[t] = by_slot.len() as u32;
            by_slot.push(t);
        }
        leaf_triangles.push(slots[t]);
    }
    let corners = source.gather(by_slot.iter().copied());
    drop(by_slot);
    let mut nodes = wide_nodes(order.len());
    fill_boxes(&mut nodes, origin, |entry| {
        let (_, j, k) = triangle_and_piece(order[entry]);
        let c = corners.get(leaf_triangles[entry] as usize);
        (c, pieces::piece_box(&c, j, k))
    });
    (nodes, corners, slots, leaf_triangles)
}

/// Ranges at least this long are split on both cores (below it, handing work to rayon
/// costs more than it saves). `tests/suite/threads.rs` builds an index above this size to
/// cover the parallel path; raise both together.
const PARALLEL_PARTITION: usize = 1 << 14;

/// A leaf entry (a triangle, or a piece of one) and its centroid, as [`partition`]
/// orders them.
///
/// Why the centroid travels with the number (32 bytes instead of 4 and a table of
/// centroids): the selections compare centroids, and each comparison read two of them
/// from the table at random. With them side by side the index build of
/// stanford_dragon_vrip_res2 took 491 M instructions instead of 545 M, and the
/// simplifier's setup on the dragon 414 ms instead of 450 ms (same tree).
#[derive(Clone, Copy, Debug)]
struct Split {
    centroid: P3,
    entry: u32,
}

/// Reorders `order` (entries: triangles, or pieces of them) so that every range of the
/// binary tree holds its entries: a range of more than [`LEAF_SIZE`] is split at its
/// middle, the lower half holding the entries whose centroids come first along the
/// longest axis of the range's centroid box (by coordinate, then by number).
///
/// Each range is split by one selection on its own elements, whichever core does it
/// and whenever, so the result is the same with any number of threads.
fn partition(order: &mut [Split]) {
    if order.len() <= LEAF_SIZE {
        return;
    }
    let mut centroid_box = Aabb::EMPTY;
    for split in order.iter() {
        centroid_box.grow(split.centroid);
    }
    let extent = sub(centroid_box.hi, centroid_box.lo);
    let axis = if extent[0] >= extent[1] && extent[0] >= extent[2] {
        0
    } else if extent[1] >= extent[2] {
        1
    } else {
        2
    };
    let mid = order.len() / 2;
    order.select_nth_unstable_by(mid, |x, y| {
        x.centroid[axis]
            .total_cmp(&y.centroid[axis])
            .then(x.entry.cmp(&y.entry))
    });
    let parallel = order.len() >= PARALLEL_PARTITION;
    let (lower, upper) = order.split_at_mut(mid);
    if parallel {
        rayon::join(|| partition(lower), || partition(upper));
    } else {
        partition(lower);
        partition(upper);
    }
}

/// The nodes of the tree over `n` triangles in leaf order, with their children and
/// leaf ranges set and every box empty (see [`fill_boxes`]): the ranges of
/// [`partition`], two binary levels a node, numbered in the order a depth-first walk
/// (last child first) meets them.
fn wide_nodes(n: usize) -> Vec<WideNode> {
    let mut nodes = Vec::with_capacity(wide_node_count(n));
    if n == 0 {
        return nodes;
    }
    nodes.push(WideNode::EMPTY);
    // (wide node, its range of entries)
    let mut stack = vec![(0usize, 0usize, n)];
    while let Some((w, start, end)) = stack.pop() {
        // The children's ranges: the quarters of a range, a half where the half is a
        // leaf; a root that is itself a leaf is its node's only child.
        let mut ranges = [(0usize, 0usize); WIDTH];
        let mut lanes = 0;
        if end - start <= LEAF_SIZE {
            ranges[0] = (start, end);
            lanes = 1;
        } else {
            let mid = start + (end - start) / 2;
            for (s, e) in [(start, mid), (mid, end)] {
                if e - s <= LEAF_SIZE {
                    ranges[lanes] = (s, e);
                    lanes += 1;
                } else {
                    let m = s + (e - s) / 2;
                    ranges[lanes] = (s, m);
                    ranges[lanes + 1] = (m, e);
                    lanes += 2;
                }
            }
        }
        let mut wide = WideNode::EMPTY;
        wide.lanes = lanes as u8;
        for (i, &(s, e)) in ranges[..lanes].iter().enumerate() {
            if e - s <= LEAF_SIZE {
                wide.child[i] = s as u32;
                wide.leaf_count[i] = (e - s) as u8;
            } else {
                wide.child[i] = nodes.len() as u32;
                stack.push((nodes.len(), s, e));
                nodes.push(WideNode::EMPTY);
            }
        }
        nodes[w] = wide;
    }
    nodes
}

/// How many nodes [`build`] makes for `n` triangles: one if there are any, plus those
/// of each child range above a leaf's size. Why exactly: a vector grown by doubling
/// holds up to twice the room it needs. At each depth the ranges have at most two
/// distinct sizes, so remembering the sizes seen keeps this O(log n).
fn wide_node_count(n: usize) -> usize {
    fn below(n: usize, seen: &mut Vec<(usize, usize)>) -> usize {
        // Nodes for a range of `n` triangles that has a node of its own.
        if let Some(&(_, c)) = seen.iter().find(|(m, _)| *m == n) {
            return c;
        }
        let mut c = 1;
        if n > LEAF_SIZE {
            for half in [n / 2, n - n / 2] {
                if half > LEAF_SIZE {
                    for quarter in [half / 2, half - half / 2] {
                        if quarter > LEAF_SIZE {
                            c += below(quarter, seen);
                        }
                    }
                }
            }
        }
        seen.push((n, c));
        c
    }
    if n == 0 {
        0
    } else {
        below(n, &mut Vec::new())
    }
}

/// Sets the boxes of each child of each node: the box of its corners and the box of
/// its unit normals, both rounded outward to `f32` (the normals' then to steps of 1/127,
/// [`NormalBox::around`]). A triangle whose normal is shorter
/// than [`MIN_PRUNING_LENGTH`] (but not zero), infinite or NaN counts as facing every
/// way; a zero-area one has no direction and no say.
///
/// Two sweeps: the leaf children first, node by node on both cores (each reads only
/// its own entries: the triangles' normals, a square root and three divisions each,
/// were most of the time, on one core while the other had finished its share of the
/// setup), then the inner children bottom-up on one core (a child node always comes
/// after its parent, see [`wide_nodes`]; each is a union of at most four lanes). Each
/// box is made by the same operations in the same order either way, so the tree is
/// the same, bit for bit, with any number of threads.
///
/// An inner child's position box is the union of its node's lanes: the same bits as
/// rounding the `f64` box of all its corners, up to the sign of a zero bound, since
/// rounding outward is monotone (the least of the rounded values is the rounded least
/// value). (`min` and `max` of 0.0 and −0.0 keep whichever came first, so the sign of
/// a zero bound depends on the order of the corners; every reader compares or squares
/// the bounds, where the two zeros are equal.)
///
/// `entry(e)` gives leaf entry `e`'s triangle and its box (the triangle's, or its
/// piece's).
fn fill_boxes(
    nodes: &mut [WideNode],
    origin: P3,
    entry: impl Fn(usize) -> ([P3; 3], (P3, P3)) + Sync,
) {
    nodes.par_iter_mut().for_each(|node| {
        for i in 0..usize::from(node.lanes) {
            let Some(entries) = node.leaf_entries(i) else {
                continue;
            };
            let mut normals = Box32::EMPTY;
            let mut bounds = Aabb::EMPTY;
            for e in entries {
                let ([a, b, c], (lo, hi)) = entry(e);
                bounds.add(&Aabb { lo, hi });
                let normal = cross(sub(b, a), sub(c, a));
                let length = length(normal);
                if length >= MIN_PRUNING_LENGTH && length.is_finite() {
                    let unit = normal.map(|x| x / length);
                    normals.grow(&Box32::around(unit, unit));
                } else if normal != [0.0; 3] {
                    normals.grow(&Box32::around([-1.0; 3], [1.0; 3]));
                }
            }
            node.set_child(
                i,
                &Box32::relative(bounds.lo, bounds.hi, origin),
                &NormalBox::around(&normals),
            );
        }
    });
    for w in (0..nodes.len()).rev() {
        for i in 0..usize::from(nodes[w].lanes) {
            if nodes[w].leaf_count[i] > 0 {
                continue;
            }
            let mut position = Box32::EMPTY;
            let mut normals = NormalBox::EMPTY;
            let child = &nodes[nodes[w].child[i] as usize];
            for j in 0..usize::from(child.lanes) {
                position.grow(&Box32 {
                    lo: [0, 1, 2].map(|k| child.lo[k][j]),
                    hi: [0, 1, 2].map(|k| child.hi[k][j]),
                });
                normals.grow(&NormalBox {
                    lo: [0, 1, 2].map(|k| child.normal_lo[k][j]),
                    hi: [0, 1, 2].map(|k| child.normal_hi[k][j]),
                });
            }
            nodes[w].set_child(i, &position, &normals);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The node whose size the normal boxes' steps were chosen for (BENCHMARKS.md,
    /// "The budget, array by array").
    #[test]
    fn a_wide_node_takes_144_bytes() {
        assert_eq!(std::mem::size_of::<WideNode>(), 144);
    }

    /// A box of normals in steps holds the bounds it was made from, is at most a step
    /// wider on each side, and stays empty when empty.
    #[test]
    fn normal_boxes_in_steps_round_outward() {
        for x in [
            -1.0f32,
            -0.5,
            -1e-9,
            0.0,
            1e-9,
            0.3,
            0.999_999,
            1.0,
            1.000_000_1,
        ] {
            let b = NormalBox::around(&Box32 {
                lo: [x; 3],
                hi: [x; 3],
            });
            let (lo, hi) = (
                f32::from(b.lo[0]) / NORMAL_STEPS,
                f32::from(b.hi[0]) / NORMAL_STEPS,
            );
            // (Beyond 1, clamped: within the facing test's margin of the bound.)
            assert!(lo <= x && (hi >= x || x > 1.0), "{x}: {lo} {hi}");
            assert!(
                x - lo <= 1.0 / NORMAL_STEPS && hi - x <= 1.0 / NORMAL_STEPS,
                "{x}"
            );
        }
        let half = NormalBox::around(&Box32::around([0.5; 3], [0.5; 3]));
        assert_eq!((half.lo, half.hi), ([63; 3], [64; 3]));
        let empty = NormalBox::around(&Box32::EMPTY);
        assert_eq!(empty, NormalBox::EMPTY);
        assert!(empty.lo[0] > empty.hi[0]);
    }

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
    }

    /// The reserved node count is the count the build makes.
    #[test]
    fn the_node_count_is_exact() {
        for n in [0usize, 1, 4, 5, 9, 17, 100, 1000, 4097] {
            let source = Source {
                count: n,
                point_count: 3 * n,
                points_of: |t: usize| [0, 1, 2].map(|k| (3 * t + k) as u32),
                point: |v: u32| {
                    let x = f64::from(v / 3);
                    [[x, 0.0, 0.0], [x, 1.0, 0.0], [x, 0.0, 1.0]][v as usize % 3]
                },
            };
            let (nodes, ..) = build(&source);
            assert_eq!(nodes.len(), wide_node_count(n), "{n} triangles");
        }
    }

    /// Every triangle sits in exactly one leaf child, and every child's box holds its
    /// triangles.
    #[test]
    fn the_wide_tree_covers_every_triangle_once() {
        let mut corners = Vec::new();
        for i in 0..97 {
            let x = f64::from(i) * 0.37;
            corners.push([[x, 0.0, 0.1 * x], [x + 1.0, 0.5, 0.0], [x, 1.0, -0.2 * x]]);
        }
        let (bvh, slots) = TriangleBvh::from_corners(corners.clone());
        let mut seen = vec![0u32; corners.len()];
        let mut stack = vec![(
            0u32,
            Box32::around([f64::NEG_INFINITY; 3], [f64::INFINITY; 3]),
        )];
        while let Some((w, parent)) = stack.pop() {
            let node = &bvh.nodes[w as usize];
            assert!((1..=WIDTH as u8).contains(&node.lanes));
            for i in 0..usize::from(node.lanes) {
                let lane = Box32 {
                    lo: [0, 1, 2].map(|k| node.lo[k][i]),
                    hi: [0, 1, 2].map(|k| node.hi[k][i]),
                };
                for k in 0..3 {
                    assert!(parent.lo[k] <= lane.lo[k] && lane.hi[k] <= parent.hi[k]);
                }
                let count = usize::from(node.leaf_count[i]);
                if count == 0 {
                    stack.push((node.child[i], lane));
                    continue;
                }
                let start = node.child[i] as usize;
                for (entry, seen) in seen.iter_mut().enumerate().skip(start).take(count) {
                    assert_eq!(bvh.triangle_of(entry), entry);
                    *seen += 1;
                    for corner in &bvh.corners.get(entry) {
                        for (k, &x) in corner.iter().enumerate() {
                            assert!(f64::from(lane.lo[k]) <= x && x <= f64::from(lane.hi[k]));
                        }
                    }
                }
            }
        }
        assert!(seen.iter().all(|&n| n == 1), "{seen:?}");
        assert!(bvh.pieces.is_none());
        for (i, &slot) in slots.iter().enumerate() {
            assert_eq!(bvh.corners(slot), corners[i]);
        }
    }

    /// A fan of long slivers across a grid of small triangles, and a cone of slivers
    /// through it: the kind of mesh that is indexed in pieces.
    fn fan_over_grid() -> Vec<[P3; 3]> {
        let mut corners = Vec::new();
        for i in 0..30 {
            for j in 0..30 {
                let (x, y) = (f64::from(i) * 0.1, f64::from(j) * 0.1);
                corners.push([[x, y, 0.0], [x + 0.1, y, 0.0], [x, y + 0.1, 0.0]]);
                corners.push([
                    [x + 0.1, y, 0.0],
                    [x + 0.1, y + 0.1, 0.0],
                    [x, y + 0.1, 0.0],
                ]);
            }
        }
        for i in 0..200 {
            let a = f64::from(i) * 0.007;
            let b = a + 0.007;
            corners.push([
                [0.0, 0.0, 0.05],
                [3.0 * a.cos(), 3.0 * a.sin(), 0.05],
                [3.0 * b.cos(), 3.0 * b.sin(), 0.05],
            ]);
            corners.push([
                [1.5, 1.5, 1.0],
                [3.0 * b.cos(), 3.0 * b.sin(), -0.5],
                [3.0 * a.cos(), 3.0 * a.sin(), -0.5],
            ]);
        }
        corners
    }

    /// Every box is the same bits with one thread and with three (`fill_boxes` fills
    /// the leaf lanes on the thread pool, then the inner ones in order), with and
    /// without pieces.
    #[test]
    fn boxes_do_not_depend_on_the_thread_count() {
        // The boxes' bits, and whether the tree has pieces.
        let bits = |corners: &Vec<[P3; 3]>, threads: usize| -> (Vec<u32>, bool) {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .expect("a thread pool");
            let (tree, _) = pool.install(|| TriangleBvh::from_corners(corners.clone()));
            let bits = (tree.nodes.iter())
                .flat_map(|n| {
                    let steps = [n.normal_lo, n.normal_hi].map(|a| a.map(|l| l.map(f32::from)));
                    [n.lo, n.hi, steps[0], steps[1]]
                })
                .flatten()
                .flatten()
                .map(f32::to_bits)
                .collect();
            (bits, tree.pieces.is_some())
        };
        let with_pieces = fan_over_grid();
        let grid = with_pieces[..1800].to_vec();
        for (corners, pieces) in [(grid, false), (with_pieces, true)] {
            let one = bits(&corners, 1);
            assert!(one.0.len() > 1000, "a tree of many nodes");
            assert_eq!(one.1, pieces);
            assert_eq!(one, bits(&corners, 3));
        }
    }

    /// With pieces, every triangle is found through its pieces: each point of a
    /// triangle lies in the box of a leaf child that holds one of its pieces, and the
    /// numbering still maps every input triangle to its corners.
    #[test]
    fn pieces_cover_their_triangles() {
        let corners = fan_over_grid();
        let (bvh, slots) = TriangleBvh::from_corners(corners.clone());
        let pieces = bvh.pieces.as_ref().expect("the slivers are cut");
        assert!(pieces.len() > corners.len());
        for (i, &slot) in slots.iter().enumerate() {
            assert_eq!(bvh.corners(slot), corners[i]);
        }
        // Leaf children: their box and the triangles of their entries.
        let mut leaves: Vec<(Box32, Vec<usize>)> = Vec::new();
        for node in &bvh.nodes {
            for i in 0..usize::from(node.lanes) {
                let count = usize::from(node.leaf_count[i]);
                if count > 0 {
                    let start = node.child[i] as usize;
                    let lane = Box32 {
                        lo: [0, 1, 2].map(|k| node.lo[k][i]),
                        hi: [0, 1, 2].map(|k| node.hi[k][i]),
                    };
                    leaves.push((
                        lane,
                        (start..start + count).map(|e| bvh.triangle_of(e)).collect(),
                    ));
                }
            }
        }
        let entries: usize = leaves.iter().map(|l| l.1.len()).sum();
        assert_eq!(entries, pieces.len());
        for t in 0..bvh.triangle_count() {
            let [a, b, c] = bvh.corners(t as u32);
            for (u, v) in [
                (0.0, 0.0),
                (1.0, 0.0),
                (0.0, 1.0),
                (0.5, 0.5),
                (0.3, 0.1),
                (0.05, 0.9),
            ] {
                let p = [0, 1, 2].map(|k| a[k] + u * (b[k] - a[k]) + v * (c[k] - a[k]));
                let held = leaves.iter().any(|(lane, triangles)| {
                    triangles.contains(&t)
                        && (0..3)
                            .all(|k| f64::from(lane.lo[k]) <= p[k] && p[k] <= f64::from(lane.hi[k]))
                });
                assert!(held, "triangle {t}: {p:?} in no leaf of its pieces");
            }
        }
    }

    /// With pieces, the searches answer as brute force does: distances, the nearest
    /// triangles (each once), and the facing-away search.
    #[test]
    fn searches_over_pieces_match_brute_force() {
        let (bvh, _) = TriangleBvh::from_corners(fan_over_grid());
        assert!(bvh.pieces.is_some());
        assert_eq!(bvh.origin, [0.0; 3]);
        searches_match_brute_force(&bvh, [0.0; 3]);
    }

    /// `corners` moved by `offset`.
    fn moved(corners: &[[P3; 3]], offset: P3) -> Vec<[P3; 3]> {
        (corners.iter())
            .map(|t| t.map(|p| [0, 1, 2].map(|k| p[k] + offset[k])))
            .collect()
    }

    /// Far from zero (a scan in UTM coordinates), the boxes are kept about an origin
    /// near the mesh, so they stay as tight as at zero (in `f32` about zero, 5e6 has
    /// steps of 0.5, wider than a leaf of these triangles: every search then visited
    /// most of the tree), and every search still answers as brute force does. An
    /// axis along which the mesh reaches zero keeps a zero origin.
    #[test]
    fn far_from_zero_the_boxes_stay_tight_and_the_answers_exact() {
        let offset = [5e6, -3.25e6, 0.0];
        for (corners, pieces) in [
            (fan_over_grid()[..1800].to_vec(), false),
            (fan_over_grid(), true),
        ] {
            let (bvh, _) = TriangleBvh::from_corners(moved(&corners, offset));
            assert_eq!(bvh.pieces.is_some(), pieces);
            assert!((bvh.origin[0] - 5e6).abs() < 10.0, "{:?}", bvh.origin);
            assert!((bvh.origin[1] + 3.25e6).abs() < 10.0, "{:?}", bvh.origin);
            assert_eq!(bvh.origin[2], 0.0);
            // Each leaf child's box holds its triangles and is at most a hair wider
            // (checked without pieces, where an entry is a whole triangle).
            for node in (bvh.nodes.iter()).filter(|_| !pieces) {
                for i in 0..usize::from(node.lanes) {
                    let Some(entries) = node.leaf_entries(i) else {
                        continue;
                    };
                    let mut exact = Aabb::EMPTY;
                    for entry in entries {
                        for corner in bvh.corners.get(bvh.triangle_of(entry)) {
                            let relative = bvh.relative(corner);
                            for (k, &x) in relative.iter().enumerate() {
                                assert!(f64::from(node.lo[k][i]) <= x);
                                assert!(x <= f64::from(node.hi[k][i]));
                            }
                            exact.grow(relative);
                        }
                    }
                    for k in 0..3 {
                        let wider = f64::from(node.hi[k][i])
                            - f64::from(node.lo[k][i])
                            - (exact.hi[k] - exact.lo[k]);
                        assert!(wider < 1e-5, "a box {wider} wider than its triangles");
                    }
                }
            }
            searches_match_brute_force(&bvh, offset);
        }
    }

    /// Random points about `fan_over_grid` moved by `offset`: `bvh`'s distances,
    /// nearest triangles and facing-away answers are brute force's.
    fn searches_match_brute_force(bvh: &TriangleBvh, offset: P3) {
        let squared = |p: P3, t: u32| {
            let [a, b, c] = bvh.corners(t);
            triangle_distance2(p, a, b, c)
        };
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut near = Vec::new();
        for _ in 0..400 {
            let p = [next() * 3.4 - 0.2, next() * 3.4 - 0.2, next() * 1.2 - 0.4];
            let p = [0, 1, 2].map(|k| p[k] + offset[k]);
            let mut all: Vec<(f64, u32)> = (0..bvh.triangle_count() as u32)
                .map(|t| (squared(p, t), t))
                .collect();
            all.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            assert_eq!(bvh.distance(p), Some(all[0].0.sqrt()));
            let nearest = bvh.nearest_triangles(p, 1.5, 1e-9, 8, &mut near);
            assert_eq!(nearest, Some(all[0].1));
            let limit = all[0].0.sqrt() * 1.5 + 1e-9;
            let mut expected: Vec<u32> = all
                .iter()
                .filter(|x| x.0.sqrt() <= limit)
                .take(8)
                .map(|x| x.1)
                .collect();
            expected.sort_unstable();
            assert_eq!(near, expected, "at {p:?}");
            let normal = [next() - 0.5, next() - 0.5, next() - 0.5];
            let radius = next() * 0.3;
            let brute = (0..bvh.triangle_count() as u32).any(|t| {
                let [a, b, c] = bvh.corners(t);
                let n = cross(sub(b, a), sub(c, a));
                let d = n[0] * normal[0] + n[1] * normal[1] + n[2] * normal[2];
                d <= 0.0 && n != [0.0; 3] && squared(p, t) <= radius * radius
            });
            if brute {
                assert!(bvh.any_facing_away(p, radius, normal), "at {p:?}");
            }
        }
    }

    /// The tree does not depend on the bits of NaN coordinates (which arithmetic does
    /// not fix): corners with NaNs of assorted payloads give the same leaf order as the
    /// same corners with one NaN throughout.
    #[test]
    fn nan_payloads_do_not_change_the_tree() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        for n in [6usize, 9, 17, 40, 100] {
            for _ in 0..20 {
                let mut with_payloads = Vec::new();
                let mut canonical = Vec::new();
                for _ in 0..n {
                    let mut triangle = [[0.0; 3]; 3];
                    let mut plain = [[0.0; 3]; 3];
                    for (corner, plain_corner) in triangle.iter_mut().zip(plain.iter_mut()) {
                        for (x, y) in corner.iter_mut().zip(plain_corner.iter_mut()) {
                            let r = next();
                            if r % 4 == 0 {
                                // A quiet NaN with a payload, of either sign.
                                *x = f64::from_bits(0x7ff8_0000_0000_0000 | (r >> 20) | (r << 63));
                                *y = f64::NAN;
                            } else {
                                *x = (r >> 11) as f64 / (1u64 << 53) as f64;
                                *y = *x;
                            }
                        }
                    }
                    with_payloads.push(triangle);
                    canonical.push(plain);
                }
                let (_, slots) = TriangleBvh::from_corners(with_payloads);
                let (_, expected) = TriangleBvh::from_corners(canonical);
                assert_eq!(slots, expected, "{n} triangles");
            }
        }
    }
}
