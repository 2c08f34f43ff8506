//! Named scenarios of the contraction engine with exact expectations.

use crate::common;

use common::{assert_valid, concat, grid, uv_sphere};
use qem_mesh::clean::CleanOptions;
use qem_mesh::simplify::{
    simplify, simplify_levels, ContractionOrder, Length, NoObserver, SimplifyError,
    SimplifyOptions, StopReason, Target,
};
use qem_mesh::store::{EdgeClass, MeshStore};
use qem_mesh::IndexedMesh;

fn options(target: Target) -> SimplifyOptions {
    SimplifyOptions::DEFAULT.with_target(target)
}

fn edge_classes(mesh: &IndexedMesh) -> (usize, usize) {
    let (store, _) = MeshStore::from_mesh(mesh).expect("valid output");
    let mut boundary = 0;
    let mut nonmanifold = 0;
    for e in store.edges() {
        match store.classify_edge(e) {
            EdgeClass::Boundary => boundary += 1,
            EdgeClass::NonManifold => nonmanifold += 1,
            _ => {}
        }
    }
    (boundary, nonmanifold)
}

fn components(mesh: &IndexedMesh) -> usize {
    MeshStore::from_mesh(mesh)
        .expect("valid output")
        .0
        .component_count()
}

#[test]
fn closed_sphere_reaches_its_target_and_stays_closed() {
    let sphere = uv_sphere([0.0; 3], 1.0, 16, 32);
    let n = sphere.triangle_count();
    let out = simplify(&sphere, &options(Target::Triangles(n / 10))).unwrap();
    assert_valid(&out.mesh, n);
    assert!(out.mesh.triangle_count() <= n / 10);
    // Each edge contraction on a closed manifold removes two faces, so the loop lands
    // at most one face under the target... or exactly on it.
    assert!(out.mesh.triangle_count() + 2 >= n / 10);
    assert_eq!(out.report.stop_reason, StopReason::TargetReached);
    assert_eq!(out.report.virtual_contractions, 0);
    assert_eq!(edge_classes(&out.mesh), (0, 0), "still closed and manifold");
    assert!(out.report.max_error > 0.0 && out.report.max_error < 0.1);
}

#[test]
fn open_strip_keeps_a_boundary() {
    // A 20 x 2 strip of quads: every vertex is on the border.
    let strip = grid(20, 2, 0.2);
    let n = strip.triangle_count();
    let out = simplify(&strip, &options(Target::Ratio(0.25))).unwrap();
    assert_valid(&out.mesh, n);
    let (boundary, _) = edge_classes(&out.mesh);
    assert!(
        boundary >= 3,
        "the strip's border survives ({boundary} boundary edges)"
    );
    // Connectivity is not asserted: without boundary constraints a strip two quads
    // wide may pinch into parts joined only by a wire edge, which is not output.
}

#[test]
fn fin_edge_survives_contraction_of_its_neighbours() {
    // Three 4x4 sheets ("wings") sharing one spine of 5 vertices: every spine edge has
    // three faces (a fin).
    //
    //            wing 1
    //              |
    //   wing 3 ----+---- ... the spine runs out of the page, bent like a parabola
    //               \
    //              wing 2
    //
    // The spine is bent (x = 0.15 z²) so that sliding along it has a cost: a straight
    // spine lies in every wing's planes and plain Garland–Heckbert would shrink it for
    // free (boundary and feature constraints are the quality issue's business).
    let wing = |angle: f64| {
        let (s, c) = angle.sin_cos();
        let mut positions = Vec::new();
        for z in 0..=4 {
            for u in 0..=4 {
                let (u, z) = (u as f64, z as f64);
                positions.push([0.15 * z * z + u * c, u * s, z]);
            }
        }
        let g = grid(4, 4, 0.0);
        IndexedMesh::new(positions, g.triangles)
    };
    let fin = concat(&[wing(1.0), wing(3.0), wing(5.0)]);
    let n = fin.triangle_count();
    let (_, nonmanifold_in) = edge_classes(&clean_only(&fin));
    assert_eq!(nonmanifold_in, 4, "the spine: 4 edges with 3 faces each");
    let out = simplify(&fin, &options(Target::Ratio(0.6))).unwrap();
    assert_valid(&out.mesh, n);
    let (_, nonmanifold) = edge_classes(&out.mesh);
    assert!(nonmanifold >= 1, "the fin survives: {:?}", out.mesh);
    assert!(out.report.edge_contractions > 0);
    // Spine vertices of wings 2 and 3 weld onto wing 1's (when bit-identical).
    assert_eq!(
        out.report.cleanup.welded_vertices, 10,
        "5 spine vertices x 2 extra wings"
    );
}

fn clean_only(mesh: &IndexedMesh) -> IndexedMesh {
    qem_mesh::clean::clean(mesh, &qem_mesh::clean::CleanOptions::DEFAULT).mesh
}

#[test]
fn two_spheres_merge_only_with_virtual_pairs() {
    // Radius 1, centres 2.04 apart: a gap of 0.04 = 2% of the size (diameter 2).
    let pair = concat(&[
        uv_sphere([0.0; 3], 1.0, 8, 16),
        uv_sphere([2.04, 0.0, 0.0], 1.0, 8, 16),
    ]);
    let n = pair.triangle_count();
    let edges_only = simplify(&pair, &options(Target::Ratio(0.3))).unwrap();
    assert_valid(&edges_only.mesh, n);
    assert_eq!(edges_only.report.virtual_contractions, 0);
    assert_eq!(components(&edges_only.mesh), 2);

    // The diagonal is about sqrt(4.04² + 2² + 2²) ≈ 4.93; t = 2% of it ≈ 0.1 > gap.
    let merged = simplify(
        &pair,
        &options(Target::Ratio(0.3)).with_pair_threshold(Length::DiagonalFraction(0.02)),
    )
    .unwrap();
    assert_valid(&merged.mesh, n);
    assert!(merged.report.virtual_pairs > 0);
    assert!(merged.report.virtual_contractions > 0);
    assert_eq!(components(&merged.mesh), 1);
}

#[test]
fn back_to_back_faces_are_cleaned_then_simplified() {
    // A sphere plus, on top, a triangle and its reverse (same three vertices).
    let mut mesh = uv_sphere([0.0; 3], 1.0, 8, 16);
    let base = mesh.positions.len() as u32;
    mesh.positions
        .extend([[0.0, 0.0, 2.0], [1.0, 0.0, 2.0], [0.0, 1.0, 2.0]]);
    mesh.triangles.push([base, base + 1, base + 2]);
    mesh.triangles.push([base, base + 2, base + 1]);
    let n = mesh.triangle_count();
    let out = simplify(&mesh, &options(Target::Ratio(0.5))).unwrap();
    assert_eq!(out.report.cleanup.duplicate_faces, 1);
    assert_valid(&out.mesh, n);
}

#[test]
fn all_degenerate_input_is_a_clear_error() {
    let mesh = IndexedMesh::new(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
        vec![[0, 1, 2], [0, 0, 1], [2, 1, 0]],
    );
    let err = simplify(&mesh, &options(Target::Ratio(0.5))).unwrap_err();
    assert_eq!(
        err,
        SimplifyError::NothingLeftAfterCleaning { triangles_in: 3 }
    );
    assert!(err
        .to_string()
        .starts_with("all 3 triangles are degenerate"));
}

#[test]
fn target_above_the_count_is_a_no_op() {
    let sphere = uv_sphere([0.0; 3], 1.0, 6, 8);
    let n = sphere.triangle_count();
    let out = simplify(&sphere, &options(Target::Triangles(n + 10))).unwrap();
    assert_eq!(
        out.mesh, sphere,
        "untouched vertices keep their exact coordinates"
    );
    assert_eq!(out.report.stop_reason, StopReason::TargetReached);
    assert_eq!(
        out.report.edge_contractions + out.report.virtual_contractions,
        0
    );
    assert_eq!(out.report.max_error, 0.0);
}

#[test]
fn max_error_stops_before_the_bound_is_exceeded() {
    let sphere = uv_sphere([0.0; 3], 1.0, 16, 32);
    let bound = 0.002;
    let out = simplify(
        &sphere,
        &options(Target::Triangles(0)).with_max_error(Some(Length::DiagonalFraction(bound))),
    )
    .unwrap();
    assert_eq!(out.report.stop_reason, StopReason::MaxErrorReached);
    assert!(out.report.max_error <= bound);
    assert!(out.mesh.triangle_count() < sphere.triangle_count());
}

#[test]
fn same_input_same_output_bit_for_bit() {
    let mesh = concat(&[uv_sphere([0.0; 3], 1.0, 10, 20), grid(6, 6, 0.5)]);
    let o = options(Target::Ratio(0.2)).with_pair_threshold(Length::DiagonalFraction(0.05));
    let a = simplify(&mesh, &o).unwrap();
    let b = simplify(&mesh, &o).unwrap();
    assert_eq!(a.mesh, b.mesh);
    assert_eq!(a.report.max_error.to_bits(), b.report.max_error.to_bits());
}

#[test]
fn a_target_of_zero_still_leaves_a_valid_mesh() {
    // Contraction stops before the last faces would vanish, so the output keeps at
    // least one triangle.
    let sphere = uv_sphere([0.0; 3], 1.0, 6, 8);
    let n = sphere.triangle_count();
    let out = simplify(&sphere, &options(Target::Triangles(0))).unwrap();
    assert_eq!(out.report.target_triangles, 0);
    assert!(out.mesh.triangle_count() >= 1);
    assert_valid(&out.mesh, n);
    assert_eq!(out.report.stop_reason, StopReason::NoValidPair);
    // A ratio that rounds to no triangle asks for that last one instead.
    let out = simplify(&sphere, &options(Target::Ratio(0.01))).unwrap();
    assert_eq!(out.report.target_triangles, 1);
    assert_valid(&out.mesh, n);
}

#[test]
fn observer_sees_progress_and_can_cancel() {
    use qem_mesh::simplify::{simplify_observed, Observer, Progress};
    struct StopAtFirstReport(Vec<Progress>);
    impl Observer for StopAtFirstReport {
        fn progress(&mut self, p: Progress) {
            self.0.push(p);
        }
        // Once the loop has reported (asked before it, at the ends of the cleaning
        // and the setup, a stop would end the run with no partial result).
        fn should_stop(&mut self) -> bool {
            !self.0.is_empty()
        }
    }
    // 16,128 triangles: the observer is polled after 4,096 attempts, which in the
    // greedy order are 4,096 contractions here (every attempt on this sphere
    // contracts), and in passes fewer (some attempts of a batch are refused).
    let sphere = uv_sphere([0.0; 3], 1.0, 64, 128);
    let n = sphere.triangle_count();
    for order in [ContractionOrder::Greedy, ContractionOrder::Passes] {
        let mut observer = StopAtFirstReport(Vec::new());
        let asked = options(Target::Ratio(0.01)).with_order(order);
        let out = simplify_observed(&sphere, &asked, &mut observer).unwrap();
        assert_eq!(out.report.stop_reason, StopReason::Cancelled, "{order:?}");
        let contractions = out.report.edge_contractions;
        match order {
            ContractionOrder::Greedy => assert_eq!(contractions, 4096),
            ContractionOrder::Passes => assert!((3000..=4096).contains(&contractions)),
        }
        assert_valid(&out.mesh, n);
        assert!(
            observer.0.len() >= 2,
            "{order:?}: a report when polled and one at the end"
        );
        assert!(observer.0[0].fraction() > 0.0 && observer.0[0].fraction() < 1.0);
    }
}

/// The observer hears each phase as it begins, in order (the loop's and the
/// compaction's once per level), and a stop asked at the end of the cleaning or of the
/// setup ends the run there, with an error naming the phase (no partial result).
#[test]
fn observer_sees_the_phases_and_can_cancel_before_the_loop() {
    use qem_mesh::simplify::{simplify_levels, Observer, Phase, SimplifyError};
    struct Phases {
        seen: Vec<Phase>,
        stop_after: Option<Phase>,
    }
    impl Observer for Phases {
        fn phase(&mut self, phase: Phase) {
            self.seen.push(phase);
        }
        fn should_stop(&mut self) -> bool {
            self.stop_after.is_some() && self.seen.last().copied() == self.stop_after
        }
    }
    let sphere = uv_sphere([0.0; 3], 1.0, 16, 32);
    let levels = [Target::Ratio(0.5), Target::Ratio(0.25)];
    let mut all = Phases {
        seen: Vec::new(),
        stop_after: None,
    };
    let out = simplify_levels(&sphere, &SimplifyOptions::DEFAULT, &levels, &mut all).unwrap();
    assert_eq!(out.len(), 2);
    use Phase::*;
    assert_eq!(
        all.seen,
        [
            Cleaning,
            SettingUp,
            Contracting,
            Compacting,
            Contracting,
            Compacting
        ]
    );
    for phase in [Cleaning, SettingUp] {
        let mut stopping = Phases {
            seen: Vec::new(),
            stop_after: Some(phase),
        };
        let err = simplify_levels(&sphere, &SimplifyOptions::DEFAULT, &levels, &mut stopping)
            .unwrap_err();
        assert_eq!(err, SimplifyError::Cancelled { after: phase });
        assert_eq!(
            stopping.seen.last(),
            Some(&phase),
            "nothing after {phase:?}"
        );
        assert!(err.to_string().contains(phase.name()), "{err}");
    }
}

/// Levels of detail from one run: each level is nested in the previous one's count,
/// and the first level is exactly what a plain run to that target gives (the chain
/// continues the same contraction sequence rather than starting over).
#[test]
fn levels_continue_one_run_and_nest_in_count() {
    let sphere = uv_sphere([0.0; 3], 1.0, 16, 32);
    let n = sphere.triangle_count();
    let levels = [
        Target::Ratio(0.5),
        Target::Ratio(0.25),
        Target::Ratio(0.125),
    ];
    let out =
        simplify_levels(&sphere, &SimplifyOptions::DEFAULT, &levels, &mut NoObserver).unwrap();
    assert_eq!(out.len(), 3);
    let mut previous = n;
    for (level, target) in out.iter().zip([n / 2, n / 4, n / 8]) {
        assert_valid(&level.mesh, n);
        assert_eq!(level.report.stop_reason, StopReason::TargetReached);
        assert!(level.mesh.triangle_count() <= target);
        assert!(level.mesh.triangle_count() <= previous);
        previous = level.mesh.triangle_count();
    }
    // Contraction counts are cumulative over the chain.
    assert!(out[2].report.edge_contractions > out[0].report.edge_contractions);

    // The error is monotone along the chain, and the first level is a plain run.
    assert!(out[1].report.max_error >= out[0].report.max_error);
    assert!(out[2].report.max_error >= out[1].report.max_error);
    let single = simplify(&sphere, &options(levels[0])).unwrap();
    assert_eq!(single.mesh, out[0].mesh);
}

// Both loops work on the cleaned mesh renumbered in locality order and number their
// output back. With the duplicate-face pass off, they keep only the first of two faces
// on the same three vertices, so their faces no longer match the triangles one to one:
// a run that contracts nothing must still give back every other face, in its order,
// with the input's vertex numbers.
#[test]
fn a_no_op_with_a_skipped_duplicate_face_keeps_the_input_order() {
    let sphere = uv_sphere([0.0; 3], 1.0, 6, 8);
    // Numbered backwards, so that the locality order differs from the input's.
    let last = sphere.vertex_count() as u32 - 1;
    let positions: Vec<[f64; 3]> = sphere.positions.iter().rev().copied().collect();
    let mut triangles: Vec<[u32; 3]> = sphere
        .triangles
        .iter()
        .rev()
        .map(|t| t.map(|v| last - v))
        .collect();
    let skipped = triangles.len() / 2;
    let [a, b, c] = triangles[3];
    triangles.insert(skipped, [b, c, a]);
    let input = IndexedMesh::new(positions, triangles);
    let mut expected = input.clone();
    expected.triangles.remove(skipped);

    for order in [SimplifyOptions::DEFAULT, SimplifyOptions::FAST] {
        let options = order
            .with_target(Target::Triangles(input.triangle_count() + 10))
            .with_clean(CleanOptions::DEFAULT.with_drop_duplicates(false));
        let out = simplify(&input, &options).unwrap();
        assert_eq!(out.report.edge_contractions, 0);
        assert_eq!(out.mesh, expected, "{:?}", options.order);
    }
}

/// The store is the engine's oracle: on the small messy corpus meshes (non-manifold
/// fans and edges, soups, degenerate faces, back-to-back faces, holes), in both orders,
/// with and without virtual pairs and topology preservation, every contraction replays
/// on the store with the same triangles removed, the store stays valid, and it ends
/// holding the output's triangles. Skips when the corpus is absent.
#[cfg(feature = "io")]
#[test]
fn the_store_replays_every_contraction_on_small_corpus_meshes() {
    use qem_mesh::simplify::{simplify_observed, ContractionOrder, StoreReplay};
    let Some(dir) = common::corpus_dir() else {
        return;
    };
    let names = [
        "cgaltest_many_umbrellas.obj",
        "tm_joined_tetrahedra.obj",
        "oscad_issue1580_back_to_back.obj",
        "tm_wallhole.obj",
        "oscad_issue945e.obj",
        "cgaltest_nm_vertices_real.obj",
        "drc_test_nm.obj",
        "asp_sphere_with_hole.obj",
        "tm_angle_block.obj",
        "c3d_suzanne.obj",
    ];
    for name in names {
        let Some(mesh) = common::corpus_mesh(&dir, name) else {
            continue;
        };
        for order in [ContractionOrder::Greedy, ContractionOrder::Passes] {
            for (threshold, topology) in [(0.0, false), (0.02, false), (0.0, true)] {
                let options = SimplifyOptions::DEFAULT
                    .with_order(order)
                    .with_target(Target::Ratio(0.05))
                    .with_pair_threshold(Length::DiagonalFraction(threshold))
                    .with_preserve_topology(topology);
                let mut replay = StoreReplay::default();
                let out = simplify_observed(&mesh, &options, &mut replay)
                    .unwrap_or_else(|e| panic!("{name} {order:?}: {e}"));
                replay.check_output(&out.mesh).unwrap_or_else(|e| {
                    panic!("{name} {order:?} t={threshold} topology={topology}: {e}")
                });
                let contractions = out.report.edge_contractions + out.report.virtual_contractions;
                assert_eq!(replay.contractions(), contractions, "{name} {order:?}");
            }
        }
    }
}
