//! libFuzzer target `recording`: see `nanohaptics_fuzz::libfuzzer::recording` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    nanohaptics_fuzz::libfuzzer::recording(data);
});
