//! Hand-computed facts about quadrics and placement.

use approx::assert_relative_eq;
use qem_core::{
    endpoint_placement, minimize, minimize_by_cofactors, optimal_placement, segment_placement,
    solve_first_placement, DVec3, Frame, PlacementRule, Quadric, SINGULAR_DETERMINANT_RATIO,
};

#[test]
fn plane_quadric_at_height_h_is_h_squared() {
    // Plane z = 2 (normal +z, d = -2); the point (7, -3, 2 + h) is h above it.
    let q = Quadric::from_plane(DVec3::Z, -2.0);
    for h in [-3.0, -0.5, 0.0, 0.25, 10.0] {
        assert_eq!(q.evaluate(DVec3::new(7.0, -3.0, 2.0 + h)), h * h);
    }
}

#[test]
fn tilted_plane_measures_euclidean_distance() {
    // Plane x + y = 0 with unit normal (1,1,0)/√2: (1, 1, 5) is √2 away.
    let n = DVec3::new(1.0, 1.0, 0.0).normalize();
    let q = Quadric::from_plane(n, 0.0);
    assert_relative_eq!(q.evaluate(DVec3::new(1.0, 1.0, 5.0)), 2.0, epsilon = 1e-15);
}

#[test]
fn three_orthogonal_planes_solve_to_their_intersection() {
    let q = Quadric::from_plane(DVec3::X, -1.5)
        + Quadric::from_plane(DVec3::Y, 2.0)
        + Quadric::from_plane(DVec3::Z, -0.25);
    let p = minimize(&q).expect("three orthogonal planes are non-singular");
    assert_eq!(p, DVec3::new(1.5, -2.0, 0.25));
    let placed = optimal_placement(&q, DVec3::ZERO, DVec3::ONE);
    assert_eq!(placed.rule, PlacementRule::Optimal);
    assert_eq!(placed.cost, 0.0);
}

#[test]
fn coplanar_faces_fall_back_to_the_segment() {
    // Two triangles in z = 0 and a pull toward x = 0.3 along the segment direction:
    // A has rank 2 (normals z and x), singular, so the rule is the segment's, and the
    // best point on the segment (0,0,0)-(1,0,0) is x = 0.3.
    let q = Quadric::from_triangle(DVec3::ZERO, DVec3::X, DVec3::Y)
        + Quadric::from_triangle(DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y)
        + Quadric::from_plane(DVec3::X, -0.3);
    assert_eq!(minimize(&q), None);
    let p = optimal_placement(&q, DVec3::ZERO, DVec3::X);
    assert_eq!(p.rule, PlacementRule::Segment);
    assert_relative_eq!(p.position.x, 0.3, epsilon = 1e-12);
    assert_relative_eq!(p.cost, 0.0, epsilon = 1e-15);
}

#[test]
fn cofactors_refuse_a_nearly_singular_matrix_at_the_ratio() {
    // A = diag(1, 1, s): the scaled determinant is s. Just above the ratio the solve
    // goes through, just below it is refused. (For this matrix the elimination's test
    // asks the same of s: its last pivot ratio is s too.)
    let at = |s: f64| {
        Quadric::from_plane(DVec3::X, -1.0)
            + Quadric::from_plane(DVec3::Y, -2.0)
            + Quadric::from_plane(DVec3::Z, -3.0) * s
    };
    let above = at(SINGULAR_DETERMINANT_RATIO * 2.0);
    let x = minimize_by_cofactors(&above).expect("above the ratio");
    assert_relative_eq!(x.z, 3.0, epsilon = 1e-6);
    assert_eq!(
        minimize_by_cofactors(&at(SINGULAR_DETERMINANT_RATIO * 0.5)),
        None
    );
    // Two small eigenvalues (a nearly flat patch): each 1e-5, the product 1e-10. Here
    // the two tests differ: the elimination solves it (each pivot ratio is 1e-5); the
    // cofactors send it to the segment rule.
    let flat = Quadric::from_plane(DVec3::X, -1.0)
        + Quadric::from_plane(DVec3::Y, -2.0) * 1e-5
        + Quadric::from_plane(DVec3::Z, -3.0) * 1e-5;
    assert!(minimize(&flat).is_some());
    assert_eq!(minimize_by_cofactors(&flat), None);
    assert_eq!(minimize_by_cofactors(&Quadric::ZERO), None);
}

#[test]
fn solve_first_falls_back_to_the_segment_only_when_singular() {
    // The singular case of the test above: the same answer as optimal_placement's.
    let q = Quadric::from_triangle(DVec3::ZERO, DVec3::X, DVec3::Y)
        + Quadric::from_triangle(DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y)
        + Quadric::from_plane(DVec3::X, -0.3);
    let p = solve_first_placement(&q, DVec3::ZERO, DVec3::X);
    assert_eq!(p, optimal_placement(&q, DVec3::ZERO, DVec3::X));
    assert_eq!(p.rule, PlacementRule::Segment);
    // Non-singular: the minimum (5, 5, 0) of the planes x = 5, y = 5, z = 0, far off
    // the segment (0,0,0)-(1,0,0), whose best point costs 16 + 25.
    let q = Quadric::from_plane(DVec3::X, -5.0)
        + Quadric::from_plane(DVec3::Y, -5.0)
        + Quadric::from_plane(DVec3::Z, 0.0);
    let p = solve_first_placement(&q, DVec3::ZERO, DVec3::X);
    assert_eq!(p.rule, PlacementRule::Optimal);
    assert_eq!(p.position, DVec3::new(5.0, 5.0, 0.0));
    assert_eq!(p.cost, 0.0);
}

#[test]
fn flat_along_the_segment_falls_back_to_midpoint() {
    // Only the plane z = 0: flat along any segment inside it; ties prefer the midpoint.
    let q = Quadric::from_plane(DVec3::Z, 0.0);
    let p = segment_placement(&q, DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0));
    assert_eq!(p.rule, PlacementRule::Midpoint);
    assert_eq!(p.position, DVec3::new(1.0, 0.0, 0.0));
}

#[test]
fn endpoint_rule_picks_the_cheapest_end() {
    let q = Quadric::from_plane(DVec3::Z, 0.0);
    let p = endpoint_placement(&q, DVec3::new(0.0, 0.0, 1.0), DVec3::new(0.0, 0.0, 3.0));
    assert_eq!(p.rule, PlacementRule::FirstEnd);
    assert_eq!(p.cost, 1.0);
}

#[test]
fn triangle_quadric_is_area_weighted() {
    // Right triangle with legs 2 and 3 in z = 0: area 3.
    let q = Quadric::from_triangle(
        DVec3::ZERO,
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 3.0, 0.0),
    );
    assert_eq!(q.weight(), 3.0);
    assert_eq!(q.evaluate(DVec3::new(0.0, 0.0, 2.0)), 12.0);
    let u = Quadric::from_triangle_unweighted(
        DVec3::ZERO,
        DVec3::new(2.0, 0.0, 0.0),
        DVec3::new(0.0, 3.0, 0.0),
    );
    assert_eq!(u.evaluate(DVec3::new(0.0, 0.0, 2.0)), 4.0);
    assert_eq!(q.rms_distance(12.0), 2.0);
}

#[test]
fn degenerate_triangle_gives_zero_quadric() {
    let q = Quadric::from_triangle(DVec3::ZERO, DVec3::X, DVec3::new(2.0, 0.0, 0.0));
    assert_eq!(q, Quadric::ZERO);
    assert_eq!(q.rms_distance(0.0), 0.0);
}

#[test]
fn boundary_constraint_is_perpendicular_to_the_face() {
    // Face in z = 0, border edge along y at x = 1: the constraint plane is x = 1,
    // so moving along z (within the constraint plane) costs nothing.
    let q = Quadric::boundary_constraint(
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::Z,
        4.0,
    );
    assert_eq!(q.evaluate(DVec3::new(1.0, 9.0, 5.0)), 0.0);
    assert_eq!(q.evaluate(DVec3::new(3.0, 0.0, 0.0)), 16.0);
    assert_eq!(
        Quadric::boundary_constraint(DVec3::ZERO, DVec3::ZERO, DVec3::Z, 1.0),
        Quadric::ZERO
    );
}

#[test]
fn point_quadric_is_weighted_squared_distance() {
    let c = DVec3::new(1.0, 2.0, 3.0);
    let q = Quadric::from_point(c, 2.0);
    assert_eq!(q.evaluate(c + DVec3::new(0.0, 3.0, 4.0)), 50.0);
    assert_eq!(minimize(&q), Some(c));
    assert_eq!(q.weight(), 6.0);
}

#[test]
fn subtraction_and_scaling_are_entrywise() {
    let a = Quadric::from_plane(DVec3::X, 1.0);
    let b = Quadric::from_plane(DVec3::Y, 2.0);
    assert_eq!((a + b) - b, a);
    assert_eq!(a * 3.0, a + a + a);
    assert_eq!(-a + a, Quadric::ZERO);
    let mut c = a;
    c += b;
    c -= a;
    c *= 2.0;
    assert_eq!(c, b * 2.0);
    assert_eq!([a, b].into_iter().sum::<Quadric>(), a + b);
}

#[test]
fn zero_quadric_never_gives_a_non_finite_point() {
    let p = optimal_placement(
        &Quadric::ZERO,
        DVec3::new(1.0, 2.0, 3.0),
        DVec3::new(3.0, 2.0, 1.0),
    );
    assert!(p.position.is_finite());
    assert_eq!(p.rule, PlacementRule::Midpoint);
    assert_eq!(p.cost, 0.0);
}

#[test]
fn huge_coordinates_give_finite_midpoint() {
    let big = DVec3::splat(f64::MAX);
    let p = endpoint_placement(&Quadric::ZERO, big, big);
    assert!(p.position.is_finite());
}

#[test]
fn an_overflowing_end_never_wins_over_a_finite_midpoint() {
    // Q(p) = x² − 2e300·x: at the midpoint 0 it is 0; at x = 1e200 it is ∞ − ∞ = NaN
    // (negative on x86, which `total_cmp` ranks below every number); at x = −1e200 it
    // is +∞. The midpoint is the only end with a cost, and must be chosen.
    let q = Quadric::from_entries([1.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1e300, 0.0, 0.0, 0.0]);
    let (a, b) = (DVec3::new(1e200, 0.0, 0.0), DVec3::new(-1e200, 0.0, 0.0));
    assert!(q.evaluate(a).is_nan() && q.evaluate(b) == f64::INFINITY);
    assert_eq!(q.evaluate(DVec3::ZERO), 0.0);
    for p in [
        endpoint_placement(&q, a, b),
        endpoint_placement(&q, b, a),
        segment_placement(&q, a, b),
        optimal_placement(&q, a, b),
    ] {
        assert_eq!(p.rule, PlacementRule::Midpoint);
        assert_eq!((p.position, p.cost), (DVec3::ZERO, 0.0));
    }
}

#[test]
fn frame_maps_box_into_unit_cube_and_errors_back() {
    let f = Frame::from_bounds(DVec3::new(-10.0, 0.0, 0.0), DVec3::new(10.0, 10.0, 0.0));
    assert_eq!(f.scale(), 10.0);
    assert_eq!(
        f.to_normalized(DVec3::new(10.0, 10.0, 0.0)),
        DVec3::new(1.0, 0.5, 0.0)
    );
    let diag = (20.0f64 * 20.0 + 10.0 * 10.0).sqrt();
    assert_relative_eq!(f.world_diagonal(), diag, epsilon = 1e-12);
    // 0.1 normalised = 1 world unit = 1/diag of the diagonal.
    assert_relative_eq!(f.distance_to_world(0.1), 1.0, epsilon = 1e-15);
    assert_relative_eq!(
        f.distance_to_diagonal_fraction(0.1),
        1.0 / diag,
        epsilon = 1e-15
    );
    assert_relative_eq!(
        f.diagonal_fraction_to_distance(f.distance_to_diagonal_fraction(0.37)),
        0.37,
        epsilon = 1e-15
    );
    assert_eq!(f.squared_to_world(0.01), 1.0);
    let p = DVec3::new(3.0, -4.0, 0.5);
    assert_relative_eq!(f.to_world(f.to_normalized(p)).x, p.x, epsilon = 1e-14);
}

#[test]
fn frame_of_coincident_points_only_translates() {
    let f = Frame::from_points([DVec3::ONE, DVec3::ONE]);
    assert_eq!(f.scale(), 1.0);
    assert_eq!(f.to_normalized(DVec3::ONE), DVec3::ZERO);
    assert_eq!(f.distance_to_diagonal_fraction(0.0), 0.0);
    assert_eq!(f.distance_to_diagonal_fraction(1.0), f64::INFINITY);
    assert_eq!(Frame::from_points(std::iter::empty()), Frame::IDENTITY);
}

#[test]
fn frame_of_extreme_box_stays_finite() {
    let f = Frame::from_bounds(DVec3::splat(-f64::MAX), DVec3::splat(f64::MAX));
    assert!(f.scale().is_finite());
    assert!(f.to_normalized(DVec3::splat(f64::MAX)).is_finite());
    let tiny = Frame::from_bounds(DVec3::ZERO, DVec3::splat(1e-300));
    assert!(tiny.to_normalized(DVec3::splat(1e-300)).is_finite());
}
