//! Integration tests of qem-mesh, gathered into one test binary (one link of the
//! library instead of one per file). Each module is a former `tests/<name>.rs`; the
//! modules that need the `io` feature are compiled with it only.
//!
//! proptest keeps its regression seeds for `suite/<name>.rs` in
//! `../proptest-regressions/<name>.txt` (its default: beside the directory holding
//! `main.rs`).

mod common;
mod passes_common;

#[cfg(feature = "io")]
mod attributes_common;
#[cfg(feature = "io")]
mod attributes_gltf;
#[cfg(feature = "io")]
mod attributes_obj;
#[cfg(feature = "io")]
mod attributes_ply_off;
mod attributes_simplify;
#[cfg(feature = "io")]
mod budget;
mod bvh_extremes;
mod cluster;
mod exact_quadrics;
#[cfg(feature = "io")]
mod hostile_attributes;
#[cfg(feature = "io")]
mod io_corpus;
#[cfg(feature = "io")]
mod io_errors;
#[cfg(feature = "io")]
mod io_lenient;
#[cfg(feature = "io")]
mod io_streaming;
mod ladder;
mod measure;
mod numeric_extremes;
#[cfg(feature = "io")]
mod orientation;
mod passes;
mod passes_soups;
mod passes_threads;
mod quality_scenarios;
mod simplify_scenarios;
mod simplify_soups;
mod store_scenarios;
mod threads;
mod topology_preservation;
mod weighting;
