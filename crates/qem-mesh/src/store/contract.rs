//! Contraction of a vertex pair, edge or not: Edelsbrunner's edge contraction generalised
//! to arbitrary triangle complexes and to "virtual pairs" that share no edge.
//!
//! The order of the three steps matters:
//! 1. faces containing both `a` and `b` are removed first, so that no later step can make
//!    a face with a repeated vertex;
//! 2. the remaining faces of `b` are re-pointed to `a`, or dropped when `a` already has a
//!    face on the same three vertices. A re-pointed face never duplicates another
//!    re-pointed one (they had distinct vertex sets with `b`), so only `a`'s original
//!    faces need checking, and those are exactly the faces in the fans of `a`'s edges
//!    that step 2 does not touch;
//! 3. the edges of `b` are re-pointed to `a`, or merged into `a`'s edge to the same
//!    neighbour, fans joined. No face can be in both fans (it would contain `a` and `b`
//!    and was removed in step 1), so joining is a plain append.
//!
//! Contraction only removes and re-points elements; it never inserts one. The store's
//! records hold 32-bit slot indices on the ground that no slot is ever reused (see
//! `MeshStore`); an insertion here would break that.

use super::{ordered_packed, remove_item, EdgeKey, FaceKey, MeshStore, Packed, VertexKey};

/// What one [`MeshStore::contract`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct ContractOutcome {
    /// Faces that contained both vertices and disappeared.
    pub faces_collapsed: usize,
    /// Faces of the removed vertex that became copies (same vertex set, any orientation)
    /// of a face of the kept vertex and were removed; the kept vertex's face stays.
    pub faces_merged: usize,
    /// Whether the two vertices were joined by an edge, which was removed.
    pub edge_collapsed: bool,
    /// Edges of the removed vertex that merged into an edge of the kept vertex to the
    /// same neighbour.
    pub edges_merged: usize,
}

impl ContractOutcome {
    /// All faces removed: collapsed plus merged.
    pub fn faces_removed(&self) -> usize {
        self.faces_collapsed + self.faces_merged
    }

    /// All edges removed: the contracted edge (if any) plus merged ones.
    pub fn edges_removed(&self) -> usize {
        usize::from(self.edge_collapsed) + self.edges_merged
    }
}

/// Which faces and edges one [`MeshStore::contract_logged`] removed, and into which
/// survivor each merged one went, for callers that keep data per face or per edge (the
/// exact quadrics of the simplifier sum the data of merged elements).
///
/// The vectors are cleared at the start of each logged contraction; keep one log and
/// pass it to every call so that they stop allocating once warm.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ContractLog {
    /// Faces that contained both vertices and disappeared, in fan order of the edge
    /// `a–b` (empty for a pair without an edge).
    pub faces_collapsed: Vec<FaceKey>,
    /// `(removed, kept)`: a face of `b` that became a copy of face `kept` of `a` and was
    /// removed.
    pub faces_merged: Vec<(FaceKey, FaceKey)>,
    /// The edge `a–b`, if there was one; it is gone.
    pub edge_collapsed: Option<EdgeKey>,
    /// `(removed, kept)`: an edge `b–x` that merged into `a`'s edge `kept` to `x`.
    pub edges_merged: Vec<(EdgeKey, EdgeKey)>,
}

impl ContractLog {
    fn clear(&mut self) {
        self.faces_collapsed.clear();
        self.faces_merged.clear();
        self.edge_collapsed = None;
        self.edges_merged.clear();
    }
}

/// Why [`MeshStore::contract`] refused; the store is unchanged.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ContractError {
    /// Both keys name the same vertex.
    #[error("cannot contract vertex {0:?} with itself")]
    SameVertex(VertexKey),
    /// A key names no live vertex.
    #[error("vertex {0:?} is not in the store")]
    MissingVertex(VertexKey),
    /// The target position has a NaN or infinite coordinate.
    #[error("contraction target {0:?} is not finite")]
    NonFinitePosition([f64; 3]),
}

impl MeshStore {
    /// Contracts `b` into `a`, which moves to `position`.
    ///
    /// Works on any pair of distinct live vertices, whether an edge joins them or not
    /// (a virtual pair, which joins parts). Afterwards:
    /// - faces that contained both `a` and `b` are gone, removed from every fan;
    /// - every other face of `b` has `a` in `b`'s place, same orientation and slot, unless
    ///   `a` already had a face on the same three vertices: then the face of `b` is removed
    ///   (merged) and `a`'s face is kept as it was;
    /// - every edge `b–x` became `a–x`, or, if `a–x` existed, was removed with its fan
    ///   appended to the fan of `a–x` (no face repeated);
    /// - the edge `a–b`, if any, is gone, and so is `b`.
    ///
    /// Edges whose fan became empty stay as wire edges, and vertices whose star became
    /// empty stay as isolated vertices: [`to_mesh`](Self::to_mesh) drops both. All keys
    /// other than `b`, the removed faces and the removed edges stay valid.
    ///
    /// Uses buffers kept in the store, so it does not allocate once they are warm (a fan
    /// or star growing past its inline size may still spill).
    ///
    /// # Errors
    /// [`ContractError`] when `a == b`, a key is not live, or `position` is not finite;
    /// the store is then unchanged.
    ///
    /// # Example
    /// Contracting an edge of a closed tetrahedron: two faces collapse, and the last face
    /// of `b` lands on the vertex set of a face of `a`, so it merges.
    /// ```
    /// use qem_mesh::{IndexedMesh, MeshStore};
    ///
    /// let mesh = IndexedMesh::new(
    ///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    ///     vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    /// );
    /// let (mut store, keys) = MeshStore::from_mesh(&mesh)?;
    /// let outcome = store.contract(keys[0], keys[1], [0.5, 0.0, 0.0])?;
    /// assert_eq!((outcome.faces_collapsed, outcome.faces_merged), (2, 1));
    /// assert_eq!((outcome.edge_collapsed, outcome.edges_merged), (true, 2));
    /// assert_eq!((store.vertex_count(), store.edge_count(), store.face_count()), (3, 3, 1));
    /// assert_eq!(store.position(keys[0]), [0.5, 0.0, 0.0]);
    /// assert!(!store.contains_vertex(keys[1]));
    /// store.validate()?;
    ///
    /// // A pair that is no longer live is an error, not a panic.
    /// assert!(store.contract(keys[0], keys[1], [0.0; 3]).is_err());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn contract(
        &mut self,
        a: VertexKey,
        b: VertexKey,
        position: [f64; 3],
    ) -> Result<ContractOutcome, ContractError> {
        self.check_contract(a, b, position)?;
        let ab = self.find_edge(a, b);
        Ok(self.contract_checked(a, b, ab, position, None))
    }

    /// [`contract`](Self::contract) that also writes into `log` (cleared first) which
    /// faces and edges were removed and which survivor each merged one went into.
    ///
    /// # Errors
    /// As [`contract`](Self::contract); `log` is then cleared and the store unchanged.
    ///
    /// # Example
    /// ```
    /// use qem_mesh::{store::ContractLog, IndexedMesh, MeshStore};
    ///
    /// // The closed tetrahedron again: faces 0 and 1 are on edge 0-1 and collapse; face
    /// // 3 (1 2 3) lands on face 2 (0 3 2) and merges.
    /// let mesh = IndexedMesh::new(
    ///     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    ///     vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    /// );
    /// let (mut store, keys) = MeshStore::from_mesh(&mesh)?;
    /// let faces: Vec<_> = store.faces().collect();
    /// let mut log = ContractLog::default();
    /// store.contract_logged(keys[0], keys[1], [0.5, 0.0, 0.0], &mut log)?;
    /// assert_eq!(log.faces_collapsed, vec![faces[0], faces[1]]);
    /// assert_eq!(log.faces_merged, vec![(faces[3], faces[2])]);
    /// assert!(log.edge_collapsed.is_some());
    /// assert_eq!(log.edges_merged.len(), 2);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn contract_logged(
        &mut self,
        a: VertexKey,
        b: VertexKey,
        position: [f64; 3],
        log: &mut ContractLog,
    ) -> Result<ContractOutcome, ContractError> {
        log.clear();
        self.check_contract(a, b, position)?;
        let ab = self.find_edge(a, b);
        Ok(self.contract_checked(a, b, ab, position, Some(log)))
    }

    /// The refusals of [`contract`](Self::contract): same vertex, dead key, non-finite
    /// position.
    fn check_contract(
        &self,
        a: VertexKey,
        b: VertexKey,
        position: [f64; 3],
    ) -> Result<(), ContractError> {
        if a == b {
            return Err(ContractError::SameVertex(a));
        }
        for v in [a, b] {
            if !self.vertices.contains_key(v) {
                return Err(ContractError::MissingVertex(v));
            }
        }
        if !position.iter().all(|c| c.is_finite()) {
            return Err(ContractError::NonFinitePosition(position));
        }
        Ok(())
    }

    /// The contraction itself, once [`check_contract`](Self::check_contract) passed;
    /// `ab` is the edge joining `a` and `b`, if any.
    fn contract_checked(
        &mut self,
        a: VertexKey,
        b: VertexKey,
        ab: Option<EdgeKey>,
        position: [f64; 3],
        mut log: Option<&mut ContractLog>,
    ) -> ContractOutcome {
        let mut outcome = ContractOutcome::default();
        // Taken out of `self` for the duration so the borrow checker lets us mutate the
        // store while walking them; put back at the end to keep their capacity.
        let mut faces = std::mem::take(&mut self.scratch.faces);
        let mut edges = std::mem::take(&mut self.scratch.edges);
        let mut moved = std::mem::take(&mut self.scratch.moved);

        // Step 1: the faces on edge a-b collapse, then the edge itself.
        if let Some(ab) = ab {
            faces.clear();
            faces.extend_from_slice(self.fan(ab));
            for &f in &faces {
                self.remove_face(f);
            }
            outcome.faces_collapsed = faces.len();
            self.remove_edge(ab);
            outcome.edge_collapsed = true;
            if let Some(log) = log.as_deref_mut() {
                log.faces_collapsed.extend_from_slice(&faces);
                log.edge_collapsed = Some(ab);
            }
        }

        // a's neighbours and the edge to each, read once: steps 2 and 3 ask for a's
        // edge to a neighbour of b per face and per edge of b, and a's star does not
        // change until step 3 appends to it (edges to vertices not listed here).
        let mut links = std::mem::take(&mut self.scratch.links);
        links.clear();
        links.extend(
            self.vertices[a]
                .star
                .iter()
                .filter_map(|&e| self.other_vertex(e, a).map(|x| (x, e))),
        );
        let edge_to = |x: VertexKey| links.iter().find(|l| l.0 == x).map(|l| l.1);

        // Step 2: faces of b move to a, or merge into a face of a.
        self.faces_of_vertex(b, &mut faces);
        for &f in &faces {
            let face = self.faces[f];
            let Some(slot) = face.slot_of(b) else {
                continue;
            };
            let x = face.vertices[(slot + 1) % 3].key();
            let y = face.vertices[(slot + 2) % 3];
            // The face a x y, if any (as `find_face`, with a's edge to x from `links`).
            let kept = edge_to(x).and_then(|ax| {
                self.fan(ax)
                    .iter()
                    .copied()
                    .find(|&g| self.faces[g].vertices.contains(&y))
            });
            if let Some(kept) = kept {
                self.remove_face(f);
                outcome.faces_merged += 1;
                if let Some(log) = log.as_deref_mut() {
                    log.faces_merged.push((f, kept));
                }
            } else {
                self.faces[f].vertices[slot] = Packed::new(a);
            }
        }

        // Step 3: edges of b move to a, or merge into a's edge to the same neighbour.
        edges.clear();
        edges.extend_from_slice(&self.vertices[b].star);
        for &e in &edges {
            let Some(x) = self.other_vertex(e, b) else {
                continue;
            };
            match edge_to(x) {
                Some(keep) => {
                    moved.clear();
                    self.fans.take(&mut self.edges[e].fan, &mut moved);
                    let (packed_e, packed_keep) = (Packed::new(e), Packed::new(keep));
                    for &f in &moved {
                        for slot in &mut self.faces[f].edges {
                            if *slot == packed_e {
                                *slot = packed_keep;
                            }
                        }
                        debug_assert!(!self.fan(keep).contains(&f));
                        self.fans.push(&mut self.edges[keep].fan, f);
                    }
                    remove_item(&mut self.vertices[x].star, &e);
                    self.edges.remove(e);
                    outcome.edges_merged += 1;
                    if let Some(log) = log.as_deref_mut() {
                        log.edges_merged.push((e, keep));
                    }
                }
                None => {
                    self.edges[e].vertices = ordered_packed(a, x);
                    self.vertices[a].star.push(e);
                }
            }
        }
        self.vertices.remove(b);
        self.vertices[a].position = position;

        self.scratch.faces = faces;
        self.scratch.edges = edges;
        self.scratch.links = links;
        self.scratch.moved = moved;
        outcome
    }

    /// The face on vertices `{a, x, y}` (any orientation), if any: a search of one star
    /// and one fan.
    ///
    /// # Panics
    /// If `a` or `x` is not in the store.
    pub fn find_face(&self, a: VertexKey, x: VertexKey, y: VertexKey) -> Option<FaceKey> {
        let e = self.find_edge(a, x)?;
        self.fan(e)
            .iter()
            .copied()
            .find(|&f| self.faces[f].has_vertex(y))
    }

    /// Removes face `f`, and each of its edges that holds no other face: what a
    /// simplifier does with the two faces a contraction merges when it keeps neither
    /// (the ladder of relaxations' merged faces, see
    /// [`RelaxationStep::MergedFaces`](crate::simplify::RelaxationStep::MergedFaces)).
    /// Vertices stay, even when no face is left on them. Does nothing when `f` is not
    /// in the store.
    pub fn remove_face_and_bare_edges(&mut self, f: FaceKey) {
        let Some(face) = self.faces.get(f) else {
            return;
        };
        let edges = face.edge_keys();
        self.remove_face(f);
        for e in edges {
            if self.edges.contains_key(e) && self.fan(e).is_empty() {
                self.remove_edge(e);
            }
        }
    }

    /// Removes face `f` from the fans of its edges and from the store.
    fn remove_face(&mut self, f: FaceKey) {
        if let Some(face) = self.faces.remove(f) {
            for e in face.edge_keys() {
                if let Some(edge) = self.edges.get_mut(e) {
                    self.fans.remove(&mut edge.fan, f);
                }
            }
        }
    }

    /// Removes edge `e` from the stars of its endpoints and from the store. Its fan must
    /// already be empty or about to be discarded by the caller.
    fn remove_edge(&mut self, e: EdgeKey) {
        if let Some(mut edge) = self.edges.remove(e) {
            self.fans.clear(&mut edge.fan);
            for v in edge.vertex_keys() {
                if let Some(vertex) = self.vertices.get_mut(v) {
                    remove_item(&mut vertex.star, &e);
                }
            }
        }
    }
}
