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
    // read to its end: nothing cut short as damage or a wild timestamp
    assert_eq!(r.damage(), None, "{}", path.display());
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

/// Sorts events within each timestamp, for formats that may reorder events sharing one.
fn canonical(b: &EventBatch) -> Vec<(i64, u16, u16, bool)> {
    let mut v: Vec<_> = (0..b.len())
        .map(|i| (b.t[i], b.x[i], b.y[i], b.p[i]))
        .collect();
    v.sort();
    v
}

#[test]
#[ignore = "needs ../shared"]
fn every_synthetic_format_equals_truth() {
    let truth = truth();
    for (name, format, reorders) in [
        ("synth_evt2.raw", "EVT 2.0", false),
        ("synth_evt21_little.raw", "EVT 2.1", false),
        ("synth_evt21_legacy.raw", "EVT 2.1", false),
        ("synth_evt3.raw", "EVT 3.0", true),
        ("synth_dat.dat", "DAT", false),
        ("synth_aedat2.aedat", "AEDAT 2.0", false),
        ("synth_aedat31.aedat", "AEDAT 3.1", false),
    ] {
        let path = shared().join("fixtures/synthetic").join(name);
        let r = open(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(r.info().format, format, "{name}");
        let got = read_all(&path);
        assert_eq!(got.len(), truth.len(), "{name}: count");
        if reorders {
            assert_eq!(canonical(&got), canonical(&truth), "{name}");
        } else {
            assert_eq!(got.t, truth.t, "{name}: t");
            assert_eq!(got.x, truth.x, "{name}: x");
            assert_eq!(got.y, truth.y, "{name}: y");
            assert_eq!(got.p, truth.p, "{name}: p");
        }
    }
}

#[test]
#[ignore = "needs ../shared"]
fn real_prophesee_files_match_the_reference_decoders() {
    type Expect = (&'static str, u64, i64, i64, (u16, u16), (u16, u16), u64);
    let cases: [Expect; 4] = [
        (
            "expelliarmus_evt2_sample.raw",
            539_481,
            1_317_888,
            1_367_888,
            (60, 599),
            (18, 475),
            367_855,
        ),
        (
            "faery_evt2.raw",
            521_252,
            913_716_224,
            913_812_095,
            (0, 639),
            (0, 479),
            185_861,
        ),
        (
            "expelliarmus_evt3_sample.raw",
            219_596,
            11_718_656,
            11_727_457,
            (0, 1279),
            (0, 719),
            115_532,
        ),
        (
            "tonic_sample_ncars.dat",
            2_009,
            0,
            99_952,
            (0, 77),
            (0, 41),
            1_350,
        ),
    ];
    for (name, n, first, last, xr, yr, on) in cases {
        let path = shared().join("fixtures/real").join(name);
        let mut r = open(&path).unwrap_or_else(|e| panic!("{e}"));
        let s = StreamStats::scan(r.as_mut()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.events, n, "{name}: count");
        assert_eq!(
            (s.first_t, s.last_t),
            (Some(first), Some(last)),
            "{name}: time span"
        );
        assert_eq!(
            (s.x_range, s.y_range),
            (Some(xr), Some(yr)),
            "{name}: ranges"
        );
        assert_eq!(s.on, on, "{name}: ON events");
    }
    // geometry from the sensor generation when the header has none
    let r = open(&shared().join("fixtures/real/expelliarmus_evt3_sample.raw")).unwrap();
    assert_eq!((r.info().width, r.info().height), (Some(1280), Some(720)));
}

#[test]
#[ignore = "needs ../shared"]
fn every_fixture_survives_truncation_and_bit_flips() {
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for sub in [
        "synthetic",
        "real",
        "containers/other",
        "containers/ros1",
        "containers/hdf5",
    ] {
        for e in std::fs::read_dir(shared().join("fixtures").join(sub)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().map(|e| e != "csv").unwrap_or(false) {
                files.push(p);
            }
        }
    }
    // rosbag2 storage files, damaged on their own
    for e in std::fs::read_dir(shared().join("fixtures/containers/ros2")).unwrap() {
        for f in std::fs::read_dir(e.unwrap().path()).unwrap() {
            let p = f.unwrap().path();
            if p.extension().is_some_and(|e| e == "db3" || e == "mcap") {
                files.push(p);
            }
        }
    }
    assert!(files.len() >= 37, "{files:?}");
    for path in files {
        let bytes = std::fs::read(&path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let damaged = dir.path().join(&name);
        let read = |p: &std::path::Path| -> usize {
            let Ok(mut r) = open(p) else { return 0 };
            let mut n = 0;
            while let Ok(Some(b)) = r.next_batch() {
                n += b.len();
            }
            n
        };
        let whole = read(&path);
        let cuts: Vec<usize> = (0..400.min(bytes.len()))
            .chain((400..bytes.len()).step_by(bytes.len() / 61 + 1))
            .collect();
        for cut in cuts {
            std::fs::write(&damaged, &bytes[..cut]).unwrap();
            assert!(
                read(&damaged) <= whole,
                "{name} cut at {cut} gave more events"
            );
        }
        let mut s = 7u64;
        for _ in 0..60 {
            let mut b = bytes.clone();
            for _ in 0..3 {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let at = (s >> 33) as usize % b.len();
                b[at] ^= 1 << ((s >> 29) & 7);
            }
            std::fs::write(&damaged, &b).unwrap();
            let _ = read(&damaged);
        }
    }
}

/// Counts, sums and ranges of a stream read to its end.
fn summary(b: &EventBatch) -> (usize, usize, i64, i64, u64, u64) {
    let on = b.p.iter().filter(|&&p| p).count();
    let sx = b.x.iter().map(|&x| x as u64).sum();
    let sy = b.y.iter().map(|&y| y as u64).sum();
    (b.len(), on, b.t[0], b.t[b.len() - 1], sx, sy)
}

#[test]
#[ignore = "needs ../shared"]
fn event_stream_and_atis_bin_decode_as_their_readme_says() {
    let other = shared().join("fixtures/containers/other");
    // Event Stream 2.0.0, DVS: 320×240, 473,225 events, t 0–999,000 µs
    let path = other.join("faery_dvs.es");
    let r = open(&path).unwrap();
    assert_eq!(r.info().format, "Event Stream");
    assert_eq!((r.info().width, r.info().height), (Some(320), Some(240)));
    let b = read_all(&path);
    let (n, _, t0, t1, ..) = summary(&b);
    assert_eq!((n, t0, t1), (473_225, 0, 999_000));
    assert!(b.t.windows(2).all(|w| w[0] <= w[1]));
    assert!(b.x.iter().all(|&x| x < 320) && b.y.iter().all(|&y| y < 240));
    // N-MNIST ATIS .bin: 34×34, 4,325 events, t 654–311,175 µs
    let path = other.join("tonic_sample_nmnist.bin");
    let b = read_all(&path);
    let (n, _, t0, t1, ..) = summary(&b);
    assert_eq!((n, t0, t1), (4_325, 654, 311_175));
    assert!(b.x.iter().all(|&x| x < 34) && b.y.iter().all(|&y| y < 34));
}

#[test]
#[ignore = "needs ../shared"]
fn ros1_bags_decode_as_their_readme_says() {
    let ros1 = shared().join("fixtures/containers/ros1");
    // the real Prophesee bag: evt3 packets, the clock's state carried across messages
    let path = ros1.join("event_camera_py_test_events_1.bag");
    let mut r = open(&path).unwrap();
    assert_eq!(r.info().format, "ROS 1 bag");
    let mut packets = EventBatch::default();
    while let Some(b) = r.next_batch().unwrap() {
        packets.extend_from(&b);
    }
    assert_eq!((r.info().width, r.info().height), (Some(640), Some(480)));
    let (n, on, t0, t1, ..) = summary(&packets);
    assert_eq!((n, on, t0, t1), (343_474, 125_183, 7_139_845, 9_218_023));
    assert!(
        r.skipped().contains(&("trigger", 4_157)),
        "{:?}",
        r.skipped()
    );
    // the dvs_msgs and prophesee_event_msgs bags hold its first 38,478 events in time order,
    // stamped in ROS time: the same events, shifted by one constant
    let first = first_in_time(&packets, 38_478);
    for name in ["ros1_dvs_msgs.bag", "ros1_prophesee_event_msgs.bag"] {
        let b = read_all(&ros1.join(name));
        assert_eq!(b.len(), 38_478, "{name}");
        let shift = b.t[0] - first.t[0];
        assert!(shift > 1_600_000_000_000_000, "{name}: ROS stamps, µs");
        let mut shifted = b.clone();
        shifted.t.iter_mut().for_each(|t| *t -= shift);
        assert_eq!(canonical(&shifted), canonical(&first), "{name}");
    }
}

/// The events of `b` in time order (a stable sort), the first `n` of them.
fn first_in_time(b: &EventBatch, n: usize) -> EventBatch {
    let mut order: Vec<usize> = (0..b.len()).collect();
    order.sort_by_key(|&i| b.t[i]);
    let mut out = EventBatch::default();
    for &i in order.iter().take(n) {
        out.push(b.t[i], b.x[i], b.y[i], b.p[i]);
    }
    out
}

#[test]
#[ignore = "needs ../shared"]
fn rosbag2_folders_decode_as_their_readme_says() {
    let ros2 = shared().join("fixtures/containers/ros2");
    let bag1 =
        read_all(&shared().join("fixtures/containers/ros1/event_camera_py_test_events_1.bag"));
    // the same recording as a rosbag2 (SQLite v8): its folder and its .db3 give the ROS 1
    // bag's events, one by one
    let folder = ros2.join("event_camera_py_test_events_1");
    for path in [folder.clone(), folder.join("test_events_1.db3")] {
        let mut r = open(&path).unwrap();
        assert_eq!(r.info().format, "rosbag2 (SQLite)");
        let topics: Vec<_> = r
            .info()
            .streams
            .iter()
            .map(|s| (s.source.clone(), s.messages))
            .collect();
        assert_eq!(
            topics,
            vec![(Some("/event_camera/events".into()), Some(517))]
        );
        let mut b = EventBatch::default();
        while let Some(x) = r.next_batch().unwrap() {
            b.extend_from(&x);
        }
        assert_eq!(b, bag1, "{}", path.display());
        assert!(
            r.skipped().contains(&("trigger", 4_157)),
            "{:?}",
            r.skipped()
        );
    }
    // MCAP (ros2idl), libcaer_cmp from a DAVIS346: the upstream test's counts, Unix times
    let path = ros2.join("event_camera_py_test_events_2");
    let r = open(&path).unwrap();
    assert_eq!(r.info().format, "rosbag2 (MCAP)");
    assert_eq!((r.info().width, r.info().height), (Some(346), Some(260)));
    let b = read_all(&path);
    let (n, on, t0, t1, ..) = summary(&b);
    assert_eq!((n, on, n - on), (571_266, 211_043, 360_223));
    // 2025-04-09T00:00:00Z, and within a second of it
    assert!(
        t0 >= 1_744_156_800_000_000 && t1 - t0 < 86_400_000_000,
        "{t0} {t1}"
    );
    assert!(b.x.iter().all(|&x| x < 346) && b.y.iter().all(|&y| y < 260));
    // event_camera_codecs' own test data: evt3 with triggers (sums in ns)
    let b = read_all(&ros2.join("codecs_evt3_trigger"));
    let (n, on, _, _, sx, sy) = summary(&b);
    let st: i128 = b.t.iter().map(|&t| t as i128 * 1000).sum();
    assert_eq!(
        (n, on, sx, sy, st),
        (
            82_469,
            41_439,
            42_078_718,
            31_656_267,
            1_222_326_831_810_000
        )
    );
    // libcaer: the 31-bit clock wraps, time goes on
    let b = read_all(&ros2.join("codecs_libcaer_rollover"));
    let (n, on, t0, t1, sx, sy) = summary(&b);
    assert_eq!((n, on, sx, sy), (334_331, 181_908, 111_651_612, 82_801_007));
    assert!(b.t.windows(2).all(|w| w[1] >= w[0]), "time goes back");
    assert!(t1 - t0 < 10_000_000, "{t0} {t1}");
    // mono (event_array_msgs, SQLite v4)
    let b = read_all(&ros2.join("codecs_mono_cd"));
    let (n, on, _, _, sx, sy) = summary(&b);
    let st: i64 = b.t.iter().map(|&t| t * 1000).sum();
    assert_eq!((n, on, sx, sy, st), (100, 50, 34_450, 26_450, 4_950_000));
    // ROS 2 dvs_msgs (CDR, fields aligned) in SQLite and in MCAP: the recording's first
    // 14,862 events in time order, stamped in ROS time
    let first = first_in_time(&bag1, 14_862);
    for name in ["ros2_dvs_msgs_sqlite3", "ros2_dvs_msgs_mcap"] {
        let b = read_all(&ros2.join(name));
        assert_eq!(b.len(), 14_862, "{name}");
        let shift = b.t[0] - first.t[0];
        assert!(shift > 1_600_000_000_000_000, "{name}: ROS stamps, µs");
        let mut shifted = b.clone();
        shifted.t.iter_mut().for_each(|t| *t -= shift);
        assert_eq!(canonical(&shifted), canonical(&first), "{name}");
    }
}

#[test]
#[ignore = "needs ../shared"]
fn hdf5_layouts_decode_as_their_readme_says() {
    let h5 = shared().join("fixtures/containers/hdf5");
    let bag1 =
        read_all(&shared().join("fixtures/containers/ros1/event_camera_py_test_events_1.bag"));
    let first = first_in_time(&bag1, 38_478);
    let from_zero = |b: &EventBatch| {
        let mut z = b.clone();
        z.t.iter_mut().for_each(|t| *t -= first.t[0]);
        z
    };
    // DSEC: every filter (blosc + zstd as DSEC, zstd 32015, deflate); t = t_offset + t
    for name in [
        "dsec_layout_blosc_zstd.h5",
        "dsec_layout_zstd32015.h5",
        "dsec_layout_gzip.h5",
    ] {
        let b = read_all(&h5.join(name));
        assert_eq!(canonical(&b), canonical(&first), "{name}");
    }
    // M3ED (blosc) and Prophesee's CD/events (deflate): times from 0
    for name in ["m3ed_layout_blosc.h5", "prophesee_cd_layout_gzip.h5"] {
        let b = read_all(&h5.join(name));
        assert_eq!(canonical(&b), canonical(&from_zero(&first)), "{name}");
    }
    let r = open(&h5.join("prophesee_cd_layout_gzip.h5")).unwrap();
    assert_eq!((r.info().width, r.info().height), (Some(640), Some(480)));
    // MVSEC: N×4 float64, t in seconds (float64 keeps Unix µs to within one)
    let b = read_all(&h5.join("mvsec_layout.h5"));
    assert_eq!(b.len(), 38_478);
    let shift = b.t[0] - first.t[0];
    assert!(shift > 1_600_000_000_000_000, "Unix seconds, as µs");
    let mut got = canonical(&b);
    let want = canonical(&first);
    for (g, w) in got.iter_mut().zip(&want) {
        assert!((g.0 - shift - w.0).abs() <= 1, "{g:?} {w:?}");
        g.0 = w.0;
    }
    assert_eq!(got, want);
    // Prophesee's ECF: all 343,474 CD events of the recording
    let b = read_all(&h5.join("prophesee_ecf_layout.hdf5"));
    assert_eq!(canonical(&b), canonical(&bag1));
}
