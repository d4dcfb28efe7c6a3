#![no_main]
//! Fuzz target: the rosbag2 MCAP reader (records, chunks, summary, CDR messages).

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::read_with_header(b"\x89MCAP0\r\n", data, "mcap");
});
