//! Integration tests of qem-core, gathered into one test binary (one link of the
//! library instead of one per file). Each module is a former `tests/<name>.rs`.
//!
//! proptest keeps its regression seeds for `suite/<name>.rs` in
//! `../proptest-regressions/<name>.txt` (its default: beside the directory holding
//! `main.rs`).

mod facts;
mod properties;
