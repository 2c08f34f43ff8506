//! End-to-end properties over random messy soups: coordinates on a small integer grid,
//! so coincident vertices, zero-area and duplicate faces are common.

use crate::common;

use common::{assert_valid, simplify_replayed};
use proptest::prelude::*;
use qem_mesh::clean::{clean, CleanOptions};
use qem_mesh::simplify::{
    BoundaryMode, Length, PlacementMode, QuadricMode, SimplifyError, SimplifyOptions, StopReason,
    Target,
};
use qem_mesh::IndexedMesh;

fn soup(max_vertices: usize) -> impl Strategy<Value = IndexedMesh> {
    (3..max_vertices).prop_flat_map(|n| {
        let positions = prop::collection::vec(prop::array::uniform3(0..4i32), n);
        let triangles = prop::collection::vec(prop::array::uniform3(0..n as u32), 1..40);
        (positions, triangles).prop_map(|(p, t)| {
            IndexedMesh::new(p.into_iter().map(|c| c.map(f64::from)).collect(), t)
        })
    })
}

/// The quality controls in every combination (with random locked vertices, some out
/// of range of the smaller soups, which must be the documented error).
fn quality() -> impl Strategy<Value = (BoundaryMode, f64, f64, bool, QuadricMode, Vec<u32>)> {
    (
        prop_oneof![
            Just(BoundaryMode::Free),
            Just(BoundaryMode::Planes(1.0)),
            Just(BoundaryMode::Locked)
        ],
        prop_oneof![Just(180.0), 10.0..180.0f64],
        prop_oneof![Just(0.0), 0.0..0.5f64],
        any::<bool>(),
        prop_oneof![Just(QuadricMode::Sum), Just(QuadricMode::Exact)],
        prop::collection::vec(0..32u32, 0..4),
    )
}

fn options() -> impl Strategy<Value = SimplifyOptions> {
    (
        0.0..1.0f64,
        prop_oneof![Just(0.0), 0.0..0.5f64],
        any::<bool>(),
        quality(),
    )
        .prop_map(
            |(r, t, mid, (boundary, angle, sliver, topology, quadrics, locked))| {
                SimplifyOptions::DEFAULT
                    .with_target(Target::Ratio(r))
                    .with_pair_threshold(Length::DiagonalFraction(t))
                    .with_placement(if mid {
                        PlacementMode::EndpointOrMidpoint
                    } else {
                        PlacementMode::Optimal
                    })
                    .with_boundary(boundary)
                    .with_max_normal_angle(angle)
                    .with_min_triangle_quality(sliver)
                    .with_preserve_topology(topology)
                    .with_quadrics(quadrics)
                    .with_locked_vertices(locked)
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Valid output or the one documented error, store invariants after every
    /// contraction, and the same result twice.
    #[test]
    fn messy_soups_give_valid_deterministic_output(mesh in soup(30), o in options()) {
        let first = simplify_replayed(&mesh, &o);
        match &first {
            Err(SimplifyError::LockedVertexOutOfRange { index, vertex_count }) => {
                prop_assert!(*index as usize >= mesh.vertex_count());
                prop_assert_eq!(*vertex_count, mesh.vertex_count());
            }
            Err(SimplifyError::NothingLeftAfterCleaning { .. }) => {
                prop_assert!(clean(&mesh, &CleanOptions::DEFAULT).mesh.triangles.is_empty());
            }
            Err(e) => prop_assert!(false, "unexpected error {e}"),
            Ok(out) => {
                assert_valid(&out.mesh, mesh.triangle_count());
                prop_assert!(!out.mesh.triangles.is_empty());
                let r = &out.report;
                prop_assert_eq!(r.triangles_out, out.mesh.triangle_count());
                prop_assert_eq!(r.vertices_out, out.mesh.vertex_count());
                prop_assert!(r.max_error >= 0.0 && r.max_error.is_finite());
                if r.stop_reason == StopReason::TargetReached {
                    prop_assert!(r.triangles_out <= r.target_triangles);
                }
                if let Length::DiagonalFraction(t) = o.pair_threshold {
                    if t == 0.0 || o.preserve_topology {
                        prop_assert_eq!(r.virtual_contractions, 0);
                    }
                }
                // Locked vertices (that cleaning kept) come out where they were.
                let kept = clean(&mesh, &o.clean);
                for &i in &o.locked_vertices {
                    if kept.vertex_map[i as usize] != qem_mesh::clean::Cleaned::REMOVED {
                        let p = mesh.positions[i as usize];
                        prop_assert!(out.mesh.positions.contains(&p), "locked {i} {p:?} lost");
                    }
                }
                if o.max_normal_angle < 180.0 && !common::climbed_flipped_faces(r) {
                    prop_assert_eq!(r.faces_flipped, 0);
                }
            }
        }
        let second = simplify_replayed(&mesh, &o);
        match (first, second) {
            (Ok(a), Ok(b)) => {
                prop_assert_eq!(a.mesh, b.mesh);
                prop_assert_eq!(a.report.max_error.to_bits(), b.report.max_error.to_bits());
            }
            (Err(a), Err(b)) => prop_assert_eq!(a, b),
            _ => prop_assert!(false, "two runs disagree"),
        }
    }

    /// With t = 0, parts never merge: clusters 1000 units apart, endpoint/midpoint
    /// placement (so new vertices stay in their cluster's hull), and no output face
    /// spans two clusters.
    #[test]
    fn components_never_merge_without_virtual_pairs(
        parts in prop::collection::vec(soup(12), 2..4), r in 0.0..1.0f64
    ) {
        let mut mesh = IndexedMesh::default();
        for (c, part) in parts.iter().enumerate() {
            let base = mesh.positions.len() as u32;
            mesh.positions.extend(part.positions.iter().map(|p| [p[0] + 1000.0 * c as f64, p[1], p[2]]));
            mesh.triangles.extend(part.triangles.iter().map(|t| t.map(|i| i + base)));
        }
        let o = SimplifyOptions::DEFAULT
            .with_target(Target::Ratio(r))
            .with_placement(PlacementMode::EndpointOrMidpoint);
        if let Ok(out) = simplify_replayed(&mesh, &o) {
            let cluster = |i: u32| (out.mesh.positions[i as usize][0] / 1000.0).round() as i64;
            for t in &out.mesh.triangles {
                prop_assert!(cluster(t[0]) == cluster(t[1]) && cluster(t[1]) == cluster(t[2]),
                    "face {t:?} spans clusters");
            }
        }
    }
}
