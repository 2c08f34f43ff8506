//! `measure`: named scenarios with exact expectations, and properties against brute force.

use proptest::prelude::*;
use qem_mesh::measure::{
    brute_force_distance, closest_point_on_triangle, measure, MeasureError, MeasureOptions,
    TriangleBvh, Which,
};
use qem_mesh::{IndexedMesh, InputError};

/// A distance this small (as a fraction of the diagonal) is floating-point rounding of
/// sample positions (`u·a + v·b + w·c` is not exactly on the triangle's plane).
const ROUNDING: f64 = 1e-15;

fn small(seed: u64) -> MeasureOptions {
    MeasureOptions {
        samples_per_face: 20.0,
        min_samples: 2000,
        max_samples: None,
        seed,
    }
}

/// An n×n grid of squares (two triangles each) over [0, 1]² at height `z`.
fn grid(n: u32, z: f64) -> IndexedMesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            positions.push([f64::from(i) / f64::from(n), f64::from(j) / f64::from(n), z]);
        }
    }
    let mut triangles = Vec::new();
    let v = |i: u32, j: u32| j * (n + 1) + i;
    for j in 0..n {
        for i in 0..n {
            triangles.push([v(i, j), v(i + 1, j), v(i + 1, j + 1)]);
            triangles.push([v(i, j), v(i + 1, j + 1), v(i, j + 1)]);
        }
    }
    IndexedMesh::new(positions, triangles)
}

/// The closed unit cube, 12 triangles.
fn cube() -> IndexedMesh {
    let mut positions = Vec::new();
    for k in 0..8u32 {
        positions.push([
            f64::from(k & 1),
            f64::from((k >> 1) & 1),
            f64::from((k >> 2) & 1),
        ]);
    }
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let triangles = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    IndexedMesh::new(positions, triangles)
}

/// A negative margin counts as 0, so the nearest triangle is always in the answer,
/// with or without a known distance to start from (a review found `None` for margins
/// below 0 before they were clamped).
#[test]
fn a_negative_margin_still_finds_the_nearest_triangle() {
    // Two triangles in planes z = 1 and z = 3 above the query point at the origin.
    let mesh = IndexedMesh::new(
        vec![
            [-1.0, -1.0, 1.0],
            [1.0, -1.0, 1.0],
            [0.0, 1.0, 1.0],
            [-1.0, -1.0, 3.0],
            [1.0, -1.0, 3.0],
            [0.0, 1.0, 3.0],
        ],
        vec![[0, 1, 2], [3, 4, 5]],
    );
    let bvh = TriangleBvh::new(&mesh);
    let p = [0.0, 0.0, 0.0];
    let far = (0..2u32)
        .max_by(|&x, &y| {
            let dx = bvh.distance_squared_to(p, x).unwrap();
            let dy = bvh.distance_squared_to(p, y).unwrap();
            dx.total_cmp(&dy)
        })
        .unwrap();
    let far2 = bvh.distance_squared_to(p, far).unwrap();
    assert_eq!(far2, 9.0);
    for margin in [-2.5, -0.5, f64::NAN] {
        let (mut plain, mut within) = (Vec::new(), Vec::new());
        let a = bvh.nearest_triangles(p, 1.0, margin, 8, &mut plain);
        let b = bvh.nearest_triangles_within(p, far2, 1.0, margin, 8, &mut within);
        assert!(a.is_some(), "margin {margin}");
        assert_ne!(a, Some(far), "margin {margin}");
        assert_eq!(a, b, "margin {margin}");
        assert_eq!(plain.len(), 1, "margin {margin}");
        assert_eq!(plain, within, "margin {margin}");
    }
}

#[test]
fn identical_meshes_are_at_distance_zero() {
    for mesh in [grid(7, 0.3), cube()] {
        let m = measure(&mesh, &mesh, &small(1)).unwrap();
        // Zero up to the rounding of a sample point built from barycentric coordinates.
        for v in [m.hausdorff, m.mean_ab, m.mean_ba, m.rms_ab, m.rms_ba] {
            assert!(v <= ROUNDING, "{m:?}");
        }
        assert!(m.samples_ab >= 2000 && m.samples_ba >= 2000);
    }
}

#[test]
fn a_plane_offset_by_d_is_at_distance_d_everywhere() {
    let d = 0.125;
    let a = grid(5, 0.0);
    let b = grid(3, d); // a different triangulation of the same square
    let m = measure(&a, &b, &small(7)).unwrap();
    let diagonal = 2f64.sqrt();
    assert_eq!(m.diagonal, diagonal);
    for (name, v) in [
        ("hausdorff", m.hausdorff),
        ("hausdorff_ab", m.hausdorff_ab),
        ("hausdorff_ba", m.hausdorff_ba),
        ("mean_ab", m.mean_ab),
        ("mean_ba", m.mean_ba),
        ("rms_ab", m.rms_ab),
        ("rms_ba", m.rms_ba),
    ] {
        assert!((v - d / diagonal).abs() <= 1e-14, "{name} = {v}");
    }
}

#[test]
fn sample_counts_follow_the_options() {
    // 50 triangles: 20/face = 1000 < min 2000, so 2000 face samples; 36 vertices;
    // boundary samples at the face spacing sqrt(1 / 2000) along a perimeter of 4.
    let a = grid(5, 0.0);
    let m = measure(&a, &a, &small(0)).unwrap();
    let spacing = (1.0f64 / 2000.0).sqrt();
    let boundary_min = (4.0 / spacing).ceil() as u64;
    assert!(m.samples_ab >= 36 + 2000 + boundary_min, "{}", m.samples_ab);
    assert!(
        m.samples_ab <= 36 + 2000 + boundary_min + 20,
        "{}",
        m.samples_ab
    );
    let capped = MeasureOptions {
        max_samples: Some(100),
        ..small(0)
    };
    let m = measure(&a, &a, &capped).unwrap();
    assert!(m.samples_ab <= 36 + 100 + 100, "{}", m.samples_ab);
}

#[test]
fn the_same_seed_gives_identical_figures_and_another_seed_different_ones() {
    let a = grid(6, 0.0);
    let mut b = grid(4, 0.0);
    for (k, p) in b.positions.iter_mut().enumerate() {
        p[2] = 0.01 * ((k * 7 % 5) as f64);
    }
    let x = measure(&a, &b, &small(3)).unwrap();
    let y = measure(&a, &b, &small(3)).unwrap();
    assert_eq!(x, y);
    let z = measure(&a, &b, &small(4)).unwrap();
    assert_ne!(x.mean_ab, z.mean_ab);
}

#[test]
fn the_results_do_not_depend_on_the_thread_count() {
    let a = cube();
    let mut b = cube();
    b.positions[7] = [1.2, 1.1, 0.9];
    let options = small(5);
    let many = measure(&a, &b, &options).unwrap();
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap()
        .install(|| measure(&a, &b, &options).unwrap());
    assert_eq!(many, one);
}

#[test]
fn a_missing_face_shows_in_one_direction_only() {
    // b is the cube without its top (z = 1) face: every point of b lies on a, but the
    // centre of a's top is 0.5 away from b's walls.
    let a = cube();
    let mut b = cube();
    b.triangles.remove(2);
    b.triangles.remove(2);
    let options = MeasureOptions {
        min_samples: 20_000,
        ..small(2)
    };
    let m = measure(&a, &b, &options).unwrap();
    let diagonal = 3f64.sqrt();
    assert!(m.hausdorff_ba <= ROUNDING && m.mean_ba <= ROUNDING, "{m:?}");
    // No point of the top is farther than 0.5; ~3,300 samples land on it, so some
    // fall within 0.05 of its centre.
    assert!(m.hausdorff_ab <= 0.5 / diagonal + ROUNDING, "{m:?}");
    assert!(m.hausdorff_ab > 0.45 / diagonal, "{m:?}");
    assert!(m.mean_ab > 0.0);
    assert_eq!(m.hausdorff, m.hausdorff_ab);
}

#[test]
fn errors_name_the_mesh() {
    let good = cube();
    let empty = IndexedMesh::new(vec![[0.0; 3]], vec![]);
    assert_eq!(
        measure(&good, &empty, &small(0)),
        Err(MeasureError::Invalid {
            mesh: Which::B,
            error: InputError::NoTriangles
        })
    );
    let point = IndexedMesh::new(vec![[1.0; 3]], vec![[0, 0, 0]]);
    assert_eq!(
        measure(&point, &good, &small(0)),
        Err(MeasureError::ZeroDiagonal)
    );
    let bad_index = IndexedMesh::new(vec![[1.0; 3]], vec![[0, 0, 5]]);
    assert!(matches!(
        measure(&bad_index, &good, &small(0)),
        Err(MeasureError::Invalid { mesh: Which::A, .. })
    ));
    let nan = MeasureOptions {
        samples_per_face: f64::NAN,
        ..small(0)
    };
    assert!(matches!(
        measure(&good, &good, &nan),
        Err(MeasureError::BadSamplesPerFace(_))
    ));
}

#[test]
fn degenerate_triangles_are_measured_as_their_edges() {
    // A needle (collinear corners) and a point triangle.
    let a = [0.0, 0.0, 0.0];
    let b = [2.0, 0.0, 0.0];
    let c = [1.0, 0.0, 0.0];
    assert_eq!(
        closest_point_on_triangle([1.5, 3.0, 0.0], a, b, c),
        [1.5, 0.0, 0.0]
    );
    assert_eq!(
        closest_point_on_triangle([5.0, 0.0, 4.0], c, c, c),
        [1.0, 0.0, 0.0]
    );
    // Plain regions of a proper triangle.
    let (a, b, c) = ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    assert_eq!(
        closest_point_on_triangle([0.25, 0.25, 2.0], a, b, c),
        [0.25, 0.25, 0.0]
    );
    assert_eq!(
        closest_point_on_triangle([-1.0, -1.0, 0.0], a, b, c),
        [0.0, 0.0, 0.0]
    );
    assert_eq!(
        closest_point_on_triangle([1.0, 1.0, 0.0], a, b, c),
        [0.5, 0.5, 0.0]
    );
    assert_eq!(
        closest_point_on_triangle([0.5, -2.0, 1.0], a, b, c),
        [0.5, 0.0, 0.0]
    );
}

fn coordinate() -> impl Strategy<Value = f64> {
    -10.0f64..10.0
}

fn point() -> impl Strategy<Value = [f64; 3]> {
    [coordinate(), coordinate(), coordinate()]
}

/// Random soups: positions, some of them repeated, and triangles over them (degenerate
/// ones included).
fn soup() -> impl Strategy<Value = IndexedMesh> {
    (4usize..40).prop_flat_map(|n| {
        (
            proptest::collection::vec(point(), n),
            proptest::collection::vec([0..n as u32, 0..n as u32, 0..n as u32], 1..80),
        )
            .prop_map(|(positions, triangles)| IndexedMesh::new(positions, triangles))
    })
}

/// Squared distance from `p` to the closest point of triangle `abc`, minimised over a
/// fine barycentric grid: an independent check that the closest point is no farther.
fn grid_search_distance(p: [f64; 3], a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    let steps = 60;
    let mut best = f64::INFINITY;
    for i in 0..=steps {
        for j in 0..=(steps - i) {
            let (u, v) = (f64::from(i) / 60.0, f64::from(j) / 60.0);
            let w = 1.0 - u - v;
            let q = [
                u * a[0] + v * b[0] + w * c[0],
                u * a[1] + v * b[1] + w * c[1],
                u * a[2] + v * b[2] + w * c[2],
            ];
            let d = (0..3).map(|k| (q[k] - p[k]).powi(2)).sum::<f64>();
            best = best.min(d);
        }
    }
    best.sqrt()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn the_index_finds_the_same_distance_as_brute_force(
        mesh in soup(),
        queries in proptest::collection::vec(point(), 1..30),
    ) {
        let bvh = TriangleBvh::new(&mesh);
        for p in queries {
            let indexed = bvh.distance(p).unwrap();
            let brute = brute_force_distance(&mesh, p).unwrap();
            // Both take the minimum of the same per-triangle values: equal to the bit.
            prop_assert_eq!(indexed, brute);
        }
    }

    /// `nearest_triangles` returns exactly the triangles a brute-force pass over the
    /// mesh finds: of those within `factor` times the nearest distance plus `margin`, the
    /// `max_count` nearest (by squared distance, then index); and the nearest one.
    #[test]
    fn nearest_triangles_are_those_brute_force_finds_within_the_bound(
        mesh in soup(),
        queries in proptest::collection::vec(point(), 1..20),
        factor in 1.0f64..2.0,
        margin in prop_oneof![Just(0.0), 0.0f64..0.5],
        max_count in prop_oneof![Just(usize::MAX), 0usize..10],
    ) {
        let bvh = TriangleBvh::new(&mesh);
        let mut near = Vec::new();
        for p in queries {
            let nearest = bvh.nearest_triangles(p, factor, margin, max_count, &mut near);
            let squared = |i: u32| {
                let [a, b, c] = bvh.corners(i);
                let q = closest_point_on_triangle(p, a, b, c);
                (0..3).map(|k| (q[k] - p[k]).powi(2)).sum::<f64>()
            };
            let mut all: Vec<(f64, u32)> =
                (0..mesh.triangles.len() as u32).map(|i| (squared(i), i)).collect();
            all.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            prop_assert_eq!(Some(all[0].0.sqrt()), bvh.distance(p));
            prop_assert_eq!(nearest, Some(all[0].1));
            let limit = all[0].0.sqrt() * factor + margin;
            let mut expected: Vec<u32> = all
                .iter()
                .filter(|&&(d2, _)| d2.sqrt() <= limit)
                .take(max_count)
                .map(|&(_, i)| i)
                .collect();
            expected.sort_unstable();
            prop_assert_eq!(&near, &expected);
        }
    }

    /// `nearest_triangles_within`, told the distance of any one triangle (as
    /// `distance_squared_to` gives it), answers exactly as `nearest_triangles`.
    #[test]
    fn nearest_triangles_within_a_known_distance_answer_the_same(
        mesh in soup(),
        queries in proptest::collection::vec((point(), any::<proptest::sample::Index>()), 1..20),
        factor in 1.0f64..2.0,
        margin in prop_oneof![Just(0.0), 0.0f64..0.5],
        max_count in prop_oneof![Just(usize::MAX), 0usize..10],
    ) {
        let bvh = TriangleBvh::new(&mesh);
        let (mut near, mut near_within) = (Vec::new(), Vec::new());
        for (p, known) in queries {
            let known = known.index(bvh.triangle_count()) as u32;
            let known2 = bvh.distance_squared_to(p, known).unwrap();
            let nearest = bvh.nearest_triangles(p, factor, margin, max_count, &mut near);
            let within = bvh.nearest_triangles_within(
                p, known2, factor, margin, max_count, &mut near_within,
            );
            prop_assert_eq!(nearest, within);
            prop_assert_eq!(&near, &near_within);
        }
    }

    /// `any_facing_away` answers exactly what a brute force over every triangle within
    /// the radius answers, up to the documented widening: it may see a triangle a
    /// rounding error beyond the radius, never miss one inside it. Normals include NaN
    /// and tiny ones (the quick test must never accept what the full test refuses).
    #[test]
    fn any_facing_away_matches_brute_force(
        mesh in soup(),
        queries in proptest::collection::vec(
            (point(), point(), prop_oneof![Just(0.0), 0.0f64..6.0]),
            1..20,
        ),
        special in prop_oneof![Just(None), Just(Some(f64::NAN)), Just(Some(1e-170))],
    ) {
        let bvh = TriangleBvh::new(&mesh);
        let cross = |a: [f64; 3], b: [f64; 3]| {
            [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
        };
        let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        for (k, (p, normal, radius)) in queries.into_iter().enumerate() {
            let normal = match special {
                Some(x) if k % 2 == 0 => normal.map(|c| c * x),
                _ => normal,
            };
            let count = mesh.triangles.len() as u32;
            let facing_away_within = |r: f64| {
                (0..count).any(|i| {
                    let [a, b, c] = bvh.corners(i);
                    let t = cross(sub(b, a), sub(c, a));
                    let d = dot(t, normal);
                    let q = closest_point_on_triangle(p, a, b, c);
                    let dist = dot(sub(q, p), sub(q, p)).sqrt();
                    (d <= 0.0 || d.is_nan()) && t != [0.0; 3] && dist <= r
                })
            };
            let got = bvh.any_facing_away(p, radius, normal);
            if facing_away_within(radius) {
                prop_assert!(got, "missed a triangle facing away within {radius}");
            } else if got {
                prop_assert!(
                    facing_away_within(radius * (1.0 + 1e-6) + 1e-9),
                    "found a triangle facing away far beyond {radius}"
                );
            }
        }
    }

    #[test]
    fn the_closest_point_is_on_the_triangle_and_no_farther_than_any_grid_point(
        p in point(), a in point(), b in point(), c in point(),
    ) {
        let q = closest_point_on_triangle(p, a, b, c);
        let d = (0..3).map(|k| (q[k] - p[k]).powi(2)).sum::<f64>().sqrt();
        prop_assert!(d <= grid_search_distance(p, a, b, c) + 1e-9);
        // q lies on the triangle: its distance to the triangle's plane region is ~0,
        // i.e. the closest point of the triangle to q is q itself.
        let back = closest_point_on_triangle(q, a, b, c);
        let err = (0..3).map(|k| (back[k] - q[k]).powi(2)).sum::<f64>().sqrt();
        prop_assert!(err <= 1e-9 * (1.0 + d), "q {:?} moved to {:?}", q, back);
    }

    #[test]
    fn the_symmetric_hausdorff_is_the_larger_directed_one(
        a in soup(), b in soup(), seed in any::<u64>(),
    ) {
        let options = MeasureOptions { samples_per_face: 2.0, min_samples: 200, max_samples: Some(400), seed };
        match measure(&a, &b, &options) {
            Ok(m) => {
                prop_assert_eq!(m.hausdorff, m.hausdorff_ab.max(m.hausdorff_ba));
                prop_assert!(m.mean_ab <= m.rms_ab * (1.0 + 1e-12) && m.rms_ab <= m.hausdorff_ab * (1.0 + 1e-12));
                prop_assert!(m.mean_ba <= m.rms_ba * (1.0 + 1e-12) && m.rms_ba <= m.hausdorff_ba * (1.0 + 1e-12));
                prop_assert!(m.samples_ab > 0 && m.samples_ba > 0);
            }
            Err(e) => prop_assert_eq!(e, MeasureError::ZeroDiagonal),
        }
    }
}

/// Faces facing away are counted exactly: none for a mesh against itself, and each
/// reversed face of B once, with its share of B's area.
#[test]
fn reversed_faces_are_counted_as_facing_away_with_their_area() {
    let a = cube();
    let same = measure(&a, &a, &small(1)).unwrap();
    assert_eq!(same.faces_facing_away, 0);
    assert_eq!(same.facing_away_area, 0.0);

    let mut b = cube();
    // Two faces of one side (1/6 of the area), and one of another side (1/12).
    for t in [0, 1, 4] {
        b.triangles[t].swap(1, 2);
    }
    let m = measure(&a, &b, &small(1)).unwrap();
    assert_eq!(m.faces_facing_away, 3);
    assert!(
        (m.facing_away_area - 0.25).abs() < 1e-12,
        "{}",
        m.facing_away_area
    );
    // The distances do not see the orientation.
    assert_eq!(m.hausdorff, same.hausdorff);
}

/// The count asks A's triangle nearest to each face's centroid, not the one it came
/// from: a face of B lying just under A's top sheet of a thin slab, facing down like
/// the bottom sheet, faces away from A there.
#[test]
fn a_face_nearest_the_other_side_of_a_thin_part_faces_away() {
    let top = grid(2, 0.1);
    let mut bottom = grid(2, 0.0);
    for t in &mut bottom.triangles {
        t.swap(1, 2);
    }
    let n = top.positions.len() as u32;
    let mut slab = top.clone();
    slab.positions.extend(bottom.positions.iter().copied());
    slab.triangles
        .extend(bottom.triangles.iter().map(|t| t.map(|v| v + n)));
    // B: one downward face at height 0.09, nearer the top sheet (0.01) than the bottom (0.09).
    let b = IndexedMesh::new(
        vec![[0.2, 0.2, 0.09], [0.3, 0.4, 0.09], [0.4, 0.2, 0.09]],
        vec![[0, 1, 2]],
    );
    let m = measure(&slab, &b, &small(1)).unwrap();
    assert_eq!(m.faces_facing_away, 1);
    assert_eq!(m.facing_away_area, 1.0);
    // Lowered to 0.04, nearer the bottom sheet: it agrees.
    let mut lower = b.clone();
    for p in &mut lower.positions {
        p[2] = 0.04;
    }
    assert_eq!(
        measure(&slab, &lower, &small(1)).unwrap().faces_facing_away,
        0
    );
}
