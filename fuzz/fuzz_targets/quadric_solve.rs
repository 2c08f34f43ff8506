//! Placement of arbitrary quadrics: finite in, finite out, never above the fallback.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| qem_tests::fuzz_checks::quadric_solve(data));
