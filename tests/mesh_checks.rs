//! What every simplified mesh must satisfy, as a checking function that panics with the
//! reason (for fuzz checks and tests of the workspace crate).

use qem_mesh::IndexedMesh;

/// Panics unless `mesh` is a valid output for an input of `triangles_in` triangles: at
/// least one and at most `triangles_in` triangles, every index in range, no repeated
/// index in a face, no face with an exactly zero cross product, finite coordinates, and
/// every vertex referenced.
pub fn assert_valid_output(mesh: &IndexedMesh, triangles_in: usize) {
    assert!(!mesh.triangles.is_empty(), "empty output");
    assert!(
        mesh.triangle_count() <= triangles_in,
        "{} triangles out of {triangles_in}",
        mesh.triangle_count()
    );
    for (v, p) in mesh.positions.iter().enumerate() {
        assert!(p.iter().all(|c| c.is_finite()), "vertex {v} is {p:?}");
    }
    let n = mesh.positions.len();
    let mut referenced = vec![false; n];
    for (f, t) in mesh.triangles.iter().enumerate() {
        assert!(
            t.iter().all(|&i| (i as usize) < n),
            "face {f} {t:?} out of range"
        );
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
            "face {f} repeats a vertex: {t:?}"
        );
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let cross = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        assert!(cross != [0.0; 3], "face {f} {t:?} has zero area");
        for &i in t {
            referenced[i as usize] = true;
        }
    }
    if let Some(v) = referenced.iter().position(|&r| !r) {
        panic!("vertex {v} is not used by any face");
    }
}
