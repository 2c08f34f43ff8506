//! The virtual-pair grid equals the brute-force rule.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| qem_tests::fuzz_checks::grid_pairs(data));
