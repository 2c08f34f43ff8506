//! Named scenarios of the quality controls: fold-over and sliver checks, border planes
//! and border locks, locked vertices.

use crate::common;

use common::{
    area, assert_valid, concat, grid, holed_grid, jagged_sheet, qualities, topology, uv_sphere,
};
use qem_mesh::simplify::{
    simplify, BoundaryMode, ContractionOrder, Length, SimplifyError, SimplifyOptions, StopReason,
    Target, VirtualPairs,
};
use qem_mesh::IndexedMesh;

fn at(ratio: f64) -> SimplifyOptions {
    SimplifyOptions::DEFAULT.with_target(Target::Ratio(ratio))
}

#[test]
fn jagged_sheet_folds_over_without_the_check_and_not_with_it() {
    let sheet = jagged_sheet();
    let options = at(0.1).with_boundary(BoundaryMode::Free);
    // Both checks off: the orientation check alone also stops these fold-overs.
    let unchecked = simplify(
        &sheet,
        &options
            .clone()
            .with_max_normal_angle(180.0)
            .with_orientation_check(false),
    )
    .unwrap();
    let checked = simplify(&sheet, &options).unwrap();
    assert_valid(&checked.mesh, sheet.triangle_count());
    assert!(unchecked.report.faces_flipped > 0);
    assert_eq!(unchecked.report.rejected.flip, 0, "the check was off");
    assert_eq!(checked.report.faces_flipped, 0);
    assert!(checked.report.rejected.flip > 0);
    assert_eq!(checked.report.stop_reason, StopReason::TargetReached);
}

/// A flat 20 x 20 sheet: every pair costs 0 with free borders, and the border is all
/// that the quadrics could keep.
fn flat_sheet() -> IndexedMesh {
    grid(20, 20, 0.0)
}

#[test]
fn flat_sheet_keeps_its_border_loop_and_area_with_border_planes() {
    let sheet = flat_sheet();
    let out = simplify(&sheet, &at(0.1)).unwrap();
    assert_valid(&out.mesh, sheet.triangle_count());
    assert!(out.mesh.triangle_count() <= 80);
    assert_eq!(topology(&out.mesh).2, 1, "one border loop");
    assert!(
        (area(&out.mesh) - 400.0).abs() < 1e-6,
        "area {}",
        area(&out.mesh)
    );
    // Without border planes the border moves inward at zero cost: the same run loses
    // about a quarter of the area (302 of 400 left).
    let free = simplify(&sheet, &at(0.1).with_boundary(BoundaryMode::Free)).unwrap();
    assert!(area(&free.mesh) < 350.0, "area {}", area(&free.mesh));
}

/// The most faces around one vertex of `mesh`.
fn max_valence(mesh: &IndexedMesh) -> usize {
    let mut count = vec![0usize; mesh.vertex_count()];
    for t in &mesh.triangles {
        for &v in t {
            count[v as usize] += 1;
        }
    }
    count.into_iter().max().unwrap_or(0)
}

/// A flat region, where every pair costs exactly 0, thins evenly. With ties popped in
/// the order of the vertices' names, one vertex won every tie around it and absorbed
/// its neighbours into a hub (122 faces on a 120 x 120 grid), and the hub's re-costed
/// pairs came back to the front only to be refused again: 704,850 fold-over refusals
/// for 13,122 contractions, 8.2 s. The queue now pops ties first in, first out. The
/// pass-based order breaks ties by a scatter of the edge's place in its list, and its
/// batches take no two edges at one vertex, so no vertex wins every tie either.
#[test]
fn flat_grid_thins_evenly_without_hubs() {
    let sheet = grid(60, 60, 0.0);
    // The most faces at one vertex, and the most fold-over refusals per contraction
    // (the hub's were 54 per contraction; in passes a batch's edges next to a
    // contraction of the same round meet the moved faces, about 1 in 6).
    let bounds = [
        (ContractionOrder::Greedy, 12, 0.1),
        (ContractionOrder::Passes, 16, 0.25),
    ];
    for (order, valence, refusals) in bounds {
        let out = simplify(&sheet, &at(0.1).with_order(order)).unwrap();
        assert_valid(&out.mesh, sheet.triangle_count());
        assert_eq!(out.report.stop_reason, StopReason::TargetReached);
        assert!(
            max_valence(&out.mesh) <= valence,
            "{order:?}: a hub of {} faces",
            max_valence(&out.mesh)
        );
        assert!(
            (out.report.rejected.flip as f64) < refusals * out.report.edge_contractions as f64,
            "{order:?}: {} fold-over refusals for {} contractions",
            out.report.rejected.flip,
            out.report.edge_contractions
        );
    }
}

#[test]
fn border_lock_keeps_every_border_vertex_bit_for_bit() {
    let sheet = grid(16, 12, 0.3);
    let out = simplify(&sheet, &at(0.2).with_boundary(BoundaryMode::Locked)).unwrap();
    assert_valid(&out.mesh, sheet.triangle_count());
    // 16 x 12 quads: 2·(17 + 13) − 4 = 56 border vertices.
    assert_eq!(out.report.locked_vertices, 56);
    for (i, p) in sheet.positions.iter().enumerate() {
        let (x, y) = (i % 17, i / 17);
        if x == 0 || x == 16 || y == 0 || y == 12 {
            assert!(
                out.mesh.positions.contains(p),
                "border vertex {i} {p:?} moved or vanished"
            );
        }
    }
    assert_eq!(topology(&out.mesh).2, 1);
}

#[test]
fn locked_vertices_stay_where_they_were() {
    let sphere = uv_sphere([0.0; 3], 1.0, 16, 32);
    let locked: Vec<u32> = (0..sphere.vertex_count() as u32).step_by(7).collect();
    let out = simplify(&sphere, &at(0.1).with_locked_vertices(locked.clone())).unwrap();
    assert_valid(&out.mesh, sphere.triangle_count());
    assert_eq!(out.report.locked_vertices, locked.len());
    for &i in &locked {
        let p = sphere.positions[i as usize];
        assert!(
            out.mesh.positions.contains(&p),
            "locked vertex {i} {p:?} moved or vanished"
        );
    }
}

#[test]
fn locked_vertices_are_input_indices_before_welding() {
    // A square pyramid without its base as an STL soup: 4 triangles, 12 vertices, every
    // position repeated (the apex 4 times). Whatever position the unlocked run removes,
    // locking its *last* copy in the input (not the one welding keeps) keeps it.
    let corners = [
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
    ];
    let faces = [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]];
    let positions: Vec<[f64; 3]> = faces.iter().flatten().map(|&i| corners[i]).collect();
    let soup = IndexedMesh::new(
        positions.clone(),
        vec![[0, 1, 2], [3, 4, 5], [6, 7, 8], [9, 10, 11]],
    );
    let options = SimplifyOptions::DEFAULT.with_target(Target::Triangles(2));
    let unlocked = simplify(&soup, &options).unwrap();
    assert_eq!(unlocked.report.cleanup.welded_vertices, 7);
    let gone = corners
        .iter()
        .find(|p| !unlocked.mesh.positions.contains(p))
        .expect("a contraction removed a corner");
    let last_copy = positions.iter().rposition(|p| p == gone).unwrap();
    let first_copy = positions.iter().position(|p| p == gone).unwrap();
    assert_ne!(last_copy, first_copy);
    let out = simplify(&soup, &options.with_locked_vertices(vec![last_copy as u32])).unwrap();
    assert!(out.mesh.triangle_count() <= 2);
    assert_eq!(out.report.locked_vertices, 1);
    assert!(out.mesh.positions.contains(gone), "{gone:?} was locked");
}

#[test]
fn a_locked_index_out_of_range_is_a_clear_error() {
    let sheet = grid(2, 2, 0.0);
    let err = simplify(&sheet, &at(0.5).with_locked_vertices(vec![4, 9])).unwrap_err();
    assert_eq!(
        err,
        SimplifyError::LockedVertexOutOfRange {
            index: 9,
            vertex_count: 9
        }
    );
    assert!(err.to_string().contains("locked vertex 9"));
}

#[test]
fn slivers_never_get_worse_than_the_threshold_or_the_input() {
    // Each face's quality either stays above the threshold or does not decrease, so
    // the output's worst face is at least min(threshold, input's worst face).
    let sheet = jagged_sheet();
    let min_in = qualities(&sheet).into_iter().fold(1.0, f64::min);
    let threshold = 0.5;
    let plain = simplify(&sheet, &at(0.1)).unwrap();
    let min_plain = qualities(&plain.mesh).into_iter().fold(1.0, f64::min);
    assert!(
        min_plain < threshold,
        "without the check slivers appear: {min_plain}"
    );
    let out = simplify(&sheet, &at(0.1).with_min_triangle_quality(threshold)).unwrap();
    assert_valid(&out.mesh, sheet.triangle_count());
    let min_out = qualities(&out.mesh).into_iter().fold(1.0, f64::min);
    assert!(out.report.rejected.sliver > 0);
    assert!(
        min_out >= threshold.min(min_in),
        "{min_out} < min({threshold}, {min_in})"
    );
}

#[test]
fn holes_survive_default_options_down_to_five_percent() {
    // (A plane region with three border loops of 3 edges needs at least 11 triangles,
    // so 5% = 24 triangles is about as low as the target can go.)
    let holed = holed_grid();
    assert_eq!(topology(&holed).2, 3);
    for ratio in [0.1, 0.05] {
        let out = simplify(&holed, &at(ratio)).unwrap();
        assert_valid(&out.mesh, holed.triangle_count());
        assert_eq!(topology(&out.mesh).2, 3, "ratio {ratio}: {:?}", out.report);
        assert_eq!(out.report.stop_reason, StopReason::TargetReached);
    }
    // Free borders lose holes at 5%.
    let free = simplify(&holed, &at(0.05).with_boundary(BoundaryMode::Free)).unwrap();
    assert!(topology(&free.mesh).2 < 3, "{:?}", topology(&free.mesh));
}

#[test]
fn virtual_pairs_between_components_ignore_a_sheet_folded_onto_itself() {
    // A 20 x 3 strip folded in two at x = 10: the second half lies 0.3 above the first.
    //
    //   z = 0.3   x=9 <------------ x=0   (columns 11..20)
    //                \
    //   z = 0     x=0 ------------> x=10  (columns 0..10)
    let mut folded = grid(20, 3, 0.0);
    for p in &mut folded.positions {
        if p[0] > 10.0 {
            *p = [20.0 - p[0], p[1], 0.3];
        }
    }
    // The diagonal is about 10.4, so 5% of it (0.52) spans the 0.3 gap.
    let options = at(0.5).with_pair_threshold(Length::DiagonalFraction(0.05));
    let any = simplify(&folded, &options).unwrap();
    assert!(any.report.virtual_pairs > 0);
    let between = simplify(
        &folded,
        &options
            .clone()
            .with_virtual_pairs(VirtualPairs::BetweenComponents),
    )
    .unwrap();
    assert_eq!(between.report.virtual_pairs, 0, "one component: no pair");
    assert_eq!(between.report.virtual_contractions, 0);

    // Cut at the fold, the two halves are two components, and pair up again.
    let halves = concat(&[grid(10, 3, 0.0), {
        let mut upper = grid(10, 3, 0.0);
        for p in &mut upper.positions {
            p[2] = 0.3;
        }
        upper
    }]);
    let parts = simplify(
        &halves,
        &options.with_virtual_pairs(VirtualPairs::BetweenComponents),
    )
    .unwrap();
    assert!(parts.report.virtual_pairs > 0);
}
