//! The simulator driven by the six real Wuhan hours: a small synthetic EV-ENFD whose references
//! are those recordings, and E-ENF scored on it per class. Needs `../shared` (run by `.ci/run`
//! with `--ignored`).

use crate::common;

use std::path::Path;

use crate::cli;
use cli::ok;

#[test]
#[ignore = "needs ../shared"]
fn e_enf_on_a_small_dataset_driven_by_the_real_hours() {
    let refs = common::shared("enf-reference").join("enf-reference");
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    ok(
        &[
            "-q",
            "simulate-dataset",
            "ds",
            "--preset",
            "small",
            "--duration",
            "90",
            "--enf-dir",
            &refs.to_string_lossy(),
        ],
        d,
    );
    let ds = d.join("ds");
    // the references are the real recordings, unchanged
    for wav in common::reference_wavs() {
        let copy = ds.join("ENF_Reference").join(wav.file_name().unwrap());
        assert_eq!(std::fs::read(&wav).unwrap(), std::fs::read(&copy).unwrap());
    }
    let manifest = std::fs::read_to_string(ds.join("manifest.csv")).unwrap();
    let mut per_class: std::collections::BTreeMap<String, Vec<(f64, f64)>> = Default::default();
    for line in manifest.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let stem = Path::new(f[0])
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let trace = format!("{stem}.enf.csv");
        ok(&["-q", "extract", f[0], "-o", &trace], &ds);
        let cmp: serde_json::Value =
            serde_json::from_str(&ok(&["compare", &trace, "ENF_Reference", "--json"], &ds))
                .unwrap();
        let (cc, mae) = (cmp["cc"].as_f64().unwrap(), cmp["mae_hz"].as_f64().unwrap());
        eprintln!(
            "{:<8} {:<44} CC {cc:.4} MAE {:.3} mHz",
            f[1],
            f[0],
            mae * 1e3
        );
        per_class
            .entry(f[1].to_string())
            .or_default()
            .push((cc, mae));
    }
    for (class, v) in &per_class {
        let cc = v.iter().map(|x| x.0).sum::<f64>() / v.len() as f64;
        let mae = v.iter().map(|x| x.1).sum::<f64>() / v.len() as f64;
        eprintln!("{class:<8} mean CC {cc:.4}, mean MAE {:.3} mHz", mae * 1e3);
        // the paper's real numbers are CC 0.955–0.987, MAE 1.9–2.1 mHz per class
        assert!(cc > 0.85 && mae < 0.005, "{class}: CC {cc}, MAE {mae}");
    }
    assert_eq!(per_class.len(), 3);
}
