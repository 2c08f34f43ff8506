//! Procedural meshes and output checks shared by the integration tests.
#![allow(dead_code)]

use qem_mesh::IndexedMesh;

/// A UV sphere of radius `r` centred at `c` with `rings` latitude bands and `segments`
/// longitude bands: closed, 2·segments·(rings−1) triangles.
pub fn uv_sphere(c: [f64; 3], r: f64, rings: u32, segments: u32) -> IndexedMesh {
    let mut positions = vec![[c[0], c[1], c[2] + r]];
    for i in 1..rings {
        let theta = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..segments {
            let phi = 2.0 * std::f64::consts::PI * j as f64 / segments as f64;
            positions.push([
                c[0] + r * theta.sin() * phi.cos(),
                c[1] + r * theta.sin() * phi.sin(),
                c[2] + r * theta.cos(),
            ]);
        }
    }
    positions.push([c[0], c[1], c[2] - r]);
    let south = positions.len() as u32 - 1;
    let ring = |i: u32, j: u32| 1 + (i - 1) * segments + j % segments;
    let mut triangles = Vec::new();
    for j in 0..segments {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
        triangles.push([south, ring(rings - 1, j + 1), ring(rings - 1, j)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            let (a, b, c2, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j),
                ring(i + 1, j + 1),
            );
            triangles.push([a, c2, d]);
            triangles.push([a, d, b]);
        }
    }
    IndexedMesh::new(positions, triangles)
}

/// A flat `nx` × `ny` grid of unit squares in z = 0 (two triangles each), with a gentle
/// bump `z = h·sin(x)·sin(y)` so the quadrics are not all coplanar.
pub fn grid(nx: u32, ny: u32, h: f64) -> IndexedMesh {
    let mut positions = Vec::new();
    for y in 0..=ny {
        for x in 0..=nx {
            let (fx, fy) = (x as f64, y as f64);
            positions.push([fx, fy, h * (fx * 0.7).sin() * (fy * 0.9).sin()]);
        }
    }
    let id = |x: u32, y: u32| y * (nx + 1) + x;
    let mut triangles = Vec::new();
    for y in 0..ny {
        for x in 0..nx {
            triangles.push([id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
            triangles.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
        }
    }
    IndexedMesh::new(positions, triangles)
}

/// Concatenates meshes, offsetting indices.
pub fn concat(parts: &[IndexedMesh]) -> IndexedMesh {
    let mut out = IndexedMesh::default();
    for m in parts {
        let base = out.positions.len() as u32;
        out.positions.extend_from_slice(&m.positions);
        out.triangles
            .extend(m.triangles.iter().map(|t| t.map(|i| i + base)));
    }
    out
}

/// Asserts the output guarantees: indices in range, no repeated index, non-zero area,
/// finite coordinates, no more triangles than `triangles_in`.
pub fn assert_valid(mesh: &IndexedMesh, triangles_in: usize) {
    assert!(mesh.triangle_count() <= triangles_in);
    for p in &mesh.positions {
        assert!(p.iter().all(|c| c.is_finite()), "non-finite {p:?}");
    }
    let n = mesh.positions.len() as u32;
    let mut referenced = vec![false; mesh.positions.len()];
    for (f, t) in mesh.triangles.iter().enumerate() {
        assert!(t.iter().all(|&i| i < n), "face {f} out of range: {t:?}");
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[0] != t[2],
            "face {f} repeats: {t:?}"
        );
        let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let cross = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        assert!(cross != [0.0; 3], "face {f} has zero area: {t:?}");
        for &i in t {
            referenced[i as usize] = true;
        }
    }
    assert!(
        referenced.iter().all(|&r| r),
        "unreferenced vertex in output"
    );
}
