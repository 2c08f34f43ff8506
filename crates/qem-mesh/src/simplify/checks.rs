//! Which contractions are allowed: fold-over (degenerate, flipped and sliver faces),
//! topology (the link condition) and locks. Cheapest first; none allocates.

use super::settings::Settings;
use crate::clean::cross_underflows;
use qem_core::{DVec3, Frame};

/// Which way an input triangle faces, as the checks read it: its unit normal in
/// octahedral coordinates, two `i16` (Cigolle et al., "A Survey of Efficient
/// Representations for Independent Unit Vectors", JCGT 2014: the normal divided by
/// its 1-norm, the lower half folded over the upper); kept per triangle only without
/// the orientation check's index, else computed from the index when asked
/// (`InputFaces`).
///
/// Why so coarse: the checks ask only the sign of its dot product with a moved face's
/// normal (has the face turned more than 90° from the input face it descends from?),
/// and octahedral coordinates in steps of 1/32767 give that sign unless the angle is
/// within about 1e-4 radian of 90°, where either answer is right. 4 bytes a triangle
/// where the `f32` normal took 12 (80 MB on a 10M-triangle mesh, kept for the whole
/// run by `--fast`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Facing([i16; 2]);

impl Facing {
    /// The facing of a triangle without area (it points nowhere), or of one the run
    /// never asks about.
    pub const NONE: Facing = Facing([i16::MIN, i16::MIN]);

    /// Octahedral coordinates in `[-1, 1]` are kept in steps of `1 / STEPS`.
    const STEPS: f64 = i16::MAX as f64;

    /// The facing of a triangle whose (unnormalised) normal is `normal`.
    pub fn of(normal: DVec3) -> Facing {
        let norm1 = normal.x.abs() + normal.y.abs() + normal.z.abs();
        if !(norm1 > 0.0 && norm1.is_finite()) {
            return Facing::NONE;
        }
        let n = normal / norm1;
        let (u, v) = if n.z >= 0.0 {
            (n.x, n.y)
        } else {
            (
                (1.0 - n.y.abs()).copysign(n.x),
                (1.0 - n.x.abs()).copysign(n.y),
            )
        };
        // In [-1, 1], in steps of 1/32767 (`i16::MIN` is left to `NONE`).
        let quantised = |x: f64| (x * Facing::STEPS).round() as i16;
        Facing([quantised(u), quantised(v)])
    }

    /// A vector the way the triangle faces (not of unit length: only its direction
    /// is kept); zero for a triangle without area.
    #[inline]
    pub fn direction(self) -> DVec3 {
        if self == Facing::NONE {
            return DVec3::ZERO;
        }
        let [u, v] = self.0.map(|x| f64::from(x) / Facing::STEPS);
        let z = 1.0 - u.abs() - v.abs();
        if z >= 0.0 {
            DVec3::new(u, v, z)
        } else {
            DVec3::new((1.0 - v.abs()).copysign(u), (1.0 - u.abs()).copysign(v), z)
        }
    }
}

/// Why a contraction was refused (each has a counter in the report).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Rejection {
    /// A surviving face would have (numerically) zero area.
    Degenerate,
    /// A surviving face's normal would turn past the allowed angle.
    Flip,
    /// A surviving face would become a sliver below the quality threshold.
    Sliver,
    /// The contraction would change the topology (or cannot be shown not to).
    Topology,
    /// Both ends are locked, or a locked vertex would lose its last face.
    Locked,
    /// The contraction would pinch, close or remove a border loop.
    Border,
    /// An edge contraction would merge two faces `a x y` and `b x y` into one.
    Merge,
    /// A moved face would face away from the input surface nearest to it.
    Orientation,
    /// The contraction would remove the last triangles.
    LastTriangles,
    /// The contraction would join the two sides of an attribute seam.
    Seam,
}

/// `4√3·area / (l₀² + l₁² + l₂²)` from twice the area (`double_area`): 1 for an
/// equilateral triangle, 0 for a degenerate one.
fn quality(p0: DVec3, p1: DVec3, p2: DVec3, double_area: f64) -> f64 {
    let sum = p0.distance_squared(p1) + p1.distance_squared(p2) + p2.distance_squared(p0);
    if sum > 0.0 {
        2.0 * 3f64.sqrt() * double_area / sum
    } else {
        0.0
    }
}

/// Whether the normal turned from `old` to `new` by more than the angle whose cosine is
/// `min_cos`: `old·new < min_cos·|old|·|new|`, compared in squares (`new_squared` is
/// `|new|²`) so that no square root is taken.
#[inline]
fn turned_past(old: DVec3, new: DVec3, new_squared: f64, min_cos: f64) -> bool {
    let dot = old.dot(new);
    let bound = min_cos * min_cos * old.length_squared() * new_squared;
    if min_cos >= 0.0 {
        dot < 0.0 || dot * dot < bound
    } else {
        dot < 0.0 && dot * dot > bound
    }
}

/// Whether the engine counts a face with these world corners as zero-area: judged in
/// the run's normalised frame (where the fold-over check refused every contraction
/// that would make one), not in the output's own.
pub(super) fn is_zero_area(
    frame: &Frame,
    settings: &Settings,
    world_corners: [[f64; 3]; 3],
) -> bool {
    let [p0, p1, p2] = world_corners.map(|c| frame.to_normalized(DVec3::from_array(c)));
    let squared = (p1 - p0).cross(p2 - p0).length_squared();
    squared.is_nan()
        || squared <= settings.min_double_area_squared
        || (settings.world_may_underflow && cross_underflows(world_corners))
}

/// The fold-over rules for one surviving face whose corners move from `old` to `new`
/// (normalised frame), shared by both contraction orders: zero area (or NaN, only from
/// overflow), a normal turned past the allowed angle or against the input face's
/// (`input_facing`: a vector its way, asked only when the angle check is on), a sliver
/// worse than before.
/// `world_underflows` is asked only for a model so small that its cross products can
/// underflow in world units (see `Settings::world_may_underflow`). Squared lengths
/// throughout: no square root unless the sliver test runs.
#[inline]
pub(super) fn moved_face_verdict(
    settings: &Settings,
    old: [DVec3; 3],
    new: [DVec3; 3],
    input_facing: impl FnOnce() -> DVec3,
    world_underflows: impl FnOnce() -> bool,
) -> Result<(), Rejection> {
    let new_normal = (new[1] - new[0]).cross(new[2] - new[0]);
    let new_squared = new_normal.length_squared();
    if new_squared.is_nan()
        || new_squared <= settings.min_double_area_squared
        || (settings.world_may_underflow && world_underflows())
    {
        return Err(Rejection::Degenerate);
    }
    let old_normal = (old[1] - old[0]).cross(old[2] - old[0]);
    if let Some(min_cos) = settings.min_normal_cos {
        if turned_past(old_normal, new_normal, new_squared, min_cos) {
            return Err(Rejection::Flip);
        }
    }
    // Stops a face from turning away from the input face it descends from in several
    // small steps.
    if settings.face_input && input_facing().dot(new_normal) < 0.0 {
        return Err(Rejection::Flip);
    }
    if let Some(min_quality) = settings.min_quality {
        let q_new = quality(new[0], new[1], new[2], new_squared.sqrt());
        if q_new < min_quality && q_new < quality(old[0], old[1], old[2], old_normal.length()) {
            return Err(Rejection::Sliver);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::{turned_past, Facing};
    use proptest::prelude::*;
    use qem_core::DVec3;

    proptest! {
        /// A facing keeps its triangle's normal to within 2e-4 radian, whatever the
        /// normal's length and octant.
        #[test]
        fn a_facing_keeps_the_normal_to_within_2e_4_radian(
            x in -1.0f64..1.0, y in -1.0f64..1.0, z in -1.0f64..1.0, scale in -12i32..12,
        ) {
            let normal = DVec3::new(x, y, z) * 10f64.powi(scale);
            prop_assume!(normal.length() > 0.0);
            let kept = Facing::of(normal).direction();
            prop_assert!(kept.angle_between(normal) < 2e-4, "{normal} -> {kept}");
        }
    }

    #[test]
    fn a_facing_points_the_right_way_at_the_poles_and_folds() {
        for normal in [
            DVec3::X,
            DVec3::NEG_X,
            DVec3::Y,
            DVec3::NEG_Y,
            DVec3::Z,
            DVec3::NEG_Z,
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(-0.5, 0.25, -3.0),
        ] {
            let kept = Facing::of(normal).direction();
            assert!(kept.angle_between(normal) < 2e-4, "{normal} -> {kept}");
        }
        // Without area (or overflowed): no direction, so no sign to ask.
        for normal in [
            DVec3::ZERO,
            DVec3::splat(f64::NAN),
            DVec3::new(f64::MAX, f64::MAX, 0.0),
        ] {
            assert_eq!(Facing::of(normal).direction(), DVec3::ZERO);
        }
    }

    /// `turned_past` against the angle computed with `acos`.
    #[test]
    fn turned_past_matches_the_angle() {
        let old = DVec3::new(0.0, 0.0, 2.0);
        for degrees in [0.0f64, 30.0, 59.0, 61.0, 89.0, 91.0, 120.0, 179.0] {
            let t = degrees.to_radians();
            let new = DVec3::new(3.0 * t.sin(), 0.0, 3.0 * t.cos());
            for limit in [45.0f64, 60.0, 90.0, 135.0] {
                let expected = degrees > limit;
                let got = turned_past(old, new, new.length_squared(), limit.to_radians().cos());
                assert_eq!(got, expected, "{degrees}° against {limit}°");
            }
        }
    }
}
