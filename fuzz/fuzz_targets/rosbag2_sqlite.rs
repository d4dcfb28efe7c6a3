#![no_main]
//! Fuzz target: the rosbag2 SQLite reader (what SQLite makes of a damaged database, then the
//! topics and CDR messages).

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::read_with_header(b"SQLite format 3\0", data, "db3");
});
