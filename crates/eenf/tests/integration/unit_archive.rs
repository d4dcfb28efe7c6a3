//! Tests of eenf's `archive` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf::archive::*;
use eenf::time::Zone;
use eenf::Result;
use std::path::Path;

fn layout(text: &str, opts: &ArchiveOptions) -> Result<Layout> {
    let lines: Vec<String> = text.lines().map(str::to_string).collect();
    sniff(&lines, opts, Path::new("x.csv"))
}

fn import_text(text: &str, opts: &ArchiveOptions) -> Result<ArchiveImport> {
    import_onto(text, opts, None)
}

fn import_onto(text: &str, opts: &ArchiveOptions, step: Option<f64>) -> Result<ArchiveImport> {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("a.csv");
    std::fs::write(&p, text).unwrap();
    import(&p, opts, step)
}

fn t(s: &str) -> f64 {
    eenf::time::parse_time(s).unwrap()
}

#[test]
fn dates_clocks_and_offsets() {
    let dt = |s: &str| parse_date_time(s.as_bytes(), DateOrder::Dmy);
    let at = |s: &str| t(s);
    assert_eq!(
        dt("2022-08-17 08:00:00"),
        Some((at("2022-08-17T08:00:00Z"), None))
    );
    assert_eq!(
        dt("17/08/2022 09:00:01"),
        Some((at("2022-08-17T09:00:01Z"), None))
    );
    assert_eq!(
        dt("17.08.2022 09:00"),
        Some((at("2022-08-17T09:00:00Z"), None))
    );
    assert_eq!(
        dt("2015-01-01T00:00:00.100+02:00"),
        Some((at("2015-01-01T00:00:00Z") + 0.1, Some(7200.0)))
    );
    assert_eq!(dt("2022-08-17 08:00:00Z").unwrap().1, Some(0.0));
    assert_eq!(dt("2022-08-17 08:00:00 -0500").unwrap().1, Some(-18_000.0));
    assert_eq!(
        parse_date_time(b"08/17/2022 09:00:00", DateOrder::Mdy)
            .unwrap()
            .0,
        at("2022-08-17T09:00:00Z")
    );
    for bad in [
        "2022-02-30 00:00:00",
        "2022-08-17 25:00:00",
        "1900-01-01 00:00:00",
        "hello",
        "2022-08-17",
    ] {
        assert!(dt(bad).is_none(), "{bad}");
    }
}

#[test]
fn layouts_are_sniffed() {
    let o = ArchiveOptions::default();
    let l = layout(
        "dtm,f\n2022-08-17 08:00:00,49.968\n2022-08-17 08:00:01,49.97\n",
        &o,
    )
    .unwrap();
    assert_eq!(l.format, ArchiveFormat::Ngeso);
    assert_eq!(
        (l.time, l.value, l.unit),
        (TimeColumns::DateTime(0), 1, ValueUnit::Hz)
    );
    assert!(matches!(l.zone, ZoneRule::Utc(_)));
    // a local-time CSV without a zone is refused, naming the file and the flag
    let e = layout("time,frequency\n2024-08-19 15:26:02,49.978\n", &o)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("x.csv") && e.contains("give it with tz ("),
        "{e}"
    );
    let berlin = ArchiveOptions {
        zone: Some(Zone::parse("Europe/Berlin").unwrap()),
        ..o.clone()
    };
    assert!(layout("time,frequency\n2024-08-19 15:26:02,49.978\n", &berlin).is_ok());
    // OSF/WETI: ;-separated fields, no header, UTC
    let l = layout("2019;7;9;0;0;0.0;50.012\n2019;7;9;0;0;1.0;50.011\n", &o).unwrap();
    assert_eq!(
        (l.format, l.time, l.value),
        (ArchiveFormat::Osf, TimeColumns::Fields(0), 6)
    );
    // German style: date and time in two columns, decimal comma, deviation in mHz
    let l = layout(
        "Datum;Uhrzeit;Abweichung [mHz]\n19.08.2024;15:26:02;-22,0\n19.08.2024;15:26:03;-21,5\n",
        &berlin,
    )
    .unwrap();
    assert_eq!(
        (l.time, l.unit, l.decimal_comma),
        (
            TimeColumns::DateAndTime(0, 1),
            ValueUnit::MilliHzDeviation,
            true
        )
    );
    assert_eq!(l.order, DateOrder::Dmy);
    // Unix milliseconds are UTC by definition
    let l = layout("ts,freq\n1660723200000,49.968\n1660723201000,49.97\n", &o).unwrap();
    assert_eq!(l.time, TimeColumns::Unix(0, 1e-3));
    // offsets in the rows need no --tz
    let l = layout("Time,Value\n2015-01-01T00:00:00.000+02:00,50.103\n", &o).unwrap();
    assert_eq!(l.zone, ZoneRule::InRows);
    // day and month that cannot be told apart, and tables without times or frequencies
    let e = layout("when,f\n05/06/2022 00:00:00,50.0\n", &berlin)
        .unwrap_err()
        .to_string();
    assert!(e.contains("give date_order dmy or mdy"), "{e}");
    let e = layout("a,b\n1,2\n3,4\n", &o).unwrap_err().to_string();
    assert!(e.contains("no time column") && e.contains("x.csv"), "{e}");
    let e = layout("just some text\n", &o).unwrap_err().to_string();
    assert!(e.contains("not a table"), "{e}");
    let e = layout("time,level\n2024-08-19 15:26:02,3.0\n", &berlin)
        .unwrap_err()
        .to_string();
    assert!(e.contains("give value_unit hz"), "{e}");
}

#[test]
fn values_are_averaged_onto_seconds_and_dropouts_dropped() {
    // 0.1 s rows (Fingrid style, offsets in the rows): each second the mean of its ten
    let mut text = String::from("Time,Value\n");
    for i in 0..50 {
        let v = if i == 23 {
            0.0
        } else {
            50.0 + 0.001 * (i / 10) as f64
        };
        let row = format!("2015-01-01T00:00:{:02}.{}00+02:00,{v:.3}\n", i / 10, i % 10);
        text += &row;
        if i == 24 {
            text += &row; // a repeated row
        }
    }
    text += "garbage,row\n";
    let imp = import_text(&text, &ArchiveOptions::default()).unwrap();
    let r = &imp.report;
    assert_eq!(
        (r.rows, r.implausible, r.repeated, r.unreadable),
        (52, 1, 1, 1),
        "{r:?}"
    );
    assert_eq!(imp.steps.len(), 1);
    assert_eq!(imp.steps[0].start, t("2014-12-31T22:00:00Z"));
    assert_eq!(imp.steps[0].step, 1.0);
    let v = &imp.steps[0].values;
    // steps are centred on whole seconds: the last holds 4.5–4.9 s
    assert_eq!(v.len(), 6);
    for (k, x) in v.iter().enumerate().skip(1).take(4) {
        assert!(
            (x - (50.0 + 0.001 * (k as f64 - 0.5))).abs() < 2e-4,
            "{k}: {x}"
        );
    }
    assert!((r.native_step_s - 0.1).abs() < 1e-9);
    let shown = r.to_string();
    assert!(shown.contains("1 outside the grid's range"), "{shown}");
}

#[test]
fn summer_time_changes_lose_and_double_nothing() {
    // Berlin wall-clock rows, 1 s, across both changes of 2024: values follow UTC time
    let berlin = Zone::parse("Europe/Berlin").unwrap();
    let f = |u: f64| 50.0 + 0.02 * ((u / 600.0).sin());
    let mut text = String::from("time,frequency\n");
    let mut truth = Vec::new();
    for (from, to) in [
        ("2024-03-31T00:00:00Z", "2024-03-31T02:00:00Z"),
        ("2024-10-26T23:30:00Z", "2024-10-27T02:30:00Z"),
    ] {
        let (a, b) = (t(from), t(to));
        let mut u = a;
        while u < b {
            let local = eenf::time::local(u, berlin.offset_at(u));
            text += &format!("{},{:.4}\n", &local[..19], f(u));
            truth.push(u);
            u += 1.0;
        }
    }
    let opts = ArchiveOptions {
        zone: Some(berlin),
        ..Default::default()
    };
    let imp = import_text(&text, &opts).unwrap();
    let r = &imp.report;
    assert_eq!(r.rows as usize, truth.len());
    assert_eq!((r.missing_times, r.second_passage), (0, 3600), "{r:?}");
    assert_eq!(r.clock_changes.len(), 1, "{:?}", r.clock_changes);
    // every UTC second of both stretches holds its own value: no hour lost or doubled
    // the two stretches, seven months apart, are two pieces
    assert_eq!(imp.steps.len(), 2);
    for &u in &truth {
        let s = imp.steps.iter().rfind(|s| s.start <= u).unwrap();
        let i = ((u - s.start) / s.step).round() as usize;
        assert!((s.values[i] - f(u)).abs() < 1e-4, "{}", eenf::time::utc(u));
    }
    let filled: usize = imp
        .steps
        .iter()
        .map(|s| s.values.iter().filter(|v| v.is_finite()).count())
        .sum();
    assert_eq!(filled, truth.len());
    // a time inside the hour skipped in spring is dropped and counted
    let text = "time,frequency\n2024-03-31 01:59:59,50.0\n2024-03-31 02:30:00,50.0\n2024-03-31 03:00:00,50.0\n";
    let imp = import_onto(text, &opts, Some(1.0)).unwrap();
    assert_eq!(imp.report.missing_times, 1);
    assert_eq!(imp.steps[0].values.len(), 2);
}

#[test]
fn a_stray_row_far_away_is_a_piece_and_endless_repeats_end() {
    let utc = ArchiveOptions {
        zone: Some(Zone::utc()),
        ..Default::default()
    };
    // one row 399 days after an hour of rows: two pieces, not 399 days of steps
    let mut text = String::from("time,frequency\n");
    for i in 0..3600 {
        text += &format!("2023-01-01 00:{:02}:{:02},50.01\n", i / 60, i % 60);
    }
    text += "2024-02-04 00:00:00,50.02\n";
    let imp = import_onto(&text, &utc, Some(1.0)).unwrap();
    let lens: Vec<usize> = imp.steps.iter().map(|s| s.values.len()).collect();
    assert_eq!(lens, vec![3600], "the stray row is dropped");
    assert_eq!(imp.report.far, 1);
    // a second hour months away is a piece of its own
    for i in 0..3600 {
        text += &format!("2023-06-05 00:{:02}:{:02},50.02\n", i / 60, i % 60);
    }
    let imp = import_onto(&text, &utc, Some(1.0)).unwrap();
    let lens: Vec<usize> = imp.steps.iter().map(|s| s.values.len()).collect();
    assert_eq!(lens, vec![3600, 3600]);
    // a row repeated past the bound: the rest is not read, and the reading says so
    let mut text = String::from("time,frequency\n2023-01-01 00:00:00,50.0\n");
    text += &"2023-01-01 00:00:01,50.0\n".repeat(MAX_STALE_ROWS as usize + 10);
    text += "2023-01-01 00:00:02,50.0\n";
    let imp = import_onto(&text, &utc, Some(1.0)).unwrap();
    assert_eq!(imp.steps[0].values.len(), 2);
    assert!(
        imp.report
            .warnings
            .iter()
            .any(|w| w.contains("bring no later time")),
        "{:?}",
        imp.report.warnings
    );
}
