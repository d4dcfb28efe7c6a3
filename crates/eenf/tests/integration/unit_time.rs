//! Tests of eenf's `time` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf::time::*;

#[test]
fn utc_formatting() {
    assert_eq!(utc_micros(0), "1970-01-01T00:00:00.000000Z");
    assert_eq!(
        clock_text(1_317_888),
        "1.317888 s on the camera's clock, no date"
    );
    assert_eq!(
        clock_text(1_605_537_493_718_345),
        "2020-11-16T14:38:13.718345Z"
    );
    assert_eq!(
        utc_micros(1_660_723_800_000_001),
        "2022-08-17T08:10:00.000001Z"
    );
}

#[test]
fn times_parse() {
    assert_eq!(parse_time("1970-01-02T00:00:00Z").unwrap(), 86_400.0);
    assert_eq!(
        parse_time("2022-08-17T16:00:00+08:00").unwrap(),
        parse_time("2022-08-17T08:00:00Z").unwrap()
    );
    assert_eq!(parse_time("12.5").unwrap(), 12.5);
    assert!(parse_time("yesterday").is_err());
    assert_eq!(utc(1_660_723_200.0), "2022-08-17T08:00:00Z");
    assert_eq!(
        parse_time("2022-08-01T00:00:00-04:00").unwrap(),
        parse_time("2022-08-01T04:00:00Z").unwrap()
    );
    assert_eq!(tz_offset("+08:00").unwrap(), 28_800.0);
    assert_eq!(tz_offset("-0500").unwrap(), -18_000.0);
    assert_eq!(offset_of("2022-08-17T16:10:00+08:00").unwrap(), 28_800.0);
    assert_eq!(offset_of("2022-08-17T16:10:00").unwrap(), 0.0);
}

#[test]
fn zones_follow_summer_time() {
    let berlin = Zone::parse("Europe/Berlin").unwrap();
    assert_eq!(berlin.name(), "Europe/Berlin");
    assert!(!berlin.is_fixed());
    let at = |y, mo, d, h, mi| LocalTime::new(y, mo, d, h, mi, 0).unwrap().local_seconds();
    // CEST in August: 15:26:02 local is 13:26:02 UTC
    let aug = at(2024, 8, 19, 15, 26) + 2;
    assert_eq!(
        berlin.instant(aug),
        LocalInstant::Unique(parse_time("2024-08-19T13:26:02Z").unwrap())
    );
    assert_eq!(
        berlin.offset_at(parse_time("2024-01-10T12:00:00Z").unwrap()),
        3600.0
    );
    // 2024-03-31 02:30 does not exist; 2024-10-27 02:30 happens twice, an hour apart
    assert_eq!(
        berlin.instant(at(2024, 3, 31, 2, 30)),
        LocalInstant::Missing
    );
    assert_eq!(
        berlin.instant(at(2024, 10, 27, 2, 30)),
        LocalInstant::Repeated(
            parse_time("2024-10-27T00:30:00Z").unwrap(),
            parse_time("2024-10-27T01:30:00Z").unwrap()
        )
    );
    assert_eq!(
        berlin.local(parse_time("2024-10-27T01:30:00Z").unwrap()),
        "2024-10-27 02:30:00 +01:00"
    );
    let ny = Zone::parse("America/New_York").unwrap();
    assert_eq!(
        ny.offset_at(parse_time("2022-08-01T00:00:00Z").unwrap()),
        -4.0 * 3600.0
    );
    for (s, name) in [
        ("+08:00", "+08:00"),
        ("Z", "UTC"),
        ("utc", "UTC"),
        ("-0530", "-05:30"),
    ] {
        let z = Zone::parse(s).unwrap();
        assert!(z.is_fixed());
        assert_eq!(z.name(), name, "{s}");
    }
    let e = Zone::parse("Mars/Olympus").unwrap_err().to_string();
    assert!(e.contains("IANA"), "{e}");
}

#[test]
fn civil_days() {
    let day = |y, m, d| LocalTime::new(y, m, d, 0, 0, 0).unwrap().local_seconds() / 86_400;
    assert_eq!(day(1970, 1, 1), 0);
    assert_eq!(day(2022, 8, 17), 19_221);
    assert_eq!(day(2000, 3, 1), 11_017);
    let leap = LocalTime::from_local_seconds(day(2024, 2, 29) * 86_400 + 3661);
    assert_eq!(
        (leap.month(), leap.day(), leap.hour(), leap.minute()),
        (2, 29, 1, 1)
    );
    assert_eq!(leap.weekday(), "Thu");
    for (y, m, d) in [
        (1970, 1, 1),
        (2022, 8, 17),
        (2000, 3, 1),
        (2024, 2, 29),
        (1969, 12, 31),
    ] {
        assert_eq!(
            days_from_civil(y as i64, m, d),
            day(y, m as i8, d as i8),
            "{y}-{m}-{d}"
        );
    }
    assert_eq!(
        (
            days_in_month(2024, 2),
            days_in_month(1900, 2),
            days_in_month(2000, 2)
        ),
        (29, 28, 29)
    );
}
