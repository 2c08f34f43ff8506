//! Small soups and options through the simplifier: valid, deterministic output.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| qem_tests::fuzz_checks::simplify_soup(data));
