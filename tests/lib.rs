//! Workspace-level integration tests for qem, and the checks behind the fuzz targets.
//!
//! Every cargo-fuzz target in `fuzz/` is one call into a function of [`fuzz_checks`], so
//! the same checks run in `cargo test` (which replays the committed fuzz corpora and
//! crash reproducers, see `tests/suite/fuzz_replay.rs`) without cargo-fuzz installed.
//!
//! The brute-force references ([`store_model`], [`pair_model`]) live here once and
//! serve both the property tests in `tests/` and the fuzz checks.
#![forbid(unsafe_code)]

pub mod fuzz_checks;
pub mod mesh_checks;
pub mod pair_model;
pub mod store_model;
