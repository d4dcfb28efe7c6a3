//! The page's API, over HTTP on 127.0.0.1: the token, uploads (good, garbage, too large, badly
//! named, two at once), the results and the report against the library run directly.

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use eenf_serve::{ServeOptions, Server};
use serde_json::Value;

/// A server on its own runtime and thread, stopped when dropped.
struct Running {
    addr: SocketAddr,
    token: String,
    stop: Option<tokio::sync::oneshot::Sender<()>>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Drop for Running {
    fn drop(&mut self) {
        if let Some(s) = self.stop.take() {
            let _ = s.send(());
        }
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn start(opts: ServeOptions) -> Running {
    let (tx, rx) = std::sync::mpsc::channel();
    let (stop, stopped) = tokio::sync::oneshot::channel::<()>();
    let thread = std::thread::spawn(move || {
        let rt = tokio::runtime::Runtime::new().unwrap();
        rt.block_on(async move {
            let server = Server::bind(opts).await.unwrap();
            assert!(server.url().starts_with("http://127.0.0.1:"));
            tx.send((server.addr(), server.token().to_string()))
                .unwrap();
            server
                .run(async {
                    let _ = stopped.await;
                })
                .await
                .unwrap();
        });
        rt.shutdown_timeout(Duration::from_millis(200));
    });
    let (addr, token) = rx.recv().unwrap();
    Running {
        addr,
        token,
        stop: Some(stop),
        thread: Some(thread),
    }
}

fn options(dir: &Path) -> ServeOptions {
    ServeOptions {
        port: 0,
        temp_dir: Some(dir.to_path_buf()),
        ..ServeOptions::default()
    }
}

/// One HTTP/1.1 exchange: the status and the body.
fn http(addr: SocketAddr, head: &str, body: &[u8]) -> (u16, Vec<u8>) {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    let req = format!(
        "{head}\r\nHost: {addr}\r\nConnection: close\r\nContent-Length: {}\r\n\r\n",
        body.len()
    );
    s.write_all(req.as_bytes()).unwrap();
    // a server that refuses early may close before the whole body is sent
    let _ = s.write_all(body);
    let mut out = Vec::new();
    let _ = s.read_to_end(&mut out);
    let split = out
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("a response");
    let status_line = String::from_utf8_lossy(&out[..split]).to_string();
    let code = status_line.split(' ').nth(1).unwrap().parse().unwrap();
    let head_text = status_line.to_ascii_lowercase();
    let mut body = out[split + 4..].to_vec();
    if head_text.contains("transfer-encoding: chunked") {
        body = unchunk(&body);
    }
    (code, body)
}

fn unchunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let end = b.windows(2).position(|w| w == b"\r\n").unwrap();
        let n = usize::from_str_radix(std::str::from_utf8(&b[..end]).unwrap().trim(), 16).unwrap();
        if n == 0 {
            return out;
        }
        out.extend_from_slice(&b[end + 2..end + 2 + n]);
        b = &b[end + 2 + n + 2..];
    }
}

fn get(r: &Running, path: &str) -> (u16, Vec<u8>) {
    http(
        r.addr,
        &format!("GET {path} HTTP/1.1\r\nX-Eenf-Token: {}", r.token),
        b"",
    )
}

fn get_json(r: &Running, path: &str) -> Value {
    let (code, body) = get(r, path);
    assert_eq!(code, 200, "{}", String::from_utf8_lossy(&body));
    serde_json::from_slice(&body).unwrap()
}

/// Posts `bytes` as the form's `file`, named `name` by the "browser".
fn upload(r: &Running, name: &str, bytes: &[u8], options: &str) -> (u16, Value) {
    let boundary = "eenfTestBoundary7MA4YWxkTrZu0gW";
    let mut body = Vec::new();
    body.extend_from_slice(
        format!(
            "--{boundary}\r\nContent-Disposition: form-data; name=\"options\"\r\n\r\n{options}\r\n"
        )
        .as_bytes(),
    );
    body.extend_from_slice(format!("--{boundary}\r\nContent-Disposition: form-data; name=\"file\"; filename=\"{name}\"\r\nContent-Type: application/octet-stream\r\n\r\n").as_bytes());
    body.extend_from_slice(bytes);
    body.extend_from_slice(format!("\r\n--{boundary}--\r\n").as_bytes());
    let (code, out) = http(
        r.addr,
        &format!(
            "POST /api/analyses HTTP/1.1\r\nX-Eenf-Token: {}\r\nContent-Type: multipart/form-data; boundary={boundary}",
            r.token
        ),
        &body,
    );
    (code, serde_json::from_slice(&out).unwrap_or(Value::Null))
}

/// Polls analysis `id` until it is done or failed.
fn finished(r: &Running, id: u64) -> Value {
    let t0 = Instant::now();
    loop {
        let v = get_json(r, &format!("/api/analyses/{id}"));
        if v["state"] == "done" || v["state"] == "failed" {
            return v;
        }
        assert!(t0.elapsed() < Duration::from_secs(300), "{v}");
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// A minute of mains hum at 8 kHz: 50 Hz wandering by ±20 mHz, with its second harmonic and
/// noise (the truth is known, and the page must give the library's own trace of it).
fn hum_wav(path: &Path, seed: u64) {
    let fs = 8000.0;
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: 8000,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut w = hound::WavWriter::create(path, spec).unwrap();
    let mut phase = 0.0f64;
    let mut state = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
    for i in 0..(60.0 * fs) as usize {
        let t = i as f64 / fs;
        let f = 50.0 + 0.02 * (2.0 * std::f64::consts::PI * t / 23.0).sin();
        phase += 2.0 * std::f64::consts::PI * f / fs;
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let noise = ((state >> 33) as f64 / (1u64 << 31) as f64) - 0.5;
        let v = 0.3 * phase.sin() + 0.1 * (2.0 * phase).sin() + 0.05 * noise;
        w.write_sample((v * 32767.0) as i16).unwrap();
    }
    w.finalize().unwrap();
}

/// Every file under `dir`, in its subfolders too.
fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(files_in(&p));
        } else {
            out.push(p);
        }
    }
    out
}

#[test]
fn every_request_needs_the_token() {
    let dir = tempfile::tempdir().unwrap();
    let r = start(options(dir.path()));
    for path in ["/", "/app.js", "/api/config", "/api/analyses/1"] {
        let (code, _) = http(r.addr, &format!("GET {path} HTTP/1.1"), b"");
        assert_eq!(code, 401, "{path} without a token");
        let (code, _) = http(
            r.addr,
            &format!("GET {path}?token=0123456789abcdef0123456789abcdef HTTP/1.1"),
            b"",
        );
        assert_eq!(code, 403, "{path} with a wrong token");
    }
    let (code, _) = http(r.addr, "POST /api/analyses HTTP/1.1", b"x");
    assert_eq!(code, 401);
    // the URL's token, the header and the page's cookie each let a request in
    let (code, page) = http(r.addr, &format!("GET /?token={} HTTP/1.1", r.token), b"");
    assert_eq!(code, 200);
    let page = String::from_utf8(page).unwrap();
    for hook in [
        "type=\"file\"",
        "id=\"verdict\"",
        "id=\"trace\"",
        "id=\"match\"",
        "id=\"edits\"",
        "id=\"report\"",
    ] {
        assert!(page.contains(hook), "the page lacks {hook}");
    }
    let (code, _) = http(
        r.addr,
        &format!(
            "GET /app.js HTTP/1.1\r\nCookie: other=1; eenf_token={}",
            r.token
        ),
        b"",
    );
    assert_eq!(code, 200);
    assert_eq!(get(&r, "/api/config").0, 200);
}

#[test]
fn a_sound_is_traced_as_the_library_traces_it_and_reported_with_its_digest() {
    let dir = tempfile::tempdir().unwrap();
    let wav = dir.path().join("hum.wav");
    hum_wav(&wav, 1);
    let bytes = std::fs::read(&wav).unwrap();
    let uploads = tempfile::tempdir().unwrap();
    let r = start(options(uploads.path()));
    let (code, v) = upload(&r, "evidence 1.wav", &bytes, "{}");
    assert_eq!(code, 202, "{v}");
    let done = finished(&r, v["id"].as_u64().unwrap());
    assert_eq!(done["state"], "done", "{done}");
    let res = &done["result"];
    assert_eq!(res["kind"], "sound");
    assert_eq!(res["grid_hz"], 50.0);
    let verdict = res["verdict"].as_str().unwrap();
    assert!(verdict.starts_with("50 Hz grid, "), "{verdict}");
    assert!(res["figures"]["trace"].as_str().unwrap().contains("<svg"));
    assert!(res["edits_verdict"].as_str().unwrap().len() > 10);
    // the library on the same file, with the same defaults
    let settings = eenf::analysis::AnalysisSettings::default();
    let lib = eenf::mains::audio_trace(
        &wav,
        &settings.audio.options(),
        &settings.audio.hum(&settings.tracker),
        settings.tracker.nominal,
        &settings.tracker.params().unwrap(),
    )
    .unwrap();
    let page: Vec<f64> = res["trace"]["enf_hz"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap_or(f64::NAN))
        .collect();
    assert_eq!(page.len(), lib.enf_hz.len());
    for (a, b) in page.iter().zip(&lib.enf_hz) {
        assert!(
            (a - b).abs() < 1e-9 || (a.is_nan() && b.is_nan()),
            "{a} {b}"
        );
    }
    // the truth: 50 Hz ± 20 mHz
    let worst = page
        .iter()
        .filter(|x| x.is_finite())
        .fold(0.0f64, |m, x| m.max((x - 50.0).abs()));
    assert!(worst < 0.03, "{worst}");
    // the report: the file's name and SHA-256 (by the system's sha256sum), and the trace
    let digest = std::process::Command::new("sha256sum")
        .arg(&wav)
        .output()
        .map(|o| {
            String::from_utf8_lossy(&o.stdout)
                .split(' ')
                .next()
                .unwrap_or("")
                .to_string()
        })
        .unwrap_or_default();
    assert_eq!(done["sha256"].as_str().unwrap(), digest);
    let (code, report) = get(&r, &format!("/api/analyses/{}/report", v["id"]));
    assert_eq!(code, 200);
    let report = String::from_utf8(report).unwrap();
    assert!(report.contains(&digest), "the report names the digest");
    assert!(report.contains("evidence 1.wav"));
    assert!(report.contains(&format!("{} bytes", bytes.len())));
    assert!(
        !report.contains(&uploads.path().display().to_string()),
        "no server path"
    );
    let start = report
        .find("id=\"trace-json\" type=\"application/json\">")
        .unwrap();
    let json = &report[start..];
    let json = &json[json.find('>').unwrap() + 1..json.find("</script>").unwrap()];
    let trace: Value = serde_json::from_str(json).unwrap();
    assert_eq!(trace["enf_hz"].as_array().unwrap().len(), lib.enf_hz.len());
    // the upload is removed once analysed
    assert!(
        files_in(uploads.path()).is_empty(),
        "{:?}",
        files_in(uploads.path())
    );
}

#[test]
fn garbage_gives_a_one_line_error_and_the_next_upload_works() {
    let uploads = tempfile::tempdir().unwrap();
    let r = start(options(uploads.path()));
    let garbage: Vec<u8> = (0..50_000u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
        .collect();
    for name in [
        "noise.wav",
        "noise.bin",
        "trace.csv",
        "clip.mp4",
        "x.aedat4",
    ] {
        let (code, v) = upload(&r, name, &garbage, "{}");
        assert_eq!(code, 202);
        let done = finished(&r, v["id"].as_u64().unwrap());
        assert_eq!(done["state"], "failed", "{name}: {done}");
        let e = done["error"].as_str().unwrap();
        assert!(!e.contains('\n') && e.contains(name), "{name}: {e}");
        assert!(!e.contains(&uploads.path().display().to_string()), "{e}");
    }
    let (code, v) = upload(&r, "options.wav", b"RIFF", "{\"window\": -3}");
    assert_eq!(code, 202);
    let done = finished(&r, v["id"].as_u64().unwrap());
    assert_eq!(done["state"], "failed");
    assert!(done["error"].as_str().unwrap().contains("window"), "{done}");
    let dir = tempfile::tempdir().unwrap();
    let wav = dir.path().join("hum.wav");
    hum_wav(&wav, 2);
    let (_, v) = upload(&r, "hum.wav", &std::fs::read(&wav).unwrap(), "{}");
    assert_eq!(finished(&r, v["id"].as_u64().unwrap())["state"], "done");
    assert!(files_in(uploads.path()).is_empty());
}

#[test]
fn two_uploads_at_once_both_finish() {
    let dir = tempfile::tempdir().unwrap();
    let uploads = tempfile::tempdir().unwrap();
    let r = start(ServeOptions {
        workers: 1, // the second waits for the first's core
        ..options(uploads.path())
    });
    let (a, b) = (dir.path().join("a.wav"), dir.path().join("b.wav"));
    hum_wav(&a, 3);
    hum_wav(&b, 4);
    let files = [a, b];
    let ids: Vec<u64> = std::thread::scope(|s| {
        let hs: Vec<_> = files
            .iter()
            .map(|p| {
                let r = &r;
                s.spawn(move || {
                    let (code, v) = upload(r, "clip.wav", &std::fs::read(p).unwrap(), "{}");
                    assert_eq!(code, 202);
                    v["id"].as_u64().unwrap()
                })
            })
            .collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_ne!(ids[0], ids[1]);
    for id in ids {
        assert_eq!(finished(&r, id)["state"], "done");
    }
}

#[test]
fn an_upload_over_the_cap_is_refused_and_a_name_never_becomes_a_path() {
    let uploads = tempfile::tempdir().unwrap();
    let r = start(ServeOptions {
        max_upload: 100_000,
        ..options(uploads.path())
    });
    let (code, v) = upload(&r, "big.wav", &vec![7u8; 300_000], "{}");
    assert!(code == 413 || code == 400, "{code} {v}");
    assert!(files_in(uploads.path()).is_empty());
    // a name that climbs out: stored under the server's own name, shown without its folders
    let outside = uploads.path().parent().unwrap().join("escaped.wav");
    let (code, v) = upload(&r, "../escaped.wav", b"RIFF....WAVE", "{}");
    assert_eq!(code, 202);
    let done = finished(&r, v["id"].as_u64().unwrap());
    assert_eq!(done["name"], "escaped.wav");
    assert!(!outside.exists());
    let (code, _) = get(&r, "/api/analyses/999999");
    assert_eq!(code, 404);
    // the server goes on
    assert_eq!(get(&r, "/api/config").0, 200);
}

#[test]
fn the_pages_options_reach_every_step_that_takes_them() {
    use eenf::analysis::AnalysisSettings;
    use eenf_core::{Grid, Nominal};
    let s = AnalysisSettings::from_json(r#"{"nominal": "60", "verify": "2022-08-17T09:20:34Z"}"#)
        .unwrap();
    let sixty = Nominal::Grid(Grid::Hz60);
    assert_eq!(s.tracker.nominal, sixty, "sound");
    assert_eq!(s.extract.tracker.nominal, sixty, "events");
    assert_eq!(s.video.nominal, sixty, "video");
    assert_eq!(s.edits.nominal, sixty, "edits");
    assert_eq!(s.matching.verify.as_deref(), Some("2022-08-17T09:20:34Z"));
    let d = AnalysisSettings::default();
    assert_eq!(d.tracker.nominal, Nominal::Auto);
    for bad in [r#"{"no_such_option": 1}"#, r#"{"window": -3}"#, "[1]", "{"] {
        assert!(AnalysisSettings::from_json(bad).is_err(), "{bad}");
    }
}
