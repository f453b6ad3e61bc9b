//! Fuzz target: arbitrary bytes as a scene file, audited by
//! `ballpit::sim::scene::audit_scene_text` (never a panic; what parses writes back the same;
//! what builds is finite, inside its arena and free of overlaps). Any input that fails is a
//! crash; keep it in `fuzz/regressions/`, which `cargo test` replays.
//!
//! Run with `cargo +nightly fuzz run scene fuzz/corpus/scene assets/scenes` (see the README).

#![no_main]

use ballpit::sim::scene::audit_scene_text;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data)
        && let Err(failure) = audit_scene_text(text)
    {
        panic!("{failure}");
    }
});
