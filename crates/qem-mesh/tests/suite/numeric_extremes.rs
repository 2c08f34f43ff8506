//! Numeric extremes through the whole simplifier: coordinates near the ends of f64's
//! range, inputs that collapse to a point, a single triangle, and very many copies of
//! one face. Each gives a valid output or the documented error, never a panic.

use crate::common;

use common::{assert_valid, concat, grid, simplify_replayed, uv_sphere};
use qem_mesh::simplify::{
    Length, PlacementMode, Simplified, SimplifyError, SimplifyOptions, StopReason, Target,
};
use qem_mesh::IndexedMesh;

fn options(target: Target) -> SimplifyOptions {
    SimplifyOptions::DEFAULT.with_target(target)
}

fn scaled(mesh: &IndexedMesh, scale: f64, offset: f64) -> IndexedMesh {
    IndexedMesh::new(
        mesh.positions
            .iter()
            .map(|p| p.map(|c| c * scale + offset))
            .collect(),
        mesh.triangles.clone(),
    )
}

fn position_bits(mesh: &IndexedMesh) -> Vec<[u64; 3]> {
    mesh.positions.iter().map(|p| p.map(f64::to_bits)).collect()
}

fn contractions(out: &Simplified) -> usize {
    out.report.edge_contractions + out.report.virtual_contractions
}

/// Simplifies to half and checks the output, the report and determinism.
fn half_of(mesh: &IndexedMesh, o: &SimplifyOptions) -> Simplified {
    let out = simplify_replayed(mesh, o).expect("a valid mesh simplifies");
    assert_valid(&out.mesh, mesh.triangle_count());
    let r = &out.report;
    assert_eq!(r.stop_reason, StopReason::TargetReached, "{r:?}");
    assert!(r.triangles_out <= mesh.triangle_count() / 2, "{r:?}");
    assert!(r.max_error.is_finite() && r.max_error >= 0.0, "{r:?}");
    let again = simplify_replayed(mesh, o).expect("the second run too");
    assert_eq!(position_bits(&again.mesh), position_bits(&out.mesh));
    assert_eq!(again.mesh.triangles, out.mesh.triangles);
    out
}

/// Scaling by a power of two is exact in f64, and the simplifier works in a frame
/// normalised to the bounding box, so a sphere scaled by 2^±100 (about 1e±30: areas
/// 1e±60, quadric entries up to 1e±120 in world units) gives exactly the unit-scale
/// result scaled by the same power: same triangles, same bits up to the exponent.
#[test]
fn scales_near_1e30_and_1e_minus_30_give_the_unit_scale_result() {
    let sphere = uv_sphere([0.3, -0.2, 0.1], 1.0, 12, 16);
    let o = options(Target::Ratio(0.5));
    let unit = half_of(&sphere, &o);
    for scale in [2f64.powi(100), 2f64.powi(-100)] {
        let out = half_of(&scaled(&sphere, scale, 0.0), &o);
        assert_eq!(out.mesh.triangles, unit.mesh.triangles, "scale {scale}");
        assert_eq!(
            position_bits(&out.mesh),
            position_bits(&scaled(&unit.mesh, scale, 0.0)),
            "scale {scale}"
        );
        assert_eq!(out.report.max_error, unit.report.max_error, "scale {scale}");
    }
}

/// A sphere of radius 1e-3 around (1e12, 1e12, 1e12): its coordinates differ only in
/// the last 20 or so bits, yet it simplifies to a valid mesh.
#[test]
fn a_small_part_far_from_the_origin_simplifies() {
    let sphere = uv_sphere([1e12, 1e12, 1e12], 1e-3, 10, 12);
    let out = half_of(&sphere, &options(Target::Ratio(0.5)));
    for p in &out.mesh.positions {
        for c in p {
            assert!((c - 1e12).abs() <= 2e-3, "{p:?} left the sphere's box");
        }
    }
}

/// Coordinates near 1e300 and near ±f64::MAX: lengths, areas and the bounding-box
/// diagonal overflow in world units, and still the result is a valid mesh.
#[test]
fn coordinates_near_the_top_of_f64_give_valid_output() {
    let bumpy = grid(6, 6, 0.4);
    for (scale, offset) in [(1e300, 0.0), (2e307, -6e307), (f64::MAX / 8.0, 0.0)] {
        let mesh = scaled(&bumpy, scale, offset);
        assert!(mesh.validate().is_ok());
        for placement in [PlacementMode::Optimal, PlacementMode::EndpointOrMidpoint] {
            let o = options(Target::Ratio(0.5))
                .with_placement(placement)
                .with_pair_threshold(Length::DiagonalFraction(0.05));
            let out = simplify_replayed(&mesh, &o).expect("finite coordinates simplify");
            assert_valid(&out.mesh, mesh.triangle_count());
            assert!(out.report.triangles_out <= mesh.triangle_count() / 2);
        }
    }
}

/// A tetrahedron of edge 1e-300: every face's cross product underflows to exactly zero
/// in world units, so no face has an area f64 can show. Cleaning drops them all and the
/// simplifier says so, rather than writing faces that are zero-area to any reader.
#[test]
fn faces_whose_area_underflows_are_degenerate() {
    let s = 1e-300;
    let tetra = IndexedMesh::new(
        vec![[0.0, 0.0, 0.0], [s, 0.0, 0.0], [0.0, s, 0.0], [s, s, s]],
        vec![[0, 1, 2], [1, 3, 2], [0, 3, 1], [0, 2, 3]],
    );
    assert_eq!(
        simplify_replayed(&tetra, &options(Target::Ratio(0.5))).unwrap_err(),
        SimplifyError::NothingLeftAfterCleaning { triangles_in: 4 }
    );
}

/// At 1e-150 the areas (1e-300) are still representable: the sphere simplifies, and
/// every output face has a non-zero area in world units (checked by `assert_valid`).
#[test]
fn scale_1e_minus_150_keeps_representable_areas() {
    let sphere = scaled(&uv_sphere([0.0; 3], 1.0, 10, 12), 1e-150, 0.0);
    for target in [Target::Ratio(0.5), Target::Triangles(4)] {
        let out = simplify_replayed(&sphere, &options(target)).expect("simplifies");
        assert_valid(&out.mesh, sphere.triangle_count());
    }
}

/// A part of size 1e-20 inside a part of size 1e20: relative to the bounding box the
/// small part is a point, its faces are zero-area and cleaning drops them; the large
/// part simplifies.
#[test]
fn a_tiny_part_beside_a_huge_one_is_dropped_as_degenerate() {
    let big = scaled(&uv_sphere([0.0; 3], 1.0, 8, 10), 1e20, 0.0);
    let tiny = scaled(&uv_sphere([0.0; 3], 1.0, 8, 10), 1e-20, 0.0);
    let mesh = concat(&[big.clone(), tiny.clone()]);
    let out = simplify_replayed(&mesh, &options(Target::Ratio(0.25))).expect("simplifies");
    assert_valid(&out.mesh, mesh.triangle_count());
    assert_eq!(out.report.cleanup.zero_area_faces, tiny.triangle_count());
    assert!(out
        .mesh
        .positions
        .iter()
        .all(|p| p[0].abs() > 1e18 || p[1].abs() > 1e18 || p[2].abs() > 1e18));
}

/// Every vertex at one point: every face has zero area, so the documented error.
#[test]
fn all_vertices_coincident_is_nothing_left_after_cleaning() {
    let mesh = IndexedMesh::new(
        vec![[1.5, -2.0, 3.0]; 6],
        vec![[0, 1, 2], [3, 4, 5], [0, 2, 4], [1, 1, 5]],
    );
    for t in [0.0, 0.5] {
        let o = options(Target::Ratio(0.5)).with_pair_threshold(Length::DiagonalFraction(t));
        assert_eq!(
            simplify_replayed(&mesh, &o).unwrap_err(),
            SimplifyError::NothingLeftAfterCleaning { triangles_in: 4 }
        );
    }
}

/// A single triangle cannot be simplified further: whatever the target it comes back
/// unchanged, bit for bit.
#[test]
fn a_single_triangle_is_kept_whatever_the_target() {
    let mesh = IndexedMesh::new(
        vec![[0.1, 0.2, 0.3], [1.0, -0.0, 0.0], [0.0, 1.0, 7.0]],
        vec![[0, 1, 2]],
    );
    for target in [
        Target::Ratio(0.0),
        Target::Triangles(0),
        Target::None,
        Target::Triangles(1),
    ] {
        for placement in [PlacementMode::Optimal, PlacementMode::EndpointOrMidpoint] {
            let o = options(target)
                .with_placement(placement)
                .with_pair_threshold(Length::DiagonalFraction(0.5));
            let out = simplify_replayed(&mesh, &o).expect("one triangle simplifies");
            assert_eq!(out.mesh.triangles, mesh.triangles);
            assert_eq!(position_bits(&out.mesh), position_bits(&mesh));
            assert_eq!(contractions(&out), 0, "{target:?}");
            // A ratio asks for at least one triangle.
            let expected = if matches!(target, Target::Triangles(1) | Target::Ratio(_)) {
                StopReason::TargetReached
            } else {
                StopReason::NoValidPair
            };
            assert_eq!(out.report.stop_reason, expected, "{target:?}");
        }
    }
}

/// 100 000 copies of one triangle, as unwelded copies, rotated and reversed: cleaning
/// welds and deduplicates them to one face, which is kept.
#[test]
fn many_coincident_faces_clean_to_one() {
    const COPIES: u32 = 100_000;
    let corners = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 3.0, 1.0]];
    let mut mesh = IndexedMesh::default();
    for copy in 0..COPIES {
        mesh.positions.extend_from_slice(&corners);
        let b = 3 * copy;
        mesh.triangles.push([b, b + 1, b + 2]);
        mesh.triangles.push([b + 1, b + 2, b]);
        mesh.triangles.push([b, b + 2, b + 1]);
    }
    let out = simplify_replayed(&mesh, &options(Target::Triangles(0))).expect("simplifies");
    assert_eq!(out.report.cleanup.welded_vertices, 3 * COPIES as usize - 3);
    assert_eq!(out.report.cleanup.duplicate_faces, 3 * COPIES as usize - 1);
    assert_eq!(out.mesh.triangles, vec![[0, 1, 2]]);
    assert_eq!(out.mesh.positions, corners.to_vec());
    assert_eq!(out.report.stop_reason, StopReason::NoValidPair);
}
