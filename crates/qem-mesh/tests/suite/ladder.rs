//! The ladder of relaxations (issue 28): a run that finds no pair passing every check
//! relaxes them, step by step, instead of stopping short; `strict` and the user's own
//! constraints stop it, and the report says what did.

use crate::common::{assert_valid, concat, grid, simplify_replayed, topology, uv_sphere};
use qem_mesh::simplify::{
    simplify, simplify_levels, BoundaryMode, Constraint, ContractionOrder, Length, NoObserver,
    RelaxationStep, SimplifyOptions, StopReason, Target,
};
use qem_mesh::IndexedMesh;

const ORDERS: [ContractionOrder; 2] = [ContractionOrder::Greedy, ContractionOrder::Passes];

/// `n` separate closed tetrahedra of slightly different sizes in a row: no edge of one
/// can be contracted without merging two of its faces, so without the ladder nothing
/// moves.
fn tetrahedra(n: u32) -> IndexedMesh {
    let parts: Vec<IndexedMesh> = (0..n)
        .map(|i| {
            let (x, s) = (3.0 * i as f64, 1.0 + 0.01 * i as f64);
            IndexedMesh::new(
                vec![[x, 0.0, 0.0], [x + s, 0.0, 0.0], [x, s, 0.0], [x, 0.0, s]],
                vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
            )
        })
        .collect();
    concat(&parts)
}

fn options(order: ContractionOrder, target: Target) -> SimplifyOptions {
    SimplifyOptions::DEFAULT
        .with_order(order)
        .with_target(target)
}

#[test]
fn strict_runs_stop_where_every_check_refuses() {
    let mesh = tetrahedra(50);
    for order in ORDERS {
        let out = simplify(&mesh, &options(order, Target::Ratio(0.1)).with_strict(true))
            .expect("simplifies");
        assert_eq!(out.mesh.triangle_count(), 200, "{order:?}");
        assert_eq!(out.report.stop_reason, StopReason::NoValidPair);
        assert_eq!(out.report.stopped_by, Some(Constraint::Strict));
        assert!(out.report.relaxations.is_empty());
        assert!(out.report.rejected.merge > 0, "{order:?}");
    }
}

#[test]
fn separate_tetrahedra_reach_the_target_by_merged_faces() {
    let mesh = tetrahedra(50);
    for order in ORDERS {
        let out =
            simplify_replayed(&mesh, &options(order, Target::Ratio(0.1))).expect("simplifies");
        let what = format!("{order:?}");
        assert_eq!(out.report.stop_reason, StopReason::TargetReached, "{what}");
        assert_eq!(out.report.stopped_by, None, "{what}");
        assert_eq!(out.mesh.triangle_count(), 20, "{what}: 5 tetrahedra left");
        assert_eq!(
            out.report.virtual_contractions, 0,
            "{what}: no virtual pairs asked for"
        );
        assert_valid(&out.mesh, 200);
        let steps: Vec<RelaxationStep> = out.report.relaxations.iter().map(|r| r.step).collect();
        assert_eq!(
            steps,
            RelaxationStep::ALL[..3],
            "{what}: up to merged faces"
        );
        let merged = &out.report.relaxations[2];
        assert_eq!(
            merged.contractions, 45,
            "{what}: one contraction per tetrahedron"
        );
        // Each tetrahedron goes whole: the 5 left are closed (no border edge).
        let (euler, parts, borders) = topology(&out.mesh);
        assert_eq!((euler, parts, borders), (10, 5, 0), "{what}");
        // The smallest went first (cost order is kept under the relaxation).
        let smallest_left = out
            .mesh
            .positions
            .iter()
            .map(|p| p[0])
            .fold(f64::INFINITY, f64::min);
        assert!(
            smallest_left >= 3.0 * 45.0 - 1e-9,
            "{what}: {smallest_left}"
        );
    }
}

#[test]
fn a_target_of_nothing_ends_at_one_triangle_and_says_why() {
    let mesh = tetrahedra(3);
    for order in ORDERS {
        let out =
            simplify_replayed(&mesh, &options(order, Target::Triangles(0))).expect("simplifies");
        assert_eq!(out.mesh.triangle_count(), 1, "{order:?}");
        assert_valid(&out.mesh, 12);
        assert_eq!(out.report.stop_reason, StopReason::NoValidPair);
        assert_eq!(out.report.stopped_by, Some(Constraint::LastTriangles));
        assert!(out.report.rejected.last_triangles > 0);
    }
}

#[test]
fn topology_preservation_is_never_relaxed() {
    let mesh = tetrahedra(10);
    for order in ORDERS {
        let out = simplify(
            &mesh,
            &options(order, Target::Ratio(0.1)).with_preserve_topology(true),
        )
        .expect("simplifies");
        assert_eq!(out.mesh.triangle_count(), 40, "{order:?}");
        assert_eq!(out.report.stopped_by, Some(Constraint::PreserveTopology));
        let steps: Vec<RelaxationStep> = out.report.relaxations.iter().map(|r| r.step).collect();
        assert_eq!(
            steps,
            [RelaxationStep::FoldOver, RelaxationStep::FlippedFaces],
            "{order:?}: neither border loops nor merged faces"
        );
        assert!(out.report.relaxations.iter().all(|r| r.contractions == 0));
    }
}

#[test]
fn locked_vertices_are_never_relaxed() {
    let mesh = tetrahedra(10);
    let all: Vec<u32> = (0..mesh.vertex_count() as u32).collect();
    for order in ORDERS {
        let out = simplify(
            &mesh,
            &options(order, Target::Ratio(0.1)).with_locked_vertices(all.clone()),
        )
        .expect("simplifies");
        assert_eq!(out.mesh.triangle_count(), 40, "{order:?}");
        assert_eq!(out.report.stopped_by, Some(Constraint::Locks), "{order:?}");
        // One corner of each tetrahedron locked: the merges that would remove a face
        // at a locked corner are refused, the others go on.
        let some: Vec<u32> = (0..10).map(|i| 4 * i + 3).collect();
        let out = simplify_replayed(
            &mesh,
            &options(order, Target::Ratio(0.1)).with_locked_vertices(some),
        )
        .expect("simplifies");
        assert_valid(&out.mesh, 40);
        for i in 0..10 {
            let p = [3.0 * i as f64, 0.0, 1.0 + 0.01 * i as f64];
            assert!(
                out.mesh.positions.contains(&p),
                "{order:?}: locked corner {i} kept"
            );
        }
    }
}

/// A flat square frame around a square hole: 8 triangles, two border loops, every
/// vertex on a border. Below 6 triangles a loop must be pinched or closed.
fn frame() -> IndexedMesh {
    let positions = vec![
        [0.0, 0.0, 0.0],
        [3.0, 0.0, 0.0],
        [3.0, 3.0, 0.0],
        [0.0, 3.0, 0.0],
        [1.0, 1.0, 0.0],
        [2.0, 1.0, 0.0],
        [2.0, 2.0, 0.0],
        [1.0, 2.0, 0.0],
    ];
    let mut triangles = Vec::new();
    for i in 0..4u32 {
        let (o, p, q, r) = (i, (i + 1) % 4, 4 + i, 4 + (i + 1) % 4);
        triangles.push([o, p, r]);
        triangles.push([o, r, q]);
    }
    IndexedMesh::new(positions, triangles)
}

#[test]
fn a_locked_boundary_is_never_relaxed() {
    let mesh = frame();
    for order in ORDERS {
        let locked = simplify(
            &mesh,
            &options(order, Target::Triangles(2)).with_boundary(BoundaryMode::Locked),
        )
        .expect("simplifies");
        assert_eq!(locked.mesh.triangle_count(), 8, "{order:?}");
        assert_eq!(
            locked.report.stopped_by,
            Some(Constraint::Locks),
            "{order:?}"
        );
        let strict = simplify(
            &mesh,
            &options(order, Target::Triangles(2)).with_strict(true),
        )
        .expect("simplifies");
        assert!(strict.mesh.triangle_count() >= 6, "{order:?}");
        let free =
            simplify_replayed(&mesh, &options(order, Target::Triangles(2))).expect("simplifies");
        assert_valid(&free.mesh, 8);
        assert!(
            free.mesh.triangle_count() <= 2,
            "{order:?}: {}",
            free.mesh.triangle_count()
        );
        assert!(
            free.report
                .relaxations
                .iter()
                .any(|r| r.step == RelaxationStep::BorderLoops && r.contractions > 0),
            "{order:?}: {:?}",
            free.report.relaxations
        );
    }
}

#[test]
fn a_clean_closed_mesh_never_climbs() {
    let mesh = uv_sphere([0.0; 3], 1.0, 24, 48);
    for order in ORDERS {
        for ratio in [0.1, 0.01] {
            let out = simplify(&mesh, &options(order, Target::Ratio(ratio))).expect("simplifies");
            assert_eq!(
                out.report.stop_reason,
                StopReason::TargetReached,
                "{order:?} {ratio}"
            );
            assert!(
                out.report.relaxations.is_empty(),
                "{order:?} {ratio}: {:?}",
                out.report.relaxations
            );
            let strict = simplify(
                &mesh,
                &options(order, Target::Ratio(ratio)).with_strict(true),
            )
            .expect("simplifies");
            assert_eq!(
                strict.mesh, out.mesh,
                "{order:?} {ratio}: the ladder changed nothing"
            );
        }
    }
}

#[test]
fn stuck_parts_beside_a_sphere_reach_the_target_with_a_valid_output() {
    // A sphere with tetrahedra around it: the sphere goes first, then the
    // tetrahedra need the ladder.
    let mesh = concat(&[uv_sphere([-5.0, 0.0, 0.0], 1.0, 8, 16), tetrahedra(20)]);
    let n = mesh.triangle_count();
    for order in ORDERS {
        let out =
            simplify_replayed(&mesh, &options(order, Target::Triangles(40))).expect("simplifies");
        assert_valid(&out.mesh, n);
        assert_eq!(
            out.report.stop_reason,
            StopReason::TargetReached,
            "{order:?}"
        );
        assert!(out.mesh.triangle_count() <= 40, "{order:?}");
        assert!(
            out.mesh.triangle_count() >= 36,
            "{order:?}: {}",
            out.mesh.triangle_count()
        );
    }
}

/// A closed part worn down to a tetrahedron vanishes at the cost of its size, not at
/// the quadrics' cost of the point it collapses to: of a long sliver (a rod 40 times the
/// others' size, nearly flat, whose planes all but contain its axis) and 20 small
/// tetrahedra, the small ones go and the rod stays, in both orders, and the report's
/// error covers the parts that vanished.
///
/// (Before the rod was priced, it was the cheapest part to collapse. On the corpus's
/// ps_mk4_gantry, two rods as long as the model went that way: see the next test.)
#[test]
fn a_long_part_does_not_vanish_before_small_ones() {
    let rod = IndexedMesh::new(
        vec![
            [0.0, 5.0, 0.0],
            [40.0, 5.0, 0.0],
            [20.0, 5.02, 0.0],
            [20.0, 5.0, 0.02],
        ],
        vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    );
    let mesh = concat(&[rod, tetrahedra(20)]);
    for order in ORDERS {
        // 21 parts, 84 triangles: 10 of them must go.
        let out =
            simplify_replayed(&mesh, &options(order, Target::Triangles(44))).expect("simplifies");
        let what = format!("{order:?}");
        assert_eq!(out.mesh.triangle_count(), 44, "{what}");
        assert_valid(&out.mesh, 84);
        let reach = |axis: usize| {
            (out.mesh.positions.iter().map(|p| p[axis])).fold(f64::NEG_INFINITY, f64::max)
        };
        assert!(reach(1) > 4.9, "{what}: the rod vanished");
        // A unit tetrahedron that vanishes into a point leaves a corner at least half
        // its edge away from it; the rod's half-length is 20.
        let error = out.report.max_error_abs;
        assert!((0.5..20.0).contains(&error), "{what}: max error {error}");
    }
}

/// ps_mk4_gantry (a CAD soup of 117 parts, several of them long rods) at ratio 0.01
/// climbs to the ladder's merged faces in both orders; no part as long as the model
/// may vanish on the way, and the parts that do vanish go smallest first. The pass-based order, whose batch grows to every pair left
/// when its cheapest pairs are all refused, took two such rods out in one pass
/// (Hausdorff distance 53% of the diagonal) before its grown batches were contracted
/// cheapest first up to a cost cap.
#[cfg(feature = "io")]
#[test]
fn the_gantry_keeps_its_rods_at_one_percent() {
    use qem_mesh::measure::{measure, MeasureOptions};
    let Some(dir) = crate::common::corpus_dir() else {
        return;
    };
    let Some(mesh) = crate::common::corpus_mesh(&dir, "ps_mk4_gantry.obj") else {
        return;
    };
    for order in ORDERS {
        let out = simplify(&mesh, &options(order, Target::Ratio(0.01))).expect("simplifies");
        let what = format!("{order:?}");
        let target = out.report.target_triangles as f64;
        let reached = out.mesh.triangle_count() as f64;
        assert!(
            (reached - target).abs() <= 0.01 * target,
            "{what}: {reached}"
        );
        let few = MeasureOptions {
            min_samples: 100_000,
            ..MeasureOptions::DEFAULT
        };
        let m = measure(&mesh, &out.mesh, &few).expect("measures");
        // Measured at 0.86% (greedy) and 0.87% (passes); meshoptimizer's 52.9%. Greedy
        // read 1.28% while it did not cost a pair again when popping it (a contraction
        // elsewhere had made it a vanishing one).
        assert!(m.hausdorff < 0.012, "{what}: Hausdorff {}", m.hausdorff);
    }
}

/// A run lands on the count asked for when passing it would miss it by more than 1%
/// and a pair that removes one triangle (a border edge) can take the last step,
/// rather than passing it with one that removes two; above 100 triangles, passing it
/// by one is within 1% and the cheapest pair goes.
#[test]
fn a_run_lands_on_a_small_target_when_a_border_edge_can_take_the_last_step() {
    let mesh = grid(12, 12, 0.8);
    assert_eq!(mesh.triangle_count(), 288);
    for order in ORDERS {
        let mut ended = Vec::new();
        for target in [251, 143, 77, 41, 23, 11] {
            let out = simplify_replayed(&mesh, &options(order, Target::Triangles(target)))
                .expect("simplifies");
            assert_valid(&out.mesh, 288);
            assert_eq!(out.report.stop_reason, StopReason::TargetReached);
            ended.push(out.mesh.triangle_count());
        }
        assert_eq!(ended[2..], [77, 41, 23, 11], "{order:?}");
        for (got, target) in ended[..2].iter().zip([251usize, 143]) {
            assert!(
                target - got <= target / 100,
                "{order:?}: {got} for {target}"
            );
        }
    }
}

/// A closed mesh has an even count of triangles: a small odd target (where one
/// triangle is more than 1%) is put off pair by pair until none lands on it, then
/// passed by one, with the target reached, not missed.
#[test]
fn a_closed_mesh_passes_a_small_odd_target_by_one() {
    let mesh = uv_sphere([0.0; 3], 1.0, 5, 8);
    assert_eq!(mesh.triangle_count(), 64);
    for order in ORDERS {
        let out =
            simplify_replayed(&mesh, &options(order, Target::Triangles(31))).expect("simplifies");
        assert_eq!(
            out.report.stop_reason,
            StopReason::TargetReached,
            "{order:?}"
        );
        assert_eq!(out.mesh.triangle_count(), 30, "{order:?}");
        assert!(out.report.relaxations.is_empty(), "{order:?}");
    }
}

/// In a chain of levels, the pairs a level put off near its target are asked again by
/// the next level: each level lands as a run straight to its target does.
#[test]
fn each_level_of_a_chain_lands_on_its_small_target() {
    let mesh = grid(12, 12, 0.8);
    let levels = [
        Target::Triangles(77),
        Target::Triangles(41),
        Target::Triangles(23),
    ];
    for order in ORDERS {
        let chain = simplify_levels(
            &mesh,
            &options(order, Target::None),
            &levels,
            &mut NoObserver,
        )
        .expect("simplifies");
        let counts: Vec<usize> = chain.iter().map(|l| l.mesh.triangle_count()).collect();
        assert_eq!(counts, [77, 41, 23], "{order:?}");
        for level in &chain {
            assert!(level.report.relaxations.is_empty(), "{order:?}");
        }
    }
}

/// Under an error bound, a pair put off near the target is asked again when the pair
/// that would land on it is over the bound: on this grid, landing on 41 takes a border
/// edge dearer than the inner edge that passes to 40, and with the bound between the
/// two the run passes to 40 instead of stopping at 42 as if the bound had stopped it.
#[test]
fn a_put_off_pair_within_the_error_bound_is_taken_when_landing_is_over_it() {
    let mesh = grid(12, 12, 0.8);
    for order in ORDERS {
        let error_to = |target| {
            simplify(&mesh, &options(order, Target::Triangles(target)))
                .expect("simplifies")
                .report
                .max_error
        };
        let (landing, passing) = (error_to(41), error_to(40));
        assert!(passing < landing, "{order:?}: {passing} against {landing}");
        let bound = Length::DiagonalFraction((passing + landing) / 2.0);
        let out = simplify(
            &mesh,
            &options(order, Target::Triangles(41)).with_max_error(Some(bound)),
        )
        .expect("simplifies");
        assert_eq!(
            out.report.stop_reason,
            StopReason::TargetReached,
            "{order:?}"
        );
        assert_eq!(out.mesh.triangle_count(), 40, "{order:?}");
    }
}

/// A UV sphere with one triangle taken out: 63 triangles around a three-edge hole.
fn holed_sphere() -> IndexedMesh {
    let mut mesh = uv_sphere([0.0; 3], 1.0, 5, 8);
    mesh.triangles.remove(20);
    mesh
}

/// A run whose last step to a small target is refused by a check (here only a
/// contraction that closes the hole removes one triangle, and closing a border loop is
/// a relaxation) climbs the ladder to land on it rather than passing it; `strict`
/// passes it, as every run did before the landing climbed.
#[test]
fn a_run_climbs_the_ladder_to_land_on_a_small_target() {
    let mesh = holed_sphere();
    for order in ORDERS {
        for target in [40, 20, 10] {
            let out = simplify_replayed(&mesh, &options(order, Target::Triangles(target)))
                .expect("simplifies");
            assert_valid(&out.mesh, 63);
            assert_eq!(out.mesh.triangle_count(), target, "{order:?}");
            assert_eq!(out.report.stop_reason, StopReason::TargetReached);
            assert!(
                out.report
                    .relaxations
                    .iter()
                    .any(|r| r.step == RelaxationStep::BorderLoops && r.contractions > 0),
                "{order:?} {target}: {:?}",
                out.report.relaxations
            );
            let strict = simplify(
                &mesh,
                &options(order, Target::Triangles(target)).with_strict(true),
            )
            .expect("simplifies");
            assert_eq!(strict.mesh.triangle_count(), target - 1, "{order:?}");
        }
    }
}

/// When no pair lands on the target, the pair put off that passes it by the fewest
/// triangles goes: beside the tetrahedra (whose last contractions merge faces and
/// remove four), a grid's inner edge ends one below the target, not three.
#[test]
fn a_target_no_pair_lands_on_is_passed_by_the_fewest_triangles() {
    let mesh = concat(&[grid(5, 5, 0.8), tetrahedra(3)]);
    for order in ORDERS {
        for target in [9, 5] {
            let out = simplify_replayed(&mesh, &options(order, Target::Triangles(target)))
                .expect("simplifies");
            assert_valid(&out.mesh, mesh.triangle_count());
            assert_eq!(out.mesh.triangle_count(), target - 1, "{order:?}");
            assert_eq!(out.report.stop_reason, StopReason::TargetReached);
        }
    }
}
