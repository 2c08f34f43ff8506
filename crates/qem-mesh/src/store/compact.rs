//! Compaction of a [`MeshStore`] back to an [`IndexedMesh`].

use slotmap::SecondaryMap;

use super::{MeshStore, VertexKey};
use crate::input::IndexedMesh;

impl MeshStore {
    /// Writes the faces of the store as an [`IndexedMesh`].
    ///
    /// Only vertices referenced by a face are written, in slotmap order; isolated
    /// vertices and wire edges do not reach the output. Triangles are written in slotmap
    /// order of faces, each starting at its face's first vertex, orientation kept. The
    /// output therefore has no unreferenced vertex and no degenerate-by-index or duplicate
    /// triangle. A store without faces gives a mesh without triangles (which
    /// [`IndexedMesh::validate`] refuses as input).
    ///
    /// ```
    /// use qem_mesh::{IndexedMesh, MeshStore};
    ///
    /// // Triangle 1-2-3; vertex 0 is unreferenced, and the second face is a duplicate.
    /// let mesh = IndexedMesh::new(
    ///     vec![[9.0, 9.0, 9.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    ///     vec![[1, 2, 3], [3, 2, 1]],
    /// );
    /// let (store, _) = MeshStore::from_mesh(&mesh)?;
    /// assert_eq!(store.build_stats().duplicate_faces_skipped, 1);
    /// let out = store.to_mesh();
    /// assert_eq!(out.positions, &mesh.positions[1..]);
    /// assert_eq!(out.triangles, vec![[0, 1, 2]]);
    /// # Ok::<(), qem_mesh::InputError>(())
    /// ```
    pub fn to_mesh(&self) -> IndexedMesh {
        self.to_mesh_with_map().0
    }

    /// Like [`to_mesh`](Self::to_mesh), and also returns, for each output vertex index,
    /// the key of the store vertex it came from (to carry per-vertex data along).
    pub fn to_mesh_with_map(&self) -> (IndexedMesh, Vec<VertexKey>) {
        // Mark referenced vertices first so that output order is slotmap order, not the
        // order in which faces happen to reach them.
        let mut index: SecondaryMap<VertexKey, u32> = SecondaryMap::new();
        for face in self.faces.values() {
            for v in face.vertex_keys() {
                index.insert(v, 0);
            }
        }
        let mut positions = Vec::with_capacity(index.len());
        let mut keys = Vec::with_capacity(index.len());
        for (v, vertex) in &self.vertices {
            if let Some(slot) = index.get_mut(v) {
                *slot = keys.len() as u32;
                keys.push(v);
                positions.push(vertex.position);
            }
        }
        // Every face vertex was marked above, so the fallback is never taken; it only
        // avoids a panic path.
        let triangles = self
            .faces
            .values()
            .map(|face| {
                face.vertex_keys()
                    .map(|v| index.get(v).copied().unwrap_or(0))
            })
            .collect();
        (IndexedMesh::new(positions, triangles), keys)
    }
}
