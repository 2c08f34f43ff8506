//! [`Quadric`]: the symmetric 4x4 matrix of Garland–Heckbert's error metric.
//!
//! A plane `n·x + d = 0` with unit normal `n` has the fundamental quadric
//! `K = [n nᵀ, d n; d nᵀ, d²]`, and `[x 1] K [x 1]ᵀ = (n·x + d)²` is the squared distance
//! of `x` to the plane. Sums of such matrices measure the (weighted) sum of squared
//! distances to a set of planes, which is all the simplifier needs.
//!
//! We store the 10 distinct entries as the 3x3 block `A = Σ w n nᵀ`, the vector
//! `b = Σ w d n` and the scalar `c = Σ w d²`, so that `Q(x) = xᵀA x + 2 b·x + c`.

use glam::{DMat3, DVec3};
use std::ops::{Add, AddAssign, Mul, MulAssign, Neg, Sub, SubAssign};

/// A symmetric 4x4 quadric `Q(x) = xᵀA x + 2 b·x + c`, stored as its 10 distinct
/// entries in f64.
///
/// Quadrics form a vector space: `+`, `-` and scaling by an `f64` act entry by entry,
/// and `evaluate` is linear in the quadric. That is what makes Garland–Heckbert's
/// `Q_new = Q_a + Q_b` and the exact inclusion–exclusion `Q(A∪B) = Q(A) + Q(B) − Q(A∩B)`
/// possible.
///
/// ```
/// use glam::DVec3;
/// use qem_core::Quadric;
/// // The plane z = 0; a point at height 3 is 3 away, so the error is 9.
/// let q = Quadric::from_plane(DVec3::Z, 0.0);
/// assert_eq!(q.evaluate(DVec3::new(5.0, -2.0, 3.0)), 9.0);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Quadric {
    /// `A[0][0]`.
    pub xx: f64,
    /// `A[0][1] = A[1][0]`.
    pub xy: f64,
    /// `A[0][2] = A[2][0]`.
    pub xz: f64,
    /// `A[1][1]`.
    pub yy: f64,
    /// `A[1][2] = A[2][1]`.
    pub yz: f64,
    /// `A[2][2]`.
    pub zz: f64,
    /// `b.x`.
    pub x: f64,
    /// `b.y`.
    pub y: f64,
    /// `b.z`.
    pub z: f64,
    /// `c`.
    pub c: f64,
}

impl Quadric {
    /// The zero quadric: every point has error 0.
    pub const ZERO: Quadric = Quadric {
        xx: 0.0,
        xy: 0.0,
        xz: 0.0,
        yy: 0.0,
        yz: 0.0,
        zz: 0.0,
        x: 0.0,
        y: 0.0,
        z: 0.0,
        c: 0.0,
    };

    /// The fundamental quadric of the plane `normal·x + d = 0`.
    ///
    /// `normal` should have unit length: the quadric then measures squared distance.
    /// A normal of another length `s` scales the error by `s²`, which is how weights
    /// can be folded in (see [`Quadric::from_triangle`]).
    pub fn from_plane(normal: DVec3, d: f64) -> Quadric {
        let n = normal;
        Quadric {
            xx: n.x * n.x,
            xy: n.x * n.y,
            xz: n.x * n.z,
            yy: n.y * n.y,
            yz: n.y * n.z,
            zz: n.z * n.z,
            x: d * n.x,
            y: d * n.y,
            z: d * n.z,
            c: d * d,
        }
    }

    /// The quadric of a triangle's plane weighted by the triangle's area: the
    /// default of Garland–Heckbert's paper ("area-weighted"), so large faces count more
    /// than slivers.
    ///
    /// A degenerate triangle (zero area) has no plane and gives [`Quadric::ZERO`].
    pub fn from_triangle(p0: DVec3, p1: DVec3, p2: DVec3) -> Quadric {
        match unit_normal_and_area(p0, p1, p2) {
            Some((n, area)) => Quadric::from_plane(n, -n.dot(p0)) * area,
            None => Quadric::ZERO,
        }
    }

    /// The quadric of a triangle's plane with weight 1, whatever its area.
    ///
    /// A degenerate triangle (zero area) has no plane and gives [`Quadric::ZERO`].
    pub fn from_triangle_unweighted(p0: DVec3, p1: DVec3, p2: DVec3) -> Quadric {
        match unit_normal_and_area(p0, p1, p2) {
            Some((n, _)) => Quadric::from_plane(n, -n.dot(p0)),
            None => Quadric::ZERO,
        }
    }

    /// The quadric of a triangle's plane with weight `area + extra`: between
    /// [`from_triangle`](Quadric::from_triangle) (`extra = 0`, identical to it bit for
    /// bit) and [`from_triangle_unweighted`](Quadric::from_triangle_unweighted) (`extra`
    /// much larger than any area, up to a common factor). The simplifier's
    /// `Weighting::Mixed` passes a multiple of the mean face area, so slivers still count
    /// less than large faces but small faces are not drowned out by large ones.
    ///
    /// A degenerate triangle (zero area) has no plane and gives [`Quadric::ZERO`],
    /// whatever `extra` is.
    ///
    /// ```
    /// use glam::DVec3;
    /// use qem_core::Quadric;
    /// // A right triangle of area 0.5 in z = 0, with 1.5 added: weight 2.
    /// let q = Quadric::from_triangle_area_plus(DVec3::ZERO, DVec3::X, DVec3::Y, 1.5);
    /// assert_eq!(q.weight(), 2.0);
    /// assert_eq!(q.evaluate(DVec3::new(0.2, 0.3, 3.0)), 2.0 * 9.0);
    /// ```
    pub fn from_triangle_area_plus(p0: DVec3, p1: DVec3, p2: DVec3, extra: f64) -> Quadric {
        match unit_normal_and_area(p0, p1, p2) {
            Some((n, area)) => Quadric::from_plane(n, -n.dot(p0)) * (area + extra),
            None => Quadric::ZERO,
        }
    }

    /// The boundary constraint plane of the edge `p0`–`p1` of a face with normal
    /// `face_normal`: the plane through the edge perpendicular to the face, scaled by
    /// `weight`.
    ///
    /// Added to the quadrics of a border edge's ends, it penalises moving them off the
    /// border line (Garland–Heckbert §6.2). A degenerate edge, or an edge parallel to
    /// the normal, has no such plane and gives [`Quadric::ZERO`].
    ///
    /// ```
    /// use glam::DVec3;
    /// use qem_core::Quadric;
    /// // Edge along x in the plane z = 0: the constraint plane is y = 0.
    /// let q = Quadric::boundary_constraint(DVec3::ZERO, DVec3::X, DVec3::Z, 2.0);
    /// assert_eq!(q.evaluate(DVec3::new(0.3, 1.5, 7.0)), 2.0 * 1.5 * 1.5);
    /// ```
    pub fn boundary_constraint(p0: DVec3, p1: DVec3, face_normal: DVec3, weight: f64) -> Quadric {
        let m = (p1 - p0).cross(face_normal);
        match m.try_normalize() {
            Some(m) => Quadric::from_plane(m, -m.dot(p0)) * weight,
            None => Quadric::ZERO,
        }
    }

    /// The point quadric `weight·|x − center|²`: a regulariser that pulls the optimum
    /// toward `center` and makes `A` positive definite.
    ///
    /// Its [`weight`](Quadric::weight) is `3·weight`, because it is the sum of three
    /// orthogonal planes through `center`.
    pub fn from_point(center: DVec3, weight: f64) -> Quadric {
        Quadric {
            xx: weight,
            xy: 0.0,
            xz: 0.0,
            yy: weight,
            yz: 0.0,
            zz: weight,
            x: -weight * center.x,
            y: -weight * center.y,
            z: -weight * center.z,
            c: weight * center.length_squared(),
        }
    }

    /// The error at `p`: `pᵀA p + 2 b·p + c`, the weighted sum of squared distances
    /// to the quadric's planes. Non-negative for sums of plane quadrics, up to rounding.
    #[inline]
    pub fn evaluate(&self, p: DVec3) -> f64 {
        let ap = self.a() * p;
        p.dot(ap) + 2.0 * self.b().dot(p) + self.c
    }

    /// The gradient of [`evaluate`](Quadric::evaluate) at `p`: `2(A p + b)`.
    pub fn gradient(&self, p: DVec3) -> DVec3 {
        2.0 * (self.a() * p + self.b())
    }

    /// The 3x3 block `A`.
    #[inline]
    pub fn a(&self) -> DMat3 {
        DMat3::from_cols(
            DVec3::new(self.xx, self.xy, self.xz),
            DVec3::new(self.xy, self.yy, self.yz),
            DVec3::new(self.xz, self.yz, self.zz),
        )
    }

    /// The vector `b`.
    #[inline]
    pub fn b(&self) -> DVec3 {
        DVec3::new(self.x, self.y, self.z)
    }

    /// The total weight of the planes summed into this quadric: the trace of `A`.
    ///
    /// Each unit-normal plane of weight `w` adds `w·|n|² = w` to the trace, so for a
    /// sum of plane quadrics this is the sum of their weights (the total area, for
    /// area-weighted triangle quadrics). `sqrt(cost / weight)` is then an RMS distance
    /// to the planes; see [`Quadric::rms_distance`].
    #[inline]
    pub fn weight(&self) -> f64 {
        self.xx + self.yy + self.zz
    }

    /// `sqrt(cost / weight)`: the error `cost` of this quadric expressed as an RMS
    /// distance to its planes, in the same units as the coordinates.
    ///
    /// Zero when the weight is not positive (no planes: nothing to be away from), and
    /// never NaN for a finite, non-negative `cost`.
    pub fn rms_distance(&self, cost: f64) -> f64 {
        let w = self.weight();
        if w > 0.0 && cost > 0.0 {
            (cost / w).sqrt()
        } else {
            0.0
        }
    }

    /// The quadric of the same planes moved by `offset`: `Q'(p) = Q(p − offset)`.
    pub fn translated(&self, offset: DVec3) -> Quadric {
        // Q(p − t) = pᵀAp − 2pᵀAt + tᵀAt + 2b·p − 2b·t + c
        //          = pᵀAp + 2(b − At)·p + (tᵀAt − 2b·t + c).
        let at = self.a() * offset;
        let b = self.b() - at;
        Quadric {
            x: b.x,
            y: b.y,
            z: b.z,
            c: offset.dot(at) - 2.0 * self.b().dot(offset) + self.c,
            ..*self
        }
    }

    /// The largest absolute entry of `A`, `b` and `c`: the scale against which
    /// relative tolerances are measured. NaN entries are passed over (all NaN: 0).
    #[inline]
    pub fn magnitude(&self) -> f64 {
        // A plain comparison rather than `f64::max`, whose NaN rule costs a few
        // instructions per entry; the placement asks this for every queued pair. Same
        // answer: the running value is never NaN, and a NaN entry never compares
        // greater.
        let mut largest = 0.0_f64;
        for v in self.entries() {
            let v = v.abs();
            if v > largest {
                largest = v;
            }
        }
        largest
    }

    /// The 10 entries in the order `xx xy xz yy yz zz x y z c`.
    pub fn entries(&self) -> [f64; 10] {
        [
            self.xx, self.xy, self.xz, self.yy, self.yz, self.zz, self.x, self.y, self.z, self.c,
        ]
    }

    /// Builds a quadric from its 10 entries in the order of [`Quadric::entries`].
    pub fn from_entries(e: [f64; 10]) -> Quadric {
        Quadric {
            xx: e[0],
            xy: e[1],
            xz: e[2],
            yy: e[3],
            yz: e[4],
            zz: e[5],
            x: e[6],
            y: e[7],
            z: e[8],
            c: e[9],
        }
    }

    /// `f` applied entry by entry. Field by field rather than through
    /// [`entries`](Quadric::entries) arrays: sums and differences of quadrics run for every
    /// queued pair, and the arrays cost a copy each way.
    #[inline]
    fn zip(self, other: Quadric, f: impl Fn(f64, f64) -> f64) -> Quadric {
        Quadric {
            xx: f(self.xx, other.xx),
            xy: f(self.xy, other.xy),
            xz: f(self.xz, other.xz),
            yy: f(self.yy, other.yy),
            yz: f(self.yz, other.yz),
            zz: f(self.zz, other.zz),
            x: f(self.x, other.x),
            y: f(self.y, other.y),
            z: f(self.z, other.z),
            c: f(self.c, other.c),
        }
    }
}

/// The unit normal (right-handed, counter-clockwise) and area of a triangle, or
/// `None` when its cross product cannot be normalised (zero or non-finite area).
#[inline]
pub fn unit_normal_and_area(p0: DVec3, p1: DVec3, p2: DVec3) -> Option<(DVec3, f64)> {
    let cross = (p1 - p0).cross(p2 - p0);
    let len = cross.length();
    if len > 0.0 && len.is_finite() {
        Some((cross / len, 0.5 * len))
    } else {
        None
    }
}

impl Add for Quadric {
    type Output = Quadric;
    #[inline]
    fn add(self, rhs: Quadric) -> Quadric {
        self.zip(rhs, |a, b| a + b)
    }
}

impl AddAssign for Quadric {
    #[inline]
    fn add_assign(&mut self, rhs: Quadric) {
        *self = *self + rhs;
    }
}

impl Sub for Quadric {
    type Output = Quadric;
    #[inline]
    fn sub(self, rhs: Quadric) -> Quadric {
        self.zip(rhs, |a, b| a - b)
    }
}

impl SubAssign for Quadric {
    #[inline]
    fn sub_assign(&mut self, rhs: Quadric) {
        *self = *self - rhs;
    }
}

impl Neg for Quadric {
    type Output = Quadric;
    fn neg(self) -> Quadric {
        self * -1.0
    }
}

impl Mul<f64> for Quadric {
    type Output = Quadric;
    #[inline]
    fn mul(self, s: f64) -> Quadric {
        Quadric::from_entries(self.entries().map(|v| v * s))
    }
}

impl MulAssign<f64> for Quadric {
    #[inline]
    fn mul_assign(&mut self, s: f64) {
        *self = *self * s;
    }
}

impl std::iter::Sum for Quadric {
    fn sum<I: Iterator<Item = Quadric>>(iter: I) -> Quadric {
        iter.fold(Quadric::ZERO, |a, b| a + b)
    }
}
