//! Topology and the simplification algorithm of qem.
//!
//! - [`IndexedMesh`]: the plain input and output type, with validation.
//! - `io` (feature `io`): readers and writers for OBJ, PLY, STL and OFF, with `.gz`.
#![forbid(unsafe_code)]
// Tests may unwrap: a panic there is the failure report.
#![cfg_attr(test, allow(clippy::unwrap_used))]

pub mod input;
#[cfg(feature = "io")]
pub mod io;

pub use input::{IndexedMesh, InputError, MAX_ELEMENTS};
