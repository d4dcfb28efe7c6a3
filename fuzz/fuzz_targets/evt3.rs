#![no_main]
//! Fuzz target: the evt3 reader.

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::read_with_header(b"% evt 3.0\n% end\n", data, "raw");
});
