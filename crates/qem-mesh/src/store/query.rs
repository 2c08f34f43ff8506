//! Read-only queries: adjacency, links, edge and vertex classes, components.
//!
//! Queries that return one thing return it by value or as a borrowed slice; queries that
//! must collect take a `&mut Vec` out-parameter (cleared first) so callers can reuse a
//! buffer across calls instead of allocating per query.

use slotmap::SecondaryMap;

use super::{EdgeKey, FaceKey, MeshStore, Packed, VertexKey};

/// How many faces an edge has, which decides its role in the surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EdgeClass {
    /// No face: a bare segment, left behind when a contraction removed the last face
    /// around it.
    Wire,
    /// Exactly one face: on the border of an open surface.
    Boundary,
    /// Exactly two faces: inside a 2-manifold surface.
    Manifold,
    /// Three or more faces: a fin, where sheets meet.
    NonManifold,
}

/// The shape of the neighbourhood of a vertex. Purely combinatorial: face orientation is
/// ignored, positions are not looked at.
///
/// Let the *fans* of `v` be the connected groups of faces around `v`, where two faces
/// around `v` are connected when they share an edge that contains `v`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum VertexClass {
    /// No edge at all (so no face either).
    Isolated,
    /// Every edge at `v` has exactly two faces and the faces around `v` form one fan,
    /// which is then a closed cycle: `v` has a disc neighbourhood.
    Interior,
    /// Every edge at `v` has one or two faces, exactly two of them have one face, and the
    /// faces around `v` form one fan, which is then an open path: a half-disc.
    Boundary,
    /// Everything else: an edge at `v` with three or more faces (on a fin), several fans
    /// (a bow-tie or umbrella vertex), or any wire edge at `v`. In particular a vertex with
    /// edges but no face (wire-only) is `NonManifold`: it has no 2-dimensional
    /// neighbourhood at all, so it is neither interior nor boundary of a surface.
    NonManifold,
}

/// Stars up to this long are scanned by [`MeshStore::find_edge`] without looking at the
/// other vertex: twice the typical valence of a triangle mesh (6).
const SHORT_STAR: usize = 12;

impl MeshStore {
    /// Number of live vertices, isolated ones included.
    pub fn vertex_count(&self) -> usize {
        self.vertices.len()
    }

    /// Number of live edges, wire edges included.
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// Number of live faces.
    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// Whether `v` is a live vertex of this store.
    pub fn contains_vertex(&self, v: VertexKey) -> bool {
        self.vertices.contains_key(v)
    }

    /// Whether `e` is a live edge of this store.
    pub fn contains_edge(&self, e: EdgeKey) -> bool {
        self.edges.contains_key(e)
    }

    /// Whether `f` is a live face of this store.
    pub fn contains_face(&self, f: FaceKey) -> bool {
        self.faces.contains_key(f)
    }

    /// Keys of all live vertices, in slotmap order (deterministic).
    pub fn vertices(&self) -> impl Iterator<Item = VertexKey> + '_ {
        self.vertices.keys()
    }

    /// Keys of all live edges, in slotmap order (deterministic).
    pub fn edges(&self) -> impl Iterator<Item = EdgeKey> + '_ {
        self.edges.keys()
    }

    /// Keys of all live faces, in slotmap order (deterministic).
    pub fn faces(&self) -> impl Iterator<Item = FaceKey> + Clone + '_ {
        self.faces.keys()
    }

    /// Position of `v`.
    ///
    /// # Panics
    /// If `v` is not in the store.
    pub fn position(&self, v: VertexKey) -> [f64; 3] {
        self.vertices[v].position
    }

    /// Moves `v` to `position`. Topology is unchanged.
    ///
    /// # Panics
    /// If `v` is not in the store.
    pub fn set_position(&mut self, v: VertexKey, position: [f64; 3]) {
        self.vertices[v].position = position;
    }

    /// The star of `v`: every edge with `v` as an endpoint, each once.
    ///
    /// # Panics
    /// If `v` is not in the store.
    pub fn star(&self, v: VertexKey) -> &[EdgeKey] {
        &self.vertices[v].star
    }

    /// The endpoints of `e`, smaller key first.
    ///
    /// # Panics
    /// If `e` is not in the store.
    pub fn edge_vertices(&self, e: EdgeKey) -> [VertexKey; 2] {
        self.edges[e].vertex_keys()
    }

    /// The endpoint of `e` that is not `v`, or `None` if `v` is not an endpoint of `e`.
    ///
    /// # Panics
    /// If `e` is not in the store.
    pub fn other_vertex(&self, e: EdgeKey, v: VertexKey) -> Option<VertexKey> {
        match self.edges[e].vertex_keys() {
            [a, b] if a == v => Some(b),
            [a, b] if b == v => Some(a),
            _ => None,
        }
    }

    /// The radial fan of `e`: every face containing both its endpoints, each once.
    ///
    /// # Panics
    /// If `e` is not in the store.
    #[inline]
    pub fn fan(&self, e: EdgeKey) -> &[FaceKey] {
        self.fans.get(&self.edges[e].fan)
    }

    /// The three vertices of `f`, in its orientation.
    ///
    /// # Panics
    /// If `f` is not in the store.
    pub fn face_vertices(&self, f: FaceKey) -> [VertexKey; 3] {
        self.faces[f].vertex_keys()
    }

    /// The three edges of `f`: element `i` joins `face_vertices(f)[i]` and
    /// `face_vertices(f)[(i + 1) % 3]`.
    ///
    /// # Panics
    /// If `f` is not in the store.
    pub fn face_edges(&self, f: FaceKey) -> [EdgeKey; 3] {
        self.faces[f].edge_keys()
    }

    /// The vertex of `f` that is not an endpoint of `e`, or `None` if `e` is not an edge
    /// of `f`.
    ///
    /// # Panics
    /// If `f` or `e` is not in the store.
    pub fn opposite_vertex(&self, f: FaceKey, e: EdgeKey) -> Option<VertexKey> {
        let face = &self.faces[f];
        let slot = face.edges.iter().position(|x| x.key() == e)?;
        Some(face.vertices[(slot + 2) % 3].key())
    }

    /// Writes every face containing `v` into `out` (cleared first), each once.
    ///
    /// Order: by the edge of the star through which the face leaves `v` in its
    /// orientation (star order), then by fan order. Deterministic, no allocation beyond
    /// `out`'s growth.
    ///
    /// # Panics
    /// If `v` is not in the store.
    pub fn faces_of_vertex(&self, v: VertexKey, out: &mut Vec<FaceKey>) {
        out.clear();
        // Indexing checks that `v` is live before it is packed; star edges are live.
        // Both keys live, comparing indices is exact.
        let star = &self.vertices[v].star;
        let packed_v = Packed::new(v);
        for &e in star {
            let packed_e = Packed::new(e);
            for &f in self.fan(e) {
                // A face at v appears in the fans of two star edges; taking it only at the
                // edge from v to its successor in the face lists it exactly once.
                // (A face's vertices are distinct, so at most one slot holds v.)
                let face = &self.faces[f];
                if (0..3).any(|s| face.vertices[s] == packed_v && face.edges[s] == packed_e) {
                    out.push(f);
                }
            }
        }
    }

    /// The edge joining `a` and `b`, if any. Scans `a`'s star when it is short, else
    /// the smaller of the two stars.
    ///
    /// Why `a`'s first: callers ask about one vertex against many (the checks and the
    /// link condition ask `find_edge(b, x)` for every neighbour `x` of `a`), so `a`'s
    /// star and its edges are already in cache, while reading `b`'s star only to compare
    /// lengths costs a cache miss per call. The bound keeps the old guarantee that a
    /// vertex of huge valence is never scanned against a small one.
    ///
    /// # Panics
    /// If `a` is not in the store, or `b` is not and `a`'s star is long.
    pub fn find_edge(&self, a: VertexKey, b: VertexKey) -> Option<EdgeKey> {
        let sa = &self.vertices[a].star;
        if sa.len() <= SHORT_STAR {
            // A key with a later version than any record holds is an endpoint of no edge.
            let (pa, pb) = (Packed::new(a), Packed::try_new(b)?);
            return sa.iter().copied().find(|&e| self.edges[e].joins(pa, pb));
        }
        let sb = &self.vertices[b].star;
        let (star, from) = if sa.len() <= sb.len() {
            (sa, a)
        } else {
            (sb, b)
        };
        let to = if from == a { b } else { a };
        star.iter()
            .copied()
            .find(|&e| self.other_vertex(e, from) == Some(to))
    }

    /// The link of vertex `v`, as in a simplicial complex.
    ///
    /// `vertices` (cleared first) receives the other endpoint of every edge at `v`,
    /// in star order, wire edges included, so each neighbour appears once. `edges`
    /// (cleared first) receives, for every face `(v, x, y)` around `v`, the link edge
    /// `[x, y]` in the face's orientation (`x` follows `v`), in
    /// [`faces_of_vertex`](Self::faces_of_vertex) order. Link edges are distinct because
    /// no two faces share a vertex set. `[x, y]` keeps the face's orientation rather
    /// than the canonical order of [`edge_vertices`](Self::edge_vertices).
    ///
    /// # Panics
    /// If `v` is not in the store.
    pub fn vertex_link(
        &self,
        v: VertexKey,
        vertices: &mut Vec<VertexKey>,
        edges: &mut Vec<[VertexKey; 2]>,
    ) {
        vertices.clear();
        edges.clear();
        for &e in &self.vertices[v].star {
            if let Some(x) = self.other_vertex(e, v) {
                vertices.push(x);
            }
            for &f in self.fan(e) {
                let face = &self.faces[f];
                if let Some(slot) = face.slot_of(v) {
                    if face.edges[slot] == Packed::new(e) {
                        edges.push([
                            face.vertices[(slot + 1) % 3].key(),
                            face.vertices[(slot + 2) % 3].key(),
                        ]);
                    }
                }
            }
        }
    }

    /// The link of edge `e`: the third vertex of every face in its fan, in fan order
    /// (each once, as fans hold distinct vertex sets). In a triangle complex the link of
    /// an edge has vertices only, no edges. Written to `out`, cleared first.
    ///
    /// # Panics
    /// If `e` is not in the store.
    pub fn edge_link(&self, e: EdgeKey, out: &mut Vec<VertexKey>) {
        out.clear();
        for &f in self.fan(e) {
            if let Some(x) = self.opposite_vertex(f, e) {
                out.push(x);
            }
        }
    }

    /// The link condition for contracting `a` and `b`: `Lk a ∩ Lk b = Lk ab`, with links
    /// as in [`vertex_link`](Self::vertex_link) and [`edge_link`](Self::edge_link) (`Lk ab`
    /// is empty when no edge joins them). Concretely: every common neighbour of `a` and `b`
    /// is the third vertex of a face on edge `a–b`, and no two faces `a x y` and `b x y`
    /// exist.
    ///
    /// For an edge whose neighbourhood is a 2-manifold (with or without boundary) this
    /// is exactly the condition under which contraction preserves topology (Dey,
    /// Edelsbrunner et al.); elsewhere it is only a useful necessary test. Costs
    /// O(deg(a) · (deg(b) + fan sizes)), no allocation.
    ///
    /// # Panics
    /// If `a` or `b` is not in the store.
    pub fn link_condition(&self, a: VertexKey, b: VertexKey) -> bool {
        let ab = self.find_edge(a, b);
        let opposite_ab = |x: VertexKey| {
            ab.is_some_and(|e| self.fan(e).iter().any(|&f| self.faces[f].has_vertex(x)))
        };
        // Vertices: a common neighbour not opposite a-b would be pinched. The converse
        // holds by construction (a face a b x has edges a-x and b-x).
        for &e in &self.vertices[a].star {
            match self.other_vertex(e, a) {
                Some(x) if x != b && self.find_edge(b, x).is_some() && !opposite_ab(x) => {
                    return false
                }
                _ => {}
            }
        }
        // Edges: Lk ab has none, so no link edge x y may be shared by a and b.
        for &e in &self.vertices[a].star {
            for &f in self.fan(e) {
                let face = &self.faces[f];
                let Some(slot) = face.slot_of(a) else {
                    continue;
                };
                // Each face once: at the edge leaving a in face order.
                if face.edges[slot] != Packed::new(e) || face.has_vertex(b) {
                    continue;
                }
                let (x, y) = (
                    face.vertices[(slot + 1) % 3].key(),
                    face.vertices[(slot + 2) % 3].key(),
                );
                if self.find_face(b, x, y).is_some() {
                    return false;
                }
            }
        }
        true
    }

    /// The class of `e` by the size of its fan.
    ///
    /// # Panics
    /// If `e` is not in the store.
    pub fn classify_edge(&self, e: EdgeKey) -> EdgeClass {
        match self.fan(e).len() {
            0 => EdgeClass::Wire,
            1 => EdgeClass::Boundary,
            2 => EdgeClass::Manifold,
            _ => EdgeClass::NonManifold,
        }
    }

    /// The class of `v`; see [`VertexClass`] for the exact definitions. Walks the faces
    /// around `v` once, without allocating.
    ///
    /// # Panics
    /// If `v` is not in the store.
    pub fn classify_vertex(&self, v: VertexKey) -> VertexClass {
        let star = &self.vertices[v].star;
        if star.is_empty() {
            return VertexClass::Isolated;
        }
        let mut face_count = 0usize; // each face at v is in exactly two star fans
        let mut border = None;
        let mut border_count = 0usize;
        for &e in star {
            match self.fan(e).len() {
                1 => {
                    border_count += 1;
                    border = Some(e);
                }
                2 => {}
                _ => return VertexClass::NonManifold,
            }
            face_count += self.fan(e).len();
        }
        face_count /= 2;
        // Walk one fan from its start: a border edge if there is one, else any edge.
        let (start, class) = match (border_count, border) {
            (0, _) => (star[0], VertexClass::Interior),
            (2, Some(b)) => (b, VertexClass::Boundary),
            _ => return VertexClass::NonManifold,
        };
        // The fan is a path (from one border edge to the other) or a cycle (back to
        // `start`); it is the only fan exactly when it visits every face at v.
        let mut visited = 0usize;
        let mut edge = start;
        let mut face = self.fan(start)[0];
        loop {
            visited += 1;
            let Some(next_edge) = self.other_edge_at(face, edge, v) else {
                return VertexClass::NonManifold;
            };
            let fan = self.fan(next_edge);
            if next_edge == start || fan.len() < 2 {
                break;
            }
            face = if fan[0] == face { fan[1] } else { fan[0] };
            edge = next_edge;
            if visited > face_count {
                // Cannot happen in a valid store; guards against an endless loop.
                return VertexClass::NonManifold;
            }
        }
        if visited == face_count {
            class
        } else {
            VertexClass::NonManifold
        }
    }

    /// The edge of face `f` that contains `v` and is not `e`.
    fn other_edge_at(&self, f: FaceKey, e: EdgeKey, v: VertexKey) -> Option<EdgeKey> {
        let face = &self.faces[f];
        let slot = face.slot_of(v)?;
        // The two edges at vertices[slot] are edges[slot] and edges[slot + 2].
        let (first, second) = (face.edges[slot].key(), face.edges[(slot + 2) % 3].key());
        if first == e {
            Some(second)
        } else if second == e {
            Some(first)
        } else {
            None
        }
    }

    /// Labels the connected components, where two vertices are connected when an edge
    /// (wire edges included) joins them; faces connect their vertices through their
    /// edges. Labels are `0..component_count()`, numbered in slotmap order of each
    /// component's first vertex. Isolated vertices belong to no component and are absent
    /// from the map.
    ///
    /// Allocates; meant for reports and tests, not for the contraction loop.
    pub fn component_labels(&self) -> SecondaryMap<VertexKey, u32> {
        let mut labels = SecondaryMap::with_capacity(self.vertices.len());
        let mut stack = Vec::new();
        let mut next = 0u32;
        for (seed, vertex) in &self.vertices {
            if vertex.star.is_empty() || labels.contains_key(seed) {
                continue;
            }
            labels.insert(seed, next);
            stack.push(seed);
            while let Some(v) = stack.pop() {
                for &e in &self.vertices[v].star {
                    if let Some(x) = self.other_vertex(e, v) {
                        if !labels.contains_key(x) {
                            labels.insert(x, next);
                            stack.push(x);
                        }
                    }
                }
            }
            next += 1;
        }
        labels
    }

    /// Number of connected components (see [`component_labels`](Self::component_labels));
    /// isolated vertices do not count.
    pub fn component_count(&self) -> usize {
        self.component_labels()
            .values()
            .max()
            .map_or(0, |&m| m as usize + 1)
    }
}
