//! Topology and the simplification algorithm of qem.
//!
//! - [`IndexedMesh`]: the plain input and output type, with validation.
//! - [`MeshStore`]: the non-manifold adjacency store that contractions mutate.
//! - `io` (feature `io`): readers and writers for OBJ, PLY, STL and OFF, with `.gz`.
#![forbid(unsafe_code)]

pub mod input;
#[cfg(feature = "io")]
pub mod io;
pub mod store;

pub use input::{IndexedMesh, InputError, MAX_ELEMENTS};
pub use store::{
    BuildStats, ContractError, ContractOutcome, EdgeClass, EdgeKey, FaceKey, MeshStore, StoreError,
    VertexClass, VertexKey,
};
