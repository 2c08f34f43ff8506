//! Topology and the simplification algorithm of qem.
//!
//! - [`IndexedMesh`]: the plain input and output type, with validation.
//! - `io` (feature `io`): readers and writers for OBJ, PLY, STL and OFF, with `.gz`.
#![forbid(unsafe_code)]

pub mod input;
#[cfg(feature = "io")]
pub mod io;

pub use input::{IndexedMesh, InputError, MAX_ELEMENTS};
