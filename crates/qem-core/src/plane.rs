//! [`WeightedPlane`]: a face's plane and weight, the compact form of its quadric.

use crate::quadric::{unit_normal_and_area, Quadric};
use glam::DVec3;

/// A plane `normal·x + d = 0` (unit normal) with a weight: everything a triangle's
/// quadric is made of, in 40 bytes where the [`Quadric`] takes 80.
///
/// Why keep planes: the exact-quadric bookkeeping holds the quadric of every face until
/// the face collapses, and on a 4M-triangle mesh those quadrics alone were 350 MB. A
/// plane gives back the very same quadric, bit for bit, whenever it is asked for:
/// [`quadric`](Self::quadric) does the arithmetic that
/// [`Quadric::from_triangle_area_plus`] does.
///
/// ```
/// use glam::DVec3;
/// use qem_core::{Quadric, WeightedPlane};
/// let (a, b, c) = (DVec3::ZERO, DVec3::X, DVec3::new(0.3, 0.7, 0.2));
/// let plane = WeightedPlane::from_triangle_area_plus(a, b, c, 0.25);
/// assert_eq!(plane.quadric(), Quadric::from_triangle_area_plus(a, b, c, 0.25));
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WeightedPlane {
    /// Unit normal (zero for a triangle without a plane).
    pub normal: DVec3,
    /// Offset: `normal·x + d = 0` on the plane.
    pub d: f64,
    /// The factor on the plane's fundamental quadric.
    pub weight: f64,
}

impl WeightedPlane {
    /// No plane: its quadric is [`Quadric::ZERO`].
    pub const NONE: WeightedPlane = WeightedPlane {
        normal: DVec3::ZERO,
        d: 0.0,
        weight: 0.0,
    };

    /// The plane of triangle `p0 p1 p2` with weight `area + extra`, as
    /// [`Quadric::from_triangle_area_plus`] weighs it; [`NONE`](Self::NONE) for a
    /// degenerate triangle.
    #[inline]
    pub fn from_triangle_area_plus(p0: DVec3, p1: DVec3, p2: DVec3, extra: f64) -> Self {
        match unit_normal_and_area(p0, p1, p2) {
            Some((n, area)) => WeightedPlane {
                normal: n,
                d: -n.dot(p0),
                weight: area + extra,
            },
            None => WeightedPlane::NONE,
        }
    }

    /// The plane of triangle `p0 p1 p2` with weight 1, as
    /// [`Quadric::from_triangle_unweighted`] weighs it; [`NONE`](Self::NONE) for a
    /// degenerate triangle.
    #[inline]
    pub fn from_triangle_unweighted(p0: DVec3, p1: DVec3, p2: DVec3) -> Self {
        match unit_normal_and_area(p0, p1, p2) {
            Some((n, _)) => WeightedPlane {
                normal: n,
                d: -n.dot(p0),
                weight: 1.0,
            },
            None => WeightedPlane::NONE,
        }
    }

    /// The weighted plane's quadric: `weight · K` for the plane's fundamental quadric
    /// `K`. (A weight of 1 multiplies every entry by 1, which changes no bit.)
    #[inline]
    pub fn quadric(&self) -> Quadric {
        Quadric::from_plane(self.normal, self.d) * self.weight
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn bits(q: &Quadric) -> [u64; 10] {
        q.entries().map(f64::to_bits)
    }

    fn point() -> impl Strategy<Value = DVec3> {
        (-10.0f64..10.0, -10.0f64..10.0, -10.0f64..10.0).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    }

    proptest! {
        /// A plane's quadric is the triangle's quadric, bit for bit, weighted or not.
        #[test]
        fn the_plane_gives_back_the_same_quadric(
            a in point(), b in point(), c in point(), extra in 0.0f64..5.0,
        ) {
            let weighted = WeightedPlane::from_triangle_area_plus(a, b, c, extra).quadric();
            let expected = Quadric::from_triangle_area_plus(a, b, c, extra);
            prop_assert_eq!(bits(&weighted), bits(&expected));
            let unweighted = WeightedPlane::from_triangle_unweighted(a, b, c).quadric();
            let expected = Quadric::from_triangle_unweighted(a, b, c);
            prop_assert_eq!(bits(&unweighted), bits(&expected));
        }
    }

    #[test]
    fn a_degenerate_triangle_has_no_plane() {
        let p = DVec3::new(1.0, 2.0, 3.0);
        let none = WeightedPlane::from_triangle_area_plus(p, p, DVec3::ZERO, 1.0);
        assert_eq!(none, WeightedPlane::NONE);
        assert_eq!(bits(&none.quadric()), bits(&Quadric::ZERO));
    }
}
