//! Downloads from grid operators: one agent (rustls, no system TLS), a pause between requests
//! to the same source, retries with backoff, `Retry-After` obeyed, and downloads that resume
//! where a cut left them (`Range`, RFC 9110 §14.2).

use std::fs::File;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use sha2::{Digest, Sha256};

use crate::error::{error, Context, Error, Result};

/// Longest wait a `Retry-After` may ask for before the fetch gives up rather than waits.
const MAX_RETRY_AFTER_S: u64 = 60;
/// The largest index or JSON page read into memory.
pub(super) const MAX_SMALL_BYTES: u64 = 32 << 20;
/// The largest file downloaded: a month of GB data at 1 s is about 80 MB as CSV, an OSF year
/// file a few hundred MB; a server sending more is refused, not followed.
const MAX_FILE_BYTES: u64 = 1 << 30;

/// An HTTP client for one source.
pub(super) struct Http {
    agent: ureq::Agent,
    /// Names the source in every message.
    source: &'static str,
    /// Retries after a failure that may pass (no connection, a cut, 5xx, 429).
    retries: u32,
    /// Least time between two requests.
    pause: Duration,
    last: Option<Instant>,
    /// A header sent with every request (an API key).
    header: Option<(&'static str, String)>,
}

/// Why one attempt failed, and whether another may succeed.
enum Attempt {
    /// Worth another try after this long.
    Again(Duration, Error),
    /// Final.
    Fail(Error),
}

impl Http {
    pub(super) fn new(source: &'static str, retries: u32, pause: Duration) -> Self {
        let agent = ureq::Agent::config_builder()
            .http_status_as_error(false)
            // the bytes as sent: a resumed range must continue the same bytes
            .accept_encoding("identity")
            .user_agent(concat!("eenf/", env!("CARGO_PKG_VERSION")))
            .timeout_connect(Some(Duration::from_secs(20)))
            .timeout_per_read(Some(Duration::from_secs(60)))
            .build()
            .new_agent();
        Http {
            agent,
            source,
            retries,
            pause,
            last: None,
            header: None,
        }
    }

    /// Sends `value` as header `name` with every request.
    pub(super) fn with_header(mut self, name: &'static str, value: String) -> Self {
        self.header = Some((name, value));
        self
    }

    fn wait_turn(&mut self) {
        if let Some(t) = self.last {
            let since = t.elapsed();
            if since < self.pause {
                std::thread::sleep(self.pause - since);
            }
        }
        self.last = Some(Instant::now());
    }

    fn fail(&self, url: &str, what: impl std::fmt::Display) -> Error {
        error!(Fetch, "{}: {url}: {what}", self.source)
    }

    /// Runs `attempt` until it succeeds, fails for good, or the retries are spent.
    fn with_retries<T>(
        &mut self,
        mut attempt: impl FnMut(&mut Self) -> Result<T, Attempt>,
    ) -> Result<T> {
        let mut tries = 0;
        loop {
            self.wait_turn();
            match attempt(self) {
                Ok(v) => return Ok(v),
                Err(Attempt::Fail(e)) => return Err(e),
                Err(Attempt::Again(wait, e)) => {
                    if tries >= self.retries {
                        return Err(e);
                    }
                    tries += 1;
                    std::thread::sleep(wait);
                }
            }
        }
    }

    /// Backoff before retry `n` (1 s, 2 s, 4 s, … at most 30 s).
    fn backoff(n: u32) -> Duration {
        Duration::from_secs(1u64 << n.min(5)).min(Duration::from_secs(30))
    }

    fn request(
        &self,
        url: &str,
        range_from: u64,
    ) -> Result<ureq::http::Response<ureq::Body>, Attempt> {
        let mut req = self.agent.get(url);
        if let Some((name, value)) = &self.header {
            req = req.header(*name, value);
        }
        if range_from > 0 {
            req = req.header("Range", format!("bytes={range_from}-"));
        }
        let resp = req.call().map_err(|e| match e {
            ureq::Error::BadUri(_) | ureq::Error::Http(_) => {
                Attempt::Fail(self.fail(url, format!("not an address ({e})")))
            }
            e => Attempt::Again(Self::backoff(0), self.fail(url, format!("no answer ({e})"))),
        })?;
        let status = resp.status().as_u16();
        if resp.status().is_success() {
            return Ok(resp);
        }
        let reason = resp.status().canonical_reason().unwrap_or("");
        if status == 429 {
            let after = resp
                .headers()
                .get("retry-after")
                .and_then(|v| v.to_str().ok())
                .and_then(|v| v.trim().parse::<u64>().ok());
            let e = self.fail(
                url,
                match after {
                    Some(s) => format!(
                        "429 Too Many Requests: the server asks to wait {s} s; try again later"
                    ),
                    None => "429 Too Many Requests: try again later".into(),
                },
            );
            return Err(match after {
                Some(s) if s <= MAX_RETRY_AFTER_S => Attempt::Again(Duration::from_secs(s), e),
                None => Attempt::Again(Self::backoff(2), e),
                Some(_) => Attempt::Fail(e),
            });
        }
        let e = self.fail(url, format!("{status} {reason}"));
        if status == 401 || status == 403 {
            return Err(Attempt::Fail(self.fail(
                url,
                format!("{status} {reason}: the server refused the request (an API key missing or wrong?)"),
            )));
        }
        Err(if status >= 500 || status == 408 {
            Attempt::Again(Self::backoff(1), e)
        } else {
            Attempt::Fail(e)
        })
    }

    /// The body at `url`, at most [`MAX_SMALL_BYTES`] (an index, a JSON page).
    pub(super) fn get_small(&mut self, url: &str) -> Result<Vec<u8>> {
        self.with_retries(|h| {
            let mut resp = h.request(url, 0)?;
            let expected = content_length(&resp);
            let mut body = Vec::new();
            let read = resp
                .body_mut()
                .as_reader()
                .take(MAX_SMALL_BYTES + 1)
                .read_to_end(&mut body);
            if let Err(e) = read {
                return Err(Attempt::Again(
                    Self::backoff(0),
                    h.fail(
                        url,
                        format!("the body was cut after {} bytes ({e})", body.len()),
                    ),
                ));
            }
            if body.len() as u64 > MAX_SMALL_BYTES {
                return Err(Attempt::Fail(h.fail(
                    url,
                    format!("over {} MB: not an index", MAX_SMALL_BYTES >> 20),
                )));
            }
            if let Some(n) = expected.filter(|&n| n != body.len() as u64) {
                return Err(Attempt::Again(
                    Self::backoff(0),
                    h.fail(
                        url,
                        format!("the body ended after {} of {n} bytes", body.len()),
                    ),
                ));
            }
            Ok(body)
        })
    }

    /// Downloads `url` to `dest`: into `dest.part` first, continued from its end when a
    /// previous attempt (or run) was cut, then renamed. A cut after the retries leaves the
    /// part for the next run to resume.
    pub(super) fn download(&mut self, url: &str, dest: &Path) -> Result<()> {
        let part = part_path(dest);
        if let Some(dir) = dest.parent() {
            std::fs::create_dir_all(dir).with_context(|| format!("{}", dir.display()))?;
        }
        self.with_retries(|h| {
            let have = std::fs::metadata(&part).map(|m| m.len()).unwrap_or(0);
            let mut resp = h.request(url, have)?;
            let status = resp.status().as_u16();
            // 206: the rest from where the part ends; 200: the whole file again
            let resume = status == 206 && have > 0;
            if resume && content_range_start(&resp) != Some(have) {
                let _ = std::fs::remove_file(&part);
                return Err(Attempt::Again(
                    Duration::ZERO,
                    h.fail(url, "the server resumed at another place; starting again"),
                ));
            }
            let start = if resume { have } else { 0 };
            let opened = if resume {
                File::options().append(true).open(&part)
            } else {
                File::create(&part)
            };
            let mut file =
                opened.map_err(|e| Attempt::Fail(error!(Fetch, "{}: {e}", part.display())))?;
            let expected = content_length(&resp).map(|n| n + start);
            let mut reader = resp.body_mut().as_reader();
            let mut buf = vec![0u8; 1 << 16];
            let mut got = start;
            let cut = loop {
                match reader.read(&mut buf) {
                    Ok(0) => break None,
                    Ok(n) => {
                        got += n as u64;
                        if got > MAX_FILE_BYTES {
                            let _ = std::fs::remove_file(&part);
                            return Err(Attempt::Fail(h.fail(url, format!("over {} GB: refused (no operator's file is this large)", MAX_FILE_BYTES >> 30))));
                        }
                        file.write_all(&buf[..n])
                            .map_err(|e| Attempt::Fail(error!(Fetch, "{}: {e}", part.display())))?;
                    }
                    Err(e) => break Some(e.to_string()),
                }
            };
            file.sync_all()
                .map_err(|e| Attempt::Fail(error!(Fetch, "{}: {e}", part.display())))?;
            let short = expected.filter(|&n| got < n);
            if cut.is_some() || short.is_some() {
                let of = expected.map(|n| format!(" of {n}")).unwrap_or_default();
                return Err(Attempt::Again(
                    Self::backoff(0),
                    h.fail(
                        url,
                        format!("the body was cut after {got}{of} bytes (kept: the next try resumes there)"),
                    ),
                ));
            }
            std::fs::rename(&part, dest)
                .map_err(|e| Attempt::Fail(error!(Fetch, "{}: {e}", dest.display())))?;
            Ok(())
        })
    }
}

/// Where a download in progress is kept.
pub(super) fn part_path(dest: &Path) -> PathBuf {
    let mut name = dest.file_name().unwrap_or_default().to_os_string();
    name.push(".part");
    dest.with_file_name(name)
}

fn content_length(resp: &ureq::http::Response<ureq::Body>) -> Option<u64> {
    resp.headers()
        .get("content-length")
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.trim().parse().ok())
}

/// The first byte a 206 answer holds (`Content-Range: bytes 100-199/200`).
fn content_range_start(resp: &ureq::http::Response<ureq::Body>) -> Option<u64> {
    let v = resp.headers().get("content-range")?.to_str().ok()?;
    let range = v.trim().strip_prefix("bytes")?.trim();
    range.split('-').next()?.trim().parse().ok()
}

/// SHA-256 of a file, hex, and its size.
pub(super) fn sha256_of(path: &Path) -> Result<(String, u64)> {
    let mut f = File::open(path).with_context(|| format!("{}", path.display()))?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    let mut n = 0u64;
    loop {
        let k = f
            .read(&mut buf)
            .with_context(|| format!("{}", path.display()))?;
        if k == 0 {
            break;
        }
        n += k as u64;
        h.update(&buf[..k]);
    }
    let hex = h.finalize().iter().map(|b| format!("{b:02x}")).collect();
    Ok((hex, n))
}
