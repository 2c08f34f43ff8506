//! Candidate pairs beyond the mesh's edges.
//!
//! Garland and Heckbert contract not only edges but also *virtual pairs*: vertices
//! closer than a threshold t that share no edge, so that separate parts can merge.
//! [`grid`] finds them with a uniform grid instead of an all-pairs scan.

pub mod grid;

pub use grid::{virtual_pairs, GridOptions, VirtualPairs};
