//! Building a [`MeshStore`] from an [`IndexedMesh`].
//!
//! Edges are found by sorting, not hashing: every face contributes three half-edge
//! records `(low index, high index, face, slot)`; once they are sorted the records of an
//! edge are adjacent, and each run becomes one edge whose fan lists the run's faces. The
//! sort is a counting sort by the low index followed by a sort of each vertex's few
//! records, so building is linear in the input, with no per-face hash lookup, and its
//! output order is a pure function of the input, which keeps keys deterministic. The
//! per-face maps and the per-vertex sorts run on rayon's thread pool; each item is
//! independent, so the store is the same for any number of threads. The slot maps
//! themselves are filled in one thread, in a fixed order.

use std::marker::PhantomData;

use rayon::prelude::*;
use slotmap::SlotMap;
use smallvec::SmallVec;

use super::{ordered_packed, Edge, EdgeKey, Face, FanPool, MeshStore, Packed, Vertex, VertexKey};
use crate::clean::group_equal_sets;
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
        let kept = kept_triangles(&mesh.triangles, mesh.positions.len(), &mut stats);

        // Half-edge records: (low vertex, high vertex, kept-face ordinal, slot in face),
        // sorted. A counting sort by the low vertex, filled in (ordinal, slot) order,
        // then a stable sort of each vertex's few records by the high vertex gives the
        // same order as sorting the whole tuples, in linear time.
        let n = mesh.positions.len();
        let half_edge = |ordinal: usize, slot: u8| {
            let tri = mesh.triangles[kept[ordinal] as usize];
            let a = tri[slot as usize];
            let b = tri[(slot as usize + 1) % 3];
            (a.min(b), a.max(b), ordinal as u32, slot)
        };
        let mut bucket_start = vec![0u32; n + 1];
        for ordinal in 0..kept.len() {
            for slot in 0..3 {
                bucket_start[half_edge(ordinal, slot).0 as usize + 1] += 1;
            }
        }
        for i in 0..n {
            bucket_start[i + 1] += bucket_start[i];
        }
        let mut records = vec![(0u32, 0u32, 0u32, 0u8); 3 * kept.len()];
        let mut fill = bucket_start;
        for ordinal in 0..kept.len() {
            for slot in 0..3 {
                let r = half_edge(ordinal, slot);
                records[fill[r.0 as usize] as usize] = r;
                fill[r.0 as usize] += 1;
            }
        }
        drop(fill);
        records
            .par_chunk_by_mut(|x, y| x.0 == y.0)
            .for_each(|bucket| bucket.sort_by_key(|r| r.1));
        // The runs of records with the same endpoints, one per edge, in sorted order.
        let runs: Vec<&[(u32, u32, u32, u8)]> =
            records.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)).collect();

        // Every edge in each vertex's star, as edge ordinals in increasing order (the
        // order in which edges are created below): a counting sort into one flat array,
        // instead of pushing into each vertex's list in turn, which jumps around memory.
        let mut star_start = vec![0u32; n + 1];
        for run in &runs {
            star_start[run[0].0 as usize + 1] += 1;
            star_start[run[0].1 as usize + 1] += 1;
        }
        for i in 0..n {
            star_start[i + 1] += star_start[i];
        }
        let mut star_fill = star_start.clone();
        let mut stars = vec![0u32; 2 * runs.len()];
        for (e, run) in runs.iter().enumerate() {
            for v in [run[0].0, run[0].1] {
                stars[star_fill[v as usize] as usize] = e as u32;
                star_fill[v as usize] += 1;
            }
        }

        // Each kept face's three edges, as edge ordinals by slot.
        let mut face_edges = vec![[0u32; 3]; kept.len()];
        for (e, run) in runs.iter().enumerate() {
            for r in *run {
                face_edges[r.2 as usize][r.3 as usize] = e as u32;
            }
        }

        // The slot maps are filled in the same order as ever (vertices in input order,
        // faces in kept order, edges in sorted order), so the keys do not change.
        let mut vertices = SlotMap::with_capacity_and_key(n);
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
        let mut faces = SlotMap::with_capacity_and_key(kept.len());
        let face_keys: Vec<_> = kept
            .iter()
            .map(|&t| {
                let [i, j, k] = mesh.triangles[t as usize];
                faces.insert(Face {
                    vertices: [i, j, k].map(|i| Packed::new(keys[i as usize])),
                    // Set below, once the edges exist (index 0 is slotmap's sentinel slot,
                    // never a key).
                    edges: [Packed(0, PhantomData); 3],
                })
            })
            .collect();
        let mut edges = SlotMap::with_capacity_and_key(runs.len());
        let mut fans = FanPool::default();
        let edge_keys: Vec<EdgeKey> = runs
            .iter()
            .map(|run| {
                let (lo, hi) = (keys[run[0].0 as usize], keys[run[0].1 as usize]);
                edges.insert(Edge {
                    vertices: ordered_packed(lo, hi),
                    fan: fans.make(run.iter().map(|r| face_keys[r.2 as usize])),
                })
            })
            .collect();
        for (f, e) in face_keys.iter().zip(&face_edges) {
            faces[*f].edges = e.map(|e| Packed::new(edge_keys[e as usize]));
        }
        for (i, key) in keys.iter().enumerate() {
            let star = &stars[star_start[i] as usize..star_start[i + 1] as usize];
            if star.is_empty() {
                stats.unreferenced_vertices += 1;
            }
            vertices[*key].star = star.iter().map(|&e| edge_keys[e as usize]).collect();
        }

        let store = MeshStore {
            vertices,
            edges,
            faces,
            fans,
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
/// first triangle of each vertex set. Counts what it drops in `stats`. (The pass-based
/// order keeps the same triangles.)
pub(crate) fn kept_triangles(
    triangles: &[[u32; 3]],
    vertex_count: usize,
    stats: &mut BuildStats,
) -> Vec<u32> {
    // Each triangle's vertex set, sorted, in input order; repeated indices dropped.
    let sets: Vec<([u32; 3], u32)> = triangles
        .par_iter()
        .enumerate()
        .filter_map(|(t, tri)| {
            let mut set = *tri;
            set.sort_unstable();
            (set[0] != set[1] && set[1] != set[2]).then_some((set, t as u32))
        })
        .collect();
    stats.degenerate_faces_skipped = triangles.len() - sets.len();

    let grouped = group_equal_sets(sets, vertex_count);
    let mut keep = vec![false; triangles.len()];
    for run in grouped.chunk_by(|x, y| x.0 == y.0) {
        keep[run[0].1 as usize] = true;
        stats.duplicate_faces_skipped += run.len() - 1;
    }
    (0..triangles.len() as u32)
        .filter(|&t| keep[t as usize])
        .collect()
}
