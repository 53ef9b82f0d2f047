//! libFuzzer target `page`: see `nanohaptics_fuzz::libfuzzer::page` and docs/fuzzing.md.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    nanohaptics_fuzz::libfuzzer::page(data);
});
