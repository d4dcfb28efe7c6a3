#![no_main]
//! Fuzz target: the text reader.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::read_with_header(b"# t x y p\n", data, "txt");
});
