//! Where to put the vertex that replaces a pair: Garland–Heckbert's placement rule.
//!
//! 1. The point that minimises the quadric, `A x = −b`, when `A` is safely invertible.
//!    "Safely" is a *relative* test on the pivots of a fully pivoted elimination, never
//!    `det == 0`: a determinant scales with the cube of the coordinates and says nothing
//!    about conditioning.
//! 2. Otherwise the best point on the segment between the pair's ends (a 1-D quadratic).
//! 3. Otherwise, or when rounding made the above worse, the best of the two ends and the
//!    midpoint.
//!
//! [`optimal_placement`]'s result never costs more than the ends and the midpoint, and
//! a finite input never gives a non-finite point. [`solve_first_placement`] skips the
//! comparison behind the first half of that guarantee (step 3's "when rounding made the
//! above worse"), for speed, and solves step 1 by cofactors ([`minimize_by_cofactors`])
//! rather than by elimination: about a fifth of the time, with a test on the scaled
//! determinant in place of the pivots'.

use crate::Quadric;
use glam::DVec3;

/// The smallest pivot of the 3x3 elimination, relative to the largest, for which `A`
/// counts as invertible.
///
/// Why 1e-8: the relative error of a solve grows like the condition number times
/// machine epsilon (2.2e-16); keeping the pivot ratio (a proxy for 1/condition) above
/// 1e-8 keeps that error below ~1e-7 of the coordinates. Below it the minimum is a line
/// or a plane of near-equal points (coplanar or cylindrical neighbourhoods), and the
/// segment rule gives a better defined answer.
pub const SINGULAR_PIVOT_RATIO: f64 = 1e-8;

/// The smallest determinant of `A` scaled so that its largest entry is 1, for which
/// [`minimize_by_cofactors`] counts `A` as invertible.
///
/// Why 1e-8, the same figure as [`SINGULAR_PIVOT_RATIO`]: the scaled determinant is the
/// product of the last two pivots of a fully pivoted elimination, each relative to the
/// first. Where the two tests matter most, a cylinder-like neighbourhood (one small
/// eigenvalue), the second pivot is close to the first and both tests ask the same.
/// Where two eigenvalues are small (a nearly flat patch), this test is the stricter one
/// and sends the pair to the segment rule sooner; the minimum of such a quadric is
/// poorly pinned down along the flat directions anyway. The determinant's rounding is
/// about machine epsilon times the largest entry cubed, so at 1e-8 the solve keeps about
/// 1e-8 relative accuracy.
pub const SINGULAR_DETERMINANT_RATIO: f64 = 1e-8;

/// The smallest curvature `dᵀA d` along the segment, relative to `|A|·|d|²`, for which
/// the 1-D minimum on the segment is trusted.
///
/// Why 1e-12: below it the quadric is flat along the segment to within rounding of its
/// entries, so every point of the segment costs the same and the 1-D minimum is noise.
pub const FLAT_SEGMENT_RATIO: f64 = 1e-12;

/// Which rule of the fallback chain produced a [`Placement`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PlacementRule {
    /// The unique minimum of the quadric (`A x = −b`).
    Optimal,
    /// The best point on the segment between the two ends.
    Segment,
    /// The first end of the pair.
    FirstEnd,
    /// The second end of the pair.
    SecondEnd,
    /// The midpoint of the pair.
    Midpoint,
}

/// A chosen position, its quadric cost there, and the rule that chose it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Where the new vertex goes.
    pub position: DVec3,
    /// The quadric's value there, clamped to be non-negative (the exact value is
    /// non-negative for sums of plane quadrics; only rounding can make it negative).
    pub cost: f64,
    /// Which rule chose the position.
    pub rule: PlacementRule,
}

/// The unique minimiser of `q`, or `None` when `A` is singular by the relative test
/// [`SINGULAR_PIVOT_RATIO`] or the solution is not finite.
///
/// ```
/// use glam::DVec3;
/// use qem_core::{minimize, Quadric};
/// // Three orthogonal planes x = 1, y = 2, z = 3 meet in one point.
/// let q = Quadric::from_plane(DVec3::X, -1.0)
///     + Quadric::from_plane(DVec3::Y, -2.0)
///     + Quadric::from_plane(DVec3::Z, -3.0);
/// assert_eq!(minimize(&q), Some(DVec3::new(1.0, 2.0, 3.0)));
/// ```
// Plain indexing on purpose (see the comment inside): clippy would have iterators.
#[allow(clippy::needless_range_loop)]
pub fn minimize(q: &Quadric) -> Option<DVec3> {
    // Augmented system [A | −b], solved by Gaussian elimination with full pivoting.
    //
    // Written with plain indexing over constant ranges (which the compiler unrolls)
    // rather than iterator adapters: this runs for every queued pair, and the adapters
    // cost about three times the instructions. The arithmetic is the textbook one, in
    // the same order, so the bits do not depend on the spelling.
    let mut m = [
        [q.xx, q.xy, q.xz, -q.x],
        [q.xy, q.yy, q.yz, -q.y],
        [q.xz, q.yz, q.zz, -q.z],
    ];
    let mut col_of = [0usize, 1, 2]; // which unknown each column now holds
    let mut first_pivot = 0.0;
    for k in 0..3 {
        // Largest remaining entry as pivot: the first in row-major order on ties.
        // The first step scans only the upper triangle: `A` is symmetric (one field per
        // pair of entries), so an entry below the diagonal always has an identical twin
        // earlier in row-major order and can never win.
        let (mut pr, mut pc, mut best) = (k, k, -1.0);
        for r in k..3 {
            for c in if k == 0 { r } else { k }..3 {
                let v = m[r][c].abs();
                if v > best {
                    (pr, pc, best) = (r, c, v);
                }
            }
        }
        if k == 0 {
            first_pivot = best;
        }
        // NaN entries make `best` stay negative; zero or relatively tiny pivots mean
        // singular.
        if best <= 0.0 || best < SINGULAR_PIVOT_RATIO * first_pivot {
            return None;
        }
        m.swap(k, pr);
        if pc != k {
            for row in &mut m {
                row.swap(k, pc);
            }
            col_of.swap(k, pc);
        }
        // Column k below the pivot is never read again (later pivots and the back
        // substitution look only right of it), so it is not updated.
        for r in k + 1..3 {
            let f = m[r][k] / m[k][k];
            for c in k + 1..4 {
                m[r][c] -= f * m[k][c];
            }
        }
    }
    let mut y = [0.0; 3];
    for k in (0..3).rev() {
        let mut s = m[k][3];
        for c in k + 1..3 {
            s -= m[k][c] * y[c];
        }
        y[k] = s / m[k][k];
    }
    let mut x = [0.0; 3];
    for k in 0..3 {
        x[col_of[k]] = y[k];
    }
    let p = DVec3::from_array(x);
    p.is_finite().then_some(p)
}

/// The unique minimiser of `q` by cofactors (the adjugate of the symmetric `A`), or
/// `None` when `A` scaled so that its largest entry is 1 has a determinant below
/// [`SINGULAR_DETERMINANT_RATIO`] in magnitude, when all of `A` is zero or not finite,
/// or when the solution is not finite.
///
/// The same point as [`minimize`] up to rounding, in about a fifth of its time: no
/// pivot search, so no branches that depend on the data (measured on a million random
/// well-conditioned quadrics, 14 ns against 60–75 ns). [`minimize`]'s elimination is the
/// more accurate one near singularity, which [`optimal_placement`] keeps for that
/// reason.
///
/// ```
/// use glam::DVec3;
/// use qem_core::{minimize_by_cofactors, Quadric};
/// // Three orthogonal planes x = 1, y = 2, z = 3 meet in one point.
/// let q = Quadric::from_plane(DVec3::X, -1.0)
///     + Quadric::from_plane(DVec3::Y, -2.0)
///     + Quadric::from_plane(DVec3::Z, -3.0);
/// assert_eq!(minimize_by_cofactors(&q), Some(DVec3::new(1.0, 2.0, 3.0)));
/// // Two planes meet in a line: no unique minimum.
/// let line = Quadric::from_plane(DVec3::X, -1.0) + Quadric::from_plane(DVec3::Y, -2.0);
/// assert_eq!(minimize_by_cofactors(&line), None);
/// ```
pub fn minimize_by_cofactors(q: &Quadric) -> Option<DVec3> {
    // Scaled by the largest entry first: the test below is then scale-free, and the
    // cofactors' products cannot overflow (every scaled entry is at most 1 in
    // magnitude); what underflows is far below the determinant's threshold. Only the
    // final factor `scale / det` can still overflow, for a largest entry below about
    // 1e-300: the point is then not finite and the solve refuses, as it does for any
    // point that is not finite.
    let largest = [q.xx, q.xy, q.xz, q.yy, q.yz, q.zz]
        .into_iter()
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    let scale = 1.0 / largest;
    // (`largest` is NaN-free: `max` drops a NaN; a NaN entry then shows in `det`.)
    if !(largest > 0.0 && scale.is_finite()) {
        return None;
    }
    let (a, b, c) = (q.xx * scale, q.xy * scale, q.xz * scale);
    let (d, e, f) = (q.yy * scale, q.yz * scale, q.zz * scale);
    // The first row of cofactors gives the determinant; the rest only when it passes.
    let c00 = d * f - e * e;
    let c01 = c * e - b * f;
    let c02 = b * e - c * d;
    let det = a * c00 + b * c01 + c * c02;
    if det.is_nan() || det.abs() < SINGULAR_DETERMINANT_RATIO {
        return None;
    }
    let c11 = a * f - c * c;
    let c12 = b * c - a * e;
    let c22 = a * d - b * b;
    // A⁻¹ = adj(A_scaled) · scale / det, applied to −b.
    let factor = -scale / det;
    let p = DVec3::new(
        (c00 * q.x + c01 * q.y + c02 * q.z) * factor,
        (c01 * q.x + c11 * q.y + c12 * q.z) * factor,
        (c02 * q.x + c12 * q.y + c22 * q.z) * factor,
    );
    p.is_finite().then_some(p)
}

/// Garland–Heckbert's placement for the pair `a`, `b` whose summed quadric is `q`:
/// the optimal point, else the best point on the segment, else the best of the ends
/// and the midpoint. Never costs more than the ends and the midpoint.
///
/// ```
/// use glam::DVec3;
/// use qem_core::{optimal_placement, PlacementRule, Quadric};
/// // Coplanar faces: every point of the plane z = 0 is optimal, so A is singular and
/// // the rule falls back to the segment (or its ends).
/// let q = Quadric::from_plane(DVec3::Z, 0.0);
/// let p = optimal_placement(&q, DVec3::ZERO, DVec3::X);
/// assert_ne!(p.rule, PlacementRule::Optimal);
/// assert_eq!(p.cost, 0.0);
/// ```
pub fn optimal_placement(q: &Quadric, a: DVec3, b: DVec3) -> Placement {
    let fallback = segment_placement(q, a, b);
    match minimize(q) {
        Some(position) => {
            let cost = q.evaluate(position);
            // Rounding in an ill-conditioned solve can land above the fallback; the
            // fallback is then the better answer, and the guarantee holds exactly.
            if cost <= fallback.cost {
                Placement {
                    position,
                    cost: cost.max(0.0),
                    rule: PlacementRule::Optimal,
                }
            } else {
                fallback
            }
        }
        None => fallback,
    }
}

/// Garland–Heckbert's placement as published: the quadric's minimum whenever the 3x3
/// solve succeeds, taken without comparing it with the segment and the ends; the
/// segment rule ([`segment_placement`]) only when `A` is singular (or the minimum's
/// cost is NaN). The solve is [`minimize_by_cofactors`], in about a fifth of the time
/// of [`minimize`]'s elimination, and the comparison of [`optimal_placement`] is
/// skipped; that comparison guards against rounding in nearly singular solves: here
/// such a solve can cost more than the segment's best point would have.
///
/// ```
/// use glam::DVec3;
/// use qem_core::{optimal_placement, solve_first_placement, PlacementRule, Quadric};
/// // Three planes meeting in (1, 2, 3): the same point as optimal_placement's.
/// let q = Quadric::from_plane(DVec3::X, -1.0)
///     + Quadric::from_plane(DVec3::Y, -2.0)
///     + Quadric::from_plane(DVec3::Z, -3.0);
/// let p = solve_first_placement(&q, DVec3::ZERO, DVec3::ONE);
/// assert_eq!(p.rule, PlacementRule::Optimal);
/// assert_eq!(p, optimal_placement(&q, DVec3::ZERO, DVec3::ONE));
/// ```
pub fn solve_first_placement(q: &Quadric, a: DVec3, b: DVec3) -> Placement {
    if let Some(position) = minimize_by_cofactors(q) {
        let cost = q.evaluate(position);
        if !cost.is_nan() {
            return Placement {
                position,
                cost: cost.max(0.0),
                rule: PlacementRule::Optimal,
            };
        }
    }
    segment_placement(q, a, b)
}

/// The best point on the segment `a`–`b`, or the best of the ends and the midpoint
/// when the quadric is flat along the segment or rounding makes them better.
#[inline]
pub fn segment_placement(q: &Quadric, a: DVec3, b: DVec3) -> Placement {
    let fallback = endpoint_placement(q, a, b);
    // Along p(s) = a + s d: Q = Q(a) + 2 s dᵀ(A a + b) + s² dᵀA d, minimal at
    // s = −dᵀ(A a + b) / dᵀA d when the curvature dᵀA d is meaningfully positive.
    let d = b - a;
    let ad = q.a() * d;
    let curvature = d.dot(ad);
    let scale = q.magnitude() * d.length_squared();
    if curvature.is_finite() && curvature > FLAT_SEGMENT_RATIO * scale {
        let slope = d.dot(q.a() * a + q.b());
        let s = (-slope / curvature).clamp(0.0, 1.0);
        if s.is_finite() {
            let position = a + s * d;
            let cost = q.evaluate(position);
            if position.is_finite() && cost < fallback.cost {
                return Placement {
                    position,
                    cost: cost.max(0.0),
                    rule: PlacementRule::Segment,
                };
            }
        }
    }
    fallback
}

/// The best of the midpoint and the two ends (in that order of preference on ties,
/// so flat regions contract to the middle).
#[inline]
pub fn endpoint_placement(q: &Quadric, a: DVec3, b: DVec3) -> Placement {
    // Halves first: (a + b) / 2 would overflow for coordinates near f64::MAX.
    let mid = a * 0.5 + b * 0.5;
    let mut best = Placement {
        position: mid,
        cost: q.evaluate(mid),
        rule: PlacementRule::Midpoint,
    };
    for (position, rule) in [(a, PlacementRule::FirstEnd), (b, PlacementRule::SecondEnd)] {
        let cost = q.evaluate(position);
        // A NaN cost (an overflowing quadric, ∞ − ∞) never wins, and any number beats
        // a NaN. (`total_cmp` alone would not do: it ranks a negative NaN, which is what
        // x86 arithmetic makes, below every number.) Between numbers, `total_cmp`'s
        // order: −0 before +0.
        if !cost.is_nan() && (best.cost.is_nan() || cost.total_cmp(&best.cost).is_lt()) {
            best = Placement {
                position,
                cost,
                rule,
            };
        }
    }
    best.cost = best.cost.max(0.0);
    best
}
