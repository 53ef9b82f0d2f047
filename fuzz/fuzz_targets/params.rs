//! libFuzzer target `params`: see `nanohaptics_fuzz::libfuzzer::params` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    nanohaptics_fuzz::libfuzzer::params(data);
});
