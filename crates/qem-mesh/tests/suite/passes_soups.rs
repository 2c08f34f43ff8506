//! Properties of the pass-based order ([`SimplifyOptions::FAST`]) over random messy
//! soups (coordinates on a small integer grid, so coincident vertices, zero-area and
//! duplicate faces are common, as in `simplify_soups.rs`) and random bumpy grids with
//! triangles missing (holes, non-manifold vertices, several parts), at random targets.

use crate::common;
use crate::passes_common;

use common::assert_valid;
use passes_common::{bits, border_loops, zero_area_faces_in_input_frame};
use proptest::prelude::*;
use qem_mesh::clean::{clean, CleanOptions, Cleaned};
use qem_mesh::simplify::{
    simplify, simplify_observed, BoundaryMode, Contraction, Observer, PlacementMode, QuadricMode,
    SimplifyError, SimplifyOptions, StopReason, Target, Weighting, DEFAULT_MAX_NORMAL_ANGLE,
};
use qem_mesh::IndexedMesh;
use std::collections::BTreeSet;

/// Up to `max_vertices` vertices on a 4×4×4 integer grid and 1 to 40 faces with any
/// indices (repeated ones included).
fn soup(max_vertices: usize) -> impl Strategy<Value = IndexedMesh> {
    (3..max_vertices).prop_flat_map(|n| {
        let positions = prop::collection::vec(prop::array::uniform3(0..4i32), n);
        let triangles = prop::collection::vec(prop::array::uniform3(0..n as u32), 1..40);
        (positions, triangles).prop_map(|(p, t)| {
            IndexedMesh::new(p.into_iter().map(|c| c.map(f64::from)).collect(), t)
        })
    })
}

/// An `nx` × `ny` grid (1 to 12 each way) with heights on a coarse integer scale (so
/// flat runs, creases and spikes), each triangle kept with a chance of `keep`, and
/// each kept one's orientation flipped at random.
fn bumpy_grid(keep_all: bool) -> impl Strategy<Value = IndexedMesh> {
    (1..13u32, 1..13u32, 0.0..1.0f64).prop_flat_map(move |(nx, ny, keep)| {
        let vertices = ((nx + 1) * (ny + 1)) as usize;
        let faces = (2 * nx * ny) as usize;
        (
            prop::collection::vec(-2..3i32, vertices),
            prop::collection::vec((0.0..1.0f64, any::<bool>()), faces),
        )
            .prop_map(move |(heights, fates)| {
                let positions = (0..=ny)
                    .flat_map(|y| (0..=nx).map(move |x| (x, y)))
                    .zip(&heights)
                    .map(|((x, y), &h)| [f64::from(x), f64::from(y), 0.5 * f64::from(h)])
                    .collect();
                let id = |x: u32, y: u32| y * (nx + 1) + x;
                let mut triangles = Vec::new();
                for y in 0..ny {
                    for x in 0..nx {
                        triangles.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
                        triangles.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
                    }
                }
                let triangles = triangles
                    .into_iter()
                    .zip(&fates)
                    .filter(|(_, (p, _))| keep_all || *p < keep.max(0.3))
                    .map(|(t, &(_, flip))| {
                        if flip && !keep_all {
                            [t[0], t[2], t[1]]
                        } else {
                            t
                        }
                    })
                    .collect();
                IndexedMesh::new(positions, triangles)
            })
    })
}

/// FAST at a random ratio, with the other options the pass-based order implements
/// varied: border handling, placement, weighting, normal-angle limit (the default
/// most often), sliver limit, the orientation check, exact quadrics, and random locked
/// vertices (some
/// out of range of the smaller inputs, which must be the documented error).
fn fast_options() -> impl Strategy<Value = SimplifyOptions> {
    (
        0.0..1.0f64,
        prop_oneof![
            Just(BoundaryMode::Free),
            Just(BoundaryMode::Planes(1.0)),
            Just(BoundaryMode::Locked)
        ],
        prop_oneof![
            Just(PlacementMode::SolveFirst),
            Just(PlacementMode::Optimal),
            Just(PlacementMode::EndpointOrMidpoint)
        ],
        prop_oneof![
            Just(Weighting::Area),
            Just(Weighting::Unweighted),
            Just(SimplifyOptions::FAST.weighting)
        ],
        prop_oneof![
            3 => Just(DEFAULT_MAX_NORMAL_ANGLE),
            1 => Just(180.0),
            1 => 10.0..180.0f64
        ],
        prop_oneof![Just(0.0), 0.0..0.5f64],
        prop::collection::vec(0..200u32, 0..4),
        any::<bool>(),
        any::<bool>(),
    )
        .prop_map(
            |(r, boundary, placement, weighting, angle, sliver, locked, orientation, exact)| {
                SimplifyOptions::FAST
                    .with_target(Target::Ratio(r))
                    .with_boundary(boundary)
                    .with_placement(placement)
                    .with_weighting(weighting)
                    .with_max_normal_angle(angle)
                    .with_min_triangle_quality(sliver)
                    .with_locked_vertices(locked)
                    .with_orientation_check(orientation)
                    .with_quadrics(if exact {
                        QuadricMode::Exact
                    } else {
                        QuadricMode::Sum
                    })
            },
        )
}

/// Runs FAST twice and checks: valid output (indices in range, no repeated index,
/// finite, every vertex used, no more triangles than the input, no zero-area face by
/// `clean`'s rule, in the simplifier's frame and in the output's own) or a documented
/// error (invalid input, a locked vertex out of range, nothing left after cleaning); the report
/// agrees with the output and with the observer's contraction events; locked vertices that cleaning kept come out where they were;
/// no flipped face while the normal check is on; the same result twice, bit for bit.
/// Returns the output, if any.
fn check_fast(
    mesh: &IndexedMesh,
    o: &SimplifyOptions,
) -> Result<Option<IndexedMesh>, TestCaseError> {
    let mut events = Events(Vec::new());
    let first = simplify_observed(mesh, o, &mut events);
    let result = match &first {
        Err(SimplifyError::Input(e)) => {
            prop_assert_eq!(mesh.validate(), Err(e.clone()), "refused a valid input");
            None
        }
        Err(SimplifyError::LockedVertexOutOfRange {
            index,
            vertex_count,
        }) => {
            prop_assert!(*index as usize >= mesh.vertex_count());
            prop_assert_eq!(*vertex_count, mesh.vertex_count());
            None
        }
        Err(SimplifyError::NothingLeftAfterCleaning { triangles_in }) => {
            prop_assert_eq!(*triangles_in, mesh.triangle_count());
            prop_assert!(clean(mesh, &o.clean).mesh.triangles.is_empty());
            None
        }
        Err(e) => return Err(TestCaseError::fail(format!("unexpected error {e}"))),
        Ok(out) => {
            assert_valid(&out.mesh, mesh.triangle_count());
            prop_assert!(!out.mesh.triangles.is_empty());
            let zero = zero_area_faces_in_input_frame(mesh, &o.clean, &out.mesh);
            prop_assert!(zero.is_empty(), "zero-area faces {:?}", zero);
            // And by `clean` run on the output alone, as a downstream tool would.
            prop_assert_eq!(passes_common::zero_area_faces_by_clean(&out.mesh), 0);
            let r = &out.report;
            prop_assert_eq!(r.triangles_in, mesh.triangle_count());
            prop_assert_eq!(r.triangles_out, out.mesh.triangle_count());
            prop_assert_eq!(r.vertices_out, out.mesh.vertex_count());
            prop_assert_eq!(r.virtual_contractions, 0);
            prop_assert!(r.max_error >= 0.0 && r.max_error.is_finite());
            prop_assert!(r.stop_reason != StopReason::MaxErrorReached, "no bound set");
            prop_assert!(r.stop_reason != StopReason::Cancelled);
            if r.stop_reason == StopReason::TargetReached {
                prop_assert!(r.triangles_out <= r.target_triangles);
            }
            if o.max_normal_angle < 180.0 && !common::climbed_flipped_faces(r) {
                prop_assert_eq!(r.faces_flipped, 0);
            }
            // One event per contraction; a removed vertex never comes back, and a
            // locked one is never removed (events use the cleaned mesh's indices).
            prop_assert_eq!(events.0.len(), r.edge_contractions);
            let kept = clean(mesh, &o.clean);
            let locked: BTreeSet<u32> = o
                .locked_vertices
                .iter()
                .map(|&i| kept.vertex_map[i as usize])
                .collect();
            let mut removed = BTreeSet::new();
            for &(a, b, is_virtual) in &events.0 {
                prop_assert!(!is_virtual);
                prop_assert!(a != b);
                prop_assert!(
                    !removed.contains(&a) && !removed.contains(&b),
                    "{} {}",
                    a,
                    b
                );
                prop_assert!(!locked.contains(&b), "locked {} removed", b);
                removed.insert(b);
            }
            let present = passes_common::position_bits(&out.mesh);
            for &i in &o.locked_vertices {
                if kept.vertex_map[i as usize] != Cleaned::REMOVED {
                    let p = mesh.positions[i as usize];
                    prop_assert!(
                        present.contains(&p.map(f64::to_bits)),
                        "locked {} {:?} lost",
                        i,
                        p
                    );
                }
            }
            Some(out.mesh.clone())
        }
    };
    let second = simplify(mesh, o);
    match (first, second) {
        (Ok(a), Ok(b)) => {
            prop_assert_eq!(bits(&a.mesh), bits(&b.mesh));
            let (mut ra, mut rb) = (a.report, b.report);
            ra.timings = Default::default();
            rb.timings = Default::default();
            prop_assert_eq!(ra.max_error.to_bits(), rb.max_error.to_bits());
            prop_assert_eq!(ra, rb);
        }
        (Err(a), Err(b)) => prop_assert_eq!(a, b),
        _ => prop_assert!(false, "two runs disagree"),
    }
    Ok(result)
}

/// The observer's contraction events: (kept, removed, virtual).
struct Events(Vec<(u32, u32, bool)>);

impl Observer for Events {
    fn contracted(&mut self, c: &Contraction) {
        self.0.push((c.kept, c.removed, c.is_virtual));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Messy soups: valid, deterministic output or the documented error.
    #[test]
    fn fast_on_messy_soups(mesh in soup(30), o in fast_options()) {
        check_fast(&mesh, &o)?;
    }

    /// Bumpy grids with holes, flipped triangles and loose parts: the same.
    #[test]
    fn fast_on_holed_grids(mesh in bumpy_grid(false), o in fast_options()) {
        check_fast(&mesh, &o)?;
    }

    /// Whole bumpy grids (one part, one border loop) with the border kept (planes or
    /// locked): the output still has exactly one border loop.
    #[test]
    fn fast_keeps_a_whole_grids_border_loop(
        mesh in bumpy_grid(true),
        r in 0.0..1.0f64,
        locked in any::<bool>(),
    ) {
        prop_assert_eq!(border_loops(&mesh), 1);
        let boundary = if locked { BoundaryMode::Locked } else { BoundaryMode::Planes(1.0) };
        // Strict: a stuck run may pinch a loop on the ladder of relaxations.
        let o = SimplifyOptions::FAST
            .with_target(Target::Ratio(r))
            .with_boundary(boundary)
            .with_strict(true);
        if let Some(out) = check_fast(&mesh, &o)? {
            prop_assert_eq!(border_loops(&out), 1);
        }
    }

    /// The default cleaning welds and drops; with every pass off (zero-area faces and
    /// duplicates reach the loop) the output is still valid.
    #[test]
    fn fast_on_uncleaned_soups(mesh in soup(20), r in 0.0..1.0f64) {
        let o = SimplifyOptions::FAST
            .with_target(Target::Ratio(r))
            .with_clean(
                CleanOptions::DEFAULT
                    .with_weld_exact(false)
                    .with_drop_zero_area(false)
                    .with_drop_duplicates(false),
            );
        let first = simplify(&mesh, &o);
        match &first {
            // Documented: with the zero-area pass off, zero-area faces can be all
            // that is left.
            Err(SimplifyError::NothingLeftAfterCleaning { .. }) => {}
            Err(e) => prop_assert!(false, "unexpected error {}", e),
            Ok(out) => {
                assert_valid(&out.mesh, mesh.triangle_count());
                let zero = zero_area_faces_in_input_frame(&mesh, &o.clean, &out.mesh);
                prop_assert!(zero.is_empty(), "zero-area faces {:?}", zero);
                if !common::climbed_flipped_faces(&out.report) {
                    prop_assert_eq!(out.report.faces_flipped, 0);
                }
            }
        }
        let second = simplify(&mesh, &o);
        match (first, second) {
            (Ok(a), Ok(b)) => prop_assert_eq!(bits(&a.mesh), bits(&b.mesh)),
            (Err(a), Err(b)) => prop_assert_eq!(a, b),
            _ => prop_assert!(false, "two runs disagree"),
        }
    }
}
