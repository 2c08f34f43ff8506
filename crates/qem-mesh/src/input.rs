//! The library's input and output type, [`IndexedMesh`], and its validation.
//!
//! Everything that enters qem is first an `IndexedMesh`: a list of positions and a list
//! of triangles that index into it. [`IndexedMesh::validate`] is the gate between
//! untrusted data and the algorithm: after it succeeds every coordinate is finite and
//! every index is in range, so later stages never have to check again.

use crate::attributes::{AttributeError, Attributes};
use std::fmt;

/// The largest number of vertices or triangles qem accepts by default.
///
/// Why: the store needs about 200 bytes per triangle; 2^28 triangles is already
/// ~50 GiB, far beyond the machines qem targets. A count above this is almost certainly
/// a corrupt or hostile header, and refusing it keeps memory bounded.
pub const MAX_ELEMENTS: usize = 1 << 28;

/// A triangle mesh as plain arrays: positions and triangles indexing into them.
///
/// This is both what qem reads and what it writes. Nothing is assumed about it
/// beyond what [`validate`](Self::validate) checks: it may be non-manifold, open,
/// unwelded, in several parts, and contain degenerate or duplicate faces.
///
/// ```
/// use qem_mesh::IndexedMesh;
/// let mesh = IndexedMesh::new(
///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
///     vec![[0, 1, 2]],
/// );
/// assert!(mesh.validate().is_ok());
/// assert_eq!(mesh.triangle_count(), 1);
/// ```
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IndexedMesh {
    /// Vertex positions in model units.
    pub positions: Vec<[f64; 3]>,
    /// Triangles as three indices into `positions`, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Texture coordinates, normals, colours and other channels per triangle corner,
    /// materials and groups per triangle (see [`crate::attributes`]); empty for a
    /// positions-only mesh.
    pub attributes: Attributes,
}

/// Why an [`IndexedMesh`] was refused, and where.
#[derive(Clone, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum InputError {
    /// The mesh has no triangles at all.
    NoTriangles,
    /// A coordinate is NaN or infinite.
    NonFiniteCoordinate {
        /// Index of the offending vertex.
        vertex: usize,
    },
    /// A triangle refers to a vertex that does not exist.
    IndexOutOfRange {
        /// Index of the offending triangle.
        face: usize,
        /// The index it holds.
        index: u32,
        /// How many vertices the mesh has.
        vertex_count: usize,
    },
    /// More elements than a limit allows: vertices or triangles above
    /// [`MAX_ELEMENTS`], or an OBJ file's lists of vertices, texture coordinates or
    /// normals above 2^31 - 1 lines.
    TooLarge {
        /// `"vertices"`, `"triangles"`, `"texture coordinates"` or `"normals"`.
        what: &'static str,
        /// How many there are.
        count: usize,
        /// The limit.
        limit: usize,
    },
    /// The attributes are malformed (see [`AttributeError`]).
    Attributes(AttributeError),
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InputError::NoTriangles => write!(f, "the mesh has no triangles"),
            InputError::NonFiniteCoordinate { vertex } => {
                write!(f, "vertex {vertex} has a non-finite coordinate")
            }
            InputError::IndexOutOfRange {
                face,
                index,
                vertex_count,
            } => write!(
                f,
                "face {face} refers to vertex {index}, but there are only {vertex_count} vertices"
            ),
            InputError::TooLarge { what, count, limit } => {
                write!(f, "{count} {what} is more than the limit of {limit}")
            }
            InputError::Attributes(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for InputError {}

impl IndexedMesh {
    /// Makes a mesh from positions and triangles without checking them.
    pub fn new(positions: Vec<[f64; 3]>, triangles: Vec<[u32; 3]>) -> Self {
        Self {
            positions,
            triangles,
            attributes: Attributes::default(),
        }
    }

    /// The mesh with `attributes` (unchecked, like [`IndexedMesh::new`]).
    pub fn with_attributes(mut self, attributes: Attributes) -> Self {
        self.attributes = attributes;
        self
    }

    /// Number of vertices (referenced or not).
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles (degenerate ones included).
    pub fn triangle_count(&self) -> usize {
        self.triangles.len()
    }

    /// Checks what every later stage relies on: at least one triangle, counts within
    /// [`MAX_ELEMENTS`], finite coordinates, indices in range, and attributes that fit
    /// the triangles (one corner triple per triangle, indices in range, finite values,
    /// labels in range). Reports the first problem found: vertices, then faces, then
    /// attributes.
    pub fn validate(&self) -> Result<(), InputError> {
        check_vertices(&self.positions, 0, self.triangles.len())?;
        let vertex_count = self.positions.len();
        for (face, tri) in self.triangles.iter().enumerate() {
            for &index in tri {
                if index as usize >= vertex_count {
                    return Err(InputError::IndexOutOfRange {
                        face,
                        index,
                        vertex_count,
                    });
                }
            }
        }
        self.attributes
            .validate(self.triangles.len())
            .map_err(InputError::Attributes)
    }

    /// The axis-aligned bounding box of all positions as `(min, max)`, or `None` when
    /// there are no positions.
    pub fn bounding_box(&self) -> Option<([f64; 3], [f64; 3])> {
        let first = *self.positions.first()?;
        let mut lo = first;
        let mut hi = first;
        for p in &self.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        Some((lo, hi))
    }
}

/// The checks of [`IndexedMesh::validate`] that need no triangle list, in its order:
/// the counts (`vertices` is `first` plus the positions given: a streaming read may
/// have let the first ones go, having checked them), at least one triangle, finite
/// coordinates (a vertex numbered from `first`).
pub(crate) fn check_vertices(
    positions: &[[f64; 3]],
    first: usize,
    triangles: usize,
) -> Result<(), InputError> {
    for (what, count) in [
        ("vertices", first + positions.len()),
        ("triangles", triangles),
    ] {
        if count > MAX_ELEMENTS {
            return Err(InputError::TooLarge {
                what,
                count,
                limit: MAX_ELEMENTS,
            });
        }
    }
    if triangles == 0 {
        return Err(InputError::NoTriangles);
    }
    match positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        Some(vertex) => Err(InputError::NonFiniteCoordinate {
            vertex: first + vertex,
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> IndexedMesh {
        IndexedMesh::new(
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            vec![[0, 1, 2]],
        )
    }

    #[test]
    fn empty_mesh_has_no_triangles() {
        let err = IndexedMesh::default()
            .validate()
            .expect_err("the mesh is invalid");
        assert_eq!(err, InputError::NoTriangles);
        assert_eq!(err.to_string(), "the mesh has no triangles");
    }

    #[test]
    fn nan_coordinate_names_the_vertex() {
        let mut m = tri();
        m.positions[2][1] = f64::NAN;
        let err = m.validate().expect_err("the mesh is invalid");
        assert_eq!(err, InputError::NonFiniteCoordinate { vertex: 2 });
        assert_eq!(err.to_string(), "vertex 2 has a non-finite coordinate");
    }

    #[test]
    fn out_of_range_index_names_the_face() {
        let mut m = tri();
        m.triangles.push([0, 1, 7]);
        let err = m.validate().expect_err("the mesh is invalid");
        assert_eq!(
            err.to_string(),
            "face 1 refers to vertex 7, but there are only 3 vertices"
        );
    }

    #[test]
    fn bounding_box_spans_positions() {
        assert_eq!(
            tri().bounding_box(),
            Some(([0.0, 0.0, 0.0], [1.0, 1.0, 0.0]))
        );
        assert_eq!(IndexedMesh::default().bounding_box(), None);
    }
}
