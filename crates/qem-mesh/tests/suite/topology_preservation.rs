//! `preserve_topology`: the Euler characteristic, the number of components and the
//! number of border loops of the cleaned input survive simplification, on closed and
//! open procedural meshes and on corpus meshes (skipped without the corpus).

use crate::common;

use common::{assert_valid, concat, grid, holed_grid, topology, torus, uv_sphere};
use qem_mesh::clean::{clean, CleanOptions};
use qem_mesh::simplify::{simplify, Length, SimplifyOptions, Target};
use qem_mesh::IndexedMesh;

fn preserving(ratio: f64) -> SimplifyOptions {
    SimplifyOptions::DEFAULT
        .with_target(Target::Ratio(ratio))
        .with_preserve_topology(true)
}

/// Simplifies with topology preservation and checks the three invariants against the
/// cleaned input; returns the output triangle count.
fn assert_topology_kept(name: &str, mesh: &IndexedMesh, options: &SimplifyOptions) -> usize {
    let before = topology(&clean(mesh, &CleanOptions::DEFAULT).mesh);
    let out = simplify(mesh, options).unwrap_or_else(|e| panic!("{name}: {e}"));
    assert_valid(&out.mesh, mesh.triangle_count());
    let after = topology(&out.mesh);
    assert_eq!(
        before, after,
        "{name}: (euler, components, border loops) changed; report {:?}",
        out.report
    );
    assert_eq!(out.report.virtual_contractions, 0);
    out.mesh.triangle_count()
}

#[test]
fn closed_sphere_stays_a_sphere_down_to_a_tetrahedron() {
    let sphere = uv_sphere([0.0; 3], 1.0, 16, 32);
    // Target 0: the loop stops at the smallest sphere the link condition allows.
    let n = assert_topology_kept("sphere", &sphere, &preserving(0.0));
    assert_eq!(n, 4, "a tetrahedron is the last triangulated sphere");
}

#[test]
fn torus_keeps_its_hole() {
    let t = torus(2.0, 0.7, 24, 12);
    assert_eq!(topology(&t), (0, 1, 0));
    let n = assert_topology_kept("torus", &t, &preserving(0.0));
    // Measured: the loop stops at 14 triangles (7 vertices: the smallest triangulated
    // torus, Möbius–Császár).
    assert!(n <= 24, "{n} triangles left");
    // Without the mode the same run closes the hole or pinches it.
    let free = simplify(
        &t,
        &SimplifyOptions::DEFAULT.with_target(Target::Triangles(0)),
    )
    .unwrap();
    assert_ne!(topology(&free.mesh), (0, 1, 0));
}

#[test]
fn open_grid_keeps_one_border_loop() {
    let g = grid(20, 14, 1.5);
    assert_eq!(topology(&g), (1, 1, 1));
    assert_topology_kept("grid", &g, &preserving(0.1));
    let n = assert_topology_kept("grid at 0", &g, &preserving(0.0));
    assert_eq!(n, 1, "a disc can shrink to one triangle");
}

#[test]
fn grid_with_holes_keeps_every_hole() {
    let holed = holed_grid();
    assert_eq!(topology(&holed), (-1, 1, 3));
    assert_topology_kept("holed grid", &holed, &preserving(0.0));
}

#[test]
fn separate_parts_stay_separate_even_with_a_pair_threshold() {
    let parts = concat(&[
        uv_sphere([0.0; 3], 1.0, 8, 16),
        uv_sphere([2.02, 0.0, 0.0], 1.0, 8, 16),
        grid(6, 6, 0.3),
    ]);
    let options = preserving(0.1).with_pair_threshold(Length::DiagonalFraction(0.05));
    assert_topology_kept("parts", &parts, &options);
}

#[test]
fn a_fin_is_left_alone() {
    // Three triangles on one edge (a fin) and a sheet around: the fin's vertices are
    // non-manifold, so every contraction touching them is refused.
    let mut sheet = grid(6, 6, 0.2);
    let base = sheet.positions.len() as u32;
    sheet.positions.push([3.0, 3.0, 2.0]);
    sheet.positions.push([3.0, 3.0, -2.0]);
    // Edge 3,3 - 4,4 of the grid (vertex ids 24 and 32) gets two more faces.
    sheet.triangles.push([24, 32, base]);
    sheet.triangles.push([32, 24, base + 1]);
    let out = simplify(&sheet, &preserving(0.0)).unwrap();
    assert!(out.report.rejected.topology > 0);
    for p in [[3.0, 3.0, 2.0], [3.0, 3.0, -2.0]] {
        assert!(out.mesh.positions.contains(&p), "fin tip {p:?} kept");
    }
}

#[cfg(feature = "io")]
mod corpus {
    use super::*;
    use common::{corpus_dir, corpus_mesh};

    /// Closed, genus 4, open with holes, multipart with a non-manifold vertex, and an
    /// open non-manifold sheet.
    const MESHES: [&str; 5] = [
        "npm_bunny.obj",
        "igl_fertility.obj",
        "cgal_mech_holes_shark.obj",
        "c3d_teapot.obj",
        "pymeshfix_planar_mesh.obj",
    ];

    #[test]
    fn corpus_meshes_keep_their_topology_at_ratio_0_1() {
        let Some(dir) = corpus_dir() else { return };
        for name in MESHES {
            // The manifest names files under public/; the shared copy is flat.
            let Some(mesh) = corpus_mesh(&dir, name) else {
                continue;
            };
            assert_topology_kept(name, &mesh, &preserving(0.1));
        }
    }

    /// Regression: with the *default* options (no topology mode), closed scans used to
    /// come out with holes — c3d_nefertiti had 9 border loops after a 50% run — because
    /// an edge contraction merged a face `a x y` with a face `b x y`. That merge is now
    /// refused, so closed inputs stay closed.
    #[test]
    fn closed_corpus_meshes_stay_closed_with_default_options() {
        let Some(dir) = corpus_dir() else { return };
        for name in ["c3d_nefertiti.obj", "npm_bunny.obj", "igl_fertility.obj"] {
            let Some(mesh) = corpus_mesh(&dir, name) else {
                continue;
            };
            assert_eq!(topology(&mesh).2, 0, "{name} is closed");
            for ratio in [0.5, 0.1] {
                let options = SimplifyOptions::DEFAULT.with_target(Target::Ratio(ratio));
                let out = simplify(&mesh, &options).unwrap_or_else(|e| panic!("{name}: {e}"));
                let (_, _, loops) = topology(&out.mesh);
                assert_eq!(loops, 0, "{name} at {ratio}: {loops} holes opened");
            }
        }
    }
}
