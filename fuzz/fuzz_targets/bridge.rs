//! libFuzzer target `bridge`: see `nanohaptics_fuzz::libfuzzer::bridge` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    nanohaptics_fuzz::libfuzzer::bridge(data);
});
