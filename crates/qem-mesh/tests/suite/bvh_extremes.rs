//! The triangle index's `f32` tree at the edges of `f64` and `f32`: the facing-away
//! quick test and the nearest searches against brute force with underflowing dot
//! products, values beyond `f32`'s range, subnormals, trees of one to nine triangles,
//! and NaN and infinite queries.

use proptest::prelude::*;
use qem_mesh::measure::{brute_force_distance, closest_point_on_triangle, TriangleBvh};
use qem_mesh::IndexedMesh;

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The leaf test of `any_facing_away`, and the full test of the orientation check,
/// over every triangle: faces away (dot ≤ 0 or NaN, non-zero normal) within `r`.
fn brute_facing_away(bvh: &TriangleBvh, p: [f64; 3], r: f64, normal: [f64; 3]) -> bool {
    (0..bvh.triangle_count() as u32).any(|i| {
        let [a, b, c] = bvh.corners(i);
        let t = cross(sub(b, a), sub(c, a));
        let d = dot(t, normal);
        let q = closest_point_on_triangle(p, a, b, c);
        (d <= 0.0 || d.is_nan()) && t != [0.0; 3] && dot(sub(q, p), sub(q, p)).sqrt() <= r
    })
}

/// A triangle and a query normal both near 2e-162 in length: each length is
/// representable (its square is a subnormal), so both get unit directions and the
/// normal box prunes the triangle (unit dot ≈ 0.46), but the raw dot product the leaf
/// test and the orientation check's full test use underflows to 0, which they count as
/// facing away. The quick test accepted what the full test refuses until normals this
/// short were kept out of the normal pruning (`MIN_PRUNING_LENGTH`).
#[test]
fn quick_test_agrees_with_leaf_test_when_the_dot_product_underflows() {
    let s = 2.3e-162f64.sqrt();
    let corners = vec![[[0.0; 3], [s, 0.0, 0.0], [0.0, s, 0.0]]];
    let (bvh, _) = TriangleBvh::from_corners(corners);
    let normal = [0.0, 2e-162, 1e-162];
    let p = [0.0; 3];
    let t = cross([s, 0.0, 0.0], [0.0, s, 0.0]);
    assert!(t[2] > 0.0 && dot(t, normal) == 0.0, "setup: {t:?}");
    assert!(brute_facing_away(&bvh, p, 1.0, normal));
    assert_eq!(
        bvh.any_facing_away(p, 1.0, normal),
        brute_facing_away(&bvh, p, 1.0, normal),
        "quick test answered false where every triangle's own test says facing away"
    );
}

/// Scales spanning `f32`'s subnormals, its overflow, and `f64`'s extremes.
fn scale() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(1.0),
        Just(1e-40),
        Just(1e-300),
        Just(3.5e38),
        Just(1e39),
        Just(1e150),
    ]
}

fn coordinate() -> impl Strategy<Value = f64> {
    prop_oneof![Just(0.0), Just(-0.0), Just(1.0), Just(-1.0), -2.0f64..2.0,]
}

fn point() -> impl Strategy<Value = [f64; 3]> {
    [coordinate(), coordinate(), coordinate()]
}

/// 1..=9 triangles (so trees of one node with 1..=4 lanes, and two levels), at one
/// scale, offset by `offset` (a model far from the origin).
fn small_mesh() -> impl Strategy<Value = (IndexedMesh, f64)> {
    (scale(), 1usize..10, -1.0f64..1.0).prop_flat_map(|(s, n, off)| {
        (
            proptest::collection::vec(point(), 3 * n),
            Just(s),
            Just(off),
            Just(n),
        )
            .prop_map(|(points, s, off, n)| {
                let positions: Vec<[f64; 3]> = points
                    .iter()
                    .map(|p| p.map(|x| (x + off * 10.0) * s))
                    .collect();
                let triangles = (0..n as u32)
                    .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
                    .collect();
                (IndexedMesh::new(positions, triangles), s)
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// Distances and the facing-away test agree with brute force at every scale.
    #[test]
    fn extremes_match_brute_force(
        (mesh, s) in small_mesh(),
        queries in proptest::collection::vec(
            (point(), point(), prop_oneof![Just(0.0), Just(-0.0), 0.0f64..6.0]),
            1..8,
        ),
    ) {
        let bvh = TriangleBvh::new(&mesh);
        for (p, normal, r) in queries {
            let p = p.map(|x| x * s);
            let r = r * s;
            let got = bvh.distance(p);
            let want = brute_force_distance(&mesh, p);
            match (got, want) {
                (Some(g), Some(w)) => prop_assert!(
                    g.to_bits() == w.to_bits() || (g.is_nan() && w.is_nan()),
                    "distance {g} vs brute force {w}"
                ),
                (g, w) => prop_assert_eq!(g.is_some(), w.is_some()),
            }
            let quick = bvh.any_facing_away(p, r, normal);
            if brute_facing_away(&bvh, p, r, normal) {
                prop_assert!(quick, "missed a triangle facing away within {r}");
            }
        }
        // Non-finite queries never panic.
        for p in [[f64::NAN; 3], [f64::INFINITY, 0.0, 0.0], [f64::MAX, -f64::MAX, 0.0]] {
            let _ = bvh.distance(p);
            let mut out = Vec::new();
            let _ = bvh.nearest_triangles(p, 1.5, 1e-9, 8, &mut out);
            for r in [f64::NAN, f64::INFINITY, 0.0, 1e300] {
                let _ = bvh.any_facing_away(p, r, [0.0, 0.0, 1.0]);
            }
        }
    }
}
