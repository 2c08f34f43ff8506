//! The orientation check: a face the loop moves must still face the same way as the
//! input surface nearest to it.
//!
//! Why the fold-over check is not enough: it compares a face with itself before the
//! move and with the input face it descends from. A large face that spans a crease or
//! a thin part can pass both and still lie, at its centroid, closest to input faces that
//! face the other way: a face of the opposite side of a thin fin, or the far wall of a
//! fold. Metro-style tools count such a face as flipped (the side-by-side harness does:
//! output normal · normal of the input face nearest to the output face's centroid < 0),
//! and rightly: it shades inside out and its centroid sits on the wrong side of the
//! surface. Seen before this check: 0.03-0.35% of the output faces on 5 of the 9 clean
//! corpus scans at ratio 0.1.
//!
//! The test: for each face a contraction would move, find the input triangles nearest
//! to the face's new centroid (all within [`NEAR_FACTOR`] of the nearest distance, so a
//! centroid over a crease hears from both sides) and refuse if any of them faces away
//! (normal dot product ≤ 0).

use crate::measure::TriangleBvh;
use crate::IndexedMesh;
use qem_core::{DVec3, Frame};

/// Input triangles up to this factor farther than the nearest one count as "nearest".
/// Why not 1: a centroid over a shared edge or vertex is equally near to several
/// triangles (ties), and a nearest-face search elsewhere (the harness looks among the 8
/// triangles with the nearest centroids) may settle on a slightly farther one.
const NEAR_FACTOR: f64 = 1.5;

/// An absolute margin (normalised units, where the model's diagonal is about 1) so that
/// a centroid lying on the input surface (distance 0) still gathers every triangle
/// through that point.
const NEAR_MARGIN: f64 = 1e-9;

/// The input surface, indexed for nearest-triangle queries, in normalised units.
#[derive(Debug)]
pub(super) struct InputSurface {
    bvh: TriangleBvh,
    /// Unnormalised normals of the indexed triangles, in the index's order.
    normals: Vec<DVec3>,
    /// Reused query result.
    near: Vec<u32>,
}

impl InputSurface {
    /// Indexes the cleaned mesh's triangles in the loop's frame.
    pub fn new(cleaned: &IndexedMesh, frame: &Frame) -> InputSurface {
        let normalized = IndexedMesh::new(
            cleaned
                .positions
                .iter()
                .map(|p| frame.to_normalized(DVec3::from_array(*p)).to_array())
                .collect(),
            cleaned.triangles.clone(),
        );
        let bvh = TriangleBvh::new(&normalized);
        let normals = (0..normalized.triangles.len() as u32)
            .map(|i| {
                let [a, b, c] = bvh.corners(i).map(DVec3::from_array);
                (b - a).cross(c - a)
            })
            .collect();
        InputSurface {
            bvh,
            normals,
            near: Vec::new(),
        }
    }

    /// Whether a face with these corners (normalised units) faces the same way as every
    /// input triangle nearest to its centroid.
    pub fn agrees(&mut self, corners: [DVec3; 3]) -> bool {
        let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
        let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
        self.bvh.nearest_triangles(
            centroid.to_array(),
            NEAR_FACTOR,
            NEAR_MARGIN,
            &mut self.near,
        );
        // A zero-area input triangle (cleaning drops exact ones) has no say.
        self.near.iter().all(|&i| {
            let n = self.normals[i as usize];
            n.dot(normal) > 0.0 || n == DVec3::ZERO
        })
    }
}
