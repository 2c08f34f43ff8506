//! Quadric error metric algebra in f64.
#![forbid(unsafe_code)]
