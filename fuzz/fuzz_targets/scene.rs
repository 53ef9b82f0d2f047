//! libFuzzer target `scene`: see `nanohaptics_fuzz::libfuzzer::scene` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    nanohaptics_fuzz::libfuzzer::scene(data);
});
