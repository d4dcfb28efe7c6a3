#![no_main]
//! Fuzz target: the dat reader.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::read_with_header(b"% Version 2\n\x00\x08", data, "dat");
});
