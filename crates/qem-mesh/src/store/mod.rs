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
//! [`IndexedMesh`](crate::IndexedMesh)), `fan` (the compact radial fan of an edge),
//! `flip` (an edge flip, in place).
//!
//! Records hold other elements as 32-bit slot indices rather than 64-bit keys where the
//! public API returns them by value (faces, edge endpoints; see `Packed`), and fans of up
//! to two faces in place: the contraction loop's time goes to cache misses on these
//! records, so smaller records are faster. Stars and fans stay slices of keys because
//! [`MeshStore::star`] and [`MeshStore::fan`] lend them out.
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

use std::marker::PhantomData;

use slotmap::{Key, KeyData, SlotMap};
use smallvec::SmallVec;

pub(crate) mod build;
mod compact;
mod contract;
mod fan;
mod flip;
mod query;
mod validate;

pub use build::BuildStats;
pub use contract::{ContractError, ContractLog, ContractOutcome};
use fan::{Fan, FanPool};
pub use flip::FlipError;
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

/// An edge: its endpoints and the radial fan of faces around it. 28 bytes, 32 in its
/// slot: two to a cache line.
#[derive(Clone, Debug)]
struct Edge {
    /// Endpoints with `vertices[0] < vertices[1]`, so that an edge has one spelling;
    /// [`Packed`] to keep the record small (the loop reads many edges per contraction).
    vertices: [Packed<VertexKey>; 2],
    /// Every face containing both endpoints, each once, read through the store's
    /// [`FanPool`]. Two in the record: a manifold edge never spills, a fin does.
    fan: Fan,
}

/// A face: three distinct vertices in input orientation and the edges between them.
///
/// Held as [`Packed`] slot indices: 24 bytes (28 in its slot) instead of 48 (56). Why:
/// the contraction loop reads every face around both ends of each pair, and each face
/// read is a cache miss the first time; half the size puts twice the faces in a line.
#[derive(Clone, Copy, Debug)]
struct Face {
    vertices: [Packed<VertexKey>; 3],
    /// `edges[i]` joins `vertices[i]` and `vertices[(i + 1) % 3]`.
    edges: [Packed<EdgeKey>; 3],
}

impl Edge {
    /// The endpoints as keys, smaller first.
    fn vertex_keys(&self) -> [VertexKey; 2] {
        self.vertices.map(Packed::key)
    }

    /// Whether this edge joins `a` and `b` (either spelling, as `other_vertex` would
    /// see it even in a store whose endpoints are out of order).
    #[inline]
    fn joins(&self, a: Packed<VertexKey>, b: Packed<VertexKey>) -> bool {
        self.vertices == [a, b] || self.vertices == [b, a]
    }
}

impl Face {
    /// The three vertices as keys.
    fn vertex_keys(&self) -> [VertexKey; 3] {
        self.vertices.map(Packed::key)
    }

    /// The three edges as keys.
    fn edge_keys(&self) -> [EdgeKey; 3] {
        self.edges.map(Packed::key)
    }

    /// The slot of `v` among the vertices, if it is one.
    fn slot_of(&self, v: VertexKey) -> Option<usize> {
        self.vertices.iter().position(|x| x.key() == v)
    }

    /// Whether `v` is one of the vertices.
    fn has_vertex(&self, v: VertexKey) -> bool {
        self.vertices.iter().any(|x| x.key() == v)
    }
}

/// A key of this store held as its slot index alone: 4 bytes instead of 8.
///
/// Why this names the key exactly: the store inserts into its slot maps only while
/// [`from_mesh`](MeshStore::from_mesh) builds them, and afterwards only removes, so no
/// slot is ever reused and every key the store holds carries slotmap's first version of
/// an occupied slot, 1. [`key`](Packed::key) rebuilds the key with that version through
/// slotmap's documented `KeyData::from_ffi` (`as_ffi` is `version << 32 | index`).
/// Order and equality are those of the keys (slotmap orders keys by index first, and
/// the versions are all equal).
#[derive(Debug)]
struct Packed<K>(u32, PhantomData<K>);

/// The version slotmap gives a slot the first time it is occupied.
const FIRST_VERSION: u64 = 1;

impl<K: Key> Packed<K> {
    /// Packs `key`, which must carry the first version: every live key of a store does,
    /// so pack only keys known to be live. To compare with a key that may be stale,
    /// compare [`key`](Packed::key) with it instead.
    fn new(key: K) -> Self {
        let ffi = key.data().as_ffi();
        debug_assert_eq!(ffi >> 32, FIRST_VERSION, "a store key with a later version");
        Packed(ffi as u32, PhantomData)
    }

    /// Packs `key` if it carries the first version; `None` otherwise, for a key that no
    /// record of a store can hold (a removed key keeps its first version, and is packed:
    /// no record names its index any more, so comparisons still find it absent).
    fn try_new(key: K) -> Option<Self> {
        let ffi = key.data().as_ffi();
        (ffi >> 32 == FIRST_VERSION).then_some(Packed(ffi as u32, PhantomData))
    }

    /// The key this index names.
    #[inline]
    fn key(self) -> K {
        KeyData::from_ffi(FIRST_VERSION << 32 | u64::from(self.0)).into()
    }
}

// By hand rather than derived: a derive would ask the same of `K`.
impl<K> Clone for Packed<K> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<K> Copy for Packed<K> {}
impl<K> PartialEq for Packed<K> {
    fn eq(&self, other: &Self) -> bool {
        self.0 == other.0
    }
}
impl<K> Eq for Packed<K> {}
impl<K> PartialOrd for Packed<K> {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl<K> Ord for Packed<K> {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.cmp(&other.0)
    }
}

/// Buffers reused by [`MeshStore::contract`] so that it does not allocate once they have
/// grown to the largest neighbourhood seen.
#[derive(Clone, Debug, Default)]
struct Scratch {
    faces: Vec<FaceKey>,
    edges: Vec<EdgeKey>,
    /// The neighbours of the kept vertex and the edge to each.
    links: Vec<(VertexKey, EdgeKey)>,
    /// The fan of an edge being merged into another.
    moved: Vec<FaceKey>,
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
///
/// Elements are inserted only by [`from_mesh`](MeshStore::from_mesh) and only removed
/// afterwards, so no slot is ever reused: the records hold 32-bit slot indices instead
/// of keys on that ground (see `Packed`). An operation that inserts after the build
/// must first give that up.
#[derive(Clone, Debug, Default)]
pub struct MeshStore {
    vertices: SlotMap<VertexKey, Vertex>,
    edges: SlotMap<EdgeKey, Edge>,
    faces: SlotMap<FaceKey, Face>,
    /// The fans of more than two faces.
    fans: FanPool,
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

/// [`ordered`], packed: the endpoints as an edge record holds them.
fn ordered_packed(a: VertexKey, b: VertexKey) -> [Packed<VertexKey>; 2] {
    ordered(a, b).map(Packed::new)
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::IndexedMesh;

    /// The sizes the loop's cache behaviour was measured with (BENCHMARKS.md); a field
    /// added to a record should be a choice, not an accident.
    #[test]
    fn records_keep_their_packed_sizes() {
        assert_eq!(std::mem::size_of::<Face>(), 24);
        assert_eq!(std::mem::size_of::<Edge>(), 28);
        assert_eq!(std::mem::align_of::<Edge>(), 4);
    }

    #[test]
    fn packed_indices_name_the_live_keys_and_no_removed_one() {
        // A closed tetrahedron; contracting 0-1 removes vertex 1, two edges of 1 and
        // three faces.
        let mesh = IndexedMesh::new(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        );
        let (mut store, keys) = MeshStore::from_mesh(&mesh).expect("valid mesh");
        let edges: Vec<EdgeKey> = store.edges().collect();
        store
            .contract(keys[0], keys[1], [0.5, 0.0, 0.0])
            .expect("live pair");
        for v in store.vertices() {
            assert_eq!(Packed::new(v).key(), v);
        }
        for e in store.edges() {
            assert_eq!(Packed::new(e).key(), e);
        }
        // A removed key keeps its version (the slot's version moved on, not the key's),
        // but no record names its index any more, so lookups find nothing.
        assert!(edges.iter().any(|&e| !store.contains_edge(e)));
        assert_eq!(store.find_edge(keys[0], keys[1]), None);
        assert_eq!(store.find_edge(keys[2], keys[1]), None);
        assert_eq!(store.find_face(keys[0], keys[2], keys[1]), None);
        assert!(store.find_face(keys[0], keys[2], keys[3]).is_some());
        // A key with a later version (what slotmap hands out when it reuses a slot,
        // which this store never does) cannot be packed and joins nothing.
        let later: VertexKey =
            KeyData::from_ffi(3 << 32 | (keys[2].data().as_ffi() & 0xffff_ffff)).into();
        assert!(Packed::try_new(later).is_none());
        assert_eq!(store.find_edge(keys[0], later), None);
        store.validate().expect("valid after the contraction");
    }
}
