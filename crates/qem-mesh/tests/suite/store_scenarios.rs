//! Tiny named scenarios for `MeshStore`, each with a sketch and exact expectations.

use qem_mesh::{
    ContractError, EdgeClass, FaceKey, IndexedMesh, InputError, MeshStore, VertexClass, VertexKey,
};

/// A store from triangles over vertices `0..n`; vertex `i` sits at `(i, i², 0)`, so
/// positions tell vertices apart in `to_mesh` output.
fn build(n: usize, triangles: &[[u32; 3]]) -> (MeshStore, Vec<VertexKey>) {
    let positions = (0..n).map(|i| [i as f64, (i * i) as f64, 0.0]).collect();
    let mesh = IndexedMesh::new(positions, triangles.to_vec());
    let (store, keys) = MeshStore::from_mesh(&mesh).expect("scenario meshes are valid");
    store.validate().expect("a fresh store is valid");
    (store, keys)
}

fn edge(store: &MeshStore, keys: &[VertexKey], a: usize, b: usize) -> qem_mesh::EdgeKey {
    store
        .find_edge(keys[a], keys[b])
        .unwrap_or_else(|| panic!("edge {a}-{b} exists"))
}

fn contract(
    store: &mut MeshStore,
    keys: &[VertexKey],
    a: usize,
    b: usize,
) -> qem_mesh::ContractOutcome {
    let p = store.position(keys[a]);
    let outcome = store
        .contract(keys[a], keys[b], p)
        .expect("the scenario contracts live, distinct vertices");
    store.validate().expect("contraction keeps the store valid");
    outcome
}

/// Face vertex triples as input indices, rotated to start at the smallest, sorted.
fn faces_as_indices(store: &MeshStore, keys: &[VertexKey]) -> Vec<[usize; 3]> {
    let id = |v: VertexKey| keys.iter().position(|&k| k == v).expect("known key");
    let mut out: Vec<[usize; 3]> = store
        .faces()
        .map(|f| {
            let mut t = store.face_vertices(f).map(id);
            while t[0] > t[1] || t[0] > t[2] {
                t.rotate_left(1);
            }
            t
        })
        .collect();
    out.sort_unstable();
    out
}

// Fin: three sheets on edge 0-1, and a face 1-5-2 next to sheet A.
//
//            2 ---- 5        sheet A: 0 1 2   (up)
//           / \    /         sheet B: 1 0 3   (down-front)
//          /   \  /          sheet C: 0 1 4   (down-back)
//         0 === 1            next to A: 1 5 2
//        / \   / \
//       3   \ /   4 ...      (3 and 4 hang off the fin edge in other planes)
#[test]
fn fin_edge_is_non_manifold_and_survives_neighbour_contraction() {
    let (mut store, keys) = build(6, &[[0, 1, 2], [1, 0, 3], [0, 1, 4], [1, 5, 2]]);
    let fin = edge(&store, &keys, 0, 1);
    assert_eq!(store.fan(fin).len(), 3);
    assert_eq!(store.classify_edge(fin), EdgeClass::NonManifold);
    assert_eq!(store.classify_vertex(keys[0]), VertexClass::NonManifold);
    assert_eq!(store.classify_vertex(keys[1]), VertexClass::NonManifold);
    assert_eq!(store.classify_vertex(keys[3]), VertexClass::Boundary);
    assert_eq!(
        store.classify_edge(edge(&store, &keys, 1, 2)),
        EdgeClass::Manifold
    );

    // Contract the neighbour edge 2-5 (5 into 2): face 1 5 2 collapses, 1-5 merges
    // into 1-2, and the fin is untouched.
    let outcome = contract(&mut store, &keys, 2, 5);
    assert_eq!((outcome.faces_collapsed, outcome.faces_merged), (1, 0));
    assert_eq!((outcome.edge_collapsed, outcome.edges_merged), (true, 1));
    assert!(store.contains_edge(fin));
    assert_eq!(store.fan(fin).len(), 3);
    assert_eq!(store.classify_edge(fin), EdgeClass::NonManifold);
    assert_eq!(
        store.classify_edge(edge(&store, &keys, 1, 2)),
        EdgeClass::Boundary
    );
    assert_eq!(
        faces_as_indices(&store, &keys),
        vec![[0, 1, 2], [0, 1, 4], [0, 3, 1]]
    );

    // Contract 3 into 4, a virtual pair on two sheets: sheet B becomes 1 0 4, a copy of
    // sheet C, and merges; C keeps its orientation and the fin becomes manifold.
    let outcome = contract(&mut store, &keys, 4, 3);
    assert_eq!((outcome.faces_collapsed, outcome.faces_merged), (0, 1));
    assert_eq!((outcome.edge_collapsed, outcome.edges_merged), (false, 2));
    assert_eq!(store.fan(fin).len(), 2);
    assert_eq!(store.classify_edge(fin), EdgeClass::Manifold);
    assert_eq!(faces_as_indices(&store, &keys), vec![[0, 1, 2], [0, 1, 4]]);
}

// Bow-tie: two triangles touching at vertex 0 only.
//
//   1         3
//   | \     / |
//   |   0     |
//   | /     \ |
//   2         4
#[test]
fn bow_tie_vertex_is_non_manifold() {
    let (store, keys) = build(5, &[[0, 1, 2], [0, 3, 4]]);
    assert_eq!(store.classify_vertex(keys[0]), VertexClass::NonManifold);
    for (i, &v) in keys.iter().enumerate().skip(1) {
        assert_eq!(
            store.classify_vertex(v),
            VertexClass::Boundary,
            "vertex {i}"
        );
    }
    assert!(store
        .edges()
        .all(|e| store.classify_edge(e) == EdgeClass::Boundary));
    assert_eq!(store.component_count(), 1);
}

// Umbrella: two closed tetrahedra sharing apex 0. Every edge at 0 is manifold, yet the
// faces around 0 form two closed fans.
#[test]
fn two_closed_fans_at_one_vertex_are_non_manifold() {
    let tet = |a: u32, b: u32, c: u32| [[0, b, a], [0, a, c], [0, c, b], [a, b, c]];
    let mut tris = tet(1, 2, 3).to_vec();
    tris.extend(tet(4, 5, 6));
    let (store, keys) = build(7, &tris);
    assert!(store
        .edges()
        .all(|e| store.classify_edge(e) == EdgeClass::Manifold));
    assert_eq!(store.classify_vertex(keys[0]), VertexClass::NonManifold);
    for (i, &v) in keys.iter().enumerate().skip(1) {
        assert_eq!(
            store.classify_vertex(v),
            VertexClass::Interior,
            "vertex {i}"
        );
    }
}

// Open strip of four triangles.
//
//   3---4---5
//   | \ | \ |
//   0---1---2
#[test]
fn open_strip_has_boundary_edges_and_vertices() {
    let (store, keys) = build(6, &[[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]]);
    assert_eq!(
        (store.vertex_count(), store.edge_count(), store.face_count()),
        (6, 9, 4)
    );
    for (a, b) in [(0, 1), (1, 2), (2, 5), (5, 4), (4, 3), (3, 0)] {
        assert_eq!(
            store.classify_edge(edge(&store, &keys, a, b)),
            EdgeClass::Boundary
        );
    }
    for (a, b) in [(0, 4), (1, 4), (1, 5)] {
        assert_eq!(
            store.classify_edge(edge(&store, &keys, a, b)),
            EdgeClass::Manifold
        );
    }
    assert!(keys
        .iter()
        .all(|&v| store.classify_vertex(v) == VertexClass::Boundary));
    assert_eq!(store.component_count(), 1);

    let mut faces = Vec::new();
    store.faces_of_vertex(keys[1], &mut faces);
    assert_eq!(faces.len(), 3);
    let mut link_vertices = Vec::new();
    let mut link_edges = Vec::new();
    store.vertex_link(keys[4], &mut link_vertices, &mut link_edges);
    let mut lv: Vec<_> = link_vertices
        .iter()
        .map(|v| keys.iter().position(|k| k == v))
        .collect();
    lv.sort_unstable();
    assert_eq!(lv, [0, 1, 3, 5].map(Some));
    // Faces at 4 are 0 1 4, 0 4 3 and 1 5 4: link edges follow each face from 4.
    let mut le: Vec<_> = link_edges
        .iter()
        .map(|e| e.map(|v| keys.iter().position(|&k| k == v).unwrap_or(usize::MAX)))
        .collect();
    le.sort_unstable();
    assert_eq!(le, vec![[0, 1], [1, 5], [3, 0]]);
    let mut el = Vec::new();
    store.edge_link(edge(&store, &keys, 1, 4), &mut el);
    assert_eq!(el.len(), 2);
    assert!(el.contains(&keys[0]) && el.contains(&keys[5]));
}

// Closed tetrahedron; contract 1 into 0.
//
//        3
//       /|\        faces: 0 2 1, 0 1 3, 0 3 2, 1 2 3
//      / | \
//     0--|--2      0 2 1 and 0 1 3 contain 0 and 1: collapsed.
//      \ | /       1 2 3 becomes 0 2 3, the vertex set of 0 3 2: merged, 0 3 2 kept.
//       \|/        Left: one face 0 3 2 and its three (boundary) edges.
//        1
#[test]
fn tetrahedron_edge_contraction_merges_the_duplicate_face() {
    let (mut store, keys) = build(4, &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
    assert!(keys
        .iter()
        .all(|&v| store.classify_vertex(v) == VertexClass::Interior));
    let kept = store
        .faces()
        .find(|&f| store.face_vertices(f) == [keys[0], keys[3], keys[2]])
        .expect("face 0 3 2");
    let outcome = contract(&mut store, &keys, 0, 1);
    assert_eq!(outcome.faces_collapsed, 2);
    assert_eq!(outcome.faces_merged, 1);
    assert_eq!(outcome.faces_removed(), 3);
    assert!(outcome.edge_collapsed);
    assert_eq!(outcome.edges_merged, 2);
    assert_eq!(outcome.edges_removed(), 3);
    assert_eq!(
        (store.vertex_count(), store.edge_count(), store.face_count()),
        (3, 3, 1)
    );
    assert_eq!(store.faces().collect::<Vec<FaceKey>>(), vec![kept]);
    assert_eq!(store.face_vertices(kept), [keys[0], keys[3], keys[2]]);
    assert!(store
        .edges()
        .all(|e| store.classify_edge(e) == EdgeClass::Boundary));
}

// Virtual pair: two separate triangles; contract 3 into 2 (no edge joins them).
//
//   0---1         3---4            0---1
//    \ /    +      \ /     ->       \ /
//     2             5                2      2 is now a bow-tie vertex
//                                   / \
//                                  4---5
#[test]
fn virtual_pair_joins_components_at_a_non_manifold_vertex() {
    let (mut store, keys) = build(6, &[[0, 2, 1], [3, 4, 5]]);
    assert_eq!(store.component_count(), 2);
    assert_eq!(store.find_edge(keys[2], keys[3]), None);
    let outcome = contract(&mut store, &keys, 2, 3);
    assert_eq!(outcome, qem_mesh::ContractOutcome::default());
    assert_eq!(store.component_count(), 1);
    assert_eq!(
        (store.vertex_count(), store.edge_count(), store.face_count()),
        (5, 6, 2)
    );
    assert_eq!(store.classify_vertex(keys[2]), VertexClass::NonManifold);
    assert_eq!(faces_as_indices(&store, &keys), vec![[0, 2, 1], [2, 4, 5]]);
}

// Two triangles on the edge 1-2, folded: contracting 3 into 0 (no edge between them)
// turns 1 2 3 into 1 2 0, the vertex set of 0 1 2.
//
//   0---1          0---1
//    \ / \   ->     \ /      one face left, the fan of 1-2 back to one face
//     2---3          2
#[test]
fn contraction_merges_faces_that_become_duplicates() {
    let (mut store, keys) = build(4, &[[0, 1, 2], [2, 1, 3]]);
    let shared = edge(&store, &keys, 1, 2);
    assert_eq!(store.fan(shared).len(), 2);
    let outcome = contract(&mut store, &keys, 0, 3);
    assert_eq!((outcome.faces_collapsed, outcome.faces_merged), (0, 1));
    assert_eq!((outcome.edge_collapsed, outcome.edges_merged), (false, 2));
    assert_eq!(
        (store.vertex_count(), store.edge_count(), store.face_count()),
        (3, 3, 1)
    );
    assert_eq!(store.fan(shared).len(), 1);
    assert_eq!(faces_as_indices(&store, &keys), vec![[0, 1, 2]]);
}

// A lone triangle; contract 1 into 0: the face collapses, 1-2 merges into 0-2, which is
// left as a wire edge between two wire-only vertices.
#[test]
fn collapsing_the_last_face_leaves_a_wire_edge() {
    let (mut store, keys) = build(3, &[[0, 1, 2]]);
    let outcome = contract(&mut store, &keys, 0, 1);
    assert_eq!((outcome.faces_collapsed, outcome.edges_merged), (1, 1));
    assert_eq!(
        (store.vertex_count(), store.edge_count(), store.face_count()),
        (2, 1, 0)
    );
    let wire = edge(&store, &keys, 0, 2);
    assert_eq!(store.classify_edge(wire), EdgeClass::Wire);
    assert_eq!(store.classify_vertex(keys[0]), VertexClass::NonManifold);
    assert_eq!(store.component_count(), 1);
    // The wire edge is still a contraction candidate; afterwards 0 is isolated.
    contract(&mut store, &keys, 0, 2);
    assert_eq!((store.vertex_count(), store.edge_count()), (1, 0));
    assert_eq!(store.classify_vertex(keys[0]), VertexClass::Isolated);
    assert_eq!(store.component_count(), 0);
    let out = store.to_mesh();
    assert!(out.positions.is_empty() && out.triangles.is_empty());
}

// Strip of 4 triangles; contract 4 into 1 (0 1 4 and 1 5 4 collapse, 0 4 3 becomes
// 0 1 3), then 2 into 1 (1 2 5 collapses, 2-5 merges into 1-5, now a wire edge).
//
//   3---4---5        3     5
//   | \ | \ |   ->   | \   /       one face 0 1 3, a wire edge 1-5,
//   0---1---2        0---1         vertices 2 and 4 gone
#[test]
fn to_mesh_after_contractions_has_no_unreferenced_vertex_or_degenerate_face() {
    let (mut store, keys) = build(6, &[[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]]);
    let first = contract(&mut store, &keys, 1, 4); // 0 1 4 and 1 5 4 collapse
    assert_eq!(first.faces_collapsed, 2);
    let second = contract(&mut store, &keys, 1, 2); // 1 2 5 collapses
    assert_eq!(second.faces_collapsed, 1);
    // Left: 0 4 3 re-pointed to 0 1 3; vertices 2 and 4 are gone, 5 hangs on a wire edge.
    assert_eq!(faces_as_indices(&store, &keys), vec![[0, 1, 3]]);
    assert_eq!(
        store.classify_edge(edge(&store, &keys, 1, 5)),
        EdgeClass::Wire
    );

    let (out, map) = store.to_mesh_with_map();
    assert_eq!(map, vec![keys[0], keys[1], keys[3]]);
    assert_eq!(
        out.positions,
        vec![[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [3.0, 9.0, 0.0]]
    );
    assert_eq!(out.triangles, vec![[0, 1, 2]]);
    assert!(out.validate().is_ok());
    assert_eq!(store.to_mesh(), out);
}

#[test]
fn build_skips_degenerate_and_duplicate_faces_and_keeps_unreferenced_vertices() {
    let mesh = IndexedMesh::new(
        vec![[0.0; 3]; 6],
        vec![
            [0, 1, 2],
            [2, 2, 3],
            [2, 1, 0],
            [1, 2, 0],
            [1, 2, 3],
            [4, 4, 4],
        ],
    );
    let (store, keys) = MeshStore::from_mesh(&mesh).expect("valid");
    let stats = store.build_stats();
    assert_eq!(stats.degenerate_faces_skipped, 2);
    assert_eq!(stats.duplicate_faces_skipped, 2);
    assert_eq!(stats.unreferenced_vertices, 2);
    assert_eq!(keys.len(), 6);
    assert_eq!(store.face_count(), 2);
    // The first of the duplicates is kept, with its orientation.
    assert_eq!(faces_as_indices(&store, &keys), vec![[0, 1, 2], [1, 2, 3]]);
    assert_eq!(store.classify_vertex(keys[5]), VertexClass::Isolated);
    store.validate().expect("valid");
}

#[test]
fn build_reports_input_errors() {
    let err = MeshStore::from_mesh(&IndexedMesh::default()).expect_err("empty");
    assert_eq!(err, InputError::NoTriangles);
    let bad = IndexedMesh::new(vec![[0.0; 3]; 2], vec![[0, 1, 2]]);
    assert!(matches!(
        MeshStore::from_mesh(&bad),
        Err(InputError::IndexOutOfRange {
            face: 0,
            index: 2,
            ..
        })
    ));
}

#[test]
fn contract_refuses_bad_pairs_without_changing_the_store() {
    let (mut store, keys) = build(4, &[[0, 1, 2], [2, 1, 3]]);
    let before = store.to_mesh();
    assert_eq!(
        store.contract(keys[0], keys[0], [0.0; 3]),
        Err(ContractError::SameVertex(keys[0]))
    );
    assert!(matches!(
        store.contract(keys[0], keys[1], [f64::NAN, 0.0, 0.0]),
        Err(ContractError::NonFinitePosition(_))
    ));
    contract(&mut store, &keys, 0, 3);
    let after = store.to_mesh();
    assert_eq!(
        store.contract(keys[3], keys[1], [0.0; 3]),
        Err(ContractError::MissingVertex(keys[3]))
    );
    assert_eq!(
        store.contract(keys[1], keys[3], [0.0; 3]),
        Err(ContractError::MissingVertex(keys[3]))
    );
    assert_eq!(store.to_mesh(), after);
    assert_ne!(before, after);
    assert!(ContractError::SameVertex(keys[0])
        .to_string()
        .contains("itself"));
}

#[test]
fn queries_agree_on_a_tetrahedron() {
    let (store, keys) = build(4, &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
    let mut faces = Vec::new();
    for &v in &keys {
        store.faces_of_vertex(v, &mut faces);
        assert_eq!(faces.len(), 3);
        let mut sorted = faces.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), 3, "each face once");
        assert!(faces.iter().all(|&f| store.face_vertices(f).contains(&v)));
        assert_eq!(store.star(v).len(), 3);
    }
    for e in store.edges().collect::<Vec<_>>() {
        let [a, b] = store.edge_vertices(e);
        assert!(a < b);
        assert_eq!(store.other_vertex(e, a), Some(b));
        assert_eq!(store.other_vertex(e, b), Some(a));
        assert_eq!(store.find_edge(b, a), Some(e));
        for &f in store.fan(e) {
            let opposite = store.opposite_vertex(f, e).expect("edge of f");
            assert!(opposite != a && opposite != b);
        }
    }
    for f in store.faces() {
        let v = store.face_vertices(f);
        let e = store.face_edges(f);
        for i in 0..3 {
            assert_eq!(store.find_edge(v[i], v[(i + 1) % 3]), Some(e[i]));
        }
    }
}

#[test]
fn same_operations_give_the_same_keys_and_output() {
    let run = || {
        let (mut store, keys) = build(6, &[[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]]);
        contract(&mut store, &keys, 4, 0);
        contract(&mut store, &keys, 2, 3);
        let faces: Vec<_> = store.faces().collect();
        let edges: Vec<_> = store.edges().collect();
        (keys, faces, edges, store.to_mesh())
    };
    assert_eq!(run(), run());
}

// Link condition. Tetrahedron edge 0-1: the link edge 2-3 is in both Lk 0 and Lk 1, so
// contracting would pinch the sphere flat: refused. Strip edge 1-4 (see the strip sketch
// above): common neighbours 0 and 5 are exactly its opposite vertices: allowed. Strip
// pair 0 and 2 (no edge): common neighbour 1 but Lk 02 is empty: refused.
#[test]
fn link_condition_on_tetrahedron_and_strip() {
    let (tet, keys) = build(4, &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
    assert!(!tet.link_condition(keys[0], keys[1]));
    let (strip, keys) = build(6, &[[0, 1, 4], [0, 4, 3], [1, 2, 5], [1, 5, 4]]);
    assert!(strip.link_condition(keys[1], keys[4]));
    assert!(strip.link_condition(keys[4], keys[1]));
    assert!(!strip.link_condition(keys[0], keys[2]));
    assert!(strip.link_condition(keys[3], keys[2]));
}
