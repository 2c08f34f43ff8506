//! Workspace-level integration tests, gathered into one test binary. Each module is a
//! former `tests/tests/<name>.rs`.
//!
//! proptest keeps its regression seeds for `suite/<name>.rs` in
//! `../proptest-regressions/<name>.txt` (its default: beside the directory holding
//! `main.rs`).

mod fuzz_findings;
mod fuzz_replay;
mod grid_pairs;
mod store_model;
