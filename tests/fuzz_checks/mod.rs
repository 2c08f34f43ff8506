//! The property each fuzz target checks, as plain functions that panic on a violation.
//!
//! A panic is how libFuzzer learns of a bug, and how a replay test fails. Each function
//! takes arbitrary bytes and decodes them with a cursor (`bytes.rs`) that never fails (an
//! exhausted input reads as zeros), so every byte string is a valid test case and the
//! committed corpus files replay through `cargo test` exactly as libFuzzer ran them.

mod bytes;
mod grid_pairs;
mod quadric;
mod readers;
mod simplify_soup;
mod store_ops;

pub use grid_pairs::grid_pairs;
pub use quadric::quadric_solve;
pub use readers::{read_checked, read_gltf, read_obj, read_off, read_ply, read_stl};
pub use simplify_soup::simplify_soup;
pub use store_ops::store_ops;

/// A fuzz check: panics on arbitrary bytes only when the property is violated.
pub type Check = fn(&[u8]);

/// Every fuzz target by name with its check, for the replay test and for tools.
pub const TARGETS: [(&str, Check); 9] = [
    ("quadric_solve", quadric_solve),
    ("simplify_soup", simplify_soup),
    ("store_ops", store_ops),
    ("grid_pairs", grid_pairs),
    ("read_obj", read_obj),
    ("read_ply", read_ply),
    ("read_stl", read_stl),
    ("read_off", read_off),
    ("read_gltf", read_gltf),
];
