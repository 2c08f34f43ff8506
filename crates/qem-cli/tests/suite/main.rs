//! Integration tests of the `qem` command (they run the built binary,
//! `CARGO_BIN_EXE_qem`), gathered into one test binary. Each module is a former
//! `tests/<name>.rs`.
//!
//! proptest keeps its regression seeds for `suite/<name>.rs` in
//! `../proptest-regressions/<name>.txt` (its default: beside the directory holding
//! `main.rs`).

mod common;

mod attributes_cli;
mod batch_cli;
mod hostile_input;
mod info_cli;
mod lods_cli;
mod measure_cli;
mod quality_flags_cli;
mod simplify_cli;
mod soak;
mod tiles_cli;
