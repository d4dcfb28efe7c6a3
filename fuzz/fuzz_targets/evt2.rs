#![no_main]
//! Fuzz target: the evt2 reader.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::read_with_header(b"% evt 2.0\n% end\n", data, "raw");
});
