//! Cleaning passes run before simplification, each optional and each counted.
//!
//! Real meshes arrive as STL soups (every triangle with its own three vertices), with
//! faces that repeat a vertex, faces of zero area, and the same face twice. The passes,
//! in the order they run:
//!
//! 1. weld bit-identical positions (`-0.0` and `+0.0` count as the same coordinate);
//! 2. weld within a tolerance (off by default);
//! 3. drop faces with a repeated index (after welding, which can create them);
//! 4. drop zero-area faces ([`ZERO_AREA_FRACTION`] of the squared diagonal, or a cross
//!    product that underflows to exactly zero in world units);
//! 5. drop duplicate faces: the same three vertices in any order. Back-to-back pairs
//!    (the same triangle with opposite orientations) are duplicates by this rule: the
//!    first occurrence is kept with its orientation, so a two-sided sheet becomes a
//!    one-sided one;
//! 6. drop unreferenced vertices.
//!
//! Everything is deterministic: vertices keep the order of their first occurrence and
//! faces keep their order. The exact weld, the per-face tests and the duplicate search
//! run on rayon's thread pool; each is a map over independent items or a sort of
//! distinct keys, so the result is the same for any number of threads.

use crate::pairs::grid::{neighbour_cells, squared_distance};
use qem_core::{DVec3, Frame};
use rayon::prelude::*;
use std::collections::HashMap;

/// A face is zero-area when its area is at most this fraction of the squared
/// bounding-box diagonal.
///
/// Why 1e-14: it is the threshold of the independent checker the project measures
/// outputs with (`meshcheck.py`: "area ≤ 1e-14·diag²"), about 100 times the rounding
/// of an area computed in f64 from coordinates of the diagonal's size, so a face below
/// it has no direction we could trust for its normal.
pub const ZERO_AREA_FRACTION: f64 = 1e-14;

/// Twice the largest area that counts as zero (so it compares with a cross product's
/// length directly), for a bounding-box diagonal in the same units.
pub fn min_double_area(diagonal: f64) -> f64 {
    2.0 * ZERO_AREA_FRACTION * diagonal * diagonal
}

/// Whether the triangle's cross product is exactly zero in its own (world) units.
///
/// Why, beside the relative test in the normalised frame: at coordinates near 1e-300
/// the area of a proper triangle underflows f64, so every reader of the output would
/// see a zero-area face (and compute no normal), however well-shaped it is relative to
/// the bounding box. Such faces count as zero-area.
pub(crate) fn cross_underflows([a, b, c]: [[f64; 3]; 3]) -> bool {
    let (a, b, c) = (
        DVec3::from_array(a),
        DVec3::from_array(b),
        DVec3::from_array(c),
    );
    (b - a).cross(c - a) == DVec3::ZERO
}

/// Which passes run. Start from [`CleanOptions::DEFAULT`] and adjust with `with_*`.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct CleanOptions {
    /// Merge vertices with bit-identical positions. Default: `true`.
    pub weld_exact: bool,
    /// Merge each vertex into the earliest kept vertex within this distance (model
    /// units); `None` = off. Default: `None`.
    pub weld_tolerance: Option<f64>,
    /// Drop faces that use a vertex twice. Default: `true`.
    pub drop_repeated_index: bool,
    /// Drop faces whose area is at most [`ZERO_AREA_FRACTION`] of the squared
    /// bounding-box diagonal, or underflows to zero in world units. Default: `true`.
    pub drop_zero_area: bool,
    /// Drop faces with the same three vertices as an earlier face. Default: `true`.
    pub drop_duplicates: bool,
    /// Drop vertices no face uses. Default: `true`.
    pub drop_unreferenced: bool,
}

impl CleanOptions {
    /// Every pass on except the tolerance weld.
    pub const DEFAULT: CleanOptions = CleanOptions {
        weld_exact: true,
        weld_tolerance: None,
        drop_repeated_index: true,
        drop_zero_area: true,
        drop_duplicates: true,
        drop_unreferenced: true,
    };

    /// The passes the simplifier runs on its own output: no welding (it would change
    /// the topology the loop produced), every drop on, so the output is valid.
    pub const OUTPUT: CleanOptions = CleanOptions {
        weld_exact: false,
        ..CleanOptions::DEFAULT
    };

    /// Sets [`weld_exact`](Self::weld_exact).
    pub fn with_weld_exact(mut self, on: bool) -> Self {
        self.weld_exact = on;
        self
    }

    /// Sets [`weld_tolerance`](Self::weld_tolerance).
    pub fn with_weld_tolerance(mut self, tolerance: Option<f64>) -> Self {
        self.weld_tolerance = tolerance;
        self
    }

    /// Sets [`drop_repeated_index`](Self::drop_repeated_index).
    pub fn with_drop_repeated_index(mut self, on: bool) -> Self {
        self.drop_repeated_index = on;
        self
    }

    /// Sets [`drop_zero_area`](Self::drop_zero_area).
    pub fn with_drop_zero_area(mut self, on: bool) -> Self {
        self.drop_zero_area = on;
        self
    }

    /// Sets [`drop_duplicates`](Self::drop_duplicates).
    pub fn with_drop_duplicates(mut self, on: bool) -> Self {
        self.drop_duplicates = on;
        self
    }

    /// Sets [`drop_unreferenced`](Self::drop_unreferenced).
    pub fn with_drop_unreferenced(mut self, on: bool) -> Self {
        self.drop_unreferenced = on;
        self
    }
}

impl Default for CleanOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What the passes did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CleanReport {
    /// Vertices merged into an earlier vertex with a bit-identical position.
    pub welded_vertices: usize,
    /// Vertices merged into an earlier vertex within the weld tolerance.
    pub tolerance_welded_vertices: usize,
    /// Faces dropped because they use a vertex twice.
    pub repeated_index_faces: usize,
    /// Faces dropped because their area is (numerically) zero.
    pub zero_area_faces: usize,
    /// Faces dropped as duplicates of an earlier face.
    pub duplicate_faces: usize,
    /// Vertices dropped because no face uses them (welded vertices not counted).
    pub unreferenced_vertices: usize,
}

/// A cleaned mesh, what was done, and where each input vertex went.
#[derive(Clone, Debug, PartialEq)]
pub struct Cleaned {
    /// The cleaned mesh.
    pub mesh: IndexedMesh,
    /// The counts.
    pub report: CleanReport,
    /// For each input vertex, its index in `mesh`, or [`Cleaned::REMOVED`].
    pub vertex_map: Vec<u32>,
}

impl Cleaned {
    /// The `vertex_map` entry of a vertex that is not in the output.
    pub const REMOVED: u32 = u32::MAX;
}

use crate::IndexedMesh;

/// Runs the passes of `options` on `mesh`.
///
/// The mesh should have passed [`IndexedMesh::validate`]; out-of-range faces are
/// dropped (and counted as repeated-index faces) rather than trusted.
///
/// ```
/// use qem_mesh::clean::{clean, CleanOptions};
/// use qem_mesh::IndexedMesh;
/// // Two triangles of an STL soup sharing an edge: 6 vertices, 2 of them repeated.
/// let soup = IndexedMesh::new(
///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0],
///          [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
///     vec![[0, 1, 2], [3, 4, 5]],
/// );
/// let cleaned = clean(&soup, &CleanOptions::DEFAULT);
/// assert_eq!(cleaned.mesh.vertex_count(), 4);
/// assert_eq!(cleaned.mesh.triangles, vec![[0, 1, 2], [1, 3, 2]]);
/// assert_eq!(cleaned.report.welded_vertices, 2);
/// ```
pub fn clean(mesh: &IndexedMesh, options: &CleanOptions) -> Cleaned {
    let n = mesh.positions.len();
    let mut report = CleanReport::default();
    // representative[i]: the input vertex that i is merged into (itself if kept).
    let mut representative: Vec<u32> = (0..n as u32).collect();
    if options.weld_exact {
        report.welded_vertices = weld_exact(&mesh.positions, &mut representative);
    }
    if let Some(tolerance) = options.weld_tolerance.filter(|t| *t > 0.0 && t.is_finite()) {
        report.tolerance_welded_vertices =
            weld_within(&mesh.positions, tolerance, &mut representative);
    }

    let frame = Frame::from_points(mesh.positions.iter().map(|p| DVec3::from_array(*p)));
    let min_double_area = min_double_area(frame.normalized_diagonal());
    // Each face's fate is decided independently (in parallel): a kept face gets its
    // welded corners, a dropped one a marker that says why. Then the dropped ones are
    // counted and taken out in input order, so the result does not depend on the
    // threads. (Markers rather than a list of fates: one array of faces, written once.)
    let mut faces: Vec<[u32; 3]> = mesh
        .triangles
        .par_iter()
        .map(|t| {
            match face_fate(
                t,
                &mesh.positions,
                &representative,
                &frame,
                min_double_area,
                options,
            ) {
                FaceFate::Keep(f) => f,
                FaceFate::RepeatedIndex => DROPPED_REPEATED_INDEX,
                FaceFate::ZeroArea => DROPPED_ZERO_AREA,
            }
        })
        .collect();
    // The input number of each kept face, for the attributes (positions-only meshes
    // need none and pay nothing).
    let mut face_from: Option<Vec<u32>> = (!mesh.attributes.is_empty()).then(|| {
        (0..faces.len() as u32)
            .filter(|&t| {
                !matches!(
                    faces[t as usize],
                    DROPPED_REPEATED_INDEX | DROPPED_ZERO_AREA
                )
            })
            .collect()
    });
    faces.retain(|f| match *f {
        DROPPED_REPEATED_INDEX => {
            report.repeated_index_faces += 1;
            false
        }
        DROPPED_ZERO_AREA => {
            report.zero_area_faces += 1;
            false
        }
        _ => true,
    });
    if options.drop_duplicates {
        report.duplicate_faces = drop_duplicate_faces(&mut faces, face_from.as_mut(), n);
    }

    // Number the surviving vertices in input order.
    let mut referenced = vec![false; n];
    for f in &faces {
        for &i in f {
            referenced[i as usize] = true;
        }
    }
    let mut vertex_map = vec![Cleaned::REMOVED; n];
    let mut positions = Vec::with_capacity(n);
    for i in 0..n {
        let is_representative = representative[i] as usize == i;
        if !is_representative {
            continue;
        }
        if referenced[i] || !options.drop_unreferenced {
            vertex_map[i] = positions.len() as u32;
            positions.push(mesh.positions[i]);
        } else {
            report.unreferenced_vertices += 1;
        }
    }
    for i in 0..n {
        vertex_map[i] = vertex_map[representative[i] as usize];
    }
    let triangles = faces
        .par_iter()
        .map(|f| f.map(|i| vertex_map[i as usize]))
        .collect();
    let attributes = face_from
        .map(|kept| mesh.attributes.for_faces(&kept))
        .unwrap_or_default();
    Cleaned {
        mesh: IndexedMesh::new(positions, triangles).with_attributes(attributes),
        report,
        vertex_map,
    }
}

/// What [`clean`] does with the exact weld as its only pass (the options
/// `CleanOptions::DEFAULT` with the repeated-index, zero-area and duplicate drops off),
/// done in place rather than into a second mesh: faces with an index out of range are
/// dropped, every corner goes to the first vertex at its bit-identical position, and
/// the vertices no face uses then (the welded ones among them) are dropped, the others
/// kept in input order. The positions and triangles come out as [`clean`]'s, bit for
/// bit; the attributes are cleared. Returns
/// [`CleanReport::welded_vertices`].
///
/// Why: `qem tiles split` welds its whole input, and [`clean`] holds the input and
/// the cleaned copy at once; this holds 9 bytes a vertex beside the mesh.
pub(crate) fn weld_in_place(mesh: &mut IndexedMesh) -> usize {
    mesh.attributes = Default::default();
    let n = mesh.positions.len();
    let mut representative: Vec<u32> = (0..n as u32).collect();
    let welded = weld_exact_lean(&mesh.positions, &mut representative);
    mesh.triangles
        .retain(|t| t.iter().all(|&i| (i as usize) < n));
    let mut referenced = vec![false; n];
    for t in &mut mesh.triangles {
        *t = t.map(|i| representative[i as usize]);
        for &i in t.iter() {
            referenced[i as usize] = true;
        }
    }
    // Only representatives are referenced now; each one's entry (itself) becomes its
    // new number, and its position moves down to it (never up: numbers only shrink).
    let mut kept = 0;
    for i in 0..n {
        if referenced[i] {
            mesh.positions[kept] = mesh.positions[i];
            representative[i] = kept as u32;
            kept += 1;
        }
    }
    drop(referenced);
    mesh.positions.truncate(kept);
    mesh.positions.shrink_to_fit();
    for t in &mut mesh.triangles {
        *t = t.map(|i| representative[i as usize]);
    }
    welded
}

/// A dropped face's place in `clean`'s list of faces, before it is taken out. No kept
/// face looks like it: that would take a vertex numbered `u32::MAX`, and a mesh that
/// passed [`IndexedMesh::validate`] has at most [`crate::MAX_ELEMENTS`] vertices.
const DROPPED_REPEATED_INDEX: [u32; 3] = [u32::MAX, u32::MAX, 0];
/// See [`DROPPED_REPEATED_INDEX`].
const DROPPED_ZERO_AREA: [u32; 3] = [u32::MAX, u32::MAX, 1];

/// What happens to one input face.
enum FaceFate {
    /// Kept, with its indices mapped to their representatives.
    Keep([u32; 3]),
    /// Dropped: an index out of range, or (with `drop_repeated_index`) a vertex twice.
    RepeatedIndex,
    /// Dropped: (numerically) zero area.
    ZeroArea,
}

/// The fate of face `t` under `options`, given the welding in `representative`.
fn face_fate(
    t: &[u32; 3],
    positions: &[[f64; 3]],
    representative: &[u32],
    frame: &Frame,
    min_double_area: f64,
    options: &CleanOptions,
) -> FaceFate {
    if t.iter().any(|&i| i as usize >= positions.len()) {
        return FaceFate::RepeatedIndex;
    }
    let f = t.map(|i| representative[i as usize]);
    if f[0] == f[1] || f[1] == f[2] || f[0] == f[2] {
        if options.drop_repeated_index {
            return FaceFate::RepeatedIndex;
        }
    } else if options.drop_zero_area {
        let [a, b, c] = f.map(|i| frame.to_normalized(DVec3::from_array(positions[i as usize])));
        let double_area = (b - a).cross(c - a).length();
        // `!(x > min)` also drops NaN areas, which only overflow could produce.
        if double_area.is_nan()
            || double_area <= min_double_area
            || cross_underflows(f.map(|i| positions[i as usize]))
        {
            return FaceFate::ZeroArea;
        }
    }
    FaceFate::Keep(f)
}

/// The bit pattern of a coordinate, with `-0.0` read as `+0.0`.
pub(crate) fn coordinate_bits(c: f64) -> u64 {
    if c == 0.0 {
        0
    } else {
        c.to_bits()
    }
}

/// Points each vertex at the first vertex with a bit-identical position; returns how
/// many were merged. Sorts (position bits, number) pairs: 32 bytes a vertex.
fn weld_exact(positions: &[[f64; 3]], representative: &mut [u32]) -> usize {
    // (key, number) pairs are all distinct, so the unstable parallel sort has one
    // possible result, and within a group the lowest number comes first.
    let mut order: Vec<([u64; 3], u32)> = positions
        .par_iter()
        .enumerate()
        .map(|(i, p)| (p.map(coordinate_bits), i as u32))
        .collect();
    order.par_sort_unstable();
    merge_groups(order.into_iter(), representative)
}

/// [`weld_exact`] sorting vertex numbers alone, each key read from `positions` when
/// compared: 4 bytes a vertex instead of 32, at twice the time (sphere:4M's 2M
/// vertices, the versus bench's `--tool prep`: 0.50 s against 0.26 s for the whole
/// cleaning). For [`weld_in_place`], whose point is memory; [`clean`] is on every
/// run's path and keeps the faster sort.
fn weld_exact_lean(positions: &[[f64; 3]], representative: &mut [u32]) -> usize {
    let key = |i: u32| positions[i as usize].map(coordinate_bits);
    let mut order: Vec<u32> = (0..positions.len() as u32).collect();
    order.par_sort_unstable_by(|&i, &j| key(i).cmp(&key(j)).then(i.cmp(&j)));
    merge_groups(order.into_iter().map(|i| (key(i), i)), representative)
}

/// Points every vertex of a group of equal keys at the group's first, given the
/// (key, number) pairs sorted; returns how many were merged.
fn merge_groups(
    sorted: impl Iterator<Item = ([u64; 3], u32)>,
    representative: &mut [u32],
) -> usize {
    let mut merged = 0;
    let mut group: Option<([u64; 3], u32)> = None;
    for (key, i) in sorted {
        match group {
            Some((k, first)) if k == key => {
                representative[i as usize] = first;
                merged += 1;
            }
            _ => group = Some((key, i)),
        }
    }
    merged
}

/// Points each remaining representative at the earliest kept representative within
/// `tolerance` (in index order), so the result does not depend on chains of near
/// points; returns how many were merged.
fn weld_within(positions: &[[f64; 3]], tolerance: f64, representative: &mut [u32]) -> usize {
    let cell = |p: [f64; 3]| p.map(|c| (c / tolerance).floor() as i64);
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut merged = 0;
    let t2 = tolerance * tolerance;
    for i in 0..positions.len() {
        if representative[i] as usize != i {
            // Already exact-welded: follow its representative's fate.
            representative[i] = representative[representative[i] as usize];
            continue;
        }
        let p = positions[i];
        let c = cell(p);
        let mut best: Option<u32> = None;
        for key in neighbour_cells(c) {
            for &j in grid.get(&key).map(Vec::as_slice).unwrap_or(&[]) {
                if squared_distance(p, positions[j as usize]) <= t2 && best.is_none_or(|b| j < b) {
                    best = Some(j);
                }
            }
        }
        match best {
            Some(j) => {
                representative[i] = j;
                merged += 1;
            }
            None => grid.entry(c).or_default().push(i as u32),
        }
    }
    merged
}

/// Removes faces whose vertex set equals an earlier face's; returns how many.
fn drop_duplicate_faces(
    faces: &mut Vec<[u32; 3]>,
    face_from: Option<&mut Vec<u32>>,
    vertex_count: usize,
) -> usize {
    let sets: Vec<([u32; 3], u32)> = faces
        .par_iter()
        .enumerate()
        .map(|(i, f)| {
            let mut set = *f;
            set.sort_unstable();
            (set, i as u32)
        })
        .collect();
    let mut keep = vec![false; faces.len()];
    for group in group_equal_sets(sets, vertex_count).chunk_by(|x, y| x.0 == y.0) {
        keep[group[0].1 as usize] = true;
    }
    let before = faces.len();
    let mut k = 0;
    faces.retain(|_| {
        k += 1;
        keep[k - 1]
    });
    if let Some(from) = face_from {
        let mut k = 0;
        from.retain(|_| {
            k += 1;
            keep[k - 1]
        });
    }
    before - faces.len()
}

/// Puts equal vertex sets next to each other, each group in the order of `sets`.
///
/// `sets` holds (sorted vertex set, face index) in increasing face index, with every
/// vertex below `vertex_count`. No hashing and no full sort: a counting sort by the
/// lowest vertex keeps the given order within each bucket, and a stable sort of each
/// (small) bucket by the other two vertices keeps it among equal sets. Linear in the
/// input; the per-bucket sorts run on rayon's pool and cannot depend on it.
pub(crate) fn group_equal_sets(
    sets: Vec<([u32; 3], u32)>,
    vertex_count: usize,
) -> Vec<([u32; 3], u32)> {
    let mut bucket_start = vec![0u32; vertex_count + 1];
    for (set, _) in &sets {
        bucket_start[set[0] as usize + 1] += 1;
    }
    for i in 0..vertex_count {
        bucket_start[i + 1] += bucket_start[i];
    }
    let mut grouped = vec![([0u32; 3], 0u32); sets.len()];
    let mut fill = bucket_start;
    for &(set, t) in &sets {
        grouped[fill[set[0] as usize] as usize] = (set, t);
        fill[set[0] as usize] += 1;
    }
    grouped
        .par_chunk_by_mut(|x, y| x.0[0] == y.0[0])
        .for_each(|bucket| bucket.sort_by_key(|(set, _)| (set[1], set[2])));
    grouped
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(p: &[[f64; 3]], t: &[[u32; 3]]) -> IndexedMesh {
        IndexedMesh::new(p.to_vec(), t.to_vec())
    }

    #[test]
    fn signed_zeros_weld() {
        let m = mesh(
            &[
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [-0.0, 0.0, -0.0],
            ],
            &[[0, 1, 2], [3, 2, 1]],
        );
        let c = clean(&m, &CleanOptions::DEFAULT);
        assert_eq!(c.report.welded_vertices, 1);
        // [3,2,1] became [0,2,1]: the same vertex set as [0,1,2], a back-to-back pair.
        assert_eq!(c.report.duplicate_faces, 1);
        assert_eq!(c.mesh.triangles, vec![[0, 1, 2]]);
        assert_eq!(c.vertex_map, vec![0, 1, 2, 0]);
    }

    #[test]
    fn repeated_index_collinear_and_unreferenced() {
        let m = mesh(
            &[
                [0.0; 3],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [2.0, 0.0, 0.0],
                [5.0, 5.0, 5.0],
            ],
            &[[0, 1, 2], [0, 0, 1], [0, 1, 3]],
        );
        let c = clean(&m, &CleanOptions::DEFAULT);
        assert_eq!(c.report.repeated_index_faces, 1);
        assert_eq!(c.report.zero_area_faces, 1, "0,1,3 are collinear");
        assert_eq!(
            c.report.unreferenced_vertices, 2,
            "3 (only in a dropped face) and 4"
        );
        assert_eq!(c.mesh.vertex_count(), 3);
        assert_eq!(c.vertex_map[3], Cleaned::REMOVED);
    }

    #[test]
    fn tolerance_weld_joins_near_but_not_far() {
        let m = mesh(
            &[
                [0.0; 3],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [1.0005, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.01, 0.0],
            ],
            &[[0, 1, 2], [3, 4, 5]],
        );
        let c = clean(&m, &CleanOptions::DEFAULT.with_weld_tolerance(Some(0.001)));
        assert_eq!(c.report.tolerance_welded_vertices, 1);
        assert_eq!(c.mesh.vertex_count(), 5);
        assert_eq!(c.vertex_map[3], c.vertex_map[1]);
        assert_ne!(c.vertex_map[5], c.vertex_map[2]);
    }

    #[test]
    fn passes_can_be_turned_off() {
        let m = mesh(
            &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [9.0; 3]],
            &[[0, 1, 2], [0, 1, 2], [0, 0, 1]],
        );
        let off = CleanOptions::DEFAULT
            .with_drop_duplicates(false)
            .with_drop_repeated_index(false)
            .with_drop_unreferenced(false)
            .with_drop_zero_area(false)
            .with_weld_exact(false);
        let c = clean(&m, &off);
        assert_eq!(c.mesh, m);
        assert_eq!(c.report, CleanReport::default());
    }

    /// `weld_in_place` gives `clean`'s mesh with the weld as the only pass, on meshes
    /// full of what it must handle: positions repeated (and `-0.0` against `0.0`),
    /// vertices no face uses, a vertex twice in a face, indices out of range.
    #[test]
    fn the_weld_in_place_gives_the_weld_alone() {
        let weld_only = CleanOptions::DEFAULT
            .with_drop_repeated_index(false)
            .with_drop_zero_area(false)
            .with_drop_duplicates(false);
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % n
        };
        for case in 0..200 {
            let n = 1 + next(40) as usize;
            // Coordinates from a few values, so that positions repeat.
            let values = [0.0, -0.0, 1.0, 2.5];
            let positions: Vec<[f64; 3]> = (0..n)
                .map(|_| std::array::from_fn(|_| values[next(4) as usize]))
                .collect();
            let triangles: Vec<[u32; 3]> = (0..next(30))
                .map(|_| std::array::from_fn(|_| next(n as u64 + 2) as u32))
                .collect();
            let input = mesh(&positions, &triangles);
            let cleaned = clean(&input, &weld_only);
            let mut in_place = input.clone();
            let welded = weld_in_place(&mut in_place);
            assert_eq!(in_place, cleaned.mesh, "case {case}");
            assert_eq!(welded, cleaned.report.welded_vertices, "case {case}");
        }
    }
}
