//! Spatial tiles: a mesh cut into pieces that are simplified one at a time, each with
//! its border locked, and welded back together.
//!
//! This is the geometry of `qem tiles split | simplify | merge` (and of the
//! out-of-core and distributed runs built on it); the files, the manifest and the
//! bookkeeping of which tile is done are `tiles::jobs` (feature `io`), which the command and
//! the Python package both call.
//!
//! - [`Tiling::new`] welds the vertices with bit-identical positions (so an STL soup,
//!   whose facets share no vertex, has its border found by position), and cuts the
//!   triangles into tiles by a k-d bisection of their centroids (`Cut`): the set (or
//!   part of it) whose centroids spread furthest along an axis is cut at the median
//!   along that axis, so tiles get equal triangle counts wherever the surface lies in
//!   its bounding box. A regular grid over the box would leave most cells of a surface
//!   empty and the others uneven. The medians are those of a sample of the centroids
//!   (`Sample`): every centroid up to [`SAMPLE_CAP`] triangles (equal counts within
//!   one), beyond that every `2^k`-th, so that the split of a file streamed from disk
//!   (`jobs::split`) needs no list of every triangle and cuts exactly as this does.
//! - [`Tiling::tile`] gives one tile as its own mesh, its **border vertices first**: a
//!   border vertex is one that triangles of more than one tile use. Each group is
//!   numbered in the order the tile's triangles (in input order) first use it.
//!   [`Tile::locked_vertices`] are those and their neighbours in the tile: locking them
//!   (`SimplifyOptions::with_locked_vertices`) leaves every triangle at the border as
//!   it is, so the tiles still meet, edge for edge, after each is simplified on its
//!   own. Locking the border vertices alone is not enough: each side may then absorb
//!   the vertices next to a border vertex into its border neighbours, and both sides
//!   build the same triangle across the corner, which overlaps (on a 4M-triangle
//!   sphere in 5 tiles at ratio 0.1: 44 edges with three or more faces, all between
//!   two border vertices).
//! - [`Tile::border_first`] finds a simplified tile's border vertices again (by their
//!   bit-identical positions, which locking keeps) and puts them first;
//!   [`Welder`] joins tiles, merging each border vertex with the earlier tiles' vertex
//!   at the same position.
//!
//! Everything is deterministic: the same mesh and tile count give the same tiles, bit
//! for bit (ties between equal centroid coordinates go by triangle number).
#[cfg(feature = "io")]
mod split;

#[cfg(feature = "io")]
pub mod budget;
#[cfg(feature = "io")]
pub mod jobs;

use crate::clean::{coordinate_bits, weld_in_place};
#[cfg(feature = "io")]
use crate::simplify::NOT_CARRIED;
use crate::IndexedMesh;
#[cfg(feature = "io")]
use qem_core::Quadric;
use rustc_hash::FxHashMap;

/// A mesh's triangles cut into spatial tiles (see the [module docs](self)).
#[derive(Clone, Debug)]
pub struct Tiling {
    /// The input, welded (bit-identical positions merged), positions and triangles only.
    mesh: IndexedMesh,
    /// The triangles of every tile, tile after tile, each tile's in input order.
    triangles: Vec<u32>,
    /// Where each tile's triangles start in `triangles` (one more entry than tiles).
    starts: Vec<usize>,
    /// Whether triangles of more than one tile use each vertex.
    border: Vec<bool>,
    /// Each tile's box of triangle centroids.
    boxes: Vec<([f64; 3], [f64; 3])>,
    /// Vertices merged into another with the same position by the weld.
    welded: usize,
}

/// One tile as a mesh of its own.
#[derive(Clone, Debug, PartialEq)]
pub struct Tile {
    /// The tile's vertices (border vertices first) and triangles.
    pub mesh: IndexedMesh,
    /// How many of the first vertices are border vertices (used by other tiles too).
    pub border_vertices: usize,
}

impl Tiling {
    /// Cuts `mesh` into `tiles` tiles (at least 1, at most one per triangle) of equal
    /// triangle counts (within one up to [`SAMPLE_CAP`] triangles; about equal beyond,
    /// see the module docs). Attributes are not carried: tiles hold positions and
    /// triangles only.
    ///
    /// Memory: besides the mesh (24 bytes a vertex, 12 a triangle), welded in place,
    /// the weld holds 9 bytes a vertex, the cut's sample 32 bytes a triangle up to
    /// [`SAMPLE_CAP`] of them, the tiles' lists 4 bytes a triangle and the border flags
    /// 5 bytes a vertex. `mesh` is expected to have passed
    /// [`IndexedMesh::validate`]; triangles with an index out of range are dropped
    /// rather than trusted.
    ///
    /// ```
    /// use qem_mesh::tiles::Tiling;
    /// use qem_mesh::IndexedMesh;
    /// // Two triangles side by side, sharing the edge 1-2.
    /// let mesh = IndexedMesh::new(
    ///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
    ///     vec![[0, 1, 2], [1, 3, 2]],
    /// );
    /// let tiling = Tiling::new(mesh, 2);
    /// assert_eq!(tiling.len(), 2);
    /// let first = tiling.tile(0);
    /// assert_eq!(first.border_vertices, 2); // vertices 1 and 2, now numbered 0 and 1
    /// assert_eq!(first.mesh.positions[..2], [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    /// ```
    pub fn new(mut mesh: IndexedMesh, tiles: usize) -> Tiling {
        // Only the exact weld: degenerate and duplicate faces are each tile's
        // simplifier's to drop, as an in-core run drops them after the same weld.
        // In place: one mesh at the peak, not the input and its welded copy.
        let welded = weld_in_place(&mut mesh);
        let count = mesh.triangles.len();
        let tiles = tiles.clamp(1, count.max(1));
        let corners = |t: &[u32; 3]| t.map(|v| mesh.positions[v as usize]);
        let mut sample = Sample::new();
        for (t, tri) in mesh.triangles.iter().enumerate() {
            sample.offer(t as u64, centroid(&corners(tri)));
        }
        let cut = Cut::new(sample, tiles);
        // Each triangle's tile, then the tiles' lists, each in input order (the file's
        // locality, and one answer).
        let tile_of: Vec<u32> = (mesh.triangles.iter().enumerate())
            .map(|(t, tri)| cut.tile_of(centroid(&corners(tri)), t as u64) as u32)
            .collect();
        let mut starts = vec![0usize; tiles + 1];
        for &k in &tile_of {
            starts[k as usize + 1] += 1;
        }
        for k in 0..tiles {
            starts[k + 1] += starts[k];
        }
        let mut next = starts.clone();
        let mut triangles = vec![0u32; count];
        for (t, &k) in tile_of.iter().enumerate() {
            triangles[next[k as usize]] = t as u32;
            next[k as usize] += 1;
        }
        drop(tile_of);
        let boxes = (starts.windows(2))
            .map(|w| {
                let part = &triangles[w[0]..w[1]];
                bounds(
                    part.iter()
                        .map(|&t| centroid(&corners(&mesh.triangles[t as usize]))),
                )
            })
            .collect();
        let border = border_flags(&mesh, &triangles, &starts);
        Tiling {
            mesh,
            triangles,
            starts,
            border,
            boxes,
            welded,
        }
    }

    /// The number of tiles.
    pub fn len(&self) -> usize {
        self.starts.len() - 1
    }

    /// Whether there are no tiles (never: a tiling has at least one, possibly empty).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The welded mesh the tiles are cut from (positions and triangles only).
    pub fn welded_mesh(&self) -> &IndexedMesh {
        &self.mesh
    }

    /// How many vertices the weld merged into another with the same position.
    pub fn welded_vertices(&self) -> usize {
        self.welded
    }

    /// The number of triangles in tile `k`.
    ///
    /// # Panics
    /// When `k >= self.len()`.
    pub fn triangle_count(&self, k: usize) -> usize {
        self.starts[k + 1] - self.starts[k]
    }

    /// The box (min, max) of tile `k`'s triangle centroids.
    ///
    /// # Panics
    /// When `k >= self.len()`.
    pub fn centroid_box(&self, k: usize) -> ([f64; 3], [f64; 3]) {
        self.boxes[k]
    }

    /// Tile `k` as a mesh: its triangles in input order, its border vertices first,
    /// then the others, each group in the order the triangles first use them
    /// (`TileBuilder`).
    ///
    /// # Panics
    /// When `k >= self.len()`.
    pub fn tile(&self, k: usize) -> Tile {
        let part = &self.triangles[self.starts[k]..self.starts[k + 1]];
        let mut builder = TileBuilder::default();
        for &t in part {
            let tri = self.mesh.triangles[t as usize];
            builder.push(tri.map(|v| {
                let p = self.mesh.positions[v as usize];
                (p, self.border[v as usize])
            }));
        }
        builder.finish()
    }
}

/// How many centroids the cut's sample holds at most (about 32 MiB): up to this many
/// triangles, the cut is made from every centroid.
pub const SAMPLE_CAP: usize = 1 << 20;

/// A triangle's centroid: each coordinate `(a + b + c) / 3` of its corners'.
#[inline]
pub(crate) fn centroid(corners: &[[f64; 3]; 3]) -> [f64; 3] {
    let [a, b, c] = corners;
    std::array::from_fn(|k| (a[k] + b[k] + c[k]) / 3.0)
}

/// The centroids a [`Cut`] is made from: of the triangles offered (numbered in input
/// order), every `stride`-th, the stride starting at 1 and doubling whenever more than
/// [`SAMPLE_CAP`] would be held (those off the new stride are let go). Which ones are
/// kept depends only on the count, so a mesh and the same triangles streamed give the
/// same sample.
#[derive(Clone, Debug)]
pub(crate) struct Sample {
    stride: u64,
    points: Vec<([f64; 3], u64)>,
}

impl Sample {
    pub(crate) fn new() -> Self {
        Sample {
            stride: 1,
            points: Vec::new(),
        }
    }

    /// Offers triangle `number`'s centroid (numbers offered in increasing order).
    #[inline]
    pub(crate) fn offer(&mut self, number: u64, centroid: [f64; 3]) {
        if number % self.stride != 0 {
            return;
        }
        self.points.push((centroid, number));
        if self.points.len() > SAMPLE_CAP {
            self.stride *= 2;
            let stride = self.stride;
            self.points.retain(|(_, n)| n % stride == 0);
        }
    }
}

/// A k-d cut of the triangles into tiles, made from a [`Sample`] of their centroids.
/// A part (at first the whole sample) to be cut into `n > 1` tiles is split along the
/// axis of the largest spread of its centroids (the first of equals), at the key
/// (coordinate, triangle number) of rank `len · ⌊n/2⌋ / n`: the keys below it go to the
/// first `⌊n/2⌋` tiles, the others to the rest. So a triangle's tile follows from its
/// centroid and number alone ([`tile_of`](Self::tile_of)), and with every centroid in
/// the sample, the tiles' counts are equal within one.
#[derive(Clone, Debug)]
pub(crate) struct Cut {
    nodes: Vec<CutNode>,
}

#[derive(Clone, Copy, Debug)]
enum CutNode {
    /// Keys below `key` along `axis` go to node `left`, the others to `left + 1`'s
    /// subtree at `right`.
    Split {
        axis: usize,
        key: (f64, u64),
        left: u32,
        right: u32,
    },
    /// Everything here goes to this tile.
    Tile(usize),
}

impl Cut {
    /// The cut into `tiles` tiles (at least 1) made from `sample`.
    pub(crate) fn new(sample: Sample, tiles: usize) -> Cut {
        let mut points = sample.points;
        let mut nodes = Vec::new();
        Self::build(&mut points, 0, tiles.max(1), &mut nodes);
        Cut { nodes }
    }

    fn build(
        part: &mut [([f64; 3], u64)],
        first: usize,
        tiles: usize,
        nodes: &mut Vec<CutNode>,
    ) -> u32 {
        let at = nodes.len() as u32;
        if tiles <= 1 || part.len() <= 1 {
            // The part's triangles go to its first tile; the others stay empty (with
            // every centroid sampled, only when there are fewer triangles than tiles).
            nodes.push(CutNode::Tile(first));
            return at;
        }
        let (min, max) = bounds(part.iter().map(|p| p.0));
        let axis = (0..3)
            .max_by(|&a, &b| {
                (max[a] - min[a])
                    .total_cmp(&(max[b] - min[b]))
                    .then(b.cmp(&a))
            })
            .unwrap_or(0);
        let left_tiles = tiles / 2;
        // Proportional, so that every tile ends up with its share (within one).
        let cut = part.len() * left_tiles / tiles;
        let by_key = |a: &([f64; 3], u64), b: &([f64; 3], u64)| {
            a.0[axis].total_cmp(&b.0[axis]).then(a.1.cmp(&b.1))
        };
        part.select_nth_unstable_by(cut, by_key);
        let key = (part[cut].0[axis], part[cut].1);
        nodes.push(CutNode::Tile(first)); // replaced below
        let (lo, hi) = part.split_at_mut(cut);
        let left = Self::build(lo, first, left_tiles, nodes);
        let right = Self::build(hi, first + left_tiles, tiles - left_tiles, nodes);
        nodes[at as usize] = CutNode::Split {
            axis,
            key,
            left,
            right,
        };
        at
    }

    /// The tile of triangle `number`, whose centroid is `centroid`.
    pub(crate) fn tile_of(&self, centroid: [f64; 3], number: u64) -> usize {
        let mut at = 0;
        loop {
            match self.nodes.get(at) {
                Some(&CutNode::Split {
                    axis,
                    key,
                    left,
                    right,
                }) => {
                    let below = centroid[axis].total_cmp(&key.0).then(number.cmp(&key.1));
                    at = if below.is_lt() { left } else { right } as usize;
                }
                Some(&CutNode::Tile(k)) => return k,
                None => return 0,
            }
        }
    }
}

/// Builds one tile from its triangles, given in input order as corners (position,
/// whether it is a border vertex): vertices welded by bit-identical position (`-0.0`
/// as `+0.0`, as the exact weld), the border ones numbered first, each group in the
/// order the triangles first use it. The one way a tile is numbered, in memory
/// ([`Tiling::tile`]) and from disk (`jobs::split`).
#[derive(Debug, Default)]
pub(crate) struct TileBuilder {
    number: FxHashMap<[u64; 3], u32>,
    positions: Vec<[f64; 3]>,
    border: Vec<bool>,
    triangles: Vec<[u32; 3]>,
}

impl TileBuilder {
    /// Adds a triangle.
    pub(crate) fn push(&mut self, corners: [([f64; 3], bool); 3]) {
        let t = corners.map(|(p, border)| {
            let fresh = self.positions.len() as u32;
            let n = *self.number.entry(position_key(p)).or_insert(fresh);
            if n == fresh {
                self.positions.push(p);
                self.border.push(border);
            }
            n
        });
        self.triangles.push(t);
    }

    /// The tile: border vertices first (see the type's docs).
    pub(crate) fn finish(self) -> Tile {
        let TileBuilder {
            number,
            positions,
            border,
            triangles,
        } = self;
        drop(number);
        let border_vertices = border.iter().filter(|&&b| b).count();
        let mut new_of = vec![0u32; positions.len()];
        let (mut b, mut o) = (0u32, border_vertices as u32);
        for (n, &is_border) in new_of.iter_mut().zip(&border) {
            let slot = if is_border { &mut b } else { &mut o };
            *n = *slot;
            *slot += 1;
        }
        let mut ordered = vec![[0.0; 3]; positions.len()];
        for (p, &n) in positions.iter().zip(&new_of) {
            ordered[n as usize] = *p;
        }
        let triangles = triangles
            .into_iter()
            .map(|t| t.map(|v| new_of[v as usize]))
            .collect();
        Tile {
            mesh: IndexedMesh::new(ordered, triangles),
            border_vertices,
        }
    }
}

/// The box (min, max) of `points`; an empty box (min > max) when there are none.
fn bounds(points: impl Iterator<Item = [f64; 3]>) -> ([f64; 3], [f64; 3]) {
    points.fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            (
                std::array::from_fn(|k| lo[k].min(p[k])),
                std::array::from_fn(|k| hi[k].max(p[k])),
            )
        },
    )
}

/// Whether triangles of more than one tile use each vertex of `mesh`.
fn border_flags(mesh: &IndexedMesh, triangles: &[u32], starts: &[usize]) -> Vec<bool> {
    const NONE: u32 = u32::MAX;
    let n = mesh.positions.len();
    // The first tile seen using each vertex.
    let mut first = vec![NONE; n];
    let mut border = vec![false; n];
    for (k, w) in starts.windows(2).enumerate() {
        for &t in &triangles[w[0]..w[1]] {
            for v in mesh.triangles[t as usize] {
                let v = v as usize;
                if v >= n {
                    continue;
                }
                if first[v] == NONE {
                    first[v] = k as u32;
                } else if first[v] != k as u32 {
                    border[v] = true;
                }
            }
        }
    }
    border
}

/// The bit pattern of a position, `-0.0` read as `+0.0` (as the exact weld does).
fn position_key(p: [f64; 3]) -> [u64; 3] {
    p.map(coordinate_bits)
}

impl Tile {
    /// The vertices to lock when this tile is simplified on its own: its border
    /// vertices and every vertex that shares a triangle with one, ascending.
    ///
    /// Why the neighbours too: a contraction changes only the triangles around its
    /// two vertices, and one whose two vertices are both locked is refused; so when
    /// every neighbour of a border vertex is locked, no contraction involves a border
    /// vertex, and every triangle with a border corner comes out as it went in (its
    /// other corners are neighbours, locked too). (Virtual pairs would reach past the
    /// neighbours: `qem tiles` refuses them.)
    ///
    /// ```
    /// use qem_mesh::tiles::Tile;
    /// use qem_mesh::IndexedMesh;
    /// // A strip of three triangles; vertex 0 is on the border.
    /// let tile = Tile {
    ///     mesh: IndexedMesh::new(
    ///         vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0], [2.0, 1.0, 0.0]],
    ///         vec![[0, 1, 2], [1, 3, 2], [1, 4, 3]],
    ///     ),
    ///     border_vertices: 1,
    /// };
    /// assert_eq!(tile.locked_vertices(), vec![0, 1, 2]);
    /// ```
    pub fn locked_vertices(&self) -> Vec<u32> {
        let n = self.mesh.positions.len();
        let border = self.border_vertices.min(n);
        let mut locked = vec![false; n];
        locked[..border].fill(true);
        for t in &self.mesh.triangles {
            if t.iter().any(|&v| (v as usize) < border) {
                for &v in t {
                    if let Some(l) = locked.get_mut(v as usize) {
                        *l = true;
                    }
                }
            }
        }
        (0..n as u32).filter(|&v| locked[v as usize]).collect()
    }

    /// `simplified` (the simplification of a tile whose border vertices, at
    /// `border`, were locked) as a tile: the vertices at the `border` positions first,
    /// in that order, then the others in their order.
    ///
    /// Locked vertices come out bit for bit where they were, so they are found by
    /// position. A border position no vertex of `simplified` has (its faces were all
    /// dropped as degenerate by the cleaning) is left out; were two vertices at one
    /// border position (a vertex placed exactly on a locked one), the first is the
    /// border vertex.
    ///
    /// ```
    /// use qem_mesh::tiles::Tile;
    /// use qem_mesh::IndexedMesh;
    /// let input = Tile {
    ///     mesh: IndexedMesh::new(
    ///         vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]],
    ///         vec![[2, 0, 1]],
    ///     ),
    ///     border_vertices: 2,
    /// };
    /// // A simplifier's output with the vertices in another order.
    /// let out = IndexedMesh::new(
    ///     vec![[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
    ///     vec![[0, 2, 1]],
    /// );
    /// let tile = Tile::border_first(&input.mesh.positions[..input.border_vertices], out);
    /// assert_eq!(tile.border_vertices, 2);
    /// assert_eq!(tile.mesh.positions, input.mesh.positions);
    /// assert_eq!(tile.mesh.triangles, vec![[2, 0, 1]]);
    /// ```
    pub fn border_first(border: &[[f64; 3]], simplified: IndexedMesh) -> Tile {
        Tile::border_first_numbered(border, simplified).0
    }

    /// [`border_first`](Self::border_first), and the new number of each vertex of
    /// `simplified` (for what goes with its vertices).
    pub(crate) fn border_first_numbered(
        border: &[[f64; 3]],
        simplified: IndexedMesh,
    ) -> (Tile, Vec<u32>) {
        let mut at: FxHashMap<[u64; 3], u32> = FxHashMap::default();
        at.reserve(simplified.positions.len().min(border.len()));
        // The first vertex at each position, so a duplicate is not taken for it.
        for (i, p) in simplified.positions.iter().enumerate().rev() {
            at.insert(position_key(*p), i as u32);
        }
        const UNSET: u32 = u32::MAX;
        let mut new_of = vec![UNSET; simplified.positions.len()];
        let mut positions = Vec::with_capacity(simplified.positions.len());
        for p in border {
            if let Some(&i) = at.get(&position_key(*p)) {
                if new_of[i as usize] == UNSET {
                    new_of[i as usize] = positions.len() as u32;
                    positions.push(simplified.positions[i as usize]);
                }
            }
        }
        let border_vertices = positions.len();
        for (i, p) in simplified.positions.iter().enumerate() {
            if new_of[i] == UNSET {
                new_of[i] = positions.len() as u32;
                positions.push(*p);
            }
        }
        let triangles = simplified
            .triangles
            .iter()
            .map(|t| t.map(|v| new_of.get(v as usize).copied().unwrap_or(v)))
            .collect();
        let tile = Tile {
            mesh: IndexedMesh::new(positions, triangles).with_attributes(simplified.attributes),
            border_vertices,
        };
        (tile, new_of)
    }
}

/// Joins tiles into one mesh, merging each tile's border vertices with the vertex an
/// earlier tile has at the same (bit-identical) position; the other vertices are
/// taken as they are. Positions and triangles only.
///
/// ```
/// use qem_mesh::tiles::{Tiling, Welder};
/// use qem_mesh::IndexedMesh;
/// let mesh = IndexedMesh::new(
///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
///     vec![[0, 1, 2], [1, 3, 2]],
/// );
/// let tiling = Tiling::new(mesh, 2);
/// let mut welder = Welder::default();
/// for k in 0..tiling.len() {
///     welder.push(&tiling.tile(k));
/// }
/// let joined = welder.finish();
/// assert_eq!(joined.vertex_count(), 4);
/// assert_eq!(joined.triangle_count(), 2);
/// ```
#[derive(Debug, Default)]
pub struct Welder {
    mesh: IndexedMesh,
    /// With [`push_carrying`](Self::push_carrying), each joined vertex's quadric:
    /// [`NOT_CARRIED`] for a border vertex. (Only the tile jobs, with `io`, carry.)
    #[cfg(feature = "io")]
    carried: Vec<Quadric>,
    /// The joined mesh's vertex at each border position seen so far.
    border: FxHashMap<[u64; 3], u32>,
}

impl Welder {
    /// Appends `tile`. Indices out of range in its triangles are kept as they are
    /// (offset like the others), for the joined mesh's validation to refuse.
    pub fn push(&mut self, tile: &Tile) {
        let base = self.mesh.positions.len();
        let mut number = Vec::with_capacity(tile.mesh.positions.len());
        for (i, p) in tile.mesh.positions.iter().enumerate() {
            let fresh = self.mesh.positions.len() as u32;
            let n = if i < tile.border_vertices {
                *self.border.entry(position_key(*p)).or_insert(fresh)
            } else {
                fresh
            };
            if n == fresh {
                self.mesh.positions.push(*p);
            }
            number.push(n);
        }
        self.mesh
            .triangles
            .extend(tile.mesh.triangles.iter().map(|t| {
                t.map(|v| match number.get(v as usize) {
                    Some(&n) => n,
                    None => (base + v as usize).min(u32::MAX as usize) as u32,
                })
            }));
    }

    /// [`push`](Self::push), and `quadrics` (one per vertex of `tile`) carried for its
    /// vertices that are not border ones: a border vertex's quadric is
    /// left to the run that takes the joined mesh, which sums it from the faces around
    /// it (see [`budget`]).
    #[cfg(feature = "io")]
    pub(crate) fn push_carrying(&mut self, tile: &Tile, quadrics: &[Quadric]) {
        let before = self.mesh.positions.len();
        self.push(tile);
        let n = tile.mesh.positions.len();
        let border = tile.border_vertices.min(n);
        // `push` appends the tile's border vertices that no earlier tile has, then all
        // its others, in order.
        let new_border = self.mesh.positions.len() - before - (n - border);
        self.carried
            .extend(std::iter::repeat_n(NOT_CARRIED, new_border));
        self.carried
            .extend((border..n).map(|i| quadrics.get(i).copied().unwrap_or(NOT_CARRIED)));
    }

    /// The joined mesh.
    pub fn finish(self) -> IndexedMesh {
        self.mesh
    }

    /// The joined mesh and its vertices' carried quadrics ([`NOT_CARRIED`] for a
    /// border vertex), after [`push_carrying`](Self::push_carrying).
    #[cfg(feature = "io")]
    pub(crate) fn finish_carrying(self) -> (IndexedMesh, Vec<Quadric>) {
        (self.mesh, self.carried)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inspect::inspect;

    /// A closed UV sphere of `n` x `n` quads (poles welded by the tiling's weld).
    fn sphere(n: u32) -> IndexedMesh {
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..n {
                let (theta, phi) = (
                    i as f64 * std::f64::consts::TAU / n as f64,
                    j as f64 * std::f64::consts::PI / n as f64,
                );
                // The poles written as one point, so the weld merges their ring.
                let (s, z) = if j == 0 || j == n {
                    (0.0, if j == 0 { 1.0 } else { -1.0 })
                } else {
                    (phi.sin(), phi.cos())
                };
                positions.push([s * theta.cos(), s * theta.sin(), z]);
            }
        }
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let a = j * n + i;
                let b = j * n + (i + 1) % n;
                if j > 0 {
                    triangles.push([a, a + n, b]);
                }
                if j + 1 < n {
                    triangles.push([b, a + n, b + n]);
                }
            }
        }
        IndexedMesh::new(positions, triangles)
    }

    /// Past the cap, every other centroid goes, then every other of those...: which
    /// ones are kept follows from the count alone.
    #[test]
    fn the_sample_halves_past_its_cap() {
        let mut sample = Sample::new();
        let n = SAMPLE_CAP as u64 * 2;
        for i in 0..n {
            sample.offer(i, [i as f64, 0.0, 0.0]);
        }
        assert_eq!(sample.stride, 2);
        assert_eq!(sample.points.len() as u64, n.div_ceil(2));
        assert!(sample
            .points
            .iter()
            .all(|&(p, i)| i % 2 == 0 && p[0] == i as f64));
        sample.offer(n, [n as f64, 0.0, 0.0]);
        assert_eq!(sample.stride, 4);
        assert!(sample.points.len() <= SAMPLE_CAP);
        // Cut from it, the tiles of the numbers left out follow their neighbours'.
        let cut = Cut::new(sample, 4);
        let tiles: Vec<usize> = (0..n)
            .step_by(n as usize / 16)
            .map(|i| cut.tile_of([i as f64, 0.0, 0.0], i))
            .collect();
        assert!(tiles.windows(2).all(|w| w[0] <= w[1]), "{tiles:?}");
        assert_eq!((tiles[0], tiles[tiles.len() - 1]), (0, 3));
    }

    #[test]
    fn tiles_have_equal_counts_and_cover_every_triangle_once() {
        let mesh = sphere(24);
        let tiling = Tiling::new(mesh.clone(), 7);
        assert_eq!(tiling.len(), 7);
        let counts: Vec<usize> = (0..7).map(|k| tiling.triangle_count(k)).collect();
        let total: usize = counts.iter().sum();
        assert_eq!(total, mesh.triangle_count());
        let (lo, hi) = (counts.iter().min(), counts.iter().max());
        assert!(hi.zip(lo).is_some_and(|(h, l)| h - l <= 1), "{counts:?}");
        let mut seen = tiling.triangles.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..total as u32).collect::<Vec<_>>());
    }

    #[test]
    fn welding_the_tiles_gives_back_the_closed_sphere() {
        let mesh = sphere(24);
        let before = inspect(&mesh).expect("valid");
        let tiling = Tiling::new(mesh.clone(), 5);
        let mut welder = Welder::default();
        for k in 0..tiling.len() {
            let tile = tiling.tile(k);
            // Border vertices really are used by another tile, and the first ones.
            assert!(tile.border_vertices > 0);
            welder.push(&tile);
        }
        let joined = welder.finish();
        let after = inspect(&joined).expect("valid");
        assert_eq!(after.boundary_edges, 0);
        assert_eq!(after.welded_vertices, 0, "every shared vertex was welded");
        assert_eq!(joined.triangle_count(), mesh.triangle_count());
        assert_eq!(
            joined.vertex_count(),
            before.vertices - before.welded_vertices
        );
    }

    #[test]
    fn a_soup_has_its_border_found_by_position() {
        let mesh = sphere(12);
        // Every triangle with three vertices of its own, as STL gives them.
        let positions: Vec<[f64; 3]> = mesh
            .triangles
            .iter()
            .flat_map(|t| t.map(|v| mesh.positions[v as usize]))
            .collect();
        let triangles = (0..mesh.triangle_count() as u32)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect();
        let soup = IndexedMesh::new(positions, triangles);
        let tiling = Tiling::new(soup, 3);
        let mut welder = Welder::default();
        for k in 0..3 {
            welder.push(&tiling.tile(k));
        }
        let joined = welder.finish();
        assert_eq!(inspect(&joined).expect("valid").boundary_edges, 0);
    }

    #[test]
    fn the_same_mesh_gives_the_same_tiles() {
        let mesh = sphere(16);
        let (a, b) = (Tiling::new(mesh.clone(), 6), Tiling::new(mesh, 6));
        for k in 0..6 {
            assert_eq!(a.tile(k), b.tile(k));
        }
    }

    #[test]
    fn more_tiles_than_triangles_gives_one_triangle_each() {
        let mesh = IndexedMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2]],
        );
        let tiling = Tiling::new(mesh, 10);
        assert_eq!(tiling.len(), 1);
        assert_eq!(tiling.tile(0).border_vertices, 0);
    }

    /// A bumpy sphere of about 2·n² triangles, so that no two tiles' borders run
    /// along the same great circles.
    fn bumpy_sphere(n: u32) -> IndexedMesh {
        let mut mesh = sphere(n);
        for p in &mut mesh.positions {
            let r = 1.0 + 0.05 * (7.0 * p[0]).sin() * (5.0 * p[1]).cos() * (3.0 * p[2]).sin();
            *p = p.map(|c| c * r);
        }
        mesh
    }

    /// Each tile simplified on its own with `locked` locked, then welded.
    fn simplify_tiles(
        tiling: &Tiling,
        ratio: f64,
        locked: impl Fn(&Tile) -> Vec<u32>,
    ) -> IndexedMesh {
        use crate::simplify::{simplify, SimplifyOptions, Target};
        let mut welder = Welder::default();
        for k in 0..tiling.len() {
            let tile = tiling.tile(k);
            let options = SimplifyOptions::DEFAULT
                .with_target(Target::Ratio(ratio))
                .with_locked_vertices(locked(&tile));
            let out = simplify(&tile.mesh, &options).expect("the tile simplifies");
            let border = &tile.mesh.positions[..tile.border_vertices];
            let out = Tile::border_first(border, out.mesh);
            assert_eq!(
                out.border_vertices, tile.border_vertices,
                "every border vertex kept"
            );
            welder.push(&out);
        }
        welder.finish()
    }

    #[test]
    fn simplified_tiles_meet_edge_for_edge() {
        let tiling = Tiling::new(bumpy_sphere(90), 6);
        let merged = simplify_tiles(&tiling, 0.1, Tile::locked_vertices);
        let info = inspect(&merged).expect("valid");
        assert_eq!(
            (
                info.boundary_edges,
                info.nonmanifold_edges,
                info.duplicate_faces
            ),
            (0, 0, 0),
            "{info:?}"
        );
        assert_eq!(info.welded_vertices, 0);
    }

    /// Why the neighbours are locked too: with the border vertices alone, the two
    /// sides of a border cut the same corners and overlap there.
    #[test]
    fn locking_the_border_alone_lets_the_sides_overlap() {
        let tiling = Tiling::new(bumpy_sphere(90), 6);
        let merged = simplify_tiles(&tiling, 0.1, |t| (0..t.border_vertices as u32).collect());
        let info = inspect(&merged).expect("valid");
        assert!(info.nonmanifold_edges > 0, "{info:?}");
    }

    #[test]
    fn border_first_finds_locked_vertices_by_position() {
        let mesh = sphere(12);
        let tiling = Tiling::new(mesh, 2);
        let input = tiling.tile(1);
        // The same tile, its vertices reversed: the border comes back first.
        let n = input.mesh.positions.len() as u32;
        let reversed = IndexedMesh::new(
            input.mesh.positions.iter().rev().copied().collect(),
            input
                .mesh
                .triangles
                .iter()
                .map(|t| t.map(|v| n - 1 - v))
                .collect(),
        );
        let b = input.border_vertices;
        let out = Tile::border_first(&input.mesh.positions[..b], reversed);
        assert_eq!(out.border_vertices, b);
        assert_eq!(out.mesh.positions[..b], input.mesh.positions[..b]);
        // The others keep the simplifier's (here reversed) order; the triangles are
        // the same corners.
        let corners = |m: &IndexedMesh| -> Vec<[[f64; 3]; 3]> {
            m.triangles
                .iter()
                .map(|t| t.map(|v| m.positions[v as usize]))
                .collect()
        };
        assert_eq!(corners(&out.mesh), corners(&input.mesh));
        assert_eq!(out.mesh.positions[b], input.mesh.positions[n as usize - 1]);
    }
}
