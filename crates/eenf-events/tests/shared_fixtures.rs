//! Decodes of the files in `../shared/fixtures`, written by other tools. These need the shared
//! data, so they are `#[ignore]`d; `.ci/run` runs them with `--ignored`, and there they fail
//! (not skip) when the data is missing.

use eenf_events::{open, EventBatch, StreamStats};
use std::path::PathBuf;

fn shared() -> PathBuf {
    let dir = std::env::var_os("EENF_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared"));
    assert!(
        dir.join("fixtures").is_dir(),
        "shared data not found at {} (set EENF_SHARED)",
        dir.display()
    );
    dir
}

fn read_all(path: &std::path::Path) -> EventBatch {
    let mut r = open(path).unwrap_or_else(|e| panic!("{e}"));
    let mut all = EventBatch::default();
    while let Some(b) = r.next_batch().unwrap_or_else(|e| panic!("{e}")) {
        all.extend_from(&b);
    }
    all
}

fn truth() -> EventBatch {
    // The truth CSV is itself a text event file with a column-name row.
    read_all(&shared().join("fixtures/synthetic/truth_t_us_x_y_p.csv"))
}

#[test]
#[ignore = "needs ../shared"]
fn synthetic_aedat4_every_codec_equals_truth() {
    let truth = truth();
    assert_eq!(truth.len(), 60_165);
    for name in ["none", "lz4", "lz4_high", "zstd", "zstd_high"] {
        let path = shared().join(format!("fixtures/synthetic/synth_{name}.aedat4"));
        let r = open(&path).unwrap();
        let info = r.info().clone();
        assert_eq!((info.width, info.height), (Some(320), Some(240)), "{name}");
        assert_eq!(
            info.event_count,
            Some(60_165),
            "{name}: FileDataTable count"
        );
        let got = read_all(&path);
        let shifted: Vec<i64> = got.t.iter().map(|t| t - 1_700_000_000_000_000).collect();
        assert_eq!(shifted, truth.t, "{name}: timestamps");
        assert_eq!(got.x, truth.x, "{name}: x");
        assert_eq!(got.y, truth.y, "{name}: y");
        assert_eq!(got.p, truth.p, "{name}: polarity");
    }
}

#[test]
#[ignore = "needs ../shared"]
fn synthetic_text_equals_truth() {
    let got = read_all(&shared().join("fixtures/synthetic/synth_evlib.txt"));
    assert_eq!(got, truth());
}

#[test]
#[ignore = "needs ../shared"]
fn real_dvxplorer_aedat4_matches_dv_processing() {
    let path = shared().join("fixtures/real/tonic_sample.aedat4");
    let mut r = open(&path).unwrap();
    let kinds: Vec<String> = r.info().streams.iter().map(|s| s.kind.clone()).collect();
    assert!(kinds.contains(&"EVTS".to_string()) && kinds.contains(&"IMUS".to_string()));
    assert_eq!((r.info().width, r.info().height), (Some(320), Some(240)));
    let s = StreamStats::scan(r.as_mut()).unwrap();
    assert_eq!(s.events, 111_954);
    assert_eq!(s.first_t, Some(1_605_537_493_718_345));
    assert_eq!(s.last_t, Some(1_605_537_494_308_262));
    assert_eq!(s.x_range, Some((0, 319)));
    assert_eq!(s.y_range, Some((0, 239)));
    assert_eq!(s.on, 55_023);
}
