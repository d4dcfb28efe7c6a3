//! Tests of eenf's `refdb` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf::refdb::*;
use eenf_dsp::matching::ReferenceValues;

/// The values a grid of the store at `d` holds, read whole.
fn stored(d: &std::path::Path, grid: &str) -> Vec<i32> {
    StoredGrid::load(d, grid).unwrap().values
}

/// The part files a grid's manifest names.
fn part_files(d: &std::path::Path, grid: &str) -> Vec<String> {
    let meta = StoredGrid::load_meta(d, grid).unwrap();
    meta.parts_listed().into_iter().map(|p| p.file).collect()
}

#[test]
fn series_merge_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = GridEdit::new(dir.path(), "g", eenf_core::Grid::Hz50, 1.0, 0.0);
    s.merge(100.0, 1.0, &[50.01, 49.99, f64::NAN]).unwrap();
    s.merge(110.0, 2.0, &[50.0, 50.002]).unwrap(); // resampled to 1 s: 3 values
    s.merge(98.0, 1.0, &[50.003]).unwrap(); // before the start: prepends a gap
    assert_eq!(s.commit().unwrap(), 15);
    let l = StoredGrid::load(dir.path(), "g").unwrap();
    assert_eq!(l.meta.start_unix_s, 98.0);
    let hz = l.hz();
    assert_eq!(hz.len(), 15);
    assert!((hz[0] - 50.003).abs() < 1e-9 && hz[1].is_nan());
    assert!((hz[2] - 50.01).abs() < 1e-9 && (hz[3] - 49.99).abs() < 1e-9 && hz[4].is_nan());
    assert!((hz[13] - 50.001).abs() < 1e-9, "{hz:?}");
    assert_eq!(
        StoredGrid::grids(dir.path()).unwrap(),
        vec!["g".to_string()]
    );
    // the same merges in memory give the same values
    let mut m = StoredGrid::new("g", eenf_core::Grid::Hz50, 1.0, 0.0);
    m.merge(100.0, 1.0, &[50.01, 49.99, f64::NAN]).unwrap();
    m.merge(110.0, 2.0, &[50.0, 50.002]).unwrap();
    m.merge(98.0, 1.0, &[50.003]).unwrap();
    assert_eq!(m.values, l.values);
}

#[test]
fn commits_replace_part_files_and_damage_is_found() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut s = GridEdit::new(d, "grid50", eenf_core::Grid::Hz50, 1.0, 1000.0);
    s.merge(1000.0, 1.0, &[50.01, 49.99, 50.0]).unwrap();
    s.commit().unwrap();
    let first = part_files(d, "grid50");
    let mut s = GridEdit::open(d, "grid50").unwrap();
    s.merge(1003.0, 1.0, &[50.02]).unwrap();
    s.commit().unwrap();
    let second = part_files(d, "grid50");
    // the commit moved to a new part file and removed the old one
    assert_eq!((first.len(), second.len()), (1, 1));
    assert_ne!(first, second);
    assert!(!d.join(&first[0]).exists() && d.join(&second[0]).exists());
    assert_eq!(stored(d, "grid50").len(), 4);
    // a file left by a build killed before its commit is not the store's, and is cleaned
    std::fs::write(d.join("grid50.1.2.i32"), [0u8; 8]).unwrap();
    assert_eq!(StoredGrid::remove_orphans(d, "grid50").unwrap(), 1);
    assert!(d.join(&second[0]).exists());
    // an edit dropped before its commit leaves nothing behind
    let mut s = GridEdit::open(d, "grid50").unwrap();
    s.merge(1004.0, 1.0, &[50.03]).unwrap();
    drop(s);
    assert_eq!(
        std::fs::read_dir(d).unwrap().count(),
        2,
        "the manifest and its part"
    );
    // a flipped bit in the values is found by the checksum, reading and changing alike
    let mut bytes = std::fs::read(d.join(&second[0])).unwrap();
    bytes[5] ^= 0x10;
    std::fs::write(d.join(&second[0]), &bytes).unwrap();
    let e = StoredGrid::load(d, "grid50").unwrap_err().to_string();
    assert!(e.contains("checksum"), "{e}");
    let mut s = GridEdit::open(d, "grid50").unwrap();
    let e = s.merge(1001.0, 1.0, &[50.0]).unwrap_err().to_string();
    assert!(e.contains("checksum"), "{e}");
    // other JSON files beside the grids (a folder of hourly WAVs and their notes) are not grids
    std::fs::write(d.join("notes.json"), "{}").unwrap();
    assert_eq!(StoredGrid::grids(d).unwrap(), vec!["grid50".to_string()]);
}

#[test]
fn a_change_rewrites_only_the_parts_it_touches() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // 1.2 stretches of values, then one far value: three parts and a gap between
    let n = PART_VALUES + PART_VALUES / 5;
    let hz: Vec<f64> = (0..n)
        .map(|i| 50.0 + ((i % 1000) as f64 - 500.0) * 1e-5)
        .collect();
    let mut s = GridEdit::new(d, "DE", eenf_core::Grid::Hz50, 1.0, 0.0);
    s.merge(0.0, 1.0, &hz).unwrap();
    s.merge((3 * PART_VALUES) as f64 + 7.0, 1.0, &[50.1])
        .unwrap();
    s.commit().unwrap();
    let before = part_files(d, "DE");
    assert_eq!(before.len(), 3, "{before:?}");
    // a value in the second stretch: only its part is new
    let mut s = GridEdit::open(d, "DE").unwrap();
    s.merge((PART_VALUES + 5) as f64, 1.0, &[49.9]).unwrap();
    s.commit().unwrap();
    let after = part_files(d, "DE");
    assert_eq!(after[0], before[0]);
    assert_ne!(after[1], before[1]);
    assert_eq!(after[2], before[2]);
    assert!(!d.join(&before[1]).exists());
    // the values are those of the same merges in memory
    let mut m = StoredGrid::new("DE", eenf_core::Grid::Hz50, 1.0, 0.0);
    m.merge(0.0, 1.0, &hz).unwrap();
    m.merge((3 * PART_VALUES) as f64 + 7.0, 1.0, &[50.1])
        .unwrap();
    m.merge((PART_VALUES + 5) as f64, 1.0, &[49.9]).unwrap();
    let g = GridValues::open_for_search(d, "DE").unwrap();
    let all = g.read_all().unwrap();
    assert_eq!(all, m.values);
    // read in any stretch, in Hz, across parts and the gap
    let at = PART_VALUES - 3;
    let w = g.window(at, 10).unwrap();
    for (i, v) in w.iter().enumerate() {
        let want = m.hz()[at + i];
        assert!(
            v == &want || (v.is_nan() && want.is_nan()),
            "{i}: {v} {want}"
        );
    }
    let sum = g.check().unwrap();
    let gaps = m.values.iter().filter(|&&v| v == GAP).count();
    assert_eq!(
        (sum.values, sum.gaps, sum.gap_runs, sum.parts),
        (m.values.len(), gaps, 1, 3)
    );
    let finite: Vec<f64> = m.hz().into_iter().filter(|v| v.is_finite()).collect();
    let mean = finite.iter().sum::<f64>() / finite.len() as f64;
    assert!((g.finite_mean().unwrap() - mean).abs() < 1e-9);
}

#[test]
fn more_stretches_than_are_held_at_once_and_a_start_moved_earlier() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // twelve stretches, more than an edit holds: some are written before the commit, and
    // removed when the edit is dropped uncommitted
    let mut s = GridEdit::new(d, "g", eenf_core::Grid::Hz60, 1.0, 0.0);
    for k in 0..12 {
        s.merge((k * PART_VALUES) as f64, 1.0, &[60.0]).unwrap();
    }
    drop(s);
    assert_eq!(std::fs::read_dir(d).unwrap().count(), 0);
    let mut s = GridEdit::new(d, "g", eenf_core::Grid::Hz60, 1.0, 0.0);
    let mut m = StoredGrid::new("g", eenf_core::Grid::Hz60, 1.0, 0.0);
    // twelve stretches, each with a few values; then values before the start
    for k in (0..12).rev() {
        let t = (k * PART_VALUES + 3 * k) as f64 + 1e6;
        let v = [60.0 + k as f64 * 1e-3, 60.01];
        s.merge(t, 1.0, &v).unwrap();
        m.merge(t, 1.0, &v).unwrap();
    }
    s.merge(5.0, 1.0, &[59.99]).unwrap();
    m.merge(5.0, 1.0, &[59.99]).unwrap();
    s.commit().unwrap();
    assert_eq!(stored(d, "g"), m.values);
    assert_eq!(StoredGrid::load_meta(d, "g").unwrap().start_unix_s, 5.0);
    // parts hold values, not the gaps around them
    let meta = StoredGrid::load_meta(d, "g").unwrap();
    let held: usize = meta.parts_listed().iter().map(|p| p.count).sum();
    assert_eq!(meta.parts_listed().len(), 12);
    assert!(held < 1_000_030, "{held}: {:?}", meta.parts);
}

#[test]
fn a_store_with_one_values_file_is_read_and_split_at_its_first_change() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // the layout stores had before parts: one values file and its checksum
    let n = PART_VALUES + 1000;
    let values: Vec<i32> = (0..n as i32).map(|i| (i % 5000) - 2500).collect();
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let mut h = crc32fast::Hasher::new();
    h.update(&bytes);
    std::fs::write(d.join("grid50.abc.1.i32"), &bytes).unwrap();
    std::fs::write(
        d.join("grid50.json"),
        format!(
            r#"{{"grid": "grid50", "nominal_hz": 50.0, "step_s": 1.0, "start_unix_s": 0.0,
            "count": {n}, "encoding": "i32", "values_file": "grid50.abc.1.i32",
            "values_crc32": {}}}"#,
            h.finalize()
        ),
    )
    .unwrap();
    assert_eq!(stored(d, "grid50"), values);
    let mut s = GridEdit::open(d, "grid50").unwrap();
    s.merge(10.0, 1.0, &[50.5]).unwrap();
    s.commit().unwrap();
    let mut want = values.clone();
    want[10] = 500_000;
    assert_eq!(stored(d, "grid50"), want);
    assert_eq!(part_files(d, "grid50").len(), 2);
    assert!(!d.join("grid50.abc.1.i32").exists());
}

#[test]
fn grid_names_are_plain_names() {
    for ok in ["grid50", "GB-2024", "a_b"] {
        assert!(check_grid_name(ok).is_ok(), "{ok}");
    }
    for bad in ["", "../x", "/abs/path", "a/b", "a.b", "-x", &"g".repeat(65)] {
        assert!(check_grid_name(bad).is_err(), "{bad}");
    }
    // a manifest that names another grid (or a path) is refused, and nothing is written
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path().join("store");
    std::fs::create_dir(&d).unwrap();
    std::fs::write(
        d.join("grid50.json"),
        r#"{"grid": "../escaped", "nominal_hz": 50.0, "step_s": 1.0, "start_unix_s": 0.0,
            "count": 0, "encoding": "i32"}"#,
    )
    .unwrap();
    let e = StoredGrid::load(&d, "grid50").unwrap_err().to_string();
    assert!(e.contains("../escaped"), "{e}");
    assert!(!dir.path().join("escaped.json").exists());
    // a part that names a path outside the store is refused before anything is read
    std::fs::write(
        d.join("grid50.json"),
        r#"{"grid": "grid50", "nominal_hz": 50.0, "step_s": 1.0, "start_unix_s": 0.0,
            "count": 4, "encoding": "i32", "parts": [{"file": "../x.i32", "first": 0, "count": 4}]}"#,
    )
    .unwrap();
    let e = StoredGrid::load(&d, "grid50").unwrap_err().to_string();
    assert!(e.contains("not a file of the store"), "{e}");
}
