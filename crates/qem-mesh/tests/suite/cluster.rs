//! Vertex clustering (`qem_mesh::cluster`, `Method::Clustering`): the count reached,
//! valid output on any input, the same bits on any number of threads, and the options
//! it refuses.

use crate::common::{assert_valid, grid, uv_sphere};
use qem_mesh::cluster::cluster;
use qem_mesh::simplify::{
    simplify, simplify_levels, BoundaryMode, Length, NoObserver, SimplifyError, SimplifyOptions,
    Target,
};
use qem_mesh::IndexedMesh;
use rayon::ThreadPoolBuilder;
use std::collections::HashSet;

/// The same surface with every triangle on its own three vertices (an STL soup).
fn unwelded(mesh: &IndexedMesh) -> IndexedMesh {
    let positions = mesh
        .triangles
        .iter()
        .flat_map(|t| t.map(|v| mesh.positions[v as usize]))
        .collect();
    let triangles = (0..mesh.triangle_count() as u32)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    IndexedMesh::new(positions, triangles)
}

/// Valid as the engine's outputs are, and no two faces on the same three vertices.
fn assert_clustered(mesh: &IndexedMesh, triangles_in: usize) {
    assert_valid(mesh, triangles_in);
    let mut seen = HashSet::new();
    for t in &mesh.triangles {
        let mut key = *t;
        key.sort_unstable();
        assert!(seen.insert(key), "duplicate face {t:?}");
    }
}

/// Within 5% of the target, valid, on closed, open and unwelded surfaces, at ratios
/// from a half to a hundredth.
#[test]
fn reaches_the_count_within_five_percent_on_any_surface() {
    let sphere = uv_sphere([0.0; 3], 1.0, 120, 240);
    let sheet = grid(150, 150, 0.0);
    let soup = unwelded(&sphere);
    for (name, mesh) in [("sphere", &sphere), ("sheet", &sheet), ("soup", &soup)] {
        let n = mesh.triangle_count();
        for ratio in [0.5, 0.1, 0.01] {
            let target = (ratio * n as f64) as usize;
            let out = cluster(mesh, target).unwrap();
            assert_clustered(&out.mesh, n);
            let got = out.mesh.triangle_count();
            assert!(
                got.abs_diff(target) as f64 <= 0.05 * target as f64,
                "{name} at {ratio}: {got} triangles for {target}"
            );
            assert_eq!(out.report.triangles_out, got);
        }
    }
}

/// An unwelded soup clusters as the welded mesh does: the cells see positions, not
/// indices. (The vertices agree to 1e-6 of the radius: each cell's vertex is pulled
/// faintly toward the mean of its vertices, and a soup's mean counts a vertex once per
/// triangle on it.)
#[test]
fn a_soup_gives_the_welded_meshs_output() {
    let sphere = uv_sphere([0.3, -0.2, 0.1], 2.0, 40, 80);
    let soup = unwelded(&sphere);
    let target = sphere.triangle_count() / 10;
    let welded = cluster(&sphere, target).unwrap().mesh;
    let from_soup = cluster(&soup, target).unwrap().mesh;
    assert_eq!(welded.triangles, from_soup.triangles);
    for (a, b) in welded.positions.iter().zip(&from_soup.positions) {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() < 2e-6, "{a:?} against {b:?}");
        }
    }
}

/// The cell's vertex lies on the surface where the surface is flat: a plane stays a
/// plane (the quadric's optimum, pulled to the cell's mean only along the plane).
#[test]
fn a_flat_sheet_stays_flat_and_inside_its_box() {
    let sheet = grid(80, 80, 0.0);
    let out = cluster(&sheet, 600).unwrap();
    for p in &out.mesh.positions {
        assert_eq!(p[2], 0.0, "{p:?} left the plane");
        assert!(
            (0.0..=80.0).contains(&p[0]) && (0.0..=80.0).contains(&p[1]),
            "{p:?}"
        );
    }
    assert!(out.report.max_error < 1e-12, "{}", out.report.max_error);
}

/// The same bits on 1, 2 and 3 threads.
#[test]
fn outputs_do_not_depend_on_the_thread_count() {
    let sphere = unwelded(&uv_sphere([0.0; 3], 1.0, 200, 400));
    let target = sphere.triangle_count() / 20;
    let on = |threads: usize| {
        ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("a thread pool")
            .install(|| cluster(&sphere, target).unwrap().mesh)
    };
    let one = on(1);
    assert_eq!(one, on(2));
    assert_eq!(one, on(3));
}

/// Through `simplify`: the report in the engine's terms, levels each clustered from
/// the input, and the options clustering cannot honour refused by name.
#[test]
fn simplify_with_clustering_reports_and_refuses_what_it_cannot_honour() {
    let sphere = uv_sphere([0.0; 3], 1.0, 60, 120);
    let n = sphere.triangle_count();
    let options = SimplifyOptions::CLUSTER.with_target(Target::Ratio(0.1));
    let out = simplify(&sphere, &options).unwrap();
    assert_eq!(out.report.target_triangles, n / 10);
    assert_eq!(out.report.triangles_out, out.mesh.triangle_count());
    assert_eq!(out.report.edge_contractions, 0);
    assert!(out.report.max_error > 0.0 && out.report.max_error < 0.05);
    assert_eq!(out.mesh, cluster(&sphere, n / 10).unwrap().mesh);

    let levels = [Target::Ratio(0.5), Target::Ratio(0.05)];
    let chain = simplify_levels(&sphere, &options, &levels, &mut NoObserver).unwrap();
    assert_eq!(chain[1].mesh, cluster(&sphere, n / 20).unwrap().mesh);

    let refused = [
        (
            options.clone().with_preserve_topology(true),
            "preserve_topology",
        ),
        (
            options.clone().with_locked_vertices(vec![0]),
            "locked_vertices",
        ),
        (
            options.clone().with_boundary(BoundaryMode::Locked),
            "boundary: Locked",
        ),
        (
            options
                .clone()
                .with_max_error(Some(Length::DiagonalFraction(0.01))),
            "max_error",
        ),
        (options.clone().with_target(Target::None), "target: None"),
    ];
    for (asked, name) in refused {
        assert_eq!(
            simplify(&sphere, &asked).unwrap_err(),
            SimplifyError::NotWithClustering { option: name }
        );
    }
}

/// A target of zero or one, and a mesh of two triangles: the fewest triangles a grid
/// keeps, never an empty mesh.
#[test]
fn tiny_targets_keep_a_triangle() {
    let sphere = uv_sphere([0.0; 3], 1.0, 10, 20);
    for target in [0, 1, 3] {
        let out = cluster(&sphere, target).unwrap();
        assert!(out.mesh.triangle_count() >= 1, "target {target}");
        assert_clustered(&out.mesh, sphere.triangle_count());
    }
    let two = grid(1, 1, 0.0);
    let out = cluster(&two, 2).unwrap();
    assert_eq!(out.mesh.triangle_count(), 2);
}

/// Bad input is the validation's error; a mesh whose vertices all coincide has nothing
/// to keep and says so, as `simplify` does.
#[test]
fn bad_and_empty_input_are_errors() {
    let nan = IndexedMesh::new(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [f64::NAN, 0.0, 0.0]],
        vec![[0, 1, 2]],
    );
    assert!(cluster(&nan, 1).is_err());
    let point = IndexedMesh::new(vec![[1.0; 3]; 3], vec![[0, 1, 2]]);
    let out = cluster(&point, 1).unwrap();
    assert_eq!(out.mesh.triangle_count(), 0);
    assert!(matches!(
        simplify(&point, &SimplifyOptions::CLUSTER),
        Err(SimplifyError::NothingLeftAfterCleaning { .. })
    ));
}

/// Every corpus mesh (CAD, soups, scans, fixtures) at ratios 0.1 and 0.01: valid, and
/// within 5% of every target of at least 100 triangles (a smaller one can be missed by
/// more than 5% by a single triangle or a single cell).
#[cfg(feature = "io")]
#[test]
fn every_corpus_mesh_clusters_to_a_valid_mesh_near_the_count() {
    let Some(dir) = crate::common::corpus_dir() else {
        return;
    };
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("the corpus directory")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".obj"))
        .collect();
    names.sort();
    assert!(
        names.len() >= 40,
        "only {} meshes in {}",
        names.len(),
        dir.display()
    );
    let mut misses = Vec::new();
    for name in &names {
        let Some(mesh) = crate::common::corpus_mesh(&dir, name) else {
            continue;
        };
        for ratio in [0.1, 0.01] {
            let target = (ratio * mesh.triangle_count() as f64) as usize;
            let out = cluster(&mesh, target).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_clustered(&out.mesh, mesh.triangle_count());
            let got = out.mesh.triangle_count();
            if target >= 100 && got.abs_diff(target) as f64 > 0.05 * target as f64 {
                misses.push(format!("{name} at {ratio}: {got} for {target}"));
            }
        }
    }
    assert!(misses.is_empty(), "off by more than 5%: {misses:#?}");
}
