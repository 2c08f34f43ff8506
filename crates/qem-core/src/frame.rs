//! [`Frame`]: the normalised coordinates the quadrics are computed in.
//!
//! Quadric entries grow with the fourth power of the coordinates (`d²` times an area),
//! so meshes in millimetres near 10^4 and meshes in metres near 10^-3 would meet very
//! different rounding. qem translates every mesh to its bounding-box centre and divides
//! by its largest half-extent, so all coordinates lie in `[-1, 1]`, and converts errors
//! back for reports: to world units, and to fractions of the bounding-box diagonal (the
//! Metro convention used in papers).

use crate::Quadric;
use glam::DVec3;

/// A translation and uniform scale between world coordinates and normalised ones.
///
/// ```
/// use glam::DVec3;
/// use qem_core::Frame;
/// let f = Frame::from_bounds(DVec3::new(0.0, 0.0, 0.0), DVec3::new(4.0, 2.0, 2.0));
/// assert_eq!(f.to_normalized(DVec3::new(4.0, 1.0, 1.0)), DVec3::new(1.0, 0.0, 0.0));
/// assert_eq!(f.to_world(DVec3::new(-1.0, 0.0, 0.0)), DVec3::new(0.0, 1.0, 1.0));
/// assert_eq!(f.distance_to_world(0.5), 1.0);
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    center: DVec3,
    /// World units per normalised unit (the largest half-extent, or 1).
    scale: f64,
    /// The bounding-box diagonal in normalised units (between 0 and 2√3).
    normalized_diagonal: f64,
}

impl Frame {
    /// The identity frame: normalised coordinates are world coordinates.
    pub const IDENTITY: Frame = Frame {
        center: DVec3::ZERO,
        scale: 1.0,
        normalized_diagonal: 0.0,
    };

    /// The frame of the box `min`–`max` (finite corners, `min ≤ max`).
    ///
    /// A box with no extent (all points coincide) keeps scale 1, so coordinates are
    /// only translated.
    pub fn from_bounds(min: DVec3, max: DVec3) -> Frame {
        // Halves first so that extents near f64::MAX do not overflow.
        let center = min * 0.5 + max * 0.5;
        let half = max * 0.5 - min * 0.5;
        let largest = half.max_element();
        let scale = if largest > 0.0 && largest.is_finite() {
            largest
        } else {
            1.0
        };
        let normalized_diagonal = 2.0 * (half / scale).length();
        Frame {
            center,
            scale,
            normalized_diagonal,
        }
    }

    /// The frame of the bounding box of `points`, or [`Frame::IDENTITY`] when there
    /// are none.
    pub fn from_points(points: impl IntoIterator<Item = DVec3>) -> Frame {
        let mut it = points.into_iter();
        let Some(first) = it.next() else {
            return Frame::IDENTITY;
        };
        let (min, max) = it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p)));
        Frame::from_bounds(min, max)
    }

    /// The centre of the bounding box, in world units.
    pub fn center(&self) -> DVec3 {
        self.center
    }

    /// World units per normalised unit.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// The bounding-box diagonal in world units.
    pub fn world_diagonal(&self) -> f64 {
        self.normalized_diagonal * self.scale
    }

    /// The bounding-box diagonal in normalised units (at most 2√3).
    pub fn normalized_diagonal(&self) -> f64 {
        self.normalized_diagonal
    }

    /// A world point in normalised coordinates.
    pub fn to_normalized(&self, p: DVec3) -> DVec3 {
        (p - self.center) / self.scale
    }

    /// A normalised point back in world coordinates.
    pub fn to_world(&self, p: DVec3) -> DVec3 {
        p * self.scale + self.center
    }

    /// A normalised distance in world units.
    pub fn distance_to_world(&self, d: f64) -> f64 {
        d * self.scale
    }

    /// A world distance in normalised units.
    pub fn distance_to_normalized(&self, d: f64) -> f64 {
        d / self.scale
    }

    /// A normalised distance as a fraction of the bounding-box diagonal.
    ///
    /// When the box has no extent the fraction of a zero distance is 0 and of any
    /// other distance is infinite.
    pub fn distance_to_diagonal_fraction(&self, d: f64) -> f64 {
        if self.normalized_diagonal > 0.0 {
            d / self.normalized_diagonal
        } else if d == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    }

    /// A fraction of the bounding-box diagonal as a normalised distance.
    pub fn diagonal_fraction_to_distance(&self, fraction: f64) -> f64 {
        fraction * self.normalized_diagonal
    }

    /// A normalised squared distance (a quadric cost per unit weight) in world units².
    pub fn squared_to_world(&self, d2: f64) -> f64 {
        d2 * self.scale * self.scale
    }

    /// A quadric in normalised coordinates, in world units about `origin`: the same
    /// planes, `Q_w(x) = s^k · Q(to_normalized(origin + x))` for the scale `s`, with
    /// `k = 4` when the planes are weighted by areas (weights and squared distances
    /// both scale by `s²`) and `k = 2` when their weights are numbers (`area_weighted`
    /// false). This is how a quadric leaves one run (one frame) for another
    /// ([`quadric_to_normalized`] brings it into the other's frame): a vertex's quadric
    /// carried from a tile of a mesh into the run that finishes the whole.
    ///
    /// `origin` should lie near the mesh: a quadric's constant term is a sum of
    /// squares of distances from its origin, and about a far origin (a scan in
    /// georeferenced coordinates, 10^6 units from zero) what it measures near the mesh
    /// is lost to rounding when it is moved back.
    ///
    /// [`quadric_to_normalized`]: Frame::quadric_to_normalized
    ///
    /// ```
    /// use glam::DVec3;
    /// use qem_core::{Frame, Quadric};
    /// let f = Frame::from_bounds(DVec3::ZERO, DVec3::new(4.0, 2.0, 2.0));
    /// // The plane z = 1 (world) is z = 0 normalised; unit area there is 4 world units
    /// // of area (the scale is 2).
    /// let q = Quadric::from_plane(DVec3::Z, 0.0);
    /// let origin = DVec3::new(2.0, 1.0, 1.0);
    /// let world = f.quadric_to_world(&q, origin, true);
    /// // 3 above the plane: squared distance 9, weight 4.
    /// assert_eq!(world.evaluate(DVec3::new(1.0, -0.5, 3.0)), 4.0 * 9.0);
    /// assert_eq!(f.quadric_to_normalized(&world, origin, true), q);
    /// // A weight that is a number does not scale.
    /// let unit = f.quadric_to_world(&q, origin, false);
    /// assert_eq!(unit.evaluate(DVec3::new(1.0, -0.5, 3.0)), 9.0);
    /// ```
    pub fn quadric_to_world(&self, q: &Quadric, origin: DVec3, area_weighted: bool) -> Quadric {
        rescaled(q, self.scale, area_weighted).translated(self.center - origin)
    }

    /// A quadric in world units about `origin` (as [`quadric_to_world`] gives it) in
    /// this frame's normalised coordinates: `Q(y) = Q_w(to_world(y) − origin) / s^k`.
    ///
    /// [`quadric_to_world`]: Frame::quadric_to_world
    pub fn quadric_to_normalized(
        &self,
        q: &Quadric,
        origin: DVec3,
        area_weighted: bool,
    ) -> Quadric {
        rescaled(
            &q.translated(origin - self.center),
            1.0 / self.scale,
            area_weighted,
        )
    }
}

/// `Q'(p) = k^n · Q(p / k)`, `n` 4 with `area_weighted` (else 2): the same planes in
/// coordinates `k` times larger, their weights `k²` times larger when they are areas.
fn rescaled(q: &Quadric, k: f64, area_weighted: bool) -> Quadric {
    let weight = if area_weighted { k * k } else { 1.0 };
    let (a, b, c) = (weight, weight * k, weight * k * k);
    Quadric {
        xx: q.xx * a,
        xy: q.xy * a,
        xz: q.xz * a,
        yy: q.yy * a,
        yz: q.yz * a,
        zz: q.zz * a,
        x: q.x * b,
        y: q.y * b,
        z: q.z * b,
        c: q.c * c,
    }
}
