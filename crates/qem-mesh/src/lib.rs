//! Topology and the simplification algorithm of qem.
//!
//! - [`IndexedMesh`]: the plain input and output type, with validation.
//! - `io` (feature `io`): readers and writers for OBJ, PLY, STL and OFF.
#![forbid(unsafe_code)]

pub mod input;

pub use input::{IndexedMesh, InputError, MAX_ELEMENTS};
