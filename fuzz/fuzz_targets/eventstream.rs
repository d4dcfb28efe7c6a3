#![no_main]
//! Fuzz target: the Event Stream (DVS) reader.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::read_with_header(b"Event Stream\x02\x00\x00\x01\x40\x01\xf0\x00", data, "es");
});
