//! Building a [`MeshStore`] from an [`IndexedMesh`].
//!
//! Edges are found by sorting, not hashing: every face contributes three half-edge
//! records `(low index, high index, face, slot)`; after one sort the records of an edge
//! are adjacent, and each run becomes one edge whose fan lists the run's faces. This is
//! O(n log n) with no per-face hash lookup, and its output order is a pure function of the
//! input, which keeps keys deterministic.

use slotmap::SlotMap;
use smallvec::SmallVec;

use super::{ordered, Edge, Face, MeshStore, Vertex, VertexKey};
use crate::input::{IndexedMesh, InputError};

/// What [`MeshStore::from_mesh`] left out of the input, for the report.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct BuildStats {
    /// Input triangles that repeat a vertex index (such as `[4, 4, 7]`); never inserted.
    pub degenerate_faces_skipped: usize,
    /// Input triangles with the same three vertices as an earlier triangle, in any order
    /// or orientation; only the first one is inserted.
    pub duplicate_faces_skipped: usize,
    /// Input vertices referenced by no inserted face. They are still created, isolated,
    /// so that the key vector lines up with input indices.
    pub unreferenced_vertices: usize,
}

impl MeshStore {
    /// Builds a store from `mesh`, after [`IndexedMesh::validate`].
    ///
    /// Returns the store and, for each input vertex index, the key of its vertex. Every
    /// input vertex gets a vertex, referenced or not. Triangles that repeat an index are
    /// skipped, and so are triangles with the same vertex set as an earlier one; both are
    /// counted in [`build_stats`](Self::build_stats). Faces keep the orientation and the
    /// first vertex of their input triangle.
    ///
    /// # Errors
    /// Whatever [`IndexedMesh::validate`] reports: no triangles, a non-finite coordinate,
    /// an index out of range, or too many elements.
    pub fn from_mesh(mesh: &IndexedMesh) -> Result<(Self, Vec<VertexKey>), InputError> {
        mesh.validate()?;
        let mut stats = BuildStats::default();

        let mut vertices = SlotMap::with_capacity_and_key(mesh.positions.len());
        let keys: Vec<VertexKey> = mesh
            .positions
            .iter()
            .map(|&position| {
                vertices.insert(Vertex {
                    position,
                    star: SmallVec::new(),
                })
            })
            .collect();

        let kept = kept_triangles(&mesh.triangles, &mut stats);

        // Faces first, in input order, with placeholder edges filled in below.
        let mut faces = SlotMap::with_capacity_and_key(kept.len());
        let face_keys: Vec<_> = kept
            .iter()
            .map(|&t| {
                let [i, j, k] = mesh.triangles[t as usize];
                faces.insert(Face {
                    vertices: [keys[i as usize], keys[j as usize], keys[k as usize]],
                    edges: Default::default(),
                })
            })
            .collect();

        // Half-edge records: (low vertex, high vertex, kept-face ordinal, slot in face).
        // All four fields together are unique, so an unstable sort is deterministic.
        let mut records: Vec<(u32, u32, u32, u8)> = Vec::with_capacity(kept.len() * 3);
        for (ordinal, &t) in kept.iter().enumerate() {
            let tri = mesh.triangles[t as usize];
            for slot in 0..3u8 {
                let a = tri[slot as usize];
                let b = tri[(slot as usize + 1) % 3];
                records.push((a.min(b), a.max(b), ordinal as u32, slot));
            }
        }
        records.sort_unstable();

        let mut edges = SlotMap::with_capacity_and_key(records.len() / 2 + 1);
        for run in records.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            let (lo, hi) = (keys[run[0].0 as usize], keys[run[0].1 as usize]);
            let fan = run.iter().map(|r| face_keys[r.2 as usize]).collect();
            let edge = edges.insert(Edge {
                vertices: ordered(lo, hi),
                fan,
            });
            for r in run {
                faces[face_keys[r.2 as usize]].edges[r.3 as usize] = edge;
            }
            vertices[lo].star.push(edge);
            vertices[hi].star.push(edge);
        }

        stats.unreferenced_vertices = vertices.values().filter(|v| v.star.is_empty()).count();
        let store = MeshStore {
            vertices,
            edges,
            faces,
            build_stats: stats,
            scratch: Default::default(),
        };
        Ok((store, keys))
    }

    /// What [`from_mesh`](Self::from_mesh) skipped. Zero for a default (empty) store.
    pub fn build_stats(&self) -> BuildStats {
        self.build_stats
    }
}

/// Indices of the triangles to insert, in input order: no repeated index, and only the
/// first triangle of each vertex set. Counts what it drops in `stats`.
fn kept_triangles(triangles: &[[u32; 3]], stats: &mut BuildStats) -> Vec<u32> {
    // Sorting (vertex set, input index) puts duplicates next to each other with the
    // earliest first; no hashing, and the choice of survivor does not depend on the sort.
    let mut sets: Vec<([u32; 3], u32)> = Vec::with_capacity(triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        let mut set = *tri;
        set.sort_unstable();
        if set[0] == set[1] || set[1] == set[2] {
            stats.degenerate_faces_skipped += 1;
        } else {
            sets.push((set, t as u32));
        }
    }
    sets.sort_unstable();
    let mut kept = Vec::with_capacity(sets.len());
    for run in sets.chunk_by(|x, y| x.0 == y.0) {
        kept.push(run[0].1);
        stats.duplicate_faces_skipped += run.len() - 1;
    }
    kept.sort_unstable();
    kept
}
