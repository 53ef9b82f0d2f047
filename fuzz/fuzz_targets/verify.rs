//! libFuzzer target `verify`: see `nanohaptics_fuzz::libfuzzer::verify` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    nanohaptics_fuzz::libfuzzer::verify(data);
});
