//! Model-based test of `MeshStore`: random small meshes and random contraction
//! sequences, applied both to the store and to the brute-force model of
//! [`qem_tests::store_model`], compared after every step.

use proptest::prelude::*;
use qem_mesh::IndexedMesh;
use qem_tests::store_model::{run, Op};

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        3 => (any::<usize>(), any::<bool>()).prop_map(|(pick, flip)| Op::Edge { pick, flip }),
        2 => (0..12usize, 0..12usize).prop_map(|(a, b)| Op::Pair { a, b }),
    ]
}

/// Random triangles over `n` vertex ids: mostly proper triangles in random orientation,
/// some with repeated indices, plus copies of earlier triangles in any order.
fn soup(n: usize) -> impl Strategy<Value = Vec<[u32; 3]>> {
    let ids: Vec<u32> = (0..n as u32).collect();
    let proper = (
        proptest::sample::subsequence(ids, 3),
        any::<bool>(),
        0..3usize,
    )
        .prop_map(|(s, flip, rot)| {
            let mut t = [s[0], s[1], s[2]];
            if flip {
                t.swap(1, 2);
            }
            t.rotate_left(rot);
            t
        });
    let any_tri = [0..n as u32, 0..n as u32, 0..n as u32];
    let tri = prop_oneof![6 => proper, 1 => any_tri];
    let copies = prop::collection::vec((any::<usize>(), any::<bool>(), 0..3usize), 0..4);
    (prop::collection::vec(tri, 1..14), copies).prop_map(|(mut tris, copies)| {
        for (pick, flip, rot) in copies {
            let mut t = tris[pick % tris.len()];
            if flip {
                t.swap(0, 1);
            }
            t.rotate_left(rot);
            tris.push(t);
        }
        tris
    })
}

/// A closed octahedron (every vertex interior) with some faces removed and some random
/// triangles added, so that manifold neighbourhoods are common.
fn octahedron_plus() -> impl Strategy<Value = Vec<[u32; 3]>> {
    const OCTAHEDRON: [[u32; 3]; 8] = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    (prop::collection::vec(any::<bool>(), 8), soup(8)).prop_map(|(drop, extra)| {
        let mut tris: Vec<[u32; 3]> = OCTAHEDRON
            .iter()
            .zip(&drop)
            // Keep most faces: drop one only where two flags in a row are set.
            .enumerate()
            .filter(|(i, (_, &d))| !(d && drop[(i + 1) % 8]))
            .map(|(_, (&t, _))| t)
            .collect();
        tris.extend(extra.into_iter().take(3));
        tris
    })
}

/// Meshes over at most 12 vertex ids: a random soup, two random soups on disjoint ids
/// (several components), or a perturbed octahedron.
fn mesh() -> impl Strategy<Value = IndexedMesh> {
    let one = (3..=10usize).prop_flat_map(|n| (Just(n), soup(n)));
    let two = (3..=6usize, 3..=6usize).prop_flat_map(|(n, k)| {
        (soup(n), soup(k)).prop_map(move |(mut first, second)| {
            first.extend(second.iter().map(|t| t.map(|v| v + n as u32)));
            (n + k, first)
        })
    });
    let octa = octahedron_plus().prop_map(|t| (8usize, t));
    prop_oneof![2 => one, 1 => two, 1 => octa].prop_map(|(n, tris)| {
        let positions = (0..n)
            .map(|i| [i as f64, (i % 3) as f64, (i / 3) as f64])
            .collect();
        IndexedMesh::new(positions, tris)
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn store_matches_brute_force_soup(mesh in mesh(), ops in prop::collection::vec(op(), 0..14)) {
        let first = run(&mesh, &ops);
        // Determinism: the same operations give the same keys and the same output.
        let second = run(&mesh, &ops);
        prop_assert_eq!(first, second);
    }
}
