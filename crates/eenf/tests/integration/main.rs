//! The tests of `eenf`, in one test binary: the library's own tests live here rather than in
//! `#[cfg(test)]` modules, so that `cargo test` links the library built for the demo instead
//! of compiling it a second time in test mode.

mod clock_off_events;
mod common;

mod audio_harmonics;
mod edits_events;
mod shared_edits;
mod shared_edits_null;
mod shared_edits_real;
mod shared_real_audio;
mod shared_reference;
mod unit_archive;
mod unit_bench_discover;
mod unit_dataset;
mod unit_errors;
mod unit_evaluate;
mod unit_flac_mask;
mod unit_grid;
mod unit_output;
mod unit_progress;
mod unit_refdb;
mod unit_refdb_search;
mod unit_time;
mod unit_trace;
