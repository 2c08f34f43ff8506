//! Procedural meshes and output checks shared by the integration tests.
#![allow(dead_code)]

use qem_mesh::IndexedMesh;
use std::path::{Path, PathBuf};

/// The shared real-mesh corpus: `$QEM_CORPUS`, or `../shared/corpus` beside the
/// workspace; `None` (with a SKIPPED message) when it is absent.
pub fn corpus_dir() -> Option<PathBuf> {
    let dir = match std::env::var_os("QEM_CORPUS") {
        Some(d) => PathBuf::from(d),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/corpus"),
    };
    if dir.join("manifest.tsv").is_file() {
        Some(dir)
    } else {
        eprintln!(
            "SKIPPED: no corpus at {} (set QEM_CORPUS to the directory holding manifest.tsv)",
            dir.display()
        );
        None
    }
}

/// The corpus mesh `name` (flat, or under `public/` as the manifest names it), loaded;
/// `None` with a SKIPPED message when the file is absent.
#[cfg(feature = "io")]
pub fn corpus_mesh(dir: &Path, name: &str) -> Option<IndexedMesh> {
    let Some(path) = [dir.join(name), dir.join("public").join(name)]
        .into_iter()
        .find(|p| p.is_file())
    else {
        eprintln!("SKIPPED: {name} is not in {}", dir.display());
        return None;
    };
    let loaded = qem_mesh::io::read_path(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    Some(loaded.mesh)
}

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

/// Topological summary of a mesh as the store sees it: `(euler, components,
/// border loops)`. The Euler characteristic is `V − E + F` over referenced vertices;
/// border loops are the connected components of the graph of border edges (edges with
/// one face), which on a manifold border are its loops.
pub fn topology(mesh: &IndexedMesh) -> (i64, usize, usize) {
    use qem_mesh::store::{EdgeClass, MeshStore};
    let (store, _) = MeshStore::from_mesh(mesh).expect("a valid mesh");
    let referenced = store
        .vertices()
        .filter(|&v| !store.star(v).is_empty())
        .count();
    let euler = referenced as i64 - store.edge_count() as i64 + store.face_count() as i64;
    // Union-find over the ends of border edges.
    let index: std::collections::HashMap<_, usize> =
        store.vertices().enumerate().map(|(i, v)| (v, i)).collect();
    let mut parent: Vec<usize> = (0..index.len()).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut on_border = vec![false; index.len()];
    for e in store.edges() {
        if store.classify_edge(e) == EdgeClass::Boundary {
            let [a, b] = store.edge_vertices(e).map(|v| index[&v]);
            on_border[a] = true;
            on_border[b] = true;
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            parent[ra] = rb;
        }
    }
    let loops = (0..index.len())
        .filter(|&i| on_border[i] && find(&mut parent, i) == i)
        .count();
    (euler, store.component_count(), loops)
}

/// A torus with `n` × `m` quads (major radius `big`, minor radius `small`).
pub fn torus(big: f64, small: f64, n: u32, m: u32) -> IndexedMesh {
    let mut positions = Vec::new();
    for i in 0..n {
        let u = 2.0 * std::f64::consts::PI * i as f64 / n as f64;
        for j in 0..m {
            let v = 2.0 * std::f64::consts::PI * j as f64 / m as f64;
            let r = big + small * v.cos();
            positions.push([r * u.cos(), r * u.sin(), small * v.sin()]);
        }
    }
    let id = |i: u32, j: u32| (i % n) * m + j % m;
    let mut triangles = Vec::new();
    for i in 0..n {
        for j in 0..m {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    IndexedMesh::new(positions, triangles)
}

/// Total area of the triangles.
pub fn area(mesh: &IndexedMesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let cross = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            0.5 * (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt()
        })
        .sum()
}

/// Quality `4√3·area / Σ l²` of every triangle (1 equilateral, 0 degenerate).
pub fn qualities(mesh: &IndexedMesh) -> Vec<f64> {
    mesh.triangles
        .iter()
        .map(|t| {
            let one = IndexedMesh::new(
                t.map(|i| mesh.positions[i as usize]).to_vec(),
                vec![[0, 1, 2]],
            );
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            let d2 = |p: [f64; 3], q: [f64; 3]| {
                (p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)
            };
            4.0 * 3f64.sqrt() * area(&one) / (d2(a, b) + d2(b, c) + d2(c, a))
        })
        .collect()
}

/// A 30 x 30 sheet whose heights are deterministic noise of ±0.3 (units of the grid
/// step): crumpled, so contractions often swing a face over its neighbours.
pub fn jagged_sheet() -> IndexedMesh {
    let mut sheet = grid(30, 30, 0.0);
    for (i, p) in sheet.positions.iter_mut().enumerate() {
        p[2] = (((i * 7919) % 101) as f64 / 101.0 - 0.5) * 0.6;
    }
    sheet
}

/// A bumpy 16 x 16 grid with two 2 x 2 holes cut out: one part, three border loops.
pub fn holed_grid() -> IndexedMesh {
    let g = grid(16, 16, 0.8);
    let in_hole = |x: u32, y: u32, t: &[u32; 3]| {
        t.iter().all(|&i| {
            let (cx, cy) = (i % 17, i / 17);
            cx >= x && cx <= x + 2 && cy >= y && cy <= y + 2
        })
    };
    let triangles = g
        .triangles
        .iter()
        .copied()
        .filter(|t| !in_hole(3, 3, t) && !in_hole(10, 9, t))
        .collect();
    IndexedMesh::new(g.positions, triangles)
}

/// [`simplify`](qem_mesh::simplify::simplify) with every contraction replayed on the
/// store ([`StoreReplay`](qem_mesh::simplify::StoreReplay)): panics when the store breaks
/// or ends unlike the output.
#[allow(dead_code)] // not every test file uses every helper
pub fn simplify_replayed(
    mesh: &IndexedMesh,
    options: &qem_mesh::simplify::SimplifyOptions,
) -> Result<qem_mesh::simplify::Simplified, qem_mesh::simplify::SimplifyError> {
    let mut replay = qem_mesh::simplify::StoreReplay::default();
    let out = qem_mesh::simplify::simplify_observed(mesh, options, &mut replay)?;
    if let Err(e) = replay.check_output(&out.mesh) {
        panic!("the store disagrees with the engine: {e}");
    }
    Ok(out)
}

/// Whether a run made contractions on the ladder of relaxations' last step, the only
/// one that may leave a face facing away from its input face.
pub fn climbed_flipped_faces(report: &qem_mesh::simplify::SimplifyReport) -> bool {
    report
        .relaxations
        .iter()
        .any(|r| r.step == qem_mesh::simplify::RelaxationStep::FlippedFaces && r.contractions > 0)
}
