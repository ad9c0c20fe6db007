#![no_main]

// The check lives in checks.rs so that tests/fuzz_corpus.rs replays the
// corpus through exactly the same code on stable.
#[allow(dead_code)]
#[path = "../checks.rs"]
mod checks;

libfuzzer_sys::fuzz_target!(|data: &[u8]| checks::hypot(data));
