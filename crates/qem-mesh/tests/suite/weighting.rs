//! Named scenarios of the plane weightings: `Weighting::Mixed(s)` is area weighting at
//! `s = 0` and unit weighting at `s = ∞`, bit for bit, with and without border planes
//! and exact quadrics, and something else in between.

use crate::common;

use common::{assert_valid, holed_grid, uv_sphere};
use qem_mesh::simplify::{simplify, QuadricMode, SimplifyOptions, Target, Weighting};
use qem_mesh::IndexedMesh;

/// A UV sphere (face areas shrink toward the poles, so the weightings differ) and a
/// bumpy grid with holes (border planes, whose weight follows the weighting too).
fn meshes() -> Vec<(&'static str, IndexedMesh)> {
    vec![
        ("uv sphere", uv_sphere([0.0; 3], 1.0, 24, 32)),
        ("holed grid", holed_grid()),
    ]
}

fn run(mesh: &IndexedMesh, weighting: Weighting, quadrics: QuadricMode) -> IndexedMesh {
    let options = SimplifyOptions::DEFAULT
        .with_target(Target::Ratio(0.2))
        .with_weighting(weighting)
        .with_quadrics(quadrics);
    let out = simplify(mesh, &options).expect("simplify").mesh;
    assert_valid(&out, mesh.triangles.len());
    out
}

#[test]
fn mixed_zero_is_area_weighting_bit_for_bit() {
    for (name, mesh) in meshes() {
        for quadrics in [QuadricMode::Sum, QuadricMode::Exact] {
            let area = run(&mesh, Weighting::Area, quadrics);
            for s in [0.0, -1.0, f64::NAN] {
                assert_eq!(
                    run(&mesh, Weighting::Mixed(s), quadrics),
                    area,
                    "{name}, {quadrics:?}, s = {s}"
                );
            }
        }
    }
}

#[test]
fn mixed_infinity_is_unit_weighting_bit_for_bit() {
    for (name, mesh) in meshes() {
        for quadrics in [QuadricMode::Sum, QuadricMode::Exact] {
            assert_eq!(
                run(&mesh, Weighting::Mixed(f64::INFINITY), quadrics),
                run(&mesh, Weighting::Unweighted, quadrics),
                "{name}, {quadrics:?}"
            );
        }
    }
}

#[test]
fn a_finite_mix_differs_from_both_ends_on_uneven_faces() {
    let mesh = uv_sphere([0.0; 3], 1.0, 24, 32);
    let area = run(&mesh, Weighting::Area, QuadricMode::Sum);
    let unit = run(&mesh, Weighting::Unweighted, QuadricMode::Sum);
    let mixed = run(&mesh, Weighting::Mixed(1.0), QuadricMode::Sum);
    assert_ne!(mixed, area);
    assert_ne!(mixed, unit);
}
