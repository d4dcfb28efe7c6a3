#![no_main]
//! Fuzz target: the aedat4 reader.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::read_with_header(b"#!AER-DAT4.0\r\n", data, "aedat4");
});
