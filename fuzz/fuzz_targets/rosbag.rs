#![no_main]
//! Fuzz target: the ROS 1 bag reader (records, chunks, messages).

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::read_with_header(b"#ROSBAG V2.0\n", data, "bag");
});
