//! Simplification under a memory budget (`tiles::budget`): a mesh that does not fit
//! goes through rounds of tiles and an in-core finish, and comes out valid, at its
//! target, close to the in-core run, the same every time, its temporary files gone.

use crate::common::{assert_valid, uv_sphere};
use qem_mesh::measure::{measure, MeasureOptions};
use qem_mesh::simplify::{simplify, NoObserver, SimplifyOptions, Target};
use qem_mesh::tiles::budget::{
    in_core_bytes, simplify_within, BudgetError, BudgetRun, CLUSTER_BYTES_PER_TRIANGLE,
    FIXED_BYTES, IN_CORE_BYTES_PER_TRIANGLE,
};
use qem_mesh::tiles::jobs::SplitInput;
use qem_mesh::IndexedMesh;
use std::path::Path;

/// A sphere of 79,600 triangles with a bumpy surface (so that it has features to
/// lose), radius about 1.
fn bumpy_sphere() -> IndexedMesh {
    let mut mesh = uv_sphere([0.0; 3], 1.0, 200, 200);
    for p in &mut mesh.positions {
        let bump = 1.0 + 0.05 * (7.0 * p[0]).sin() * (5.0 * p[1]).cos() * (3.0 * p[2]).sin();
        *p = p.map(|c| c * bump);
    }
    mesh
}

fn run(mesh: &IndexedMesh, options: &SimplifyOptions, budget: u64, scratch: &Path) -> BudgetRun {
    let input = SplitInput {
        name: "bumpy.ply".into(),
        size_bytes: 0,
        mesh: mesh.clone(),
    };
    simplify_within(input, options, budget, scratch, &mut NoObserver).expect("simplifies")
}

/// A budget that holds `triangles` in core.
fn room_for(triangles: u64) -> u64 {
    FIXED_BYTES + IN_CORE_BYTES_PER_TRIANGLE * triangles
}

#[test]
fn a_mesh_over_the_budget_is_tiled_then_finished_close_to_in_core() {
    let mesh = bumpy_sphere();
    let n = mesh.triangle_count();
    let options = SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.02));
    let scratch = tempfile::tempdir().unwrap();
    // Room for a quarter of the mesh: tiles of 19,900 triangles.
    let out = run(&mesh, &options, room_for(n as u64 / 4), scratch.path());
    assert_eq!(out.rounds.len(), 1, "{:?}", out.rounds);
    let round = &out.rounds[0];
    assert_eq!(round.triangles_in, n);
    assert!(round.tiles >= 4, "{round:?}");
    assert!(round.triangles_out <= out.room, "{round:?}");
    assert_eq!(out.result.mesh.triangle_count(), out.target_triangles);
    assert_eq!(out.target_triangles, 1592);
    assert_valid(&out.result.mesh, n);
    // Nothing left in the scratch directory.
    assert_eq!(std::fs::read_dir(scratch.path()).unwrap().count(), 0);

    // Close to the in-core run (BENCHMARKS.md has the figures on large meshes).
    let in_core = simplify(&mesh, &options).unwrap();
    let m = |out: &IndexedMesh| measure(&mesh, out, &MeasureOptions::DEFAULT).unwrap();
    let (tiled, whole) = (m(&out.result.mesh), m(&in_core.mesh));
    let mean = |x: &qem_mesh::measure::Measurement| (x.mean_ab + x.mean_ba) / 2.0;
    assert!(
        mean(&tiled) <= 1.25 * mean(&whole),
        "mean {} against {}",
        mean(&tiled),
        mean(&whole)
    );
    assert!(
        tiled.hausdorff <= 1.25 * whole.hausdorff,
        "Hausdorff {} against {}",
        tiled.hausdorff,
        whole.hausdorff
    );

    // The same again, bit for bit.
    let again = run(&mesh, &options, room_for(n as u64 / 4), scratch.path());
    assert_eq!(again.result.mesh, out.result.mesh);

    // Far from zero (a scan in georeferenced coordinates) it is as close to in core:
    // the quadrics the tiles carry keep their precision.
    let mut far = mesh.clone();
    for p in &mut far.positions {
        *p = [p[0] + 3.0e6, p[1] - 5.0e6, p[2] + 1.0e5];
    }
    let far_out = run(&far, &options, room_for(n as u64 / 4), scratch.path());
    let far_in_core = simplify(&far, &options).unwrap();
    let m = |out: &IndexedMesh| measure(&far, out, &MeasureOptions::DEFAULT).unwrap();
    let (tiled, whole) = (m(&far_out.result.mesh), m(&far_in_core.mesh));
    assert!(
        mean(&tiled) <= 1.25 * mean(&whole) && tiled.hausdorff <= 1.25 * whole.hausdorff,
        "far from zero: mean {} against {}, Hausdorff {} against {}",
        mean(&tiled),
        mean(&whole),
        tiled.hausdorff,
        whole.hausdorff
    );
}

#[test]
fn a_mesh_within_the_budget_is_simplified_in_core_as_without_one() {
    let mesh = bumpy_sphere();
    let options = SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.1));
    let scratch = tempfile::tempdir().unwrap();
    let out = run(
        &mesh,
        &options,
        in_core_bytes(mesh.triangle_count(), &options),
        scratch.path(),
    );
    assert!(out.rounds.is_empty());
    assert_eq!(out.result.mesh, simplify(&mesh, &options).unwrap().mesh);
}

#[test]
fn a_budget_too_small_is_a_clear_error_before_any_file() {
    let mesh = bumpy_sphere();
    let scratch = tempfile::tempdir().unwrap();
    let input = || SplitInput {
        name: "bumpy.ply".into(),
        size_bytes: 0,
        mesh: mesh.clone(),
    };
    let options = SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.1));
    // Room for 5,000 triangles: tiles would be all border.
    let e = simplify_within(
        input(),
        &options.clone().with_target(Target::Ratio(0.02)),
        room_for(5_000),
        scratch.path(),
        &mut NoObserver,
    )
    .unwrap_err();
    assert!(matches!(e, BudgetError::TooSmall { .. }), "{e}");
    assert!(e.to_string().contains("too small for tiles"), "{e}");
    // The output must fit in one piece.
    let most = options.clone().with_target(Target::Ratio(0.5));
    let e = simplify_within(
        input(),
        &most,
        room_for(20_000),
        scratch.path(),
        &mut NoObserver,
    )
    .unwrap_err();
    assert!(e.to_string().contains("the last step"), "{e}");
    // Clustering runs in one piece only.
    let cluster = SimplifyOptions::CLUSTER.with_target(Target::Ratio(0.1));
    let e = simplify_within(
        input(),
        &cluster,
        FIXED_BYTES + CLUSTER_BYTES_PER_TRIANGLE * 1_000,
        scratch.path(),
        &mut NoObserver,
    )
    .unwrap_err();
    assert!(e.to_string().contains("vertex clustering"), "{e}");
    // Options the tiles refuse are refused before anything is written.
    let locked = options.clone().with_locked_vertices(vec![0]);
    let e = simplify_within(
        input(),
        &locked,
        room_for(20_000),
        scratch.path(),
        &mut NoObserver,
    )
    .unwrap_err();
    assert!(e.to_string().contains("locked vertices"), "{e}");
    assert_eq!(std::fs::read_dir(scratch.path()).unwrap().count(), 0);
}

/// A file read by the budgeted run itself (streamed into tiles when it does not fit,
/// read whole when it does) gives what the run on the mesh read from it gives, bit
/// for bit, and leaves nothing in the scratch directory; as PLY and as OBJ (whose
/// reader numbers vertices its own way).
#[test]
fn a_file_gives_what_its_mesh_gives_streamed_or_read() {
    use qem_mesh::tiles::budget::simplify_file_within;
    let mesh = bumpy_sphere();
    let n = mesh.triangle_count() as u64;
    let dir = tempfile::tempdir().unwrap();
    let options = SimplifyOptions::DEFAULT.with_target(Target::Ratio(0.02));
    let scratch = tempfile::tempdir().unwrap();
    let cases = ["bumpy.ply", "bumpy.obj"].into_iter().flat_map(|name| {
        [
            (name, room_for(n / 4), true),
            (name, room_for(2 * n), false),
        ]
    });
    for (name, budget, tiled) in cases {
        let path = dir.path().join(name);
        qem_mesh::io::write_path(&path, &mesh).unwrap();
        let read = qem_mesh::io::read_path(&path).unwrap().mesh;
        let from_file =
            simplify_file_within(&path, &options, budget, scratch.path(), &mut NoObserver)
                .expect("simplifies");
        let from_mesh = run(&read, &options, budget, scratch.path());
        assert_eq!(from_file.run.rounds.is_empty(), !tiled);
        assert_eq!(from_file.run.rounds, from_mesh.rounds);
        assert_eq!(from_file.run.result.mesh, from_mesh.result.mesh);
        assert_eq!(
            (from_file.triangles_in, from_file.vertices_in),
            (read.triangle_count(), read.vertex_count())
        );
        assert_eq!(std::fs::read_dir(scratch.path()).unwrap().count(), 0);
    }
}
