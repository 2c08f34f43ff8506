//! The non-manifold adjacency store: vertices, edges with a radial fan of faces, and
//! faces, on `slotmap` keys.
//!
//! [`MeshStore`] is the only code in qem that mutates adjacency. It represents any
//! triangle complex, not just 2-manifolds:
//!
//! - a **vertex** holds its position and its *star*: every edge that has it as an endpoint;
//! - an **edge** holds its two endpoints (in a canonical order: smaller key first) and its
//!   *fan*: every face that contains both endpoints. A fan may have 0 faces (a *wire*
//!   edge, left behind by a contraction), 1 (boundary), 2 (manifold) or 3 and more (a
//!   non-manifold *fin*);
//! - a **face** holds its three vertices, in the orientation of the input, and its three
//!   edges, where `face_edges(f)[i]` joins `face_vertices(f)[i]` and
//!   `face_vertices(f)[(i + 1) % 3]`.
//!
//! Invariants, all checked by [`MeshStore::validate`]: adjacency is symmetric (a face is
//! in the fan of each of its edges, an edge in the star of both its endpoints, exactly
//! once each); no two edges join the same pair of vertices; no face repeats a vertex; no
//! two faces have the same set of vertices.
//!
//! Submodules, one job each: `build` (from an [`IndexedMesh`](crate::IndexedMesh)),
//! `query` (adjacency, links, classes, components), `contract` (edge and virtual-pair
//! contraction), `validate` (the invariant check), `compact` (back to an
//! [`IndexedMesh`](crate::IndexedMesh)).
//!
//! ```
//! use qem_mesh::{IndexedMesh, MeshStore, EdgeClass, VertexClass};
//!
//! // Two triangles sharing the edge 1-2, a square split along its diagonal.
//! let mesh = IndexedMesh::new(
//!     vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
//!     vec![[0, 1, 2], [2, 1, 3]],
//! );
//! let (store, keys) = MeshStore::from_mesh(&mesh)?;
//! assert_eq!((store.vertex_count(), store.edge_count(), store.face_count()), (4, 5, 2));
//! let diagonal = store.find_edge(keys[1], keys[2]).expect("the shared edge exists");
//! assert_eq!(store.classify_edge(diagonal), EdgeClass::Manifold);
//! assert_eq!(store.classify_vertex(keys[0]), VertexClass::Boundary);
//! store.validate()?;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use slotmap::SlotMap;
use smallvec::SmallVec;

mod build;
mod compact;
mod contract;
mod query;
mod validate;

pub use build::BuildStats;
pub use contract::{ContractError, ContractLog, ContractOutcome};
pub use query::{EdgeClass, VertexClass};
pub use validate::StoreError;

slotmap::new_key_type! {
    /// Key of a vertex in a [`MeshStore`]. Stays valid until the vertex is removed by a
    /// contraction; a removed key is never reused for another vertex.
    pub struct VertexKey;
    /// Key of an edge in a [`MeshStore`].
    pub struct EdgeKey;
    /// Key of a face in a [`MeshStore`].
    pub struct FaceKey;
}

/// A vertex: where it is and which edges touch it.
#[derive(Clone, Debug)]
struct Vertex {
    position: [f64; 3],
    /// Every edge with this vertex as an endpoint, each once. Eight inline covers the
    /// typical valence of a triangle mesh (six) without spilling to the heap.
    star: SmallVec<[EdgeKey; 8]>,
}

/// An edge: its endpoints and the radial fan of faces around it.
#[derive(Clone, Debug)]
struct Edge {
    /// Endpoints with `vertices[0] < vertices[1]`, so that an edge has one spelling.
    vertices: [VertexKey; 2],
    /// Every face containing both endpoints, each once. Two inline: a manifold edge
    /// never spills, a fin does.
    fan: SmallVec<[FaceKey; 2]>,
}

/// A face: three distinct vertices in input orientation and the edges between them.
#[derive(Clone, Copy, Debug)]
struct Face {
    vertices: [VertexKey; 3],
    /// `edges[i]` joins `vertices[i]` and `vertices[(i + 1) % 3]`.
    edges: [EdgeKey; 3],
}

/// Buffers reused by [`MeshStore::contract`] so that it does not allocate once they have
/// grown to the largest neighbourhood seen.
#[derive(Clone, Debug, Default)]
struct Scratch {
    faces: Vec<FaceKey>,
    edges: Vec<EdgeKey>,
    /// The neighbours of the kept vertex and the edge to each.
    links: Vec<(VertexKey, EdgeKey)>,
}

/// A radial-edge adjacency store for arbitrary triangle complexes.
///
/// Built from an [`IndexedMesh`](crate::IndexedMesh) with [`MeshStore::from_mesh`],
/// simplified with [`MeshStore::contract`], written back with [`MeshStore::to_mesh`].
/// See the [module documentation](self) for the data model and its invariants.
///
/// Accessors that take a key (`position`, `star`, `fan`, ...) panic if the key is not in
/// the store, like indexing a `SlotMap`; use `contains_vertex` and friends when a key
/// may be stale. [`contract`](MeshStore::contract) never panics: it reports bad keys as
/// errors.
///
/// Everything is deterministic: the same input and the same sequence of operations give
/// the same keys, the same iteration order and the same output, bit for bit.
#[derive(Clone, Debug, Default)]
pub struct MeshStore {
    vertices: SlotMap<VertexKey, Vertex>,
    edges: SlotMap<EdgeKey, Edge>,
    faces: SlotMap<FaceKey, Face>,
    build_stats: BuildStats,
    scratch: Scratch,
}

/// Returns `[a, b]` sorted, the canonical spelling of an edge.
fn ordered(a: VertexKey, b: VertexKey) -> [VertexKey; 2] {
    if a < b {
        [a, b]
    } else {
        [b, a]
    }
}

/// Removes the first occurrence of `item` from `list`, keeping the order of the rest
/// (so that iteration order stays a function of the operation sequence alone).
/// Returns whether it was present.
fn remove_item<T: PartialEq, const N: usize>(list: &mut SmallVec<[T; N]>, item: &T) -> bool {
    match list.iter().position(|x| x == item) {
        Some(i) => {
            list.remove(i);
            true
        }
        None => false,
    }
}
