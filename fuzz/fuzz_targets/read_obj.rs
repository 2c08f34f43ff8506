//! Arbitrary bytes as OBJ: a valid mesh (that survives a write and re-read) or a one-line error.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| qem_tests::fuzz_checks::read_obj(data));
