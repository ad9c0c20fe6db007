#![no_main]

// The check lives in the library (`src/fuzz_checks.rs`, built with
// `--cfg fuzzing`), whose tests replay the corpus through the same code
// on stable.
libfuzzer_sys::fuzz_target!(|data: &[u8]| screensaver::fuzz_checks::hypot(data));
