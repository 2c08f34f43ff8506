//! Edge flips: the store's side of the simplifier's last step, which turns faces that
//! face away from the input back by flipping an edge (see
//! `crate::simplify::turn_back`); the replay oracle follows the engine's flips with it.

use super::{ordered_packed, Face, MeshStore, Packed};
use crate::store::{FaceKey, VertexKey};
use smallvec::SmallVec;

/// Why an edge could not be flipped.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum FlipError {
    /// No edge joins the two vertices.
    #[error("no edge joins the two vertices")]
    NoEdge,
    /// The edge holds other than two faces, or two faces that do not run it in
    /// opposite directions (`p q r` and `q p s`).
    #[error("the edge is not held by two faces oriented alike")]
    NotTwoFaces,
    /// The two opposite vertices coincide or are joined already.
    #[error("the new edge would coincide with an existing one")]
    EdgeExists,
}

impl MeshStore {
    /// Flips the edge `{p, q}` held by the faces `p q r` and `q p s`: they become
    /// `p s r` and `s q r` (the same orientation, the quad `p s q r` cut along `r s`
    /// instead of `p q`). The edge record of `p q` becomes `r s` (its key now names
    /// `r s`); the two faces keep their keys. Positions and every other face stay.
    pub fn flip_edge(&mut self, p: VertexKey, q: VertexKey) -> Result<(), FlipError> {
        if !(self.contains_vertex(p) && self.contains_vertex(q)) {
            return Err(FlipError::NoEdge);
        }
        let e = self.find_edge(p, q).ok_or(FlipError::NoEdge)?;
        let fan: SmallVec<[FaceKey; 2]> = self.fan(e).iter().copied().collect();
        if fan.len() != 2 {
            return Err(FlipError::NotTwoFaces);
        }
        // The vertex after `from` in face `f`'s order.
        let next = |store: &Self, f: FaceKey, from: VertexKey| {
            let v = store.face_vertices(f);
            let k = v.iter().position(|&x| x == from)?;
            Some(v[(k + 1) % 3])
        };
        let (t, u) = if next(self, fan[0], p) == Some(q) {
            (fan[0], fan[1])
        } else {
            (fan[1], fan[0])
        };
        if next(self, t, p) != Some(q) || next(self, u, q) != Some(p) {
            return Err(FlipError::NotTwoFaces);
        }
        let r = next(self, t, q).ok_or(FlipError::NotTwoFaces)?;
        let s = next(self, u, p).ok_or(FlipError::NotTwoFaces)?;
        if r == s || self.find_edge(r, s).is_some() {
            return Err(FlipError::EdgeExists);
        }
        // Rewritten in place, no record made: the store's packed keys name slots of
        // the first generation only, and a removed slot is reused at a later one.
        // The edge `p q` becomes `r s`; `p s` moves from `u` to `t`, `q r` from `t` to
        // `u`.
        let edge_of = |store: &Self, f: FaceKey, a: VertexKey, b: VertexKey| {
            store.face_edges(f).into_iter().find(|&x| {
                let [x0, x1] = store.edge_vertices(x);
                (x0 == a && x1 == b) || (x0 == b && x1 == a)
            })
        };
        let (Some(ps), Some(qr), Some(rp), Some(sq)) = (
            edge_of(self, u, p, s),
            edge_of(self, t, q, r),
            edge_of(self, t, r, p),
            edge_of(self, u, s, q),
        ) else {
            return Err(FlipError::NotTwoFaces);
        };
        self.faces[t] = Face {
            vertices: [p, s, r].map(Packed::new),
            edges: [ps, e, rp].map(Packed::new),
        };
        self.faces[u] = Face {
            vertices: [s, q, r].map(Packed::new),
            edges: [sq, qr, e].map(Packed::new),
        };
        for (edge, from, to) in [(ps, u, t), (qr, t, u)] {
            let fan = &mut self.edges[edge].fan;
            self.fans.remove(fan, from);
            self.fans.push(fan, to);
        }
        self.edges[e].vertices = ordered_packed(r, s);
        for v in [p, q] {
            super::remove_item(&mut self.vertices[v].star, &e);
        }
        for v in [r, s] {
            self.vertices[v].star.push(e);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::IndexedMesh;

    /// A square cut along 0-2, flipped to 1-3: both faces keep their orientation, and
    /// the store stays valid; a border edge or a missing one is refused.
    #[test]
    fn a_square_is_cut_along_its_other_diagonal() {
        let mesh = IndexedMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            vec![[0, 1, 2], [2, 3, 0]],
        );
        let (mut store, keys) = MeshStore::from_mesh(&mesh).unwrap();
        assert_eq!(
            store.flip_edge(keys[0], keys[1]),
            Err(FlipError::NotTwoFaces)
        );
        assert_eq!(store.flip_edge(keys[1], keys[3]), Err(FlipError::NoEdge));
        store.flip_edge(keys[2], keys[0]).unwrap();
        store.validate().unwrap();
        assert!(store.find_edge(keys[0], keys[2]).is_none());
        assert!(store.find_edge(keys[1], keys[3]).is_some());
        let out = store.to_mesh();
        let mut faces: Vec<[u32; 3]> = out
            .triangles
            .iter()
            .map(|t| {
                // Rotated to start at the least vertex, keeping the orientation.
                let k = (0..3).min_by_key(|&k| t[k]).unwrap();
                [t[k], t[(k + 1) % 3], t[(k + 2) % 3]]
            })
            .collect();
        faces.sort_unstable();
        assert_eq!(faces, [[0, 1, 3], [1, 2, 3]]);
    }
}
