//! Workspace-level integration tests for qem; the tests live in `tests/tests/`.
#![forbid(unsafe_code)]
