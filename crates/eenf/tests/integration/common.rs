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

/// The 24 continuous hours of one day of real mains (`enf-reference` and `mains-day`), in
/// time order.
pub fn day_wavs() -> Vec<PathBuf> {
    let mut paths: Vec<PathBuf> = ["enf-reference", "mains-day"]
        .iter()
        .flat_map(|sub| {
            let dir = shared(sub).join(sub);
            std::fs::read_dir(dir)
                .unwrap()
                .map(|e| e.unwrap().path())
                .filter(|p| p.extension().is_some_and(|e| e == "wav"))
                .collect::<Vec<_>>()
        })
        .collect();
    paths.sort_by_key(|p| p.file_name().map(|n| n.to_owned()));
    assert_eq!(paths.len(), 24, "the day's 24 hours");
    paths
}

/// `n` clips scaled by `EENF_EDITS_SCALE` (default 1), at least one.
pub fn scale_clips(n: usize) -> usize {
    let k: f64 = std::env::var("EENF_EDITS_SCALE")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1.0);
    ((n as f64 * k).round() as usize).max(1)
}
