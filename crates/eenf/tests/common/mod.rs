//! Helpers shared by the test targets that need `../shared`.
#![allow(dead_code)] // each test target uses only some of the helpers

use std::path::PathBuf;

/// The shared data folder (`EENF_SHARED`, else `../shared` beside the clone). Fails, not skips,
/// when `sub` is not there: these tests only run where the data is meant to be.
pub fn shared(sub: &str) -> PathBuf {
    let dir = std::env::var_os("EENF_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared"));
    assert!(
        dir.join(sub).is_dir(),
        "shared data not found at {} (set EENF_SHARED)",
        dir.display()
    );
    dir
}

/// The shared hourly mains recordings (`enf-reference/*.wav`), sorted by name (= by time).
pub fn reference_wavs() -> Vec<PathBuf> {
    let dir = shared("enf-reference").join("enf-reference");
    let mut wavs: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().map(|e| e == "wav").unwrap_or(false))
        .collect();
    wavs.sort();
    wavs
}
