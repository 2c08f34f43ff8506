//! What is messy about a mesh: counts of parts, borders, non-manifold places, duplicate
//! and degenerate faces, and the bounding box ([`inspect`], behind `qem info`).
//!
//! # Definitions
//! Counts describe the mesh **after welding bit-identical positions** (as the
//! simplifier's first cleaning pass does; `-0.0` and `+0.0` are the same coordinate),
//! because an STL soup or an OBJ split into sections has every edge "open" otherwise.
//! After welding, a face that uses a vertex twice (*repeated index*) has no edges and is
//! left out of every topological count. All other faces count, **zero-area faces and
//! duplicate faces included**: a file that holds the same triangle twice really does
//! have more than two faces on each of its edges.
//!
//! - `vertices`, `triangles`: as given, before welding.
//! - `welded_vertices`: vertices merged into an earlier vertex with the same position.
//! - `unreferenced_vertices`: vertices (after welding) that no face uses, where faces
//!   with a repeated index do not count as using their vertices.
//! - `components`: groups of faces connected through shared vertices.
//! - `boundary_edges`: edges (unordered vertex pairs) used by exactly one face;
//!   `nonmanifold_edges`: edges used by three or more faces, each copy of a duplicate
//!   face counted.
//! - `boundary_loops`: connected groups of boundary edges, two boundary edges being
//!   connected when they share a vertex (a border that touches itself at a vertex is
//!   one loop), as in the project's peer-comparison harness.
//! - `nonmanifold_vertices`: vertices whose faces form more than one *fan*, where two
//!   faces at `v` are in the same fan when they share an edge that contains `v`:
//!   bow-ties and umbrellas, the vertices where separate sheets touch at a point. A
//!   vertex that lies on a non-manifold edge but whose faces all connect through edges
//!   is *not* counted here: its problem is counted in `nonmanifold_edges`. (This is a
//!   narrower notion than [`VertexClass::NonManifold`], which also includes those.)
//! - `duplicate_faces`: faces with the same three vertices as an earlier face, in any
//!   order or orientation.
//! - `degenerate_faces`: faces with a repeated index after welding, plus faces whose
//!   area is at most [`ZERO_AREA_FRACTION`](crate::clean::ZERO_AREA_FRACTION) of the
//!   squared bounding-box diagonal (the test of [`clean`](crate::clean), with the box
//!   of the vertices faces use).
//! - `bbox_min`, `bbox_max`, `bbox_diagonal`: the axis-aligned box of the vertices some
//!   triangle uses (unused vertices are ignored), in model units.
//!
//! These are the definitions of the corpus manifest (`manifest.tsv`: `components`,
//! `boundary_edges`, `nonmanifold_edges`, `nonmanifold_vertices`, `duplicate_faces`,
//! `bbox_diag`), which `qem-cli`'s tests compare against. Its `degenerate_faces` agrees
//! except on two meshes, where its zero-area test flags more near-degenerate faces.

use crate::clean::{clean, CleanOptions};
use crate::store::{EdgeClass, EdgeKey, MeshStore, VertexClass, VertexKey};
use crate::{IndexedMesh, InputError};
use slotmap::SecondaryMap;

/// Counts of what is messy about a mesh; see the [module docs](self) for the exact
/// definition of each field.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct MeshInfo {
    /// Vertices as given.
    pub vertices: usize,
    /// Triangles as given.
    pub triangles: usize,
    /// Vertices merged into an earlier vertex with a bit-identical position.
    pub welded_vertices: usize,
    /// Vertices (after welding) that no face with three distinct vertices uses.
    pub unreferenced_vertices: usize,
    /// Groups of faces connected through shared vertices.
    pub components: usize,
    /// Edges used by exactly one face.
    pub boundary_edges: usize,
    /// Connected groups of boundary edges.
    pub boundary_loops: usize,
    /// Edges used by three or more faces (duplicate faces counted).
    pub nonmanifold_edges: usize,
    /// Vertices whose faces form more than one fan (bow-ties, umbrellas).
    pub nonmanifold_vertices: usize,
    /// Faces with the same vertex set as an earlier face.
    pub duplicate_faces: usize,
    /// Faces with a repeated index (after welding) or zero area.
    pub degenerate_faces: usize,
    /// Smallest coordinates of the vertices triangles use.
    pub bbox_min: [f64; 3],
    /// Largest coordinates of the vertices triangles use.
    pub bbox_max: [f64; 3],
    /// Length of the bounding box's diagonal.
    pub bbox_diagonal: f64,
}

/// Counts what is messy about `mesh` (see the [module docs](self) for the definitions).
///
/// Costs about as much as building a [`MeshStore`] twice over; it allocates.
///
/// # Errors
/// Whatever [`IndexedMesh::validate`] reports.
///
/// ```
/// use qem_mesh::inspect::inspect;
/// use qem_mesh::IndexedMesh;
/// // Two triangles touching at vertex 0 only (a bow-tie), plus a copy of the first
/// // triangle with its own vertices, as an STL soup would have it.
/// let mesh = IndexedMesh::new(
///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0],
///          [0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
///     vec![[0, 1, 2], [0, 3, 4], [0, 5, 6]],
/// );
/// let info = inspect(&mesh)?;
/// assert_eq!((info.vertices, info.triangles, info.welded_vertices), (7, 3, 2));
/// assert_eq!(info.components, 1);
/// assert_eq!(info.duplicate_faces, 1);
/// // The doubled triangle's edges have two faces each; the other triangle's three are
/// // open and form one loop. The triangles touch only at vertex 0: two fans there.
/// assert_eq!((info.boundary_edges, info.boundary_loops), (3, 1));
/// assert_eq!(info.nonmanifold_vertices, 1);
/// assert_eq!(info.bbox_diagonal, 8f64.sqrt());
/// # Ok::<(), qem_mesh::InputError>(())
/// ```
pub fn inspect(mesh: &IndexedMesh) -> Result<MeshInfo, InputError> {
    mesh.validate()?;
    let (bbox_min, bbox_max) = used_bounding_box(mesh);
    let bbox_diagonal = (0..3)
        .map(|k| (bbox_max[k] - bbox_min[k]).powi(2))
        .sum::<f64>()
        .sqrt();

    // Weld and drop repeated-index faces only: zero-area and duplicate faces stay, as
    // they are part of the file's topology.
    let welding = CleanOptions::DEFAULT
        .with_drop_zero_area(false)
        .with_drop_duplicates(false);
    let welded = clean(mesh, &welding);
    let mut info = MeshInfo {
        vertices: mesh.vertex_count(),
        triangles: mesh.triangle_count(),
        welded_vertices: welded.report.welded_vertices,
        unreferenced_vertices: welded.report.unreferenced_vertices,
        components: 0,
        boundary_edges: 0,
        boundary_loops: 0,
        nonmanifold_edges: 0,
        nonmanifold_vertices: 0,
        duplicate_faces: 0,
        degenerate_faces: welded.report.repeated_index_faces,
        bbox_min,
        bbox_max,
        bbox_diagonal,
    };
    let surface = welded.mesh;
    if surface.triangles.is_empty() {
        // Every face repeats a vertex: no edges, no components.
        return Ok(info);
    }

    // Zero-area faces among the rest, by the cleaning pass's own test.
    let zero_area_only = CleanOptions::DEFAULT
        .with_weld_exact(false)
        .with_drop_repeated_index(false)
        .with_drop_duplicates(false)
        .with_drop_unreferenced(false);
    info.degenerate_faces += clean(&surface, &zero_area_only).report.zero_area_faces;

    // The store keeps the first face of each vertex set; the copies it skips still
    // count on their edges.
    let (store, keys) = MeshStore::from_mesh(&surface)?;
    info.duplicate_faces = store.build_stats().duplicate_faces_skipped;
    let extra_faces = duplicate_faces_per_edge(&store, &keys, &surface.triangles);

    info.components = store.component_count();
    let mut boundary = Vec::new();
    for e in store.edges() {
        let extra = extra_faces.get(e).copied().unwrap_or(0);
        let faces = store.fan(e).len() + extra;
        let class = if extra == 0 {
            store.classify_edge(e)
        } else if faces > 2 {
            EdgeClass::NonManifold
        } else {
            EdgeClass::Manifold
        };
        match class {
            EdgeClass::Boundary => boundary.push(store.edge_vertices(e)),
            EdgeClass::NonManifold => info.nonmanifold_edges += 1,
            EdgeClass::Wire | EdgeClass::Manifold => {}
        }
    }
    info.boundary_edges = boundary.len();
    info.boundary_loops = count_edge_groups(&boundary);

    let mut around = Vec::new();
    for v in store.vertices() {
        let several_fans = match store.classify_vertex(v) {
            VertexClass::Isolated | VertexClass::Interior | VertexClass::Boundary => false,
            VertexClass::NonManifold => fan_count(&store, v, &mut around) > 1,
        };
        info.nonmanifold_vertices += usize::from(several_fans);
    }
    Ok(info)
}

/// The bounding box of the vertices some triangle uses. `mesh` is valid, so there is
/// at least one triangle and every index is in range.
fn used_bounding_box(mesh: &IndexedMesh) -> ([f64; 3], [f64; 3]) {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for t in &mesh.triangles {
        for &i in t {
            let p = mesh.positions[i as usize];
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    (lo, hi)
}

/// For every edge, how many faces [`MeshStore::from_mesh`] skipped as duplicates use it.
/// `triangles` have no repeated index; `keys` maps their indices to store vertices.
fn duplicate_faces_per_edge(
    store: &MeshStore,
    keys: &[VertexKey],
    triangles: &[[u32; 3]],
) -> SecondaryMap<EdgeKey, usize> {
    let mut sets: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t| {
            let mut s = *t;
            s.sort_unstable();
            s
        })
        .collect();
    sets.sort_unstable();
    let mut extra = SecondaryMap::new();
    for run in sets.chunk_by(|a, b| a == b) {
        let copies = run.len() - 1;
        if copies == 0 {
            continue;
        }
        let [a, b, c] = run[0].map(|i| keys[i as usize]);
        for (x, y) in [(a, b), (b, c), (a, c)] {
            // The first copy was inserted, so its edges exist.
            if let Some(slot) = store.find_edge(x, y).and_then(|e| extra.entry(e)) {
                *slot.or_insert(0) += copies;
            }
        }
    }
    extra
}

/// Number of fans around `v`: groups of its faces joined through the edges at `v`.
fn fan_count(store: &MeshStore, v: VertexKey, faces: &mut Vec<crate::FaceKey>) -> usize {
    store.faces_of_vertex(v, faces);
    let mut parent: Vec<usize> = (0..faces.len()).collect();
    for &e in store.star(v) {
        let fan = store.fan(e);
        let Some(first) = fan.first().and_then(|f| faces.iter().position(|x| x == f)) else {
            continue;
        };
        for f in &fan[1..] {
            if let Some(i) = faces.iter().position(|x| x == f) {
                union(&mut parent, first, i);
            }
        }
    }
    (0..parent.len())
        .filter(|&i| find(&mut parent, i) == i)
        .count()
}

/// Number of connected groups of `edges`, two edges being connected when they share a
/// vertex.
fn count_edge_groups(edges: &[[VertexKey; 2]]) -> usize {
    let mut index: SecondaryMap<VertexKey, usize> = SecondaryMap::new();
    let mut parent = Vec::new();
    let mut slot = |v: VertexKey, parent: &mut Vec<usize>| -> usize {
        if let Some(&i) = index.get(v) {
            return i;
        }
        let i = parent.len();
        parent.push(i);
        index.insert(v, i);
        i
    };
    for &[a, b] in edges {
        let (i, j) = (slot(a, &mut parent), slot(b, &mut parent));
        union(&mut parent, i, j);
    }
    (0..parent.len())
        .filter(|&i| find(&mut parent, i) == i)
        .count()
}

/// Union–find root of `i`, halving the path on the way.
pub(crate) fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Joins the groups of `i` and `j`.
pub(crate) fn union(parent: &mut [usize], i: usize, j: usize) {
    let (ri, rj) = (find(parent, i), find(parent, j));
    if ri != rj {
        parent[ri.max(rj)] = ri.min(rj);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mesh(p: &[[f64; 3]], t: &[[u32; 3]]) -> IndexedMesh {
        IndexedMesh::new(p.to_vec(), t.to_vec())
    }

    /// A closed tetrahedron: no border, nothing non-manifold.
    fn tetrahedron() -> IndexedMesh {
        mesh(
            &[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        )
    }

    #[test]
    fn closed_tetrahedron_is_clean() {
        let info = inspect(&tetrahedron()).unwrap();
        assert_eq!(info.components, 1);
        assert_eq!((info.boundary_edges, info.boundary_loops), (0, 0));
        assert_eq!((info.nonmanifold_edges, info.nonmanifold_vertices), (0, 0));
        assert_eq!((info.duplicate_faces, info.degenerate_faces), (0, 0));
        assert_eq!(info.bbox_min, [0.0; 3]);
        assert_eq!(info.bbox_max, [1.0; 3]);
    }

    #[test]
    fn soup_is_welded_before_counting() {
        let t = tetrahedron();
        let mut p = Vec::new();
        let mut f = Vec::new();
        for tri in &t.triangles {
            let base = p.len() as u32;
            p.extend(tri.iter().map(|&i| t.positions[i as usize]));
            f.push([base, base + 1, base + 2]);
        }
        let info = inspect(&mesh(&p, &f)).unwrap();
        assert_eq!((info.vertices, info.welded_vertices), (12, 8));
        assert_eq!(info.boundary_edges, 0);
        assert_eq!(info.components, 1);
    }

    #[test]
    fn two_tetrahedra_glued_on_a_doubled_face() {
        // Each tetrahedron keeps its own copy of the shared face 0-1-2: the three
        // shared edges carry four faces each.
        let p = [
            [0.0; 3],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ];
        let f = [
            [0, 2, 1],
            [0, 1, 3],
            [1, 2, 3],
            [0, 3, 2],
            [0, 1, 2],
            [0, 4, 1],
            [1, 4, 2],
            [0, 2, 4],
        ];
        let info = inspect(&mesh(&p, &f)).unwrap();
        assert_eq!(info.duplicate_faces, 1);
        assert_eq!(info.nonmanifold_edges, 3);
        assert_eq!(info.boundary_edges, 0);
        assert_eq!(
            info.nonmanifold_vertices, 0,
            "fins, not pinches: counted as edges"
        );
    }

    #[test]
    fn two_open_squares_touching_at_a_corner() {
        // Square A (0..4) and square B sharing only vertex 2: one vertex, two fans;
        // the two borders touch there, so they form one loop.
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 1.0, 0.0],
            [2.0, 2.0, 0.0],
            [1.0, 2.0, 0.0],
        ];
        let f = [[0, 1, 2], [0, 2, 3], [2, 4, 5], [2, 5, 6]];
        let info = inspect(&mesh(&p, &f)).unwrap();
        assert_eq!(info.components, 1);
        assert_eq!(info.nonmanifold_vertices, 1);
        assert_eq!((info.boundary_edges, info.boundary_loops), (8, 1));
    }

    #[test]
    fn separate_parts_and_holes_are_counted_apart() {
        let mut m = tetrahedron();
        // A second, open triangle far away: its own component and border loop.
        m.positions
            .extend([[5.0, 5.0, 5.0], [6.0, 5.0, 5.0], [5.0, 6.0, 5.0]]);
        m.triangles.push([4, 5, 6]);
        // An unused vertex does not stretch the box.
        m.positions.push([100.0; 3]);
        let info = inspect(&m).unwrap();
        assert_eq!(info.components, 2);
        assert_eq!((info.boundary_edges, info.boundary_loops), (3, 1));
        assert_eq!(info.unreferenced_vertices, 1);
        assert_eq!(info.bbox_max, [6.0, 6.0, 5.0]);
    }

    #[test]
    fn degenerate_faces_are_counted_and_left_out_of_topology() {
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        // [0, 1, 3] is collinear (zero area, kept in the topology); [2, 4, 0] repeats
        // a vertex once 4 is welded to 2 (left out).
        let f = [[0, 1, 2], [0, 1, 3], [2, 4, 0]];
        let info = inspect(&mesh(&p, &f)).unwrap();
        assert_eq!(info.degenerate_faces, 2);
        // Edge 0-1 carries two faces; the other four edges one each.
        assert_eq!(info.boundary_edges, 4);
    }

    #[test]
    fn every_face_degenerate_leaves_no_topology() {
        let info = inspect(&mesh(&[[0.0; 3], [1.0, 0.0, 0.0]], &[[0, 0, 1]])).unwrap();
        assert_eq!(info.degenerate_faces, 1);
        assert_eq!((info.components, info.boundary_edges), (0, 0));
        assert_eq!(info.bbox_diagonal, 1.0);
    }

    /// Edge counts and components by brute force on welded positions, as an oracle:
    /// (components, boundary edges, non-manifold edges).
    fn oracle(m: &IndexedMesh) -> (usize, usize, usize) {
        use std::collections::BTreeMap;
        let key = |p: [f64; 3]| p.map(|c| if c == 0.0 { 0 } else { c.to_bits() });
        let mut first: BTreeMap<[u64; 3], usize> = BTreeMap::new();
        let welded: Vec<usize> = (0..m.positions.len())
            .map(|i| *first.entry(key(m.positions[i])).or_insert(i))
            .collect();
        let mut edges: BTreeMap<(usize, usize), usize> = BTreeMap::new();
        let mut parent: Vec<usize> = (0..m.positions.len()).collect();
        let mut used = vec![false; m.positions.len()];
        for t in &m.triangles {
            let [a, b, c] = t.map(|i| welded[i as usize]);
            if a == b || b == c || a == c {
                continue;
            }
            for (x, y) in [(a, b), (b, c), (c, a)] {
                *edges.entry((x.min(y), x.max(y))).or_default() += 1;
                union(&mut parent, x, y);
            }
            used[a] = true;
            used[b] = true;
            used[c] = true;
        }
        let components = (0..parent.len())
            .filter(|&i| used[i] && find(&mut parent, i) == i)
            .count();
        let boundary = edges.values().filter(|&&n| n == 1).count();
        let nonmanifold = edges.values().filter(|&&n| n > 2).count();
        (components, boundary, nonmanifold)
    }

    proptest::proptest! {
        /// On small random meshes over a coarse grid (so positions coincide, faces
        /// repeat and collapse), the store-based counts equal the brute-force ones, and
        /// nothing changes when the mesh is turned into a soup or its faces reversed.
        #[test]
        fn counts_match_brute_force_and_ignore_vertex_sharing(
            points in proptest::collection::vec((0u8..4, 0u8..4, 0u8..2), 3..14),
            faces in proptest::collection::vec((0usize..64, 0usize..64, 0usize..64), 1..24),
        ) {
            let positions: Vec<[f64; 3]> = points
                .iter()
                .map(|&(x, y, z)| [f64::from(x), f64::from(y), f64::from(z)])
                .collect();
            let n = positions.len();
            let triangles: Vec<[u32; 3]> = faces
                .iter()
                .map(|&(a, b, c)| [(a % n) as u32, (b % n) as u32, (c % n) as u32])
                .collect();
            let m = IndexedMesh::new(positions, triangles);
            let info = inspect(&m).unwrap();
            let (components, boundary, nonmanifold) = oracle(&m);
            proptest::prop_assert_eq!(info.components, components);
            proptest::prop_assert_eq!(info.boundary_edges, boundary);
            proptest::prop_assert_eq!(info.nonmanifold_edges, nonmanifold);
            proptest::prop_assert!(info.boundary_loops <= info.boundary_edges);

            let mut soup = IndexedMesh::default();
            for t in &m.triangles {
                let base = soup.positions.len() as u32;
                soup.positions.extend(t.map(|i| m.positions[i as usize]));
                soup.triangles.push([base, base + 1, base + 2]);
            }
            let mut reversed = m.clone();
            reversed.triangles.reverse();
            for other in [inspect(&soup).unwrap(), inspect(&reversed).unwrap()] {
                let counts = |i: &MeshInfo| (
                    i.components, i.boundary_edges, i.boundary_loops, i.nonmanifold_edges,
                    i.nonmanifold_vertices, i.duplicate_faces, i.degenerate_faces,
                );
                proptest::prop_assert_eq!(counts(&other), counts(&info));
                proptest::prop_assert_eq!(other.bbox_diagonal, info.bbox_diagonal);
            }
        }
    }

    #[test]
    fn invalid_input_is_refused() {
        let err = inspect(&mesh(&[[0.0; 3]], &[[0, 1, 2]])).unwrap_err();
        assert!(matches!(err, InputError::IndexOutOfRange { face: 0, .. }));
    }
}
