//! Contraction sequences on the store against the brute-force model.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| qem_tests::fuzz_checks::store_ops(data));
