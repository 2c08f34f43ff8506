//! Topology and the simplification algorithm of qem.
//!
//! - [`IndexedMesh`]: the plain input and output type, with validation.
//! - [`attributes`]: texture coordinates, normals, colours per corner; materials and
//!   groups per face.
//! - [`clean`]: weld, drop degenerate and duplicate faces, with counts.
//! - [`MeshStore`]: the non-manifold adjacency store that contractions mutate.
//! - [`pairs`]: virtual pairs (close vertices that share no edge) from a uniform grid.
//! - [`simplify`]: the Garland–Heckbert contraction loop, its options and report.
//! - [`cluster`]: vertex clustering on a grid (fast, any input, topology not kept).
//! - [`tiles`]: a mesh cut into spatial tiles with their borders found, and tiles welded
//!   back together (the geometry of `qem tiles`).
//! - `io` (feature `io`): readers and writers for OBJ, PLY, STL, OFF and glTF
//!   (`.gltf`, `.glb`), with `.gz`.
#![forbid(unsafe_code)]

pub mod attributes;
pub mod clean;
pub mod cluster;
pub mod input;
pub mod inspect;
#[cfg(feature = "io")]
pub mod io;
pub mod measure;
pub mod pairs;
pub mod simplify;
pub mod store;
pub mod tiles;

pub use input::{IndexedMesh, InputError, MAX_ELEMENTS};
pub use store::{
    BuildStats, ContractError, ContractOutcome, EdgeClass, EdgeKey, FaceKey, MeshStore, StoreError,
    VertexClass, VertexKey,
};
