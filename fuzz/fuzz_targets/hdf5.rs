#![no_main]
//! Fuzz target: the HDF5 reader (superblock, groups, layouts, chunks and their filters).

#[path = "common.rs"]
mod common;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    common::read_with_header(b"\x89HDF\r\n\x1a\n", data, "h5");
});
