//! Tests of eenf's `bench/discover` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf::bench::discover::*;
use std::path::PathBuf;

#[test]
fn recordings_group_by_the_prominence_the_manifest_gives() {
    let rec = |name: &str, p: Option<f64>| DatasetEntry {
        path: PathBuf::from(name),
        class: "camera".into(),
        reference: PathBuf::from("ref.csv"),
        offset_s: 0.0,
        videos: vec![],
        duration_s: None,
        prominence: p,
    };
    let mut recs = vec![
        rec("d", Some(25.0)),
        rec("a", Some(3.0)),
        rec("c", Some(15.0)),
        rec("b", Some(10.0)),
    ];
    group_by_prominence(&mut recs).unwrap();
    let got: Vec<(&str, &str)> = recs
        .iter()
        .map(|r| (r.path.to_str().unwrap(), r.class.as_str()))
        .collect();
    assert_eq!(
        got,
        [
            ("a", "prominence <10"),
            ("b", "prominence 10-15"),
            ("c", "prominence 15-20"),
            ("d", "prominence >=20")
        ]
    );
    let mut none = vec![rec("e", None)];
    assert!(group_by_prominence(&mut none).is_err());
}
