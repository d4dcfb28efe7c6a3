//! A search of a store checks its values as it reads them (once), and answers as a search
//! that checked them all first.

use eenf::refdb::*;
use eenf_dsp::matching::{match_trace, MatchOptions, MatchResult, ReferenceValues};

/// A grid over 1.5 stretches with a gap inside: three parts, each with its sums.
fn store(d: &std::path::Path) -> Vec<f64> {
    let n = PART_VALUES + PART_VALUES / 2;
    // a random walk held near 50 Hz, like a grid's one-second means
    let (mut x, mut state) = (0.0f64, 0x9e37_79b9_7f4a_7c15u64);
    let mut hz: Vec<f64> = (0..n)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            x = 0.999 * x + ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 4e-3;
            50.0 + (x * 1e6).round() * 1e-6
        })
        .collect();
    for v in &mut hz[PART_VALUES - 500..PART_VALUES + 500] {
        *v = f64::NAN;
    }
    let mut s = GridEdit::new(d, "DE", eenf_core::Grid::Hz50, 1.0, 0.0);
    s.merge(0.0, 1.0, &hz).unwrap();
    s.commit().unwrap();
    hz
}

fn search(d: &std::path::Path, clip: &[f64]) -> Result<MatchResult, String> {
    let g = GridValues::open_for_search(d, "DE").map_err(|e| e.to_string())?;
    match_trace(clip, &g, &MatchOptions::default()).map_err(|e| e.to_string())
}

/// The manifest's parts, to change by hand.
fn edit_manifest(d: &std::path::Path, change: impl Fn(&mut serde_json::Value)) {
    let path = d.join("DE.json");
    let mut meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    for p in meta["parts"].as_array_mut().unwrap() {
        change(p);
    }
    std::fs::write(&path, serde_json::to_string(&meta).unwrap()).unwrap();
}

#[test]
fn a_search_checks_the_values_it_reads_and_answers_as_one_that_checked_first() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let hz = store(d);
    let meta = StoredGrid::load_meta(d, "DE").unwrap();
    let parts = meta.parts_listed();
    assert_eq!(parts.len(), 2, "{parts:?}");
    assert!(parts
        .iter()
        .all(|p| p.finite.is_some() && p.sum_uhz.is_some()));
    let at = 4_000_123;
    let clip = &hz[at..at + 300];
    let deferred = search(d, clip).unwrap();
    assert_eq!(deferred.candidates[0].offset.round() as usize, at);
    // the same store without the sums (as written before them): checked before the search
    let with_sums = std::fs::read(d.join("DE.json")).unwrap();
    edit_manifest(d, |p| {
        let p = p.as_object_mut().unwrap();
        p.remove("finite");
        p.remove("sum_uhz");
    });
    let first = search(d, clip).unwrap();
    assert_eq!(
        serde_json::to_string(&deferred).unwrap(),
        serde_json::to_string(&first).unwrap()
    );
    // the mean from the sums is the mean read from the values
    std::fs::write(d.join("DE.json"), &with_sums).unwrap();
    let g = GridValues::open_for_search(d, "DE").unwrap();
    let read = GridValues::open(d, "DE").unwrap().finite_mean().unwrap();
    assert_eq!(g.finite_mean().unwrap(), read);

    // a flipped bit in the second part: the search reads it and fails, naming the file
    let file = d.join(&parts[1].file);
    let mut bytes = std::fs::read(&file).unwrap();
    bytes[4 * 1000] ^= 0x04;
    std::fs::write(&file, &bytes).unwrap();
    let e = search(d, clip).unwrap_err();
    assert!(e.contains("checksum") && e.contains(&parts[1].file), "{e}");
    // and any read before a search checks first
    let g = GridValues::open_for_search(d, "DE").unwrap();
    let e = g.window(10, 5).unwrap_err().to_string();
    assert!(e.contains("checksum"), "{e}");
    bytes[4 * 1000] ^= 0x04;
    std::fs::write(&file, &bytes).unwrap();
    assert!(search(d, clip).is_ok());

    // sums in the manifest that are not the values' are damage too
    edit_manifest(d, |p| {
        let s = p["sum_uhz"].as_i64().unwrap();
        p["sum_uhz"] = (s + 1).into();
    });
    let e = search(d, clip).unwrap_err();
    assert!(e.contains("sums"), "{e}");
    // and sums no count of values could give are not believed: the values are read first
    std::fs::write(d.join("DE.json"), &with_sums).unwrap();
    edit_manifest(d, |p| {
        let n = p["count"].as_u64().unwrap();
        p["finite"] = (n + 1).into();
    });
    let e = GridValues::open_for_search(d, "DE")
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("sums"), "{e}");
}
