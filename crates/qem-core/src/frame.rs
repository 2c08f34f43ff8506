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

    /// A quadric of area-weighted planes in normalised coordinates, in world ones:
    /// the same planes with world areas for weights and world squared distances for
    /// errors, `Q_w(x) = s⁴ · Q(to_normalized(x))` for the scale `s`. This is how a
    /// quadric leaves one run (one frame) for another ([`quadric_to_normalized`]
    /// brings it into the other's frame): a vertex's quadric carried from a tile of a
    /// mesh into the run that finishes the whole.
    ///
    /// [`quadric_to_normalized`]: Frame::quadric_to_normalized
    ///
    /// ```
    /// use glam::DVec3;
    /// use qem_core::{Frame, Quadric};
    /// let f = Frame::from_bounds(DVec3::ZERO, DVec3::new(4.0, 2.0, 2.0));
    /// // The plane z = 1 (world) is z = 0 normalised; unit weight there is weight 4
    /// // (2² world area units) in the world.
    /// let q = Quadric::from_plane(DVec3::Z, 0.0);
    /// let world = f.quadric_to_world(&q);
    /// assert_eq!(world.evaluate(DVec3::new(3.0, 0.5, 4.0)), 4.0 * 3.0 * 3.0);
    /// assert_eq!(f.quadric_to_normalized(&world), q);
    /// ```
    pub fn quadric_to_world(&self, q: &Quadric) -> Quadric {
        rescaled(q, self.scale).translated(self.center)
    }

    /// A quadric in world coordinates (as [`quadric_to_world`] gives it) in this
    /// frame's normalised ones: `Q(y) = Q_w(to_world(y)) / s⁴`.
    ///
    /// [`quadric_to_world`]: Frame::quadric_to_world
    pub fn quadric_to_normalized(&self, q: &Quadric) -> Quadric {
        rescaled(&q.translated(-self.center), 1.0 / self.scale)
    }
}

/// `Q'(p) = k⁴ · Q(p / k)`: the same planes in coordinates `k` times larger, with
/// weights (areas) `k²` times larger.
fn rescaled(q: &Quadric, k: f64) -> Quadric {
    let (k2, k3) = (k * k, k * k * k);
    Quadric {
        xx: q.xx * k2,
        xy: q.xy * k2,
        xz: q.xz * k2,
        yy: q.yy * k2,
        yz: q.yz * k2,
        zz: q.zz * k2,
        x: q.x * k3,
        y: q.y * k3,
        z: q.z * k3,
        c: q.c * k2 * k2,
    }
}
