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

use crate::store::{ContractError, ContractLog, EdgeKey, FaceKey, MeshStore, VertexKey};
use qem_core::Quadric;
use slotmap::SecondaryMap;

/// Intersection quadrics on edges and faces, and the buffers of one contraction.
#[derive(Debug, Default)]
pub(super) struct ExactQuadrics {
    /// `Q_ab` for every live edge `a–b`.
    edges: SecondaryMap<EdgeKey, Quadric>,
    /// `Q_abc` for every live face: the planes of the original faces now on it.
    faces: SecondaryMap<FaceKey, Quadric>,
    /// What the store merged, reused across contractions.
    log: ContractLog,
    /// The third vertex and quadric of each face on the contracted edge, taken before
    /// the store removes them.
    collapsed: Vec<(VertexKey, Quadric)>,
}

impl ExactQuadrics {
    /// Zero quadrics on every edge of `store`, room for every face.
    pub fn new(store: &MeshStore) -> Self {
        let mut edges = SecondaryMap::with_capacity(store.edge_count());
        for e in store.edges() {
            edges.insert(e, Quadric::ZERO);
        }
        ExactQuadrics {
            edges,
            faces: SecondaryMap::with_capacity(store.face_count()),
            log: ContractLog::default(),
            collapsed: Vec::new(),
        }
    }

    /// Records the plane `q` of face `f`, whose edges are `edges`.
    pub fn add_face(&mut self, f: FaceKey, edges: [EdgeKey; 3], q: Quadric) {
        self.faces.insert(f, q);
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

    /// `Q_ab` of edge `e`, or zero for a pair without edge.
    #[inline]
    pub fn edge(&self, e: Option<EdgeKey>) -> Quadric {
        e.and_then(|e| self.edges.get(e).copied())
            .unwrap_or(Quadric::ZERO)
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
            faces,
            log,
            collapsed,
        } = self;
        collapsed.clear();
        if let Some(ab) = ab.filter(|&e| store.contains_edge(e)) {
            for &f in store.fan(ab) {
                if let (Some(x), Some(&q)) = (store.opposite_vertex(f, ab), faces.get(f)) {
                    collapsed.push((x, q));
                }
            }
        }
        store.contract_along(a, b, ab, position, Some(log))?;
        for &(removed, kept) in &log.faces_merged {
            let q = faces.remove(removed).unwrap_or(Quadric::ZERO);
            if let Some(sum) = faces.get_mut(kept) {
                *sum += q;
            }
        }
        for &(removed, kept) in &log.edges_merged {
            let q_bx = edges.remove(removed).unwrap_or(Quadric::ZERO);
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
            faces.remove(f);
        }
        if let Some(e) = log.edge_collapsed {
            edges.remove(e);
        }
        Ok(())
    }
}
