//! Helpers shared by the tests of the pass-based order (`passes*.rs`): topology counts
//! computed from the triangles alone (without the store, so they check the engine
//! against an independent count), bit-level comparison, and noisy procedural meshes.
#![allow(dead_code)]

use qem_core::{DVec3, Frame};
use qem_mesh::clean::{clean, min_double_area, CleanOptions};
use qem_mesh::IndexedMesh;
use std::collections::{BTreeMap, BTreeSet};

/// Every undirected edge with the number of triangles that hold it.
pub fn edge_valences(mesh: &IndexedMesh) -> BTreeMap<(u32, u32), usize> {
    let mut edges = BTreeMap::new();
    for t in &mesh.triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    edges
}

/// (edges with one triangle, edges with more than two).
pub fn border_and_nonmanifold_edges(mesh: &IndexedMesh) -> (usize, usize) {
    let valences = edge_valences(mesh);
    (
        valences.values().filter(|&&n| n == 1).count(),
        valences.values().filter(|&&n| n > 2).count(),
    )
}

/// A union-find over `n` elements.
struct Sets(Vec<usize>);

impl Sets {
    fn new(n: usize) -> Self {
        Sets((0..n).collect())
    }
    fn find(&mut self, mut i: usize) -> usize {
        while self.0[i] != i {
            self.0[i] = self.0[self.0[i]];
            i = self.0[i];
        }
        i
    }
    fn join(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        self.0[ra] = rb;
    }
}

/// The connected components of the graph of border edges (edges with exactly one
/// triangle): on a manifold border, its loops.
pub fn border_loops(mesh: &IndexedMesh) -> usize {
    let mut sets = Sets::new(mesh.positions.len());
    let mut on_border = BTreeSet::new();
    for (&(a, b), &n) in &edge_valences(mesh) {
        if n == 1 {
            sets.join(a as usize, b as usize);
            on_border.insert(a as usize);
            on_border.insert(b as usize);
        }
    }
    on_border.into_iter().filter(|&v| sets.find(v) == v).count()
}

/// The connected components of the triangles (sharing a vertex joins them).
pub fn components(mesh: &IndexedMesh) -> usize {
    let mut sets = Sets::new(mesh.positions.len());
    let mut used = BTreeSet::new();
    for t in &mesh.triangles {
        sets.join(t[0] as usize, t[1] as usize);
        sets.join(t[1] as usize, t[2] as usize);
        used.extend(t.map(|i| i as usize));
    }
    used.into_iter().filter(|&v| sets.find(v) == v).count()
}

/// The vertices on edges with exactly one triangle.
pub fn border_vertices(mesh: &IndexedMesh) -> BTreeSet<u32> {
    edge_valences(mesh)
        .into_iter()
        .filter(|&(_, n)| n == 1)
        .flat_map(|((a, b), _)| [a, b])
        .collect()
}

/// The bit patterns of a mesh, so that equality is bit for bit (not `==` on f64).
pub fn bits(mesh: &IndexedMesh) -> (Vec<[u64; 3]>, Vec<[u32; 3]>) {
    (
        mesh.positions.iter().map(|p| p.map(f64::to_bits)).collect(),
        mesh.triangles.clone(),
    )
}

/// The mesh's positions as bit patterns, for "is this input vertex still there".
pub fn position_bits(mesh: &IndexedMesh) -> BTreeSet<[u64; 3]> {
    mesh.positions.iter().map(|p| p.map(f64::to_bits)).collect()
}

/// The faces of `out` that are zero-area by `qem_mesh::clean`'s rule (twice the area at
/// most [`min_double_area`] of the normalised diagonal, or a world cross product of
/// exactly zero), judged in the frame of `input` cleaned with `options`: the frame the
/// simplifier works in, where its output promises none.
pub fn zero_area_faces_in_input_frame(
    input: &IndexedMesh,
    options: &CleanOptions,
    out: &IndexedMesh,
) -> Vec<usize> {
    let cleaned = clean(input, options).mesh;
    let frame = Frame::from_points(cleaned.positions.iter().map(|p| DVec3::from_array(*p)));
    let min = min_double_area(frame.normalized_diagonal());
    out.triangles
        .iter()
        .enumerate()
        .filter(|(_, t)| {
            let world = t.map(|i| DVec3::from_array(out.positions[i as usize]));
            let [a, b, c] = world.map(|p| frame.to_normalized(p));
            let double_area = (b - a).cross(c - a).length();
            double_area.is_nan()
                || double_area <= min
                || (world[1] - world[0]).cross(world[2] - world[0]) == DVec3::ZERO
        })
        .map(|(f, _)| f)
        .collect()
}

/// The same judged by `clean` itself on the output alone (in the output's own frame),
/// as a downstream checker would: the number of faces it would drop as zero-area.
pub fn zero_area_faces_by_clean(out: &IndexedMesh) -> usize {
    clean(out, &CleanOptions::DEFAULT).report.zero_area_faces
}

/// A UV sphere with every vertex pushed in or out a little (a deterministic wobble), so
/// that no two edges cost the same and the order's tie-breaking is not all a test sees.
pub fn noisy_sphere(rings: u32, segments: u32) -> IndexedMesh {
    let mut sphere = super::common::uv_sphere([0.0; 3], 1.0, rings, segments);
    for (i, p) in sphere.positions.iter_mut().enumerate() {
        let s = 1.0 + 0.02 * ((i as f64) * 1.618).sin();
        *p = p.map(|c| c * s);
    }
    sphere
}
