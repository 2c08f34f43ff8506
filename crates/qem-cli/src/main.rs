//! The `qem` command.
#![forbid(unsafe_code)]
fn main() {}
