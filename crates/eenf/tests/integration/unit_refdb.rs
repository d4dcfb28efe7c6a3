//! Tests of eenf's `refdb` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf::refdb::*;

#[test]
fn series_merge_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = StoredGrid::new("g", eenf_core::Grid::Hz50, 1.0, 0.0);
    s.merge(100.0, 1.0, &[50.01, 49.99, f64::NAN]).unwrap();
    s.merge(110.0, 2.0, &[50.0, 50.002]).unwrap(); // resampled to 1 s: 3 values
    s.merge(98.0, 1.0, &[50.003]).unwrap(); // before the start: prepends a gap
    s.save(dir.path()).unwrap();
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
}

#[test]
fn commits_replace_values_files_and_damage_is_found() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut s = StoredGrid::new("grid50", eenf_core::Grid::Hz50, 1.0, 1000.0);
    s.merge(1000.0, 1.0, &[50.01, 49.99, 50.0]).unwrap();
    s.save(d).unwrap();
    let first = s.meta.values_file.clone().unwrap();
    s.merge(1003.0, 1.0, &[50.02]).unwrap();
    s.save(d).unwrap();
    let second = s.meta.values_file.clone().unwrap();
    // the commit moved to a new values file and removed the old one
    assert_ne!(first, second);
    assert!(!d.join(&first).exists() && d.join(&second).exists());
    assert_eq!(StoredGrid::load(d, "grid50").unwrap().values.len(), 4);
    // a file left by a build killed before its commit is not the store's, and is cleaned
    std::fs::write(d.join("grid50.1.2.i32"), [0u8; 8]).unwrap();
    assert_eq!(StoredGrid::remove_orphans(d, "grid50").unwrap(), 1);
    assert!(d.join(&second).exists());
    // a flipped bit in the values is found by the checksum
    let mut bytes = std::fs::read(d.join(&second)).unwrap();
    bytes[5] ^= 0x10;
    std::fs::write(d.join(&second), &bytes).unwrap();
    let e = StoredGrid::load(d, "grid50").unwrap_err().to_string();
    assert!(e.contains("checksum"), "{e}");
    // other JSON files beside the grids (a folder of hourly WAVs and their notes) are not grids
    std::fs::write(d.join("notes.json"), "{}").unwrap();
    assert_eq!(StoredGrid::grids(d).unwrap(), vec!["grid50".to_string()]);
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
}
