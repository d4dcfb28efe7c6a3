//! The tests of `eenf-events`, in one test binary: the library's own tests live here rather
//! than in `#[cfg(test)]` modules, so that `cargo test` links the library built for the demo
//! instead of compiling it a second time in test mode.

mod aedat4_roundtrip;
mod shared_fixtures;
mod unit_aedat4;
mod unit_aedat4_flatbuf;
mod unit_aedat4_lz4;
mod unit_atis;
mod unit_contain;
mod unit_eventstream;
mod unit_hdf5;
mod unit_hdf5_ecf;
mod unit_memory;
mod unit_rosbag;
mod unit_rosbag2;
mod unit_rosbag2_folder;
mod unit_rosmsg;
mod unit_spool;
mod unit_text;
mod writers_roundtrip;

use eenf_events::{EventBatch, EventReader, Result, StreamInfo};

/// Every event of `r` and what its header said.
pub(crate) fn read_all(mut r: Box<dyn EventReader>) -> Result<(StreamInfo, EventBatch)> {
    let mut all = EventBatch::default();
    while let Some(b) = r.next_batch()? {
        all.extend_from(&b);
    }
    Ok((r.info().clone(), all))
}
