#![no_main]
//! Fuzz target: the aedat31 reader.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::read_with_header(b"#!AER-DAT3.1\r\n#!END-HEADER\r\n", data, "aedat");
});
