//! libFuzzer target `script`: see `nanohaptics_fuzz::libfuzzer::script` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    nanohaptics_fuzz::libfuzzer::script(data);
});
