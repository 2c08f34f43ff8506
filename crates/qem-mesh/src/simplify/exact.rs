//! The bookkeeping of [`QuadricMode::Exact`](super::QuadricMode::Exact): quadrics of
//! plane-set *unions* by inclusion–exclusion.
//!
//! Every plane has a support: the original vertices it belongs to (a face plane: the
//! face's three corners; a border plane: its edge's two ends). A current vertex `v`
//! stands for a group `G(v)` of original vertices, and its quadric `Q_v` is the sum of
//! the planes whose support meets `G(v)`. Contracting `a` and `b` must give the planes
//! meeting `G(a) ∪ G(b)`:
//!
//! ```text
//! Q_new = Q_a + Q_b − Q_ab,   Q_ab  = Σ planes meeting both G(a) and G(b)
//! ```
//!
//! `Q_ab` is kept on the edge `a–b`. Why an edge always exists when `Q_ab ≠ 0`: a plane
//! meeting both groups has two support vertices, one in each, and the original edge
//! between them now joins `a` and `b`; the store removes an edge only when its ends
//! merge (it keeps wire edges), and merges duplicate edges. A virtual pair therefore has
//! `Q_ab = 0`.
//!
//! After the contraction the edge to a neighbour `x` needs the planes meeting
//! `G(a) ∪ G(b)` and `G(x)`:
//!
//! ```text
//! Q_(new,x) = Q_ax + Q_bx − Q_abx,   Q_abx = Σ planes meeting G(a), G(b) and G(x)
//! ```
//!
//! Only face planes have three support vertices, and such a plane's face now sits on
//! the triangle `a b x` (faces disappear only when two corners merge, and duplicates
//! are merged with their quadrics summed), so `Q_abx` is the quadric kept on that face,
//! which is exactly one of the faces that collapse. A face `b x y` that merges into
//! `a x y` sums into it (a 4-vertex intersection is always empty). Edges and faces away
//! from `a` and `b` keep their quadrics: their groups did not change.

use crate::store::{ContractError, ContractLog, EdgeKey, FaceKey, MeshStore, SlotVec, VertexKey};
use qem_core::{Quadric, WeightedPlane};
use std::collections::HashMap;

/// Intersection quadrics on edges and faces, and the buffers of one contraction.
///
/// Kept in [`SlotVec`]s rather than `SecondaryMap`s: the versions a `SecondaryMap`
/// keeps (8 bytes an entry, with padding) were 80 MB on a 4M-triangle mesh. Entries are
/// read only for live keys (the loop never asks about a removed edge or face), and a
/// removed element's entry is cleared, so a stale read would see no plane rather than
/// an old one.
#[derive(Debug)]
pub(super) struct ExactQuadrics {
    /// `Q_ab` for every live edge `a–b`.
    edges: SlotVec<EdgeKey, Quadric>,
    /// The plane of the input face on each face: its `Q_abc` while no other face has
    /// merged into it. Why planes (40 bytes) rather than quadrics (80): a face's quadric
    /// is read only when it collapses or merges, about twice per contraction, and was
    /// 350 MB on a 4M-triangle mesh.
    face_planes: SlotVec<FaceKey, WeightedPlane>,
    /// `Q_abc` of the faces that duplicates merged into (no longer one plane). Rare:
    /// only duplicate faces merge. Only looked up, never iterated.
    merged_faces: HashMap<FaceKey, Quadric>,
    /// What the store merged, reused across contractions.
    log: ContractLog,
    /// The third vertex and quadric of each face on the contracted edge, taken before
    /// the store removes them.
    collapsed: Vec<(VertexKey, Quadric)>,
}

impl ExactQuadrics {
    /// Zero quadrics on every edge of `store`, room for every face.
    pub fn new(store: &MeshStore) -> Self {
        ExactQuadrics {
            edges: SlotVec::for_keys(store.edges(), Quadric::ZERO),
            face_planes: SlotVec::for_keys(store.faces(), WeightedPlane::NONE),
            merged_faces: HashMap::new(),
            log: ContractLog::default(),
            collapsed: Vec::new(),
        }
    }

    /// Records `plane`, the plane of face `f`, whose edges are `edges`; `q` is its
    /// quadric (`plane.quadric()`, which the caller has already computed).
    pub fn add_face(&mut self, f: FaceKey, edges: [EdgeKey; 3], plane: WeightedPlane, q: Quadric) {
        // Bits, not values: a NaN entry (never seen in the normalised frame) is not
        // equal to itself.
        debug_assert!(plane.quadric().entries().map(f64::to_bits) == q.entries().map(f64::to_bits));
        self.face_planes.set(f, plane);
        for e in edges {
            self.add_edge_plane(e, q);
        }
    }

    /// Records a plane supported by the two ends of edge `e` (a border plane).
    pub fn add_edge_plane(&mut self, e: EdgeKey, q: Quadric) {
        if let Some(sum) = self.edges.get_mut(e) {
            *sum += q;
        }
    }

    /// `Q_ab` of edge `e` (live), or zero for a pair without edge.
    #[inline]
    pub fn edge(&self, e: Option<EdgeKey>) -> Quadric {
        e.map_or(Quadric::ZERO, |e| *self.edges.get(e))
    }

    /// Contracts `b` into `a` in `store` and updates the intersection quadrics. The
    /// caller sets `a`'s own quadric to `Q_a + Q_b − Q_ab`.
    pub fn contract(
        &mut self,
        store: &mut MeshStore,
        a: VertexKey,
        b: VertexKey,
        ab: Option<EdgeKey>,
        position: [f64; 3],
    ) -> Result<(), ContractError> {
        let ExactQuadrics {
            edges,
            face_planes,
            merged_faces,
            log,
            collapsed,
        } = self;
        collapsed.clear();
        if let Some(ab) = ab.filter(|&e| store.contains_edge(e)) {
            for &f in store.fan(ab) {
                if let Some(x) = store.opposite_vertex(f, ab) {
                    collapsed.push((x, face_quadric(face_planes, merged_faces, f)));
                }
            }
        }
        store.contract_along(a, b, ab, position, Some(log))?;
        for &(removed, kept) in &log.faces_merged {
            let q = face_quadric(face_planes, merged_faces, removed);
            let sum = face_quadric(face_planes, merged_faces, kept) + q;
            merged_faces.insert(kept, sum);
            forget_face(face_planes, merged_faces, removed);
        }
        for &(removed, kept) in &log.edges_merged {
            let q_bx = edges.take(removed);
            let Some(x) = store.other_vertex(kept, a) else {
                continue;
            };
            // At most one collapsed face is on a, b and x (no two faces share a vertex
            // set), and a merging edge without one has Q_abx = 0.
            let q_abx = collapsed
                .iter()
                .find(|(y, _)| *y == x)
                .map_or(Quadric::ZERO, |(_, q)| *q);
            if let Some(sum) = edges.get_mut(kept) {
                *sum += q_bx - q_abx;
            }
        }
        for &f in &log.faces_collapsed {
            forget_face(face_planes, merged_faces, f);
        }
        if let Some(e) = log.edge_collapsed {
            edges.take(e);
        }
        Ok(())
    }
}

/// `Q_abc` of live face `f`: the sum kept for it if faces merged into it, else its
/// input face's plane.
fn face_quadric(
    face_planes: &SlotVec<FaceKey, WeightedPlane>,
    merged_faces: &HashMap<FaceKey, Quadric>,
    f: FaceKey,
) -> Quadric {
    match merged_faces.get(&f) {
        Some(&q) => q,
        None => face_planes.get(f).quadric(),
    }
}

/// Clears the entries of removed face `f`.
fn forget_face(
    face_planes: &mut SlotVec<FaceKey, WeightedPlane>,
    merged_faces: &mut HashMap<FaceKey, Quadric>,
    f: FaceKey,
) {
    face_planes.take(f);
    merged_faces.remove(&f);
}
