//! The brute-force model of `MeshStore`: a plain triangle soup plus an explicit edge
//! set (for wire edges), over input vertex ids. [`run`] applies a sequence of
//! operations to both a store and the model and, after every step, compares every query
//! of the store with the same quantity recomputed from the model by brute force.
//!
//! Used by the `store_model` property test and the `store_ops` fuzz target, so the two
//! check the same thing.

use std::collections::BTreeSet;

use qem_mesh::{ContractError, EdgeClass, IndexedMesh, MeshStore, VertexClass, VertexKey};

/// The brute-force model, over input vertex ids.
#[derive(Clone, Debug)]
struct Model {
    live: Vec<bool>,
    positions: Vec<[f64; 3]>,
    /// Oriented faces, no repeated vertex, no two with the same vertex set.
    faces: Vec<[u32; 3]>,
    /// Every edge, `(low, high)`; wire edges (no face) included.
    edges: BTreeSet<(u32, u32)>,
}

/// What the model expects `contract` to report.
#[derive(Debug, Default, PartialEq)]
struct Expected {
    faces_collapsed: usize,
    faces_merged: usize,
    edge_collapsed: bool,
    edges_merged: usize,
}

fn set_of(t: [u32; 3]) -> [u32; 3] {
    let mut s = t;
    s.sort_unstable();
    s
}

fn pair(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Rotates a face to start at its smallest id, keeping orientation.
fn canonical(t: [u32; 3]) -> [u32; 3] {
    let mut t = t;
    while t[0] > t[1] || t[0] > t[2] {
        t.rotate_left(1);
    }
    t
}

impl Model {
    fn new(mesh: &IndexedMesh) -> Self {
        let mut faces: Vec<[u32; 3]> = Vec::new();
        for &t in &mesh.triangles {
            let s = set_of(t);
            let degenerate = s[0] == s[1] || s[1] == s[2];
            if !degenerate && !faces.iter().any(|&f| set_of(f) == s) {
                faces.push(t);
            }
        }
        let mut edges = BTreeSet::new();
        for f in &faces {
            for i in 0..3 {
                edges.insert(pair(f[i], f[(i + 1) % 3]));
            }
        }
        Model {
            live: vec![true; mesh.positions.len()],
            positions: mesh.positions.clone(),
            faces,
            edges,
        }
    }

    /// The contraction semantics, stated over the soup: drop faces with both a and b;
    /// substitute a for b; a substituted face whose vertex set already exists among the
    /// faces that never contained b is dropped (first one wins among the rest).
    fn contract(&mut self, a: u32, b: u32, p: [f64; 3]) -> Expected {
        let mut ex = Expected::default();
        let has = |f: &[u32; 3], v: u32| f.contains(&v);
        ex.faces_collapsed = self.faces.iter().filter(|f| has(f, a) && has(f, b)).count();
        let survivors: Vec<[u32; 3]> = self
            .faces
            .iter()
            .copied()
            .filter(|f| !(has(f, a) && has(f, b)))
            .collect();
        let mut faces: Vec<[u32; 3]> = survivors.iter().copied().filter(|f| !has(f, b)).collect();
        for f in survivors.iter().filter(|f| has(f, b)) {
            let g = f.map(|v| if v == b { a } else { v });
            if faces.iter().any(|&h| set_of(h) == set_of(g)) {
                ex.faces_merged += 1;
            } else {
                faces.push(g);
            }
        }
        self.faces = faces;

        ex.edge_collapsed = self.edges.contains(&pair(a, b));
        let mut edges = BTreeSet::new();
        for &(x, y) in &self.edges {
            if pair(x, y) == pair(a, b) {
                continue;
            }
            let (x, y) = (if x == b { a } else { x }, if y == b { a } else { y });
            if !edges.insert(pair(x, y)) {
                ex.edges_merged += 1;
            }
        }
        self.edges = edges;
        self.live[b as usize] = false;
        self.positions[a as usize] = p;
        ex
    }

    fn fan_size(&self, (x, y): (u32, u32)) -> usize {
        self.faces
            .iter()
            .filter(|f| f.contains(&x) && f.contains(&y))
            .count()
    }

    fn edge_class(&self, e: (u32, u32)) -> EdgeClass {
        match self.fan_size(e) {
            0 => EdgeClass::Wire,
            1 => EdgeClass::Boundary,
            2 => EdgeClass::Manifold,
            _ => EdgeClass::NonManifold,
        }
    }

    /// Vertex class by union-find over the faces at v (a different method from the
    /// store's walk around the fan).
    fn vertex_class(&self, v: u32) -> VertexClass {
        let edges: Vec<(u32, u32)> = self
            .edges
            .iter()
            .copied()
            .filter(|&(x, y)| x == v || y == v)
            .collect();
        if edges.is_empty() {
            return VertexClass::Isolated;
        }
        let mut border = 0;
        for &e in &edges {
            match self.fan_size(e) {
                1 => border += 1,
                2 => {}
                _ => return VertexClass::NonManifold,
            }
        }
        let at_v: Vec<[u32; 3]> = self
            .faces
            .iter()
            .copied()
            .filter(|f| f.contains(&v))
            .collect();
        let mut parent: Vec<usize> = (0..at_v.len()).collect();
        for i in 0..at_v.len() {
            for j in 0..i {
                let shared = at_v[i].iter().filter(|x| at_v[j].contains(x)).count();
                if shared == 2 {
                    let (ri, rj) = (find(&mut parent, i), find(&mut parent, j));
                    parent[ri] = rj;
                }
            }
        }
        let fans = (0..at_v.len())
            .filter(|&i| find(&mut parent, i) == i)
            .count();
        match (fans, border) {
            (1, 0) => VertexClass::Interior,
            (1, 2) => VertexClass::Boundary,
            _ => VertexClass::NonManifold,
        }
    }

    /// Component root of every id (isolated and dead ids are their own roots).
    fn component_roots(&self) -> Vec<usize> {
        let mut parent: Vec<usize> = (0..self.live.len()).collect();
        for &(x, y) in &self.edges {
            let (rx, ry) = (find(&mut parent, x as usize), find(&mut parent, y as usize));
            parent[rx] = ry;
        }
        (0..self.live.len()).map(|i| find(&mut parent, i)).collect()
    }

    fn component_count(&self) -> usize {
        let roots = self.component_roots();
        let mut used: BTreeSet<usize> = BTreeSet::new();
        for &(x, _) in &self.edges {
            used.insert(roots[x as usize]);
        }
        used.len()
    }

    /// Lk a ∩ Lk b = Lk ab, over explicit sets.
    fn link_condition(&self, a: u32, b: u32) -> bool {
        let neighbours = |v: u32| -> BTreeSet<u32> {
            self.edges
                .iter()
                .filter_map(|&(x, y)| (x == v).then_some(y).or((y == v).then_some(x)))
                .collect()
        };
        let link_edges = |v: u32| -> BTreeSet<(u32, u32)> {
            self.faces
                .iter()
                .filter(|f| f.contains(&v))
                .map(|f| {
                    let rest: Vec<u32> = f.iter().copied().filter(|&x| x != v).collect();
                    pair(rest[0], rest[1])
                })
                .collect()
        };
        let lk_ab: BTreeSet<u32> = if self.edges.contains(&pair(a, b)) {
            self.faces
                .iter()
                .filter(|f| f.contains(&a) && f.contains(&b))
                .flat_map(|f| f.iter().copied().filter(|&x| x != a && x != b))
                .collect()
        } else {
            BTreeSet::new()
        };
        let common: BTreeSet<u32> = neighbours(a)
            .intersection(&neighbours(b))
            .copied()
            .collect();
        common == lk_ab && link_edges(a).intersection(&link_edges(b)).next().is_none()
    }

    fn sorted_faces(&self) -> Vec<[u32; 3]> {
        let mut out: Vec<_> = self.faces.iter().map(|&f| canonical(f)).collect();
        out.sort_unstable();
        out
    }
}

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// The store side, with key-to-id translation.
struct Subject {
    store: MeshStore,
    keys: Vec<VertexKey>,
}

impl Subject {
    fn id(&self, v: VertexKey) -> u32 {
        self.keys
            .iter()
            .position(|&k| k == v)
            .expect("every key comes from from_mesh") as u32
    }

    fn ids<const N: usize>(&self, vs: [VertexKey; N]) -> [u32; N] {
        vs.map(|v| self.id(v))
    }
}

/// Compares every query of the store with the model.
fn check(s: &Subject, m: &Model) {
    let store = &s.store;
    if let Err(e) = store.validate() {
        panic!("validate failed: {e}");
    }

    // Vertices and positions.
    let live: Vec<u32> = (0..m.live.len() as u32)
        .filter(|&i| m.live[i as usize])
        .collect();
    let mut store_vertices: Vec<u32> = store.vertices().map(|v| s.id(v)).collect();
    store_vertices.sort_unstable();
    assert_eq!(store_vertices, live, "live vertices");
    assert_eq!(store.vertex_count(), live.len());
    for &i in &live {
        let v = s.keys[i as usize];
        assert!(store.contains_vertex(v));
        assert_eq!(
            store.position(v),
            m.positions[i as usize],
            "position of {i}"
        );
    }
    for (i, &v) in s.keys.iter().enumerate() {
        assert_eq!(store.contains_vertex(v), m.live[i]);
    }

    // Faces, orientation included.
    let mut faces: Vec<[u32; 3]> = store
        .faces()
        .map(|f| canonical(s.ids(store.face_vertices(f))))
        .collect();
    faces.sort_unstable();
    assert_eq!(faces, m.sorted_faces(), "faces");
    assert_eq!(store.face_count(), m.faces.len());

    // Edges, fans and edge classes.
    let mut edges: Vec<(u32, u32)> = store
        .edges()
        .map(|e| {
            let [x, y] = s.ids(store.edge_vertices(e));
            pair(x, y)
        })
        .collect();
    edges.sort_unstable();
    assert_eq!(edges, m.edges.iter().copied().collect::<Vec<_>>(), "edges");
    assert_eq!(store.edge_count(), m.edges.len());
    let mut link = Vec::new();
    for e in store.edges() {
        let [x, y] = s.ids(store.edge_vertices(e));
        assert_eq!(store.fan(e).len(), m.fan_size((x, y)), "fan of {x}-{y}");
        assert_eq!(
            store.classify_edge(e),
            m.edge_class((x, y)),
            "class of {x}-{y}"
        );
        store.edge_link(e, &mut link);
        let mut got: Vec<u32> = link.iter().map(|&v| s.id(v)).collect();
        got.sort_unstable();
        let mut want: Vec<u32> = m
            .faces
            .iter()
            .filter(|f| f.contains(&x) && f.contains(&y))
            .filter_map(|f| f.iter().copied().find(|&z| z != x && z != y))
            .collect();
        want.sort_unstable();
        assert_eq!(got, want, "link of edge {x}-{y}");
    }

    // Per-vertex adjacency, links and classes.
    let mut around = Vec::new();
    let mut link_vertices = Vec::new();
    let mut link_edges = Vec::new();
    for &i in &live {
        let v = s.keys[i as usize];
        let mut star: Vec<(u32, u32)> = store
            .star(v)
            .iter()
            .map(|&e| {
                let [x, y] = s.ids(store.edge_vertices(e));
                pair(x, y)
            })
            .collect();
        star.sort_unstable();
        let want_star: Vec<(u32, u32)> = m
            .edges
            .iter()
            .copied()
            .filter(|&(x, y)| x == i || y == i)
            .collect();
        assert_eq!(star, want_star, "star of {i}");

        store.faces_of_vertex(v, &mut around);
        let mut got: Vec<[u32; 3]> = around
            .iter()
            .map(|&f| canonical(s.ids(store.face_vertices(f))))
            .collect();
        got.sort_unstable();
        let mut want: Vec<[u32; 3]> = m
            .faces
            .iter()
            .filter(|f| f.contains(&i))
            .map(|&f| canonical(f))
            .collect();
        want.sort_unstable();
        assert_eq!(got, want, "faces of vertex {i}");

        store.vertex_link(v, &mut link_vertices, &mut link_edges);
        let mut got_lv: Vec<u32> = link_vertices.iter().map(|&x| s.id(x)).collect();
        got_lv.sort_unstable();
        let mut want_lv: Vec<u32> = want_star
            .iter()
            .map(|&(x, y)| if x == i { y } else { x })
            .collect();
        want_lv.sort_unstable();
        assert_eq!(got_lv, want_lv, "link vertices of {i}");
        let mut got_le: Vec<[u32; 2]> = link_edges.iter().map(|&e| s.ids(e)).collect();
        got_le.sort_unstable();
        let mut want_le: Vec<[u32; 2]> = want
            .iter()
            .map(|f| {
                let k = f.iter().position(|&x| x == i).unwrap_or(0);
                [f[(k + 1) % 3], f[(k + 2) % 3]]
            })
            .collect();
        want_le.sort_unstable();
        assert_eq!(got_le, want_le, "link edges of {i}");

        assert_eq!(
            store.classify_vertex(v),
            m.vertex_class(i),
            "class of vertex {i}"
        );
    }

    // Components: same count and same partition.
    assert_eq!(
        store.component_count(),
        m.component_count(),
        "component count"
    );
    let labels = store.component_labels();
    let roots = m.component_roots();
    for &i in &live {
        for &j in &live {
            let (vi, vj) = (s.keys[i as usize], s.keys[j as usize]);
            match (labels.get(vi), labels.get(vj)) {
                (Some(li), Some(lj)) => {
                    assert_eq!(
                        li == lj,
                        roots[i as usize] == roots[j as usize],
                        "{i} ~ {j}"
                    )
                }
                (None, _) => assert_eq!(m.vertex_class(i), VertexClass::Isolated),
                (_, None) => assert_eq!(m.vertex_class(j), VertexClass::Isolated),
            }
        }
    }

    // Link condition, for every ordered pair of live vertices.
    for &i in &live {
        for &j in &live {
            if i != j {
                let (vi, vj) = (s.keys[i as usize], s.keys[j as usize]);
                assert_eq!(
                    store.link_condition(vi, vj),
                    m.link_condition(i, j),
                    "link condition of {i} and {j}"
                );
            }
        }
    }

    // Compaction.
    let (out, map) = store.to_mesh_with_map();
    assert_eq!(store.to_mesh(), out);
    let referenced: BTreeSet<u32> = m.faces.iter().flatten().copied().collect();
    let map_ids: Vec<u32> = map.iter().map(|&v| s.id(v)).collect();
    assert_eq!(
        map_ids.len(),
        referenced.len(),
        "output vertices are the referenced ones"
    );
    assert!(map_ids.iter().all(|i| referenced.contains(i)));
    for (k, &i) in map_ids.iter().enumerate() {
        assert_eq!(out.positions[k], m.positions[i as usize]);
    }
    let mut used = vec![false; out.positions.len()];
    let mut tris: Vec<[u32; 3]> = Vec::new();
    for t in &out.triangles {
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[2] != t[0],
            "degenerate output {t:?}"
        );
        for &k in t {
            used[k as usize] = true;
        }
        tris.push(canonical(t.map(|k| map_ids[k as usize])));
    }
    assert!(used.iter().all(|&u| u), "unreferenced output vertex");
    tris.sort_unstable();
    assert_eq!(tris, m.sorted_faces(), "output triangles");
}

/// One step of a sequence applied by [`run`].
#[derive(Clone, Debug)]
pub enum Op {
    /// Contract the `pick`-th edge (in sorted model order, modulo the edge count), into
    /// its smaller or larger id.
    Edge {
        /// Which edge.
        pick: usize,
        /// Keep the larger id instead of the smaller.
        flip: bool,
    },
    /// Contract an arbitrary pair of input ids (modulo the vertex count), which may be
    /// equal or no longer live.
    Pair {
        /// The kept vertex.
        a: usize,
        /// The removed vertex.
        b: usize,
    },
}

/// Runs `ops` on a fresh store and model, checking after every step (panics on the first
/// difference); returns the final output and live keys so determinism can be checked.
///
/// `mesh` must pass [`IndexedMesh::validate`].
pub fn run(mesh: &IndexedMesh, ops: &[Op]) -> (IndexedMesh, Vec<VertexKey>) {
    let (store, keys) = MeshStore::from_mesh(mesh).expect("generated meshes are valid");
    let mut s = Subject { store, keys };
    let mut m = Model::new(mesh);
    check(&s, &m);
    for (step, op) in ops.iter().enumerate() {
        let (a, b) = match *op {
            Op::Edge { pick, flip } => {
                let Some(&(x, y)) = m.edges.iter().nth(pick % m.edges.len().max(1)) else {
                    continue;
                };
                if flip {
                    (y, x)
                } else {
                    (x, y)
                }
            }
            Op::Pair { a, b } => ((a % m.live.len()) as u32, (b % m.live.len()) as u32),
        };
        let p = [step as f64, a as f64 * 0.5, b as f64 * 0.25];
        let (ka, kb) = (s.keys[a as usize], s.keys[b as usize]);
        let got = s.store.contract(ka, kb, p);
        if a == b {
            assert_eq!(got, Err(ContractError::SameVertex(ka)));
        } else if !m.live[a as usize] {
            assert_eq!(got, Err(ContractError::MissingVertex(ka)));
        } else if !m.live[b as usize] {
            assert_eq!(got, Err(ContractError::MissingVertex(kb)));
        } else {
            let outcome = got.expect("a live distinct pair contracts");
            let want = m.contract(a, b, p);
            let have = Expected {
                faces_collapsed: outcome.faces_collapsed,
                faces_merged: outcome.faces_merged,
                edge_collapsed: outcome.edge_collapsed,
                edges_merged: outcome.edges_merged,
            };
            assert_eq!(have, want, "outcome of contracting {b} into {a}");
        }
        check(&s, &m);
    }
    (s.store.to_mesh(), s.store.vertices().collect())
}
