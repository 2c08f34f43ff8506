//! Property tests of the quadric algebra and of placement.

use proptest::prelude::*;
use qem_core::{
    minimize, minimize_by_cofactors, optimal_placement, solve_first_placement, DVec3, Frame,
    Quadric, SINGULAR_DETERMINANT_RATIO,
};

/// A plane with unit normal, offset and weight, kept explicitly for brute force.
#[derive(Clone, Copy, Debug)]
struct Plane {
    normal: DVec3,
    d: f64,
    weight: f64,
}

impl Plane {
    fn squared_distance(&self, p: DVec3) -> f64 {
        let s = self.normal.dot(p) + self.d;
        s * s
    }
    fn quadric(&self) -> Quadric {
        Quadric::from_plane(self.normal, self.d) * self.weight
    }
}

fn point() -> impl Strategy<Value = DVec3> {
    (-2.0..2.0f64, -2.0..2.0f64, -2.0..2.0f64).prop_map(|(x, y, z)| DVec3::new(x, y, z))
}

fn plane() -> impl Strategy<Value = Plane> {
    (point(), -2.0..2.0f64, 0.01..10.0f64)
        .prop_filter("normal must be normalisable", |(n, _, _)| n.length() > 1e-3)
        .prop_map(|(n, d, weight)| Plane {
            normal: n.normalize(),
            d,
            weight,
        })
}

fn planes() -> impl Strategy<Value = Vec<Plane>> {
    prop::collection::vec(plane(), 1..12)
}

fn sum(planes: &[Plane]) -> Quadric {
    planes.iter().map(Plane::quadric).sum()
}

fn brute_force(planes: &[Plane], p: DVec3) -> f64 {
    planes
        .iter()
        .map(|pl| pl.weight * pl.squared_distance(p))
        .sum()
}

/// The determinant of `q`'s `A` divided by its largest entry cubed, by the rule of
/// Sarrus over the full matrix (not the cofactors' expansion the solve uses).
fn scaled_determinant(q: &Quadric) -> f64 {
    let m = [[q.xx, q.xy, q.xz], [q.xy, q.yy, q.yz], [q.xz, q.yz, q.zz]];
    let largest = m.iter().flatten().fold(0.0_f64, |l, v| l.max(v.abs()));
    let m = m.map(|row| row.map(|v| v / largest));
    m[0][0] * m[1][1] * m[2][2] + m[0][1] * m[1][2] * m[2][0] + m[0][2] * m[1][0] * m[2][1]
        - m[0][2] * m[1][1] * m[2][0]
        - m[0][0] * m[1][2] * m[2][1]
        - m[0][1] * m[1][0] * m[2][2]
}

/// Rounding allowance for a sum of `n` terms of the given magnitude.
fn rounding(magnitude: f64) -> f64 {
    1e-12 * (1.0 + magnitude)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn evaluate_is_non_negative(ps in planes(), p in point()) {
        let q = sum(&ps);
        let scale = q.magnitude() * (1.0 + p.length_squared());
        prop_assert!(q.evaluate(p) >= -rounding(scale));
    }

    #[test]
    fn evaluate_is_additive(a in planes(), b in planes(), p in point()) {
        let (qa, qb) = (sum(&a), sum(&b));
        let lhs = (qa + qb).evaluate(p);
        let rhs = qa.evaluate(p) + qb.evaluate(p);
        let scale = (qa.magnitude() + qb.magnitude()) * (1.0 + p.length_squared());
        prop_assert!((lhs - rhs).abs() <= rounding(scale));
    }

    #[test]
    fn from_plane_is_squared_distance(pl in plane(), p in point()) {
        let q = Quadric::from_plane(pl.normal, pl.d);
        let expected = pl.squared_distance(p);
        prop_assert!((q.evaluate(p) - expected).abs() <= 1e-12 * (1.0 + expected));
    }

    /// The reference for "exact" later: a quadric of planes equals the brute-force sum
    /// of weighted squared distances over the explicit plane list, to 1e-9 relative.
    #[test]
    fn quadric_of_planes_equals_brute_force_sum(ps in planes(), p in point()) {
        let q = sum(&ps);
        let exact = brute_force(&ps, p);
        let scale: f64 = ps.iter().map(|pl| pl.weight * (1.0 + pl.d.abs() + p.length()).powi(2)).sum();
        prop_assert!((q.evaluate(p) - exact).abs() <= 1e-9 * exact.max(1e-3 * scale),
            "quadric {} vs brute force {}", q.evaluate(p), exact);
    }

    #[test]
    fn triangle_quadric_equals_area_times_squared_distance(
        a in point(), b in point(), c in point(), p in point()
    ) {
        let cross = (b - a).cross(c - a);
        prop_assume!(cross.length() > 1e-6);
        let n = cross.normalize();
        let area = 0.5 * cross.length();
        let expected = area * (n.dot(p - a)).powi(2);
        let q = Quadric::from_triangle(a, b, c);
        prop_assert!((q.evaluate(p) - expected).abs() <= 1e-9 * (1.0 + expected) * (1.0 + area));
    }

    #[test]
    fn placement_never_costs_more_than_ends_and_midpoint(ps in planes(), a in point(), b in point()) {
        let q = sum(&ps);
        let placed = optimal_placement(&q, a, b);
        prop_assert!(placed.position.is_finite());
        prop_assert!(placed.cost >= 0.0);
        for candidate in [a, b, a * 0.5 + b * 0.5] {
            prop_assert!(placed.cost <= q.evaluate(candidate).max(0.0),
                "{:?} costs more than {candidate}", placed);
        }
    }

    #[test]
    fn gradient_vanishes_at_a_unique_minimum(ps in prop::collection::vec(plane(), 3..12)) {
        let q = sum(&ps);
        if let Some(x) = minimize(&q) {
            let g = q.gradient(x);
            let scale = q.magnitude() * (1.0 + x.length());
            prop_assert!(g.length() <= 1e-6 * scale, "gradient {g} at {x}");
            // And it is a minimum: nearby points cost no less.
            for dir in [DVec3::X, DVec3::Y, DVec3::Z] {
                let here = q.evaluate(x);
                prop_assert!(q.evaluate(x + 1e-3 * dir) >= here - rounding(scale));
                prop_assert!(q.evaluate(x - 1e-3 * dir) >= here - rounding(scale));
            }
        }
    }

    /// The solve by cofactors finds the same minimum as the elimination wherever it
    /// finds one, and where the elimination finds none (a singular `A`), it finds none
    /// either: for a sum of planes its test is the stricter of the two (the scaled
    /// determinant is the product of two pivot ratios, each at most 1).
    #[test]
    fn cofactors_agree_with_elimination(ps in prop::collection::vec(plane(), 1..12)) {
        let q = sum(&ps);
        match (minimize_by_cofactors(&q), minimize(&q)) {
            (Some(x), Some(y)) => {
                let scale = 1.0 + y.length();
                prop_assert!((x - y).length() <= 1e-6 * scale, "cofactors {x}, elimination {y}");
                let g = q.gradient(x);
                prop_assert!(g.length() <= 1e-6 * q.magnitude() * scale, "gradient {g} at {x}");
            }
            (Some(x), None) => prop_assert!(false, "cofactors found {x} where elimination found none"),
            // A refusal only where the scaled determinant, computed here apart, is at
            // the ratio or below (1% allowed for rounding): a solve that refused too
            // often would fail here.
            (None, _) => {
                let det = scaled_determinant(&q);
                prop_assert!(det.abs() <= SINGULAR_DETERMINANT_RATIO * 1.01, "refused at {det:e}");
            }
        }
    }

    /// The test is scale-free: the quadric times any power of two (exact, so the
    /// scaled entries are the same bits) gives the same verdict and the same point.
    #[test]
    fn cofactors_are_scale_free(ps in planes(), k in -900..900i32) {
        let q = sum(&ps);
        let factor = 2f64.powi(k);
        let scaled = Quadric::from_entries(q.entries().map(|e| e * factor));
        prop_assume!(scaled.entries().iter().zip(q.entries()).all(|(s, e)| *s / factor == e));
        prop_assert_eq!(minimize_by_cofactors(&scaled), minimize_by_cofactors(&q));
    }

    #[test]
    fn any_entries_give_a_finite_point_or_none(
        e in prop::array::uniform10(any_entry()), a in point(), b in point()
    ) {
        let q = Quadric::from_entries(e);
        if let Some(x) = minimize_by_cofactors(&q) {
            prop_assert!(x.is_finite());
        }
        let placed = solve_first_placement(&q, a, b);
        prop_assert!(placed.position.is_finite());
    }

    #[test]
    fn translation_is_equivariant(ps in planes(), t in point(), p in point()) {
        let q = sum(&ps);
        let moved = q.translated(t);
        let scale = q.magnitude() * (1.0 + (p + t).length_squared());
        prop_assert!((moved.evaluate(p + t) - q.evaluate(p)).abs() <= 1e-10 * (1.0 + scale));
        // The planes moved by t, built from scratch, give the same quadric.
        let shifted: Vec<Plane> = ps.iter().map(|pl| Plane { d: pl.d - pl.normal.dot(t), ..*pl }).collect();
        let direct = sum(&shifted);
        for (x, y) in moved.entries().iter().zip(direct.entries()) {
            prop_assert!((x - y).abs() <= 1e-10 * (1.0 + scale));
        }
        if let (Some(x0), Some(x1)) = (minimize(&q), minimize(&moved)) {
            prop_assert!((x1 - (x0 + t)).length() <= 1e-6 * (1.0 + x0.length()));
        }
    }

    #[test]
    fn finite_entries_give_finite_placement(
        e in prop::array::uniform10(-1e6..1e6f64), a in point(), b in point()
    ) {
        let placed = optimal_placement(&Quadric::from_entries(e), a, b);
        prop_assert!(placed.position.is_finite());
        prop_assert!(!placed.cost.is_nan());
    }
}

/// An entry for `magnitude`'s test: ordinary, tiny, huge, zero of either sign, NaN or
/// infinite.
fn any_entry() -> impl Strategy<Value = f64> {
    prop_oneof![
        -10.0..10.0f64,
        -1e-300..1e-300f64,
        Just(0.0),
        Just(-0.0),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(-f64::MAX),
    ]
}

proptest! {
    /// `magnitude` is the largest absolute entry with NaN entries passed over, bit for
    /// bit what folding `f64::max` over the absolute entries from 0 gives (its first
    /// definition; relative tolerances of the placement depend on it).
    #[test]
    fn magnitude_is_the_largest_absolute_entry(entries in proptest::array::uniform10(any_entry())) {
        let q = Quadric::from_entries(entries);
        let folded = entries.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        prop_assert_eq!(q.magnitude().to_bits(), folded.to_bits());
    }
}

proptest! {
    /// A triangle's quadric (area-weighted, or of unit weight) built in a frame's
    /// normalised coordinates and taken to the world about an origin near the mesh is
    /// the one built there, to rounding of what it measures near the mesh; and back.
    /// Far from zero too (a scan in georeferenced coordinates).
    #[test]
    fn a_quadric_taken_to_the_world_is_the_one_built_there(
        corners in proptest::array::uniform3(point()),
        far in proptest::sample::select(vec![0.0, 1e3, 1e6, 5e6]),
        lo in point(),
        extent in (0.01..100.0f64, 0.01..100.0f64, 0.01..100.0f64),
        p in point(),
    ) {
        let lo = lo + DVec3::new(far, -far, 0.5 * far);
        let hi = lo + DVec3::new(extent.0, extent.1, extent.2);
        let frame = Frame::from_bounds(lo, hi);
        let world = corners.map(|c| lo + c.abs() * 0.25 * (hi - lo));
        let origin = world[0];
        let [a, b, c] = world.map(|w| frame.to_normalized(w));
        let [wa, wb, wc] = world.map(|w| w - origin);
        for area_weighted in [true, false] {
            let (normalized, built_in_world) = if area_weighted {
                (Quadric::from_triangle(a, b, c), Quadric::from_triangle(wa, wb, wc))
            } else {
                (
                    Quadric::from_triangle_unweighted(a, b, c),
                    Quadric::from_triangle_unweighted(wa, wb, wc),
                )
            };
            let carried = frame.quadric_to_world(&normalized, origin, area_weighted);
            let x = frame.to_world(p) - origin;
            let scale = built_in_world.magnitude() * (1.0 + x.length_squared());
            prop_assert!((carried.evaluate(x) - built_in_world.evaluate(x)).abs() <= 1e-9 * scale);
            let back = frame.quadric_to_normalized(&carried, origin, area_weighted);
            let n_scale = normalized.magnitude() * (1.0 + p.length_squared());
            prop_assert!((back.evaluate(p) - normalized.evaluate(p)).abs() <= 1e-9 * n_scale);
        }
    }
}
