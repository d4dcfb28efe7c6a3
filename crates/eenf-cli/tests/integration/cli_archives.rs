//! `eenf refdb build` on grid archives written here as operators publish them: local times
//! across both changes of summer time, 0.1 s rows in zip, 7z and gzip containers, and files
//! it cannot read.

use std::io::Write;

use crate::cli::{ok_out_err as ok, refused, truth_hz as truth};

use eenf::refdb::StoredGrid;
use eenf::time::{parse_time, Zone};

fn t(s: &str) -> f64 {
    parse_time(s).unwrap()
}

/// A site's CSV in Berlin wall-clock time, 1 s, over the UTC stretches given.
fn berlin_csv(stretches: &[(&str, &str)]) -> String {
    let berlin = Zone::parse("Europe/Berlin").unwrap();
    let mut text = String::from("time,frequency\n");
    for (from, to) in stretches {
        let mut u = t(from);
        while u < t(to) {
            let local = berlin.local(u);
            text += &format!("{},{:.5}\n", &local[..19], truth(u));
            u += 1.0;
        }
    }
    text
}

#[test]
fn an_archive_across_both_summer_time_changes_loses_and_doubles_no_hour() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    // Berlin 00:00–04:00 local on 2024-03-31 (three hours: 02:00–03:00 does not exist) and
    // 01:00–04:00 local on 2024-10-27 (four hours: 02:00–03:00 happens twice)
    let spring = ("2024-03-30T23:00:00Z", "2024-03-31T02:00:00Z");
    let autumn = ("2024-10-26T23:00:00Z", "2024-10-27T03:00:00Z");
    std::fs::write(d.join("spring.csv"), berlin_csv(&[spring])).unwrap();
    std::fs::write(d.join("autumn.csv"), berlin_csv(&[autumn])).unwrap();
    let (_, said) = ok(
        &[
            "refdb",
            "build",
            "store",
            "spring.csv",
            "autumn.csv",
            "--tz",
            "Europe/Berlin",
            "--grid",
            "DE",
        ],
        d,
    );
    assert!(
        said.contains("2024-10-27 02:00 (Europe/Berlin) passed twice")
            && said.contains("3600 rows in the second"),
        "{said}"
    );
    let s = StoredGrid::load(&d.join("store"), "DE").unwrap();
    let hz = s.hz();
    assert_eq!(s.meta.start_unix_s, t(spring.0));
    // every UTC second of both stretches holds its own value, and nothing else is filled
    let mut want = 0;
    for (from, to) in [spring, autumn] {
        let mut u = t(from);
        while u < t(to) {
            let i = (u - s.meta.start_unix_s) as usize;
            assert!((hz[i] - truth(u)).abs() < 2e-5, "{}", eenf::time::utc(u));
            u += 1.0;
            want += 1;
        }
    }
    assert_eq!(want, 7 * 3600);
    assert_eq!(hz.iter().filter(|v| v.is_finite()).count(), want);
    let (info, _) = ok(&["refdb", "info", "store", "--tz", "Europe/Berlin"], d);
    assert!(
        info.contains("2024-03-31 00:00:00 +01:00") && info.contains("2024-10-27 03:59:59 +01:00"),
        "{info}"
    );
    // without the zone the same file is refused, in one line that says how to give it
    let e = refused(&["refdb", "build", "other", "spring.csv"], d);
    assert!(e.contains("spring.csv") && e.contains("--tz"), "{e}");
    assert!(!d.join("other").join("grid50.json").exists());
}

/// Ten minutes of 0.1 s rows with their UTC offsets (a Fingrid-style day file), in halves.
fn tenth_second_days() -> Vec<(String, String)> {
    let start = t("2023-06-01T21:55:00Z");
    let mut days = Vec::new();
    for half in 0..2 {
        let mut text = String::from("Time,Value\n");
        for k in 0..3000 {
            let u = start + half as f64 * 300.0 + k as f64 * 0.1;
            // Finnish summer time, +03:00, written with the offset
            let local = eenf::time::local(u, 3.0 * 3600.0);
            let frac = (k % 10) as u32;
            text += &format!(
                "{}T{}.{frac}00+03:00,{:.6}\n",
                &local[..10],
                &local[11..19],
                truth(u)
            );
        }
        days.push((format!("2023-06-0{}.csv", half + 1), text));
    }
    days
}

#[test]
fn zip_7z_and_gzip_archives_give_the_same_seconds() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let days = tenth_second_days();
    // zip: a month's archive of day files (and a readme that is skipped)
    let mut zip = zip::ZipWriter::new(std::fs::File::create(d.join("month.zip")).unwrap());
    let opts = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    for (name, text) in &days {
        zip.start_file(format!("2023-06/{name}"), opts).unwrap();
        zip.write_all(text.as_bytes()).unwrap();
    }
    zip.start_file("README.pdf", opts).unwrap();
    zip.write_all(b"%PDF").unwrap();
    zip.finish().unwrap();
    // 7z of the same day files
    let src = d.join("days");
    std::fs::create_dir(&src).unwrap();
    for (name, text) in &days {
        std::fs::write(src.join(name), text).unwrap();
    }
    sevenz_rust2::compress_to_path(&src, d.join("month.7z")).unwrap();
    // gzip of both days in one file
    let mut gz = flate2::write::GzEncoder::new(
        std::fs::File::create(d.join("month.csv.gz")).unwrap(),
        flate2::Compression::default(),
    );
    gz.write_all(days[0].1.as_bytes()).unwrap();
    gz.write_all(
        days[1]
            .1
            .lines()
            .skip(1)
            .collect::<Vec<_>>()
            .join("\n")
            .as_bytes(),
    )
    .unwrap();
    gz.finish().unwrap();
    let mut stores = Vec::new();
    for (i, file) in ["month.zip", "month.7z", "month.csv.gz"].iter().enumerate() {
        let store = format!("s{i}");
        let (_, said) = ok(&["refdb", "build", &store, file, "--format", "fingrid"], d);
        assert!(
            said.contains("fingrid layout") && said.contains("own UTC offsets"),
            "{file}: {said}"
        );
        if file.ends_with(".zip") {
            assert!(
                said.contains("2 files") && said.contains("README.pdf"),
                "{said}"
            );
        }
        stores.push(StoredGrid::load(&d.join(&store), "grid50").unwrap());
    }
    let s = &stores[0];
    assert_eq!(s.meta.start_unix_s, t("2023-06-01T21:55:00Z"));
    assert_eq!(s.meta.step_s, 1.0);
    let hz = s.hz();
    // each whole second is the mean of the ten 0.1 s rows around it, not one picked row
    assert_eq!(hz.len(), 601);
    for (k, v) in hz.iter().enumerate().skip(1).take(599) {
        let u = s.meta.start_unix_s + k as f64;
        let mean: f64 = (-5..5).map(|j| truth(u + j as f64 * 0.1)).sum::<f64>() / 10.0;
        assert!((v - mean).abs() < 1e-5, "second {k}: {v} vs {mean}");
    }
    for other in &stores[1..] {
        assert_eq!(other.values, s.values);
    }
    // a download cut short (no directory at the end): the whole first day is kept, with a warning
    let whole = std::fs::read(d.join("month.zip")).unwrap();
    std::fs::write(d.join("cut.zip"), &whole[..whole.len() * 3 / 4]).unwrap();
    let (_, said) = ok(
        &["refdb", "build", "cut", "cut.zip", "--format", "fingrid"],
        d,
    );
    assert!(
        said.contains("warning") && said.contains("damaged zip"),
        "{said}"
    );
    let cut = StoredGrid::load(&d.join("cut"), "grid50").unwrap();
    assert!(cut.values.len() >= 300, "{}", cut.values.len());
    assert_eq!(cut.values[..300], s.values[..300]);
    // a 7z keeps its directory at the end: cut short, it is refused in one line
    let whole = std::fs::read(d.join("month.7z")).unwrap();
    std::fs::write(d.join("cut.7z"), &whole[..whole.len() * 3 / 4]).unwrap();
    let e = refused(
        &["refdb", "build", "cut7", "cut.7z", "--format", "fingrid"],
        d,
    );
    assert!(e.contains("cut.7z") && e.contains("7z"), "{e}");
}

#[test]
fn files_it_cannot_read_get_one_line_naming_them() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let write = |name: &str, bytes: &[u8]| std::fs::write(d.join(name), bytes).unwrap();
    write("numbers.csv", b"a,b\n1,2\n3,4\n");
    write("words.csv", b"hello there\nno columns here\n");
    write(
        "binary.bin",
        &[0u8, 159, 146, 150, 7, 1, 0, 0].repeat(40_000),
    );
    write(
        "ambiguous.csv",
        b"when,f\n05/06/2022 00:00:00,50.01\n05/06/2022 00:00:01,50.02\n",
    );
    write(
        "level.csv",
        b"time,level\n2024-08-19 15:26:02,3.1\n2024-08-19 15:26:03,3.2\n",
    );
    write(
        "dropouts.csv",
        b"dtm,f\n2022-08-17 08:00:00,0\n2022-08-17 08:00:01,0\n",
    );
    write("truncated.zip", b"PK\x03\x04\x14\x00\x00\x00\x08\x00");
    write("empty.csv", b"");
    for (file, expect) in [
        ("numbers.csv", "nor a grid archive"),
        ("words.csv", "nor a grid archive"),
        ("binary.bin", "binary.bin"),
        ("ambiguous.csv", "--date-order"),
        ("level.csv", "--value-unit"),
        ("dropouts.csv", "plausible"),
        ("truncated.zip", "zip"),
        ("empty.csv", "empty.csv"),
        ("missing.csv", "missing.csv"),
    ] {
        let e = refused(
            &["refdb", "build", "store", file, "--tz", "Europe/Berlin"],
            d,
        );
        assert!(e.contains(file) && e.contains(expect), "{file}: {e}");
    }
    let e = refused(
        &[
            "refdb",
            "build",
            "store",
            "level.csv",
            "--tz",
            "Mars/Olympus",
        ],
        d,
    );
    assert!(e.contains("IANA"), "{e}");
    assert!(!d.join("store").join("grid50.json").exists());
}
