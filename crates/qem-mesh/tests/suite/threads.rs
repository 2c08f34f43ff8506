//! The parallel phases (cleaning, store building, virtual pairs, the index of the input
//! surface, the quadrics' and pairs' setup) give the same result with one thread as with
//! several: every output is compared bit for bit between a
//! rayon pool of 1 thread and pools of 2 and 3 threads.
//!
//! The inputs are large enough (tens of thousands of triangles) for rayon to split the
//! work: its parallel sorts and maps only divide slices above a few thousand items.
use crate::common;

use qem_mesh::clean::{clean, CleanOptions};
use qem_mesh::measure::TriangleBvh;
use qem_mesh::pairs::{virtual_pairs, GridOptions};
use qem_mesh::simplify::{simplify, ContractionOrder, Length, SimplifyOptions, Target};
use qem_mesh::{IndexedMesh, MeshStore};
use rayon::ThreadPoolBuilder;

/// Runs `f` on a rayon pool of `threads` threads.
fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a thread pool")
        .install(f)
}

/// A messy input: two overlapping noisy spheres written as an STL soup (every
/// triangle with its own three vertices), plus repeated faces, reversed duplicates,
/// faces with a repeated vertex and zero-area faces, interleaved.
fn messy_soup() -> IndexedMesh {
    let a = common::uv_sphere([0.0, 0.0, 0.0], 1.0, 60, 120);
    let b = common::uv_sphere([0.9, 0.1, 0.0], 0.8, 50, 100);
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for (part, mesh) in [a, b].iter().enumerate() {
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let base = positions.len() as u32;
            for &i in tri {
                let mut p = mesh.positions[i as usize];
                // A deterministic wobble, the same for every copy of a vertex.
                p[0] += 1e-3 * ((i as f64) * 0.37 + part as f64).sin();
                positions.push(p);
            }
            triangles.push([base, base + 1, base + 2]);
            match t % 97 {
                0 => triangles.push([base, base + 1, base + 2]), // exact repeat
                1 => triangles.push([base + 2, base + 1, base]), // reversed duplicate
                2 => triangles.push([base, base, base + 1]),     // repeated vertex
                3 => {
                    // Zero area: three collinear points.
                    let p = positions[base as usize];
                    let start = positions.len() as u32;
                    positions.push(p);
                    positions.push([p[0] + 1e-3, p[1], p[2]]);
                    positions.push([p[0] + 2e-3, p[1], p[2]]);
                    triangles.push([start, start + 1, start + 2]);
                }
                _ => {}
            }
        }
    }
    IndexedMesh::new(positions, triangles)
}

/// The bit patterns of a mesh, so that equality is bit for bit (not `==` on f64).
fn bits(mesh: &IndexedMesh) -> (Vec<[u64; 3]>, Vec<[u32; 3]>) {
    (
        mesh.positions.iter().map(|p| p.map(f64::to_bits)).collect(),
        mesh.triangles.clone(),
    )
}

#[test]
fn cleaning_is_the_same_on_1_2_and_3_threads() {
    let soup = messy_soup();
    let options = CleanOptions::DEFAULT;
    let one = on_threads(1, || clean(&soup, &options));
    assert!(one.report.welded_vertices > 10_000, "{:?}", one.report);
    assert!(one.report.duplicate_faces > 100, "{:?}", one.report);
    assert!(one.report.zero_area_faces > 50, "{:?}", one.report);
    assert!(one.report.repeated_index_faces > 50, "{:?}", one.report);
    for threads in [2, 3] {
        let many = on_threads(threads, || clean(&soup, &options));
        assert_eq!(many.report, one.report, "{threads} threads");
        assert_eq!(many.vertex_map, one.vertex_map, "{threads} threads");
        assert_eq!(bits(&many.mesh), bits(&one.mesh), "{threads} threads");
    }
}

/// Everything a store exposes, in iteration order, keys included.
fn store_dump(mesh: &IndexedMesh) -> Vec<String> {
    let (store, keys) = MeshStore::from_mesh(mesh).expect("a valid mesh");
    store.validate().expect("a consistent store");
    let mut dump = vec![format!("{keys:?}"), format!("{:?}", store.build_stats())];
    for v in store.vertices() {
        dump.push(format!(
            "v {v:?} {:?} {:?}",
            store.position(v),
            store.star(v)
        ));
    }
    for e in store.edges() {
        dump.push(format!(
            "e {e:?} {:?} {:?}",
            store.edge_vertices(e),
            store.fan(e)
        ));
    }
    for f in store.faces() {
        dump.push(format!(
            "f {f:?} {:?} {:?}",
            store.face_vertices(f),
            store.face_edges(f)
        ));
    }
    dump
}

#[test]
fn store_building_is_the_same_on_1_2_and_3_threads() {
    // Uncleaned on purpose: from_mesh skips repeated-index and duplicate faces itself.
    let welded = clean(
        &messy_soup(),
        &CleanOptions::DEFAULT.with_drop_duplicates(false),
    );
    let one = on_threads(1, || store_dump(&welded.mesh));
    for threads in [2, 3] {
        assert!(on_threads(threads, || store_dump(&welded.mesh)) == one);
    }
}

#[test]
fn virtual_pairs_are_the_same_on_1_2_and_3_threads() {
    let points = clean(&messy_soup(), &CleanOptions::DEFAULT).mesh.positions;
    let options = GridOptions::new(0.02).with_max_per_vertex(3);
    let odd = |i: u32, j: u32| (i ^ j) % 5 != 0;
    let one = on_threads(1, || virtual_pairs(&points, &options, odd));
    assert!(
        one.pairs.len() > 1000 && one.capped > 0,
        "{}",
        one.pairs.len()
    );
    for threads in [2, 3] {
        assert_eq!(
            on_threads(threads, || virtual_pairs(&points, &options, odd)),
            one
        );
    }
}

/// The index's leaf order: where each triangle went, and the corners in that order.
fn index_dump(mesh: &IndexedMesh) -> (Vec<u32>, Vec<[[u64; 3]; 3]>) {
    let (index, slots) = TriangleBvh::with_slots(mesh);
    let corners = (0..index.triangle_count() as u32)
        .map(|i| index.corners(i).map(|c| c.map(f64::to_bits)))
        .collect();
    (slots, corners)
}

#[test]
fn the_index_is_the_same_on_1_2_and_3_threads() {
    let mesh = clean(&messy_soup(), &CleanOptions::DEFAULT).mesh;
    // Above the size at which the index splits its ranges on both cores
    // (`PARALLEL_PARTITION` in measure/bvh.rs, 16,384).
    assert!(mesh.triangle_count() > 20_000, "{}", mesh.triangle_count());
    let one = on_threads(1, || index_dump(&mesh));
    for threads in [2, 3] {
        assert!(on_threads(threads, || index_dump(&mesh)) == one);
    }
    // And the same searches: the triangles nearest to some points, in index terms.
    let index = on_threads(1, || TriangleBvh::new(&mesh));
    for threads in [2, 3] {
        let other = on_threads(threads, || TriangleBvh::new(&mesh));
        for p in mesh.positions.iter().step_by(97) {
            let (mut near, mut near_other) = (Vec::new(), Vec::new());
            let q = [p[0] + 1e-3, p[1] - 2e-3, p[2] + 5e-4];
            assert_eq!(
                index.nearest_triangles(q, 1.5, 1e-9, 8, &mut near),
                other.nearest_triangles(q, 1.5, 1e-9, 8, &mut near_other)
            );
            assert_eq!(near, near_other);
        }
    }
}

/// In both orders, with virtual pairs and with topology preservation.
#[test]
fn simplification_is_the_same_on_1_2_and_3_threads() {
    let soup = messy_soup();
    for order in [ContractionOrder::Greedy, ContractionOrder::Passes] {
        for topology in [false, true] {
            let options = SimplifyOptions::DEFAULT
                .with_order(order)
                .with_target(Target::Ratio(0.05))
                .with_pair_threshold(Length::DiagonalFraction(0.01))
                .with_preserve_topology(topology);
            let one = on_threads(1, || simplify(&soup, &options)).expect("simplifies");
            assert_eq!(one.report.virtual_pairs > 0, !topology, "{order:?}");
            for threads in [2, 3] {
                let many = on_threads(threads, || simplify(&soup, &options)).expect("simplifies");
                let what = format!("{order:?}, topology {topology}, {threads} threads");
                assert_eq!(bits(&many.mesh), bits(&one.mesh), "{what}");
                let mut report = many.report.clone();
                report.timings = one.report.timings;
                assert_eq!(report, one.report, "{what}");
            }
        }
    }
}
