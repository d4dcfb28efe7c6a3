//! Grid archives as operators and measurement sites publish them (`../shared/fixtures/
//! grid-archives`): each imports into a store as its README says, and a 5-minute clip cut from
//! each is placed at its right UTC second by `eenf match`. `#[ignore]`d (needs ../shared);
//! `.ci/run` runs it.

use std::path::{Path, PathBuf};

use crate::cli;
use cli::{eenf, ok};

use crate::common;

fn archives() -> PathBuf {
    common::shared("fixtures/grid-archives")
        .join("fixtures")
        .join("grid-archives")
}

/// The `time,value` rows of a CSV fixture (header skipped).
fn rows(name: &str) -> Vec<(String, f64)> {
    std::fs::read_to_string(archives().join(name))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let (t, v) = l.split_once(',').unwrap();
            (t.to_string(), v.trim().parse().unwrap())
        })
        .collect()
}

/// The store's values (Hz, NaN for gaps) and its first time, read back through the library.
fn stored(store: &Path, grid: &str) -> (f64, Vec<f64>) {
    let s = eenf::refdb::StoredGrid::load(store, grid).unwrap();
    (s.meta.start_unix_s, s.hz())
}

fn utc(s: &str) -> f64 {
    eenf::time::parse_time(s).unwrap()
}

/// Writes `values` as a 1 s `time_s,enf_hz` trace.
fn write_clip(path: &Path, values: &[f64]) {
    let mut text = String::from("time_s,enf_hz\n");
    for (i, v) in values.iter().enumerate() {
        text += &format!("{i},{v}\n");
    }
    std::fs::write(path, text).unwrap();
}

/// The best candidate of `eenf match`: its start (Unix s), CC and p-value.
fn best(clip: &Path, store: &Path, dir: &Path) -> (f64, f64, f64) {
    let out = ok(
        &[
            "match",
            clip.to_str().unwrap(),
            store.to_str().unwrap(),
            "--json",
            "--top",
            "1",
        ],
        dir,
    );
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let c = &v["candidates"][0];
    (
        c["start_s"].as_f64().unwrap(),
        c["cc"].as_f64().unwrap(),
        c["p_value"].as_f64().unwrap(),
    )
}

/// An ESO hour is the mains hour of the WAV written from it (16:00 and 17:00 UTC+8 =
/// 08:00 and 09:00 UTC), value for value; a clip traced from that WAV lands on its second.
#[test]
#[ignore]
fn national_grid_eso_hours_import_in_utc_and_place_clips() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let store = d.join("store");
    let wavs = common::reference_wavs();
    for (file, hour, wav) in [
        ("ngeso_2022-08-17T08Z.csv", "2022-08-17T08:00:00Z", &wavs[0]),
        (
            "ngeso_dmy_2022-08-17T09Z.csv",
            "2022-08-17T09:00:00Z",
            &wavs[1],
        ),
    ] {
        let out = eenf(
            &[
                "refdb",
                "build",
                store.to_str().unwrap(),
                archives().join(file).to_str().unwrap(),
                "--grid",
                "GB",
            ],
            d,
        );
        let said = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{file}: {said}");
        assert!(
            said.contains("ngeso layout") && said.contains("UTC"),
            "{said}"
        );
        let (start, hz) = stored(&store, "GB");
        let from = ((utc(hour) - start) as usize, rows(file));
        assert_eq!(from.1.len(), 3600, "{file}");
        for (i, (_, v)) in from.1.iter().enumerate() {
            let got = hz[from.0 + i];
            assert!((got - v).abs() < 1e-6, "{file} row {i}: {got} vs {v}");
        }
        // the same hour traced from the mains WAV (local names at UTC+8) agrees with the CSV
        let trace = d.join("hour.csv");
        ok(
            &[
                "reference",
                wav.to_str().unwrap(),
                "-o",
                trace.to_str().unwrap(),
            ],
            d,
        );
        let traced: Vec<f64> = std::fs::read_to_string(&trace)
            .unwrap()
            .lines()
            .skip(1)
            .filter_map(|l| l.split(',').nth(1)?.parse().ok())
            .collect();
        let a = eenf_dsp::agreement(&traced[..3600], &hz[from.0..from.0 + 3600]).unwrap();
        assert!(a.cc > 0.99 && a.mae_hz < 1e-3, "{file}: {a:?}");
        // a 5-minute clip of the WAV's trace, placed in the store built from the CSV
        let at = 1234;
        let clip = d.join("clip.csv");
        write_clip(&clip, &traced[at..at + 300]);
        let (when, cc, p) = best(&clip, &store, d);
        let want = utc(hour) + at as f64;
        assert!(
            (when - want).abs() < 0.5 && cc > 0.95,
            "{file}: placed at {} (want {}), CC {cc}, p {p}",
            eenf::time::utc(when),
            eenf::time::utc(want)
        );
    }
}

/// A German measurement site's CSV in local wall-clock time: refused without a zone, and with
/// `--tz Europe/Berlin` 8.6 minutes from 13:26:02 UTC (CEST); a noisy 5-minute clip of it is
/// placed at its UTC second.
#[test]
#[ignore]
fn a_local_time_site_csv_needs_its_zone_and_then_places_clips() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let store = d.join("store");
    let file = "netzfrequenzmessung_2024-08-19T15-26-02.csv";
    let csv = archives().join(file);
    let csv = csv.to_str().unwrap();
    let st = store.to_str().unwrap();
    let refused = eenf(&["refdb", "build", st, csv], d);
    let said = String::from_utf8_lossy(&refused.stderr);
    assert!(!refused.status.success(), "{said}");
    assert_eq!(said.trim().lines().count(), 1, "{said}");
    assert!(said.contains(file) && said.contains("--tz"), "{said}");
    assert!(!store.join("grid50.json").exists());
    ok(&["refdb", "build", st, csv, "--tz", "Europe/Berlin"], d);
    let (start, hz) = stored(&store, "grid50");
    assert_eq!(start, utc("2024-08-19T13:26:02Z"));
    let src = rows(file);
    assert_eq!((hz.len(), src.len()), (517, 517));
    for (i, (_, v)) in src.iter().enumerate() {
        assert!((hz[i] - v).abs() < 1e-6, "row {i}");
    }
    let info = ok(&["refdb", "info", st, "--tz", "Europe/Berlin"], d);
    assert!(
        info.contains("2024-08-19T13:26:02Z") && info.contains("2024-08-19 15:26:02 +02:00"),
        "{info}"
    );
    // a clip with 1 mHz of estimation noise (the values are given to 1 mHz)
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut noise = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2e-3
    };
    let at = 150;
    let values: Vec<f64> = src[at..at + 300].iter().map(|(_, v)| v + noise()).collect();
    let clip = d.join("clip.csv");
    write_clip(&clip, &values);
    let (when, cc, p) = best(&clip, &store, d);
    let want = utc("2024-08-19T13:28:32Z");
    assert!(
        (when - want).abs() < 0.5 && cc > 0.9,
        "placed at {} (want 2024-08-19T13:28:32Z), CC {cc}, p {p}",
        eenf::time::utc(when)
    );
    // the archive searched directly, with the zone
    let out = ok(
        &[
            "match",
            clip.to_str().unwrap(),
            csv,
            "--tz",
            "Europe/Berlin",
            "--top",
            "1",
        ],
        d,
    );
    let first = out.lines().nth(2).unwrap_or("");
    assert!(
        first.contains("2024-08-19T13:28:32")
            && first.contains("2024-08-19 15:28:32")
            && first.contains("+02:00"),
        "{out}"
    );
}
