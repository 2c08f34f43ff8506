//! Attribute quadrics: the error of a vertex's attributes (texture coordinates,
//! normals, colours) beside its position, after Garland and Heckbert ("Simplifying
//! Surfaces with Color and Texture using Quadric Error Metrics", IEEE Visualization
//! 1998) in the memory-efficient form of Hoppe ("New Quadric Metric for Simplifying
//! Meshes with Appearance Attributes", IEEE Visualization 1999).
//!
//! On a triangle, each attribute component `s` is a linear function of position:
//! `s(p) = g·p + d`, with the gradient `g` in the triangle's plane. A vertex at `p`
//! with value `s` is off by `g·p + d − s` on that triangle; summed over triangles with
//! their areas `A`, the error of one channel of `k` components is
//!
//! `E(p, s) = Σ_t A_t Σ_j (g_tj·p + d_tj − s_j)²`.
//!
//! Given `p`, the best `s_j` is `(G_j·p + D_j) / W` with `G_j = Σ A g_j`,
//! `D_j = Σ A d_j`, `W = Σ A`, and the error left at that best value is a quadric in
//! `p` alone ([`AttributeQuadric::position_quadric`]). So a simplifier can add it to
//! the geometric quadric, place the vertex with its usual solver, and then read the
//! vertex's attributes off [`AttributeQuadric::values_at`].
//!
//! ```
//! use glam::DVec3;
//! use qem_core::AttributeQuadric;
//! // u = x on a unit right triangle: a vertex anywhere on that field has no error.
//! let mut q = AttributeQuadric::new(1);
//! let p = [DVec3::ZERO, DVec3::X, DVec3::Y];
//! q.add_triangle(p, [&[0.0][..], &[1.0], &[0.0]]);
//! assert!(q.position_quadric().evaluate(DVec3::new(0.25, 0.25, 0.0)).abs() < 1e-12);
//! let u = q.values_at(DVec3::new(0.25, 0.25, 0.0));
//! assert!((u[0] - 0.25).abs() < 1e-12);
//! ```

use crate::Quadric;
use glam::DVec3;
use smallvec::SmallVec;
use std::ops::AddAssign;

/// The largest number of components one channel may have.
pub const MAX_COMPONENTS: usize = 4;

/// The attribute error of one channel (1 to [`MAX_COMPONENTS`] components) over a set
/// of triangles, in Hoppe's form: `Σ A g gᵀ`, `Σ A d g`, `Σ A d²` and `W = Σ A` for
/// all components together, and `G_j`, `D_j` per component.
#[derive(Clone, Debug, PartialEq)]
pub struct AttributeQuadric {
    /// `Σ_t A Σ_j g_j g_jᵀ`, `Σ_t A Σ_j d_j g_j` and `Σ_t A Σ_j d_j²`, as one quadric.
    fields: Quadric,
    /// `Σ A`.
    area: f64,
    /// Per component, `G_j = Σ A g_j`.
    gradient: SmallVec<[DVec3; MAX_COMPONENTS]>,
    /// Per component, `D_j = Σ A d_j`.
    offset: SmallVec<[f64; MAX_COMPONENTS]>,
}

impl AttributeQuadric {
    /// The zero quadric of a channel of `components` components (clamped to
    /// 1..=[`MAX_COMPONENTS`]).
    pub fn new(components: usize) -> AttributeQuadric {
        let k = components.clamp(1, MAX_COMPONENTS);
        AttributeQuadric {
            fields: Quadric::ZERO,
            area: 0.0,
            gradient: SmallVec::from_elem(DVec3::ZERO, k),
            offset: SmallVec::from_elem(0.0, k),
        }
    }

    /// How many components the channel has.
    pub fn components(&self) -> usize {
        self.offset.len()
    }

    /// The total area of the triangles added.
    pub fn area(&self) -> f64 {
        self.area
    }

    /// Adds the triangle `p` with the values `values[i]` at corner `i` (at least
    /// [`components`](Self::components) each), weighted by its area. A triangle of
    /// zero area (or a non-finite one) adds nothing: it has no plane for a gradient.
    pub fn add_triangle(&mut self, p: [DVec3; 3], values: [&[f64]; 3]) {
        let e1 = p[1] - p[0];
        let e2 = p[2] - p[0];
        let n = e1.cross(e2);
        let nn = n.length_squared();
        if nn.is_nan() || nn <= 0.0 || !nn.is_finite() {
            return;
        }
        let area = 0.5 * nn.sqrt();
        // g with g·e1 = s1 − s0, g·e2 = s2 − s0 and g·n = 0:
        // g = ((s1 − s0)(e2 × n) + (s2 − s0)(n × e1)) / |n|².
        let (a, b) = (e2.cross(n) / nn, n.cross(e1) / nn);
        for j in 0..self.components() {
            let s = values.map(|v| v.get(j).copied().unwrap_or(0.0));
            let g = (s[1] - s[0]) * a + (s[2] - s[0]) * b;
            let d = s[0] - g.dot(p[0]);
            if !g.is_finite() || !d.is_finite() {
                continue;
            }
            self.fields += Quadric::from_plane(g, d) * area;
            self.gradient[j] += area * g;
            self.offset[j] += area * d;
        }
        self.area += area;
    }

    /// The error left when the values are the best ones for `p`, as a quadric in `p`:
    /// `Σ A (g·p + d)² − Σ_j (G_j·p + D_j)² / W`, summed over the components. Zero
    /// when no triangle was added.
    pub fn position_quadric(&self) -> Quadric {
        if self.area.is_nan() || self.area <= 0.0 {
            return Quadric::ZERO;
        }
        let mut q = self.fields;
        for (g, &d) in self.gradient.iter().zip(&self.offset) {
            // (G·p + D)² / W is the quadric of the "plane" (G, D) scaled by 1/W.
            q -= Quadric::from_plane(*g, d) * (1.0 / self.area);
        }
        q
    }

    /// The best values at `p`: `(G_j·p + D_j) / W` for each component (zeros when no
    /// triangle was added).
    pub fn values_at(&self, p: DVec3) -> SmallVec<[f64; MAX_COMPONENTS]> {
        self.gradient
            .iter()
            .zip(&self.offset)
            .map(|(g, &d)| {
                if self.area > 0.0 {
                    (g.dot(p) + d) / self.area
                } else {
                    0.0
                }
            })
            .collect()
    }
}

impl AddAssign<&AttributeQuadric> for AttributeQuadric {
    /// Adds the triangles of `other` (of the same number of components; extra ones
    /// are ignored).
    fn add_assign(&mut self, other: &AttributeQuadric) {
        self.fields += other.fields;
        self.area += other.area;
        for (g, o) in self.gradient.iter_mut().zip(&other.gradient) {
            *g += *o;
        }
        for (d, o) in self.offset.iter_mut().zip(&other.offset) {
            *d += *o;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> [DVec3; 3] {
        [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.5),
        ]
    }

    #[test]
    fn the_values_of_one_triangle_are_its_linear_field() {
        let mut q = AttributeQuadric::new(2);
        let p = tri();
        q.add_triangle(p, [&[0.1, 1.0], &[0.9, 0.0], &[0.1, 0.5]]);
        for (i, want) in [[0.1, 1.0], [0.9, 0.0], [0.1, 0.5]].iter().enumerate() {
            let got = q.values_at(p[i]);
            assert!((got[0] - want[0]).abs() < 1e-12 && (got[1] - want[1]).abs() < 1e-12);
        }
        // On one triangle's field the best values leave no error anywhere.
        let centre = (p[0] + p[1] + p[2]) / 3.0;
        assert!(q.position_quadric().evaluate(centre).abs() < 1e-12);
        assert!(q.position_quadric().evaluate(centre + DVec3::Z).abs() < 1e-12);
    }

    #[test]
    fn two_fields_that_disagree_cost_where_they_differ() {
        // u = x on one triangle, u = 1 − x on its mirror: they agree only at x = 0.5.
        let mut q = AttributeQuadric::new(1);
        let a = [DVec3::ZERO, DVec3::X, DVec3::Y];
        q.add_triangle(a, [&[0.0], &[1.0], &[0.0]]);
        q.add_triangle(a, [&[1.0], &[0.0], &[1.0]]);
        let e = q.position_quadric();
        assert!(e.evaluate(DVec3::new(0.5, 0.3, 0.0)).abs() < 1e-12);
        assert!(e.evaluate(DVec3::new(0.0, 0.3, 0.0)) > 0.1);
        assert!((q.values_at(DVec3::new(0.0, 0.3, 0.0))[0] - 0.5).abs() < 1e-12);
        // The error is never negative (a variance).
        for x in [-1.0, 0.0, 0.25, 2.0] {
            assert!(e.evaluate(DVec3::new(x, 0.7, -0.3)) >= -1e-12);
        }
    }

    #[test]
    fn sums_add_triangles_and_degenerate_ones_add_nothing() {
        let mut q = AttributeQuadric::new(1);
        q.add_triangle(
            [DVec3::ZERO, DVec3::X, DVec3::X * 2.0],
            [&[0.0], &[1.0], &[2.0]],
        );
        assert_eq!(q, AttributeQuadric::new(1));
        let mut a = AttributeQuadric::new(1);
        a.add_triangle(tri(), [&[0.0], &[1.0], &[0.0]]);
        let mut b = AttributeQuadric::new(1);
        b.add_triangle(tri(), [&[1.0], &[1.0], &[0.0]]);
        let mut both = AttributeQuadric::new(1);
        both.add_triangle(tri(), [&[0.0], &[1.0], &[0.0]]);
        both.add_triangle(tri(), [&[1.0], &[1.0], &[0.0]]);
        a += &b;
        assert_eq!(a, both);
        assert!((a.area() - 2.0 * 0.5 * (2.0f64 * 1.118033988749895)).abs() < 1e-9);
    }
}
