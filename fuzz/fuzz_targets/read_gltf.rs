//! Arbitrary bytes as glTF (`.glb` when they start with `glTF`, else `.gltf` JSON): a valid
//! mesh (that survives a write and re-read with its attributes) or a one-line error.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| qem_tests::fuzz_checks::read_gltf(data));
