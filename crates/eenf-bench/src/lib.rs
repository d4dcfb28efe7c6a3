//! Criterion benchmarks of the eenf crates, kept in a package of their own (see `Cargo.toml`):
//! `benches/containers.rs` (decoding inside rosbag2 and HDF5), `benches/simulate.rs` (the
//! simulator), `benches/pipeline.rs` (decoding and whole extraction) and `benches/matching.rs`.
//! Run them with `cargo bench -p eenf-bench`; `docs/performance.md` quotes their results.
