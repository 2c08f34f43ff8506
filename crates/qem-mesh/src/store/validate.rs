//! The full invariant check of a [`MeshStore`].
//!
//! Slow (it sorts and allocates) and thorough: it is what the tests run after every
//! operation, and what a debug build can call after every contraction.

use super::{EdgeKey, FaceKey, MeshStore, VertexKey};

/// A broken invariant of a [`MeshStore`]: what is wrong and with which key.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum StoreError {
    /// A vertex's star names an edge that does not exist.
    StarEdgeMissing {
        /// The vertex.
        vertex: VertexKey,
        /// The missing edge.
        edge: EdgeKey,
    },
    /// A vertex's star holds an edge that does not have the vertex as an endpoint.
    StarEdgeNotIncident {
        /// The vertex.
        vertex: VertexKey,
        /// The edge.
        edge: EdgeKey,
    },
    /// An edge is not in the star of one of its endpoints exactly once.
    EdgeNotInStarOnce {
        /// The edge.
        edge: EdgeKey,
        /// The endpoint.
        vertex: VertexKey,
        /// How many times it is there.
        count: usize,
    },
    /// An edge names an endpoint that does not exist.
    EdgeVertexMissing {
        /// The edge.
        edge: EdgeKey,
        /// The missing vertex.
        vertex: VertexKey,
    },
    /// An edge's endpoints are equal or not in canonical (ascending) order.
    EdgeNotCanonical {
        /// The edge.
        edge: EdgeKey,
    },
    /// Two edges join the same two vertices.
    DuplicateEdge {
        /// The first edge.
        first: EdgeKey,
        /// The second edge.
        second: EdgeKey,
    },
    /// An edge's fan names a face that does not exist.
    FanFaceMissing {
        /// The edge.
        edge: EdgeKey,
        /// The missing face.
        face: FaceKey,
    },
    /// An edge's fan holds a face that does not have the edge among its edges.
    FanFaceNotIncident {
        /// The edge.
        edge: EdgeKey,
        /// The face.
        face: FaceKey,
    },
    /// A face is not in the fan of one of its edges exactly once.
    FaceNotInFanOnce {
        /// The face.
        face: FaceKey,
        /// The edge.
        edge: EdgeKey,
        /// How many times it is there.
        count: usize,
    },
    /// A face names a vertex that does not exist.
    FaceVertexMissing {
        /// The face.
        face: FaceKey,
        /// The missing vertex.
        vertex: VertexKey,
    },
    /// A face repeats a vertex.
    DegenerateFace {
        /// The face.
        face: FaceKey,
    },
    /// A face names an edge that does not exist.
    FaceEdgeMissing {
        /// The face.
        face: FaceKey,
        /// The missing edge.
        edge: EdgeKey,
    },
    /// A face's edge slot `slot` does not join vertices `slot` and `slot + 1` of the face.
    FaceEdgeMismatch {
        /// The face.
        face: FaceKey,
        /// The slot, 0 to 2.
        slot: usize,
    },
    /// Two faces have the same three vertices.
    DuplicateFace {
        /// The first face.
        first: FaceKey,
        /// The second face.
        second: FaceKey,
    },
}

impl std::fmt::Display for StoreError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use StoreError as E;
        match *self {
            E::StarEdgeMissing { vertex, edge } => {
                write!(f, "star of vertex {vertex:?} names missing edge {edge:?}")
            }
            E::StarEdgeNotIncident { vertex, edge } => write!(
                f,
                "star of vertex {vertex:?} holds edge {edge:?}, which does not touch it"
            ),
            E::EdgeNotInStarOnce {
                edge,
                vertex,
                count,
            } => write!(
                f,
                "edge {edge:?} is {count} times in the star of its endpoint {vertex:?}"
            ),
            E::EdgeVertexMissing { edge, vertex } => {
                write!(f, "edge {edge:?} names missing vertex {vertex:?}")
            }
            E::EdgeNotCanonical { edge } => {
                write!(f, "edge {edge:?} has equal or unordered endpoints")
            }
            E::DuplicateEdge { first, second } => {
                write!(f, "edges {first:?} and {second:?} join the same vertices")
            }
            E::FanFaceMissing { edge, face } => {
                write!(f, "fan of edge {edge:?} names missing face {face:?}")
            }
            E::FanFaceNotIncident { edge, face } => write!(
                f,
                "fan of edge {edge:?} holds face {face:?}, which does not have that edge"
            ),
            E::FaceNotInFanOnce { face, edge, count } => write!(
                f,
                "face {face:?} is {count} times in the fan of its edge {edge:?}"
            ),
            E::FaceVertexMissing { face, vertex } => {
                write!(f, "face {face:?} names missing vertex {vertex:?}")
            }
            E::DegenerateFace { face } => write!(f, "face {face:?} repeats a vertex"),
            E::FaceEdgeMissing { face, edge } => {
                write!(f, "face {face:?} names missing edge {edge:?}")
            }
            E::FaceEdgeMismatch { face, slot } => write!(
                f,
                "edge slot {slot} of face {face:?} does not join its vertices {slot} and {}",
                (slot + 1) % 3
            ),
            E::DuplicateFace { first, second } => {
                write!(f, "faces {first:?} and {second:?} have the same vertices")
            }
        }
    }
}

impl std::error::Error for StoreError {}

impl MeshStore {
    /// Checks every invariant of the store and reports the first one broken.
    ///
    /// Vertices: every star entry exists and has the vertex as an endpoint. Edges: both
    /// endpoints exist, are distinct and in ascending order; the edge is in each
    /// endpoint's star exactly once; no other edge joins the same pair; every fan entry
    /// exists and has the edge among its three edges. Faces: three existing, distinct
    /// vertices; three existing edges, slot `i` joining vertices `i` and `i + 1`; the face
    /// is in each edge's fan exactly once; no other face has the same vertex set.
    /// Together these make adjacency symmetric in every direction.
    ///
    /// Allocates and sorts; meant for tests and debug builds.
    ///
    /// # Errors
    /// The first broken invariant found, naming the keys involved.
    pub fn validate(&self) -> Result<(), StoreError> {
        self.validate_vertices()?;
        self.validate_edges()?;
        self.validate_faces()
    }

    fn validate_vertices(&self) -> Result<(), StoreError> {
        for (vertex, v) in &self.vertices {
            for &edge in &v.star {
                let Some(e) = self.edges.get(edge) else {
                    return Err(StoreError::StarEdgeMissing { vertex, edge });
                };
                if !e.vertex_keys().contains(&vertex) {
                    return Err(StoreError::StarEdgeNotIncident { vertex, edge });
                }
            }
        }
        Ok(())
    }

    fn validate_edges(&self) -> Result<(), StoreError> {
        let mut pairs = Vec::with_capacity(self.edges.len());
        for (edge, e) in &self.edges {
            for vertex in e.vertex_keys() {
                let Some(v) = self.vertices.get(vertex) else {
                    return Err(StoreError::EdgeVertexMissing { edge, vertex });
                };
                let count = v.star.iter().filter(|&&x| x == edge).count();
                if count != 1 {
                    return Err(StoreError::EdgeNotInStarOnce {
                        edge,
                        vertex,
                        count,
                    });
                }
            }
            if e.vertices[0] >= e.vertices[1] {
                return Err(StoreError::EdgeNotCanonical { edge });
            }
            for &face in self.fans.get(&e.fan) {
                let Some(f) = self.faces.get(face) else {
                    return Err(StoreError::FanFaceMissing { edge, face });
                };
                if !f.edge_keys().contains(&edge) {
                    return Err(StoreError::FanFaceNotIncident { edge, face });
                }
                // A repeated fan entry is reported from the face side (count != 1).
            }
            pairs.push((e.vertex_keys(), edge));
        }
        pairs.sort_unstable();
        for w in pairs.windows(2) {
            if w[0].0 == w[1].0 {
                return Err(StoreError::DuplicateEdge {
                    first: w[0].1,
                    second: w[1].1,
                });
            }
        }
        Ok(())
    }

    fn validate_faces(&self) -> Result<(), StoreError> {
        let mut sets = Vec::with_capacity(self.faces.len());
        for (face, f) in &self.faces {
            let vertices = f.vertex_keys();
            for vertex in vertices {
                if !self.vertices.contains_key(vertex) {
                    return Err(StoreError::FaceVertexMissing { face, vertex });
                }
            }
            let [p, q, r] = f.vertices;
            if p == q || q == r || r == p {
                return Err(StoreError::DegenerateFace { face });
            }
            for (slot, edge) in f.edge_keys().into_iter().enumerate() {
                let Some(e) = self.edges.get(edge) else {
                    return Err(StoreError::FaceEdgeMissing { face, edge });
                };
                let want = super::ordered(vertices[slot], vertices[(slot + 1) % 3]);
                if e.vertex_keys() != want {
                    return Err(StoreError::FaceEdgeMismatch { face, slot });
                }
                let count = self.fan(edge).iter().filter(|&&x| x == face).count();
                if count != 1 {
                    return Err(StoreError::FaceNotInFanOnce { face, edge, count });
                }
            }
            let mut set = vertices;
            set.sort_unstable();
            sets.push((set, face));
        }
        sets.sort_unstable();
        for w in sets.windows(2) {
            if w[0].0 == w[1].0 {
                return Err(StoreError::DuplicateFace {
                    first: w[0].1,
                    second: w[1].1,
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    //! Each test breaks one invariant by hand and checks that `validate` names it: the
    //! check must be able to fail for the model test's `validate()` calls to mean anything.

    use super::*;
    use crate::IndexedMesh;

    /// Two triangles on the shared edge 1-2: `0 1 2` and `2 1 3`.
    fn square() -> (MeshStore, Vec<VertexKey>) {
        let mesh = IndexedMesh::new(vec![[0.0; 3]; 4], vec![[0, 1, 2], [2, 1, 3]]);
        let (store, keys) = MeshStore::from_mesh(&mesh).expect("valid mesh");
        assert_eq!(store.validate(), Ok(()));
        (store, keys)
    }

    fn shared(store: &MeshStore, keys: &[VertexKey]) -> EdgeKey {
        store.find_edge(keys[1], keys[2]).expect("edge 1-2")
    }

    #[test]
    fn missing_and_repeated_star_entries() {
        let (mut s, k) = square();
        let e = shared(&s, &k);
        s.vertices[k[1]].star.retain(|x| *x != e);
        assert_eq!(
            s.validate(),
            Err(StoreError::EdgeNotInStarOnce {
                edge: e,
                vertex: k[1],
                count: 0
            })
        );
        let (mut s, k) = square();
        s.vertices[k[2]].star.push(e);
        assert!(matches!(
            s.validate(),
            Err(StoreError::EdgeNotInStarOnce { count: 2, .. })
        ));
        let (mut s, k) = square();
        let far = s.find_edge(k[1], k[3]).expect("1-3");
        s.vertices[k[0]].star.push(far);
        assert!(matches!(
            s.validate(),
            Err(StoreError::StarEdgeNotIncident { .. })
        ));
    }

    #[test]
    fn broken_edges() {
        let (mut s, k) = square();
        let e = shared(&s, &k);
        s.edges[e].vertices.swap(0, 1);
        assert_eq!(s.validate(), Err(StoreError::EdgeNotCanonical { edge: e }));

        let (mut s, k) = square();
        let copy = s.edges.insert(super::super::Edge {
            vertices: s.edges[e].vertices,
            fan: Default::default(),
        });
        s.vertices[k[1]].star.push(copy);
        s.vertices[k[2]].star.push(copy);
        assert!(matches!(
            s.validate(),
            Err(StoreError::DuplicateEdge { .. })
        ));

        let (mut s, k) = square();
        s.vertices.remove(k[3]);
        assert!(matches!(
            s.validate(),
            Err(StoreError::EdgeVertexMissing { vertex, .. }) if vertex == k[3]
        ));
    }

    #[test]
    fn broken_fans() {
        let (mut s, k) = square();
        let e = shared(&s, &k);
        let f = s.fan(e)[0];
        s.fans.push(&mut s.edges[e].fan, f);
        assert_eq!(
            s.validate(),
            Err(StoreError::FaceNotInFanOnce {
                face: f,
                edge: e,
                count: 2
            })
        );
        s.fans.clear(&mut s.edges[e].fan);
        assert!(matches!(
            s.validate(),
            Err(StoreError::FaceNotInFanOnce { count: 0, .. })
        ));

        // Keys are deterministic, so `e` names the same edge in a fresh store.
        let (mut s, _) = square();
        let f = s.fan(e)[0];
        s.faces.remove(f);
        assert!(matches!(
            s.validate(),
            Err(StoreError::FanFaceMissing { face, .. }) if face == f
        ));

        let (mut s, k) = square();
        let boundary = s.find_edge(k[0], k[1]).expect("0-1");
        let other = s.fan(e)[1];
        s.fans.push(&mut s.edges[boundary].fan, other);
        assert_eq!(
            s.validate(),
            Err(StoreError::FanFaceNotIncident {
                edge: boundary,
                face: other
            })
        );
    }

    #[test]
    fn broken_faces() {
        let (mut s, k) = square();
        let f = s.faces().next().expect("a face");
        s.faces[f].vertices[2] = super::super::Packed::new(k[0]);
        assert_eq!(s.validate(), Err(StoreError::DegenerateFace { face: f }));

        let (mut s, _) = square();
        s.faces[f].edges.swap(0, 1);
        assert_eq!(
            s.validate(),
            Err(StoreError::FaceEdgeMismatch { face: f, slot: 0 })
        );

        let (mut s, _) = square();
        let mut copy = s.faces[f];
        copy.vertices.reverse();
        copy.edges = [copy.edges[1], copy.edges[0], copy.edges[2]];
        let g = s.faces.insert(copy);
        for e in copy.edge_keys() {
            s.fans.push(&mut s.edges[e].fan, g);
        }
        assert_eq!(
            s.validate(),
            Err(StoreError::DuplicateFace {
                first: f,
                second: g
            })
        );
        assert!(StoreError::DuplicateFace {
            first: f,
            second: g
        }
        .to_string()
        .contains("same vertices"));
    }
}
