//! `eenf refdb fetch` and `refdb update` against a replay server on 127.0.0.1 that answers in
//! each operator's documented format (NESO's datapackage index and monthly `dtm,f` files,
//! Svenska kraftnät's `{"Data": [{x, y}]}`, Swissgrid's `data.series[0].data`), and with every
//! failure a download meets. Nothing here reaches the internet.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use crate::cli::{ok_out_err as ok, refused, truth_hz as truth};
use crate::replay::{query, Replay, Reply, Request};

use eenf::refdb::StoredGrid;
use eenf::time::{parse_time, utc};
use sha2::Digest;

/// `refdb fetch SOURCE --from FROM --to TO --store STORE --cache cache --endpoint ENDPOINT`.
fn fetch_args<'a>(
    source: &'a str,
    from: &'a str,
    to: &'a str,
    store: &'a str,
    endpoint: &'a str,
) -> Vec<&'a str> {
    vec![
        "refdb",
        "fetch",
        source,
        "--from",
        from,
        "--to",
        to,
        "--store",
        store,
        "--cache",
        "cache",
        "--endpoint",
        endpoint,
    ]
}

fn t(s: &str) -> f64 {
    parse_time(s).unwrap()
}

/// A month's file as National Grid ESO publishes it (`dtm,f`, UTC, 1 s, three decimals):
/// here only the last two hours of the month, to keep the test small.
fn gb_month_csv(year: i32, month: u32) -> Vec<u8> {
    let next = if month == 12 {
        format!("{}-01-01T00:00:00Z", year + 1)
    } else {
        format!("{year}-{:02}-01T00:00:00Z", month + 1)
    };
    let end = t(&next);
    let mut text = String::from("dtm,f\n");
    let mut u = end - 7200.0;
    while u < end {
        text += &format!("{},{:.3}\n", utc(u)[..19].replace('T', " "), truth(u));
        u += 1.0;
    }
    text.into_bytes()
}

/// `csv` in a zip, as the older months are published.
fn zipped(name: &str, csv: &[u8]) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    let mut zip = zip::ZipWriter::new(&mut out);
    let opts = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    zip.start_file(name, opts).unwrap();
    zip.write_all(csv).unwrap();
    zip.finish().unwrap();
    out.into_inner()
}

const MONTH_NAMES: [&str; 12] = [
    "january",
    "february",
    "march",
    "april",
    "may",
    "june",
    "july",
    "august",
    "september",
    "october",
    "november",
    "december",
];

/// A GB replay: the datapackage index lists the months in `months` (shared, so that a test
/// can publish another), January as CSV and the others as zip; `cut_once` cuts the first
/// answer for February halfway.
struct Gb {
    replay: Replay,
    months: Arc<Mutex<Vec<u32>>>,
}

fn gb_server(cut_once: bool, cut_always: bool) -> Gb {
    let months = Arc::new(Mutex::new(vec![1u32, 2]));
    let m2 = months.clone();
    let cut_done = Arc::new(AtomicBool::new(false));
    let base = Arc::new(Mutex::new(String::new()));
    let base2 = base.clone();
    let replay = Replay::start(move |r: &Request| {
        let base = base2.lock().unwrap().clone();
        let path = r.target.split('?').next().unwrap_or("");
        if path == "/api/3/action/datapackage_show" {
            let resources: Vec<serde_json::Value> = m2
                .lock()
                .unwrap()
                .iter()
                .map(|&m| {
                    let zip = m != 1;
                    serde_json::json!({
                        // libhum reads both dashes; NESO has used both
                        "name": format!("{}_2023_{}_historic_frequency_data", MONTH_NAMES[m as usize - 1], if m == 2 { "–" } else { "-" }),
                        // March's address is relative to the index's host, as a mirror may write it
                        "path": format!("{}/files/f-2023-{m}.{}", if m == 3 { "" } else { &base }, if zip { "zip" } else { "csv" }),
                        "format": if zip { "ZIP" } else { "CSV" },
                    })
                })
                .collect();
            let index = serde_json::json!({"success": true, "result": {"name": "system-frequency-data", "resources": resources}});
            return Reply::ok(index.to_string().into_bytes());
        }
        for m in 1..=12u32 {
            let csv = format!("/files/f-2023-{m}.csv");
            let zip = format!("/files/f-2023-{m}.zip");
            if path == csv {
                return Reply::file(gb_month_csv(2023, m), r.range_from);
            }
            if path == zip {
                let body = zipped(&format!("f-2023-{m}.csv"), &gb_month_csv(2023, m));
                let mut reply = Reply::file(body, r.range_from);
                if m == 2
                    && r.range_from.is_none()
                    && (cut_always || (cut_once && !cut_done.swap(true, Ordering::SeqCst)))
                {
                    reply.cut = Some(reply.body.len() / 2);
                }
                return reply;
            }
        }
        Reply::status(404)
    });
    *base.lock().unwrap() = replay.base.clone();
    Gb { replay, months }
}

fn gb_endpoint(gb: &Gb) -> String {
    format!(
        "{}/api/3/action/datapackage_show?id=system-frequency-data",
        gb.replay.base
    )
}

/// The files of the store at `dir` and their bytes (its lock file aside): equal before and
/// after means the store was left as it was.
fn store_digest(dir: &Path) -> String {
    let mut names: Vec<PathBuf> = match std::fs::read_dir(dir) {
        Ok(r) => r.map(|e| e.unwrap().path()).collect(),
        Err(_) => return "no store".into(),
    };
    names.sort();
    let mut h = sha2::Sha256::new();
    for p in names {
        let n = p.file_name().unwrap().to_string_lossy().into_owned();
        if n.starts_with(".eenf-store.lock") {
            continue;
        }
        h.update(n.as_bytes());
        h.update(std::fs::read(&p).unwrap());
    }
    format!("{:x}", h.finalize())
}

fn files_in(dir: &Path) -> Vec<String> {
    let mut out: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path().display().to_string())
        .filter(|p| !p.ends_with(".part"))
        .collect();
    out.sort();
    out
}

fn sha256_hex(path: &str) -> String {
    format!("{:x}", sha2::Sha256::digest(std::fs::read(path).unwrap()))
}

#[test]
fn gb_fetch_fills_the_store_refdb_build_makes_from_the_same_files_and_update_fetches_only_the_new_month(
) {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let gb = gb_server(false, false);
    let endpoint = gb_endpoint(&gb);
    let (out, err) = ok(
        &fetch_args("gb", "2023-01-01", "2023-02-28", "fetched", &endpoint),
        d,
    );
    assert!(err.contains("downloaded"), "{err}");
    // the index, then one file per month
    let requests = gb.replay.requests();
    assert_eq!(requests.len(), 3, "{requests:?}");
    let cached = files_in(&d.join("cache/gb"));
    assert_eq!(cached.len(), 2, "{cached:?}");

    // the same files through refdb build
    let mut args = vec![
        "refdb", "build", "built", "--format", "ngeso", "--grid", "gb",
    ];
    args.extend(cached.iter().map(String::as_str));
    ok(&args, d);
    let a = StoredGrid::load(&d.join("fetched"), "gb").unwrap();
    let b = StoredGrid::load(&d.join("built"), "gb").unwrap();
    assert_eq!(a.values, b.values, "fetch and build differ");
    assert_eq!(a.meta.start_unix_s, b.meta.start_unix_s);
    assert_eq!(a.meta.step_s, b.meta.step_s);
    // and the values are the operator's, to its three decimals
    let at = t("2023-02-28T23:00:00Z");
    let i = ((at - a.meta.start_unix_s) / a.meta.step_s).round() as usize;
    let hz = a.hz()[i];
    assert!((hz - truth(at)).abs() < 0.0006, "{hz} vs {}", truth(at));

    // provenance: source, address, time of retrieval, SHA-256 of each file
    assert_eq!(a.meta.fetched.len(), 1);
    let prov = &a.meta.fetched[0];
    assert_eq!(prov.source, "gb");
    assert_eq!(prov.endpoint, endpoint);
    assert_eq!(prov.files.len(), 2);
    for (f, path) in prov.files.iter().zip(&cached) {
        assert_eq!(f.sha256, sha256_hex(path));
        assert!(f.url.starts_with(&gb.replay.base), "{}", f.url);
        assert!(f.retrieved_utc.ends_with('Z'), "{}", f.retrieved_utc);
    }
    assert!(b.meta.fetched.is_empty());
    for f in &prov.files {
        assert!(
            out.contains(&f.sha256),
            "refdb info does not show {}: {out}",
            f.sha256
        );
    }
    assert!(
        out.contains(&format!("fetched     gb from {endpoint}")),
        "{out}"
    );

    // March is published: update asks the index and March, nothing else
    gb.months.lock().unwrap().push(3);
    gb.replay.clear();
    ok(&["refdb", "update", "fetched", "--cache", "cache"], d);
    let requests = gb.replay.requests();
    assert_eq!(requests.len(), 2, "{requests:?}");
    assert!(requests[1].contains("f-2023-3"), "{requests:?}");
    let a = StoredGrid::load(&d.join("fetched"), "gb").unwrap();
    let at = t("2023-03-31T23:30:00Z");
    let i = ((at - a.meta.start_unix_s) / a.meta.step_s).round() as usize;
    assert!((a.hz()[i] - truth(at)).abs() < 0.0006);
    assert_eq!(a.meta.fetched[0].files.len(), 3);
    // nothing new: nothing downloaded
    gb.replay.clear();
    let (_, err) = ok(&["refdb", "update", "fetched", "--cache", "cache"], d);
    assert!(
        gb.replay.requests().len() <= 1,
        "{:?}",
        gb.replay.requests()
    );
    assert!(!err.contains("downloaded"), "{err}");
}

#[test]
fn a_cut_download_fails_in_one_line_then_resumes_where_it_was_cut_and_gives_the_same_store() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let gb = gb_server(true, false);
    let endpoint = gb_endpoint(&gb);
    let fetch = |store: &str, retries: &str| -> Vec<String> {
        vec![
            "refdb".into(),
            "fetch".into(),
            "gb".into(),
            "--from".into(),
            "2023-01-01".into(),
            "--to".into(),
            "2023-02-28".into(),
            "--store".into(),
            store.into(),
            "--cache".into(),
            "cache".into(),
            "--endpoint".into(),
            endpoint.clone(),
            "--retries".into(),
            retries.into(),
        ]
    };
    let args = fetch("s", "0");
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let err = refused(&args, d);
    assert!(err.contains("gb:") && err.contains("cut after"), "{err}");
    assert_eq!(
        store_digest(&d.join("s")),
        "no store",
        "a failed fetch made a store"
    );
    let part = files_in(&d.join("cache/gb"));
    assert!(
        std::fs::read_dir(d.join("cache/gb")).unwrap().any(|e| e
            .unwrap()
            .path()
            .to_string_lossy()
            .ends_with(".part")),
        "{part:?}"
    );

    gb.replay.clear();
    ok(&args, d);
    let requests = gb.replay.requests();
    assert!(
        requests.iter().any(|r| r.contains("f-2023-2.zip range=")),
        "not resumed: {requests:?}"
    );
    assert!(
        !requests.iter().any(|r| r.ends_with("f-2023-1.csv")),
        "January fetched again: {requests:?}"
    );

    // the same store as a download never cut
    let clean = gb_server(false, false);
    let e2 = gb_endpoint(&clean);
    ok(
        &[
            "refdb",
            "fetch",
            "gb",
            "--from",
            "2023-01-01",
            "--to",
            "2023-02-28",
            "--store",
            "clean",
            "--cache",
            "cache2",
            "--endpoint",
            &e2,
        ],
        d,
    );
    let a = StoredGrid::load(&d.join("s"), "gb").unwrap();
    let b = StoredGrid::load(&d.join("clean"), "gb").unwrap();
    assert_eq!(a.values, b.values);
    assert_eq!(
        a.meta.fetched[0].files[1].sha256,
        b.meta.fetched[0].files[1].sha256
    );
}

#[test]
fn every_failure_is_one_line_naming_the_source_and_leaves_the_store_as_it_was() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let gb = gb_server(false, true);
    let endpoint = gb_endpoint(&gb);
    // a store with January in it
    ok(
        &fetch_args("gb", "2023-01-01", "2023-01-31", "s", &endpoint),
        d,
    );
    let before = store_digest(&d.join("s"));
    let status = |code: u16, headers: Vec<(String, String)>| {
        Replay::start(move |_r: &Request| Reply {
            status: code,
            headers: headers.clone(),
            body: b"{}".to_vec(),
            cut: None,
        })
    };
    let s404 = status(404, vec![]);
    let s429 = status(429, vec![("Retry-After".into(), "3600".into())]);
    let changed = Replay::start(|_r: &Request| {
        Reply::ok(br#"{"success": true, "result": {"name": "x", "files": []}}"#.to_vec())
    });
    let se_changed = Replay::start(|_r: &Request| {
        Reply::ok(br#"{"Data": [{"time": 1, "value": 50.0}]}"#.to_vec())
    });
    let cases: Vec<(&str, String, &str, &[&str])> = vec![
        (
            "gb",
            "http://127.0.0.1:1/index".to_string(),
            "no answer",
            &[],
        ),
        ("gb", format!("{}/index", s404.base), "404", &[]),
        ("gb", format!("{}/index", s429.base), "wait 3600 s", &[]),
        // the index is fine, February's body is always cut
        ("gb", endpoint.clone(), "cut after", &["--to", "2023-02-28"]),
        (
            "gb",
            format!("{}/index", changed.base),
            "no resources list (expected NESO's datapackage JSON",
            &[],
        ),
        (
            "se",
            format!("{}/freq", se_changed.base),
            "format may have changed",
            &[],
        ),
        ("se", format!("{}/freq", s404.base), "404", &[]),
    ];
    for (source, url, expected, extra) in cases {
        let mut args = vec![
            "refdb",
            "fetch",
            source,
            "--from",
            "2023-01-15",
            "--store",
            "s",
            "--cache",
            "cache",
            "--retries",
            "0",
            "--endpoint",
            &url,
        ];
        if extra.is_empty() {
            args.extend(["--to", "2023-01-15T02:00:00Z"]);
        }
        args.extend(extra);
        let err = refused(&args, d);
        assert!(
            err.starts_with(&format!("error: {source}:")) || err.contains(&format!(" {source}: ")),
            "{err}"
        );
        assert!(
            err.contains(expected),
            "{url}: expected {expected:?}: {err}"
        );
        assert_eq!(
            store_digest(&d.join("s")),
            before,
            "{url} changed the store: {err}"
        );
    }
}

/// Svenska kraftnät's answer for `[from_ms, to_ms)`, one point a second.
fn svk_answer(from_ms: i64, to_ms: i64) -> Vec<u8> {
    let data: Vec<serde_json::Value> = (from_ms / 1000..to_ms / 1000)
        .map(|s| serde_json::json!({"x": s * 1000, "y": (truth(s as f64) * 1000.0).round() / 1000.0}))
        .collect();
    serde_json::json!({ "Data": data }).to_string().into_bytes()
}

#[test]
fn se_fetch_asks_an_hour_at_a_time_and_fills_the_store_refdb_build_makes_from_the_same_files() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let longest = Arc::new(AtomicUsize::new(0));
    let l2 = longest.clone();
    let se = Replay::start(move |r: &Request| {
        let (Some(a), Some(b)) = (
            query(&r.target, "fromDateTime"),
            query(&r.target, "toDateTime"),
        ) else {
            return Reply::status(400);
        };
        let (a, b): (i64, i64) = (a.parse().unwrap(), b.parse().unwrap());
        l2.fetch_max((b - a) as usize, Ordering::SeqCst);
        Reply::ok(svk_answer(a, b))
    });
    let endpoint = format!("{}/services/controlroom/v2/freq", se.base);
    ok(
        &fetch_args(
            "se",
            "2023-05-01T10:30:00Z",
            "2023-05-01T13:00:00Z",
            "fetched",
            &endpoint,
        ),
        d,
    );
    assert_eq!(se.requests().len(), 3, "{:?}", se.requests());
    assert!(longest.load(Ordering::SeqCst) <= 3_600_000);
    let cached = files_in(&d.join("cache/se"));
    let mut args = vec!["refdb", "build", "built", "--grid", "se"];
    args.extend(cached.iter().map(String::as_str));
    ok(&args, d);
    let a = StoredGrid::load(&d.join("fetched"), "se").unwrap();
    let b = StoredGrid::load(&d.join("built"), "se").unwrap();
    assert_eq!(a.values, b.values);
    assert_eq!(a.meta.start_unix_s, t("2023-05-01T10:00:00Z"));
    assert_eq!(a.meta.count, 3 * 3600);
    let at = t("2023-05-01T12:34:56Z");
    let i = (at - a.meta.start_unix_s) as usize;
    assert!((a.hz()[i] - truth(at)).abs() < 0.0006);
    assert_eq!(a.meta.fetched[0].files.len(), 3);
    // past hours are final: asked again, they come from the cache
    se.clear();
    ok(
        &fetch_args(
            "se",
            "2023-05-01T10:30:00Z",
            "2023-05-01T13:00:00Z",
            "fetched",
            &endpoint,
        ),
        d,
    );
    assert!(se.requests().is_empty(), "{:?}", se.requests());
    // an address written as libhum's template asks the same hours
    let template = format!("{endpoint}?fromDateTime={{from_dt}}&toDateTime={{to_dt}}");
    ok(
        &[
            "refdb",
            "fetch",
            "se",
            "--from",
            "2023-05-01T13:00:00Z",
            "--to",
            "2023-05-01T14:00:00Z",
            "--store",
            "fetched",
            "--cache",
            "cache2",
            "--endpoint",
            &template,
        ],
        d,
    );
    let r = se.requests();
    assert_eq!(r.len(), 1, "{r:?}");
    assert!(
        r[0].ends_with("fromDateTime=1682946000000&toDateTime=1682949600000"),
        "{r:?}"
    );
}

/// Swissgrid's chart answer: the last ten minutes at 1 s, its times encoded as `offset_s`
/// east of UTC (3600 or 7200: Zurich's wall clock; 0: Unix time).
fn swissgrid_answer(now: f64, zurich: bool) -> Vec<u8> {
    let offset = if zurich {
        eenf::time::Zone::parse("Europe/Zurich")
            .unwrap()
            .offset_at(now)
    } else {
        0.0
    };
    let end = now.floor() - 30.0;
    let data: Vec<serde_json::Value> = (0..600)
        .map(|k| {
            let u = end - 600.0 + k as f64;
            serde_json::json!([
                ((u + offset) * 1000.0) as i64,
                (truth(u) * 1000.0).round() / 1000.0
            ])
        })
        .collect();
    serde_json::json!({"data": {"series": [{"name": "Frequenz", "data": data}]}})
        .to_string()
        .into_bytes()
}

#[test]
fn ch_times_are_read_in_the_zone_the_time_of_retrieval_shows() {
    for zurich in [true, false] {
        let tmp = tempfile::tempdir().unwrap();
        let d = tmp.path();
        let ch = Replay::start(move |_r: &Request| {
            let now = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .unwrap()
                .as_secs_f64();
            Reply::ok(swissgrid_answer(now, zurich))
        });
        let now = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap()
            .as_secs_f64();
        let from = utc((now - 3600.0).floor());
        let (_, err) = ok(
            &[
                "refdb",
                "fetch",
                "ch",
                "--from",
                &from,
                "--store",
                "s",
                "--cache",
                "cache",
                "--endpoint",
                &format!("{}/chart", ch.base),
            ],
            d,
        );
        let zone = if zurich { "Europe/Zurich" } else { "UTC" };
        assert!(err.contains(&format!("read as {zone}")), "{err}");
        let a = StoredGrid::load(&d.join("s"), "ch").unwrap();
        // the values sit at their true UTC times
        let mid = a.meta.start_unix_s + 300.0;
        let hz = a.hz()[300];
        assert!(
            (hz - truth(mid)).abs() < 0.0006,
            "{zone}: {hz} vs {}",
            truth(mid)
        );
        assert!(
            (a.meta.start_unix_s - (now - 630.0)).abs() < 5.0,
            "{zone}: starts at {}",
            utc(a.meta.start_unix_s)
        );
    }
}

/// Fingrid's answer for `[a, b)`: 1 s values, in pages of 2,000 rows (the server's choice, as
/// the API caps a page), with the API's `pagination`.
fn fingrid_answer(a: f64, b: f64, page: usize) -> Vec<u8> {
    let rows: Vec<f64> = (0..(b - a) as usize).map(|k| a + k as f64).collect();
    let per = 2000;
    let pages = rows.len().div_ceil(per).max(1);
    let data: Vec<serde_json::Value> = rows
        .iter()
        .skip((page - 1) * per)
        .take(per)
        .map(|&u| {
            serde_json::json!({"datasetId": 177, "startTime": utc(u).replace('Z', ".000Z"),
                "endTime": utc(u + 1.0).replace('Z', ".000Z"), "value": (truth(u) * 1000.0).round() / 1000.0})
        })
        .collect();
    serde_json::json!({"data": data, "pagination": {"total": rows.len(), "lastPage": pages,
        "prevPage": if page > 1 { Some(page - 1) } else { None },
        "nextPage": if page < pages { Some(page + 1) } else { None },
        "perPage": per, "currentPage": page, "from": (page - 1) * per + 1, "to": (page * per).min(rows.len())}})
    .to_string()
    .into_bytes()
}

#[test]
fn fi_fetch_sends_its_key_follows_the_pages_and_fills_the_store_refdb_build_makes() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    let fi = Replay::start(|r: &Request| {
        if r.api_key.as_deref() != Some("k3y") {
            return Reply::status(401);
        }
        let (Some(a), Some(b), Some(p)) = (
            query(&r.target, "startTime"),
            query(&r.target, "endTime"),
            query(&r.target, "page"),
        ) else {
            return Reply::status(400);
        };
        Reply::ok(fingrid_answer(t(&a), t(&b), p.parse().unwrap()))
    });
    let endpoint = format!("{}/api/datasets/177/data", fi.base);
    let mut args = fetch_args(
        "fi",
        "2023-06-01T00:00:00Z",
        "2023-06-01T01:00:00Z",
        "fetched",
        &endpoint,
    );
    // no key: one line, before any request
    let err = refused(&args, d);
    assert!(err.contains("fi:") && err.contains("--api-key"), "{err}");
    assert!(fi.requests().is_empty());
    // a wrong key: the server's 401, named
    args.extend(["--api-key", "wrong", "--retries", "0"]);
    let err = refused(&args, d);
    assert!(err.contains("401") && err.contains("API key"), "{err}");
    fi.clear();
    let n = args.len();
    args[n - 3] = "k3y";
    ok(&args, d);
    let requests = fi.requests();
    assert_eq!(requests.len(), 2, "{requests:?}");
    assert!(requests[1].contains("page=2"), "{requests:?}");
    let cached = files_in(&d.join("cache/fi"));
    let mut build = vec!["refdb", "build", "built", "--grid", "fi"];
    build.extend(cached.iter().map(String::as_str));
    ok(&build, d);
    let a = StoredGrid::load(&d.join("fetched"), "fi").unwrap();
    let b = StoredGrid::load(&d.join("built"), "fi").unwrap();
    assert_eq!(a.values, b.values);
    assert_eq!(a.meta.count, 3600);
    let at = t("2023-06-01T00:45:00Z");
    assert!((a.hz()[2700] - truth(at)).abs() < 0.0006);
    // the key is sent, never stored
    let manifest = std::fs::read_to_string(d.join("fetched/fi.json")).unwrap();
    assert!(!manifest.contains("k3y"));
}
