//! A replay server on 127.0.0.1 for the fetch tests: it answers each request with what the
//! test's handler says (an operator's documented answer, or a failure: a status, a
//! `Retry-After`, a body cut short) and logs every request. It honours `Range` (RFC 9110
//! §14), as the operators' file servers do, so that resumed downloads can be tested.

use std::io::{BufRead, BufReader, Write};
use std::net::TcpListener;
use std::sync::{Arc, Mutex};

/// One answer.
pub struct Reply {
    pub status: u16,
    pub headers: Vec<(String, String)>,
    pub body: Vec<u8>,
    /// Send only this many bytes of the body, then close (with the full length announced).
    pub cut: Option<usize>,
}

impl Reply {
    /// 200 with `body`, or 206 with its rest when the request asks for a range.
    pub fn file(body: Vec<u8>, range_from: Option<u64>) -> Reply {
        match range_from {
            Some(from) if (from as usize) < body.len() => Reply {
                status: 206,
                headers: vec![(
                    "Content-Range".into(),
                    format!("bytes {from}-{}/{}", body.len() - 1, body.len()),
                )],
                body: body[from as usize..].to_vec(),
                cut: None,
            },
            _ => Reply::ok(body),
        }
    }

    /// 200 with `body`.
    pub fn ok(body: Vec<u8>) -> Reply {
        Reply {
            status: 200,
            headers: Vec::new(),
            body,
            cut: None,
        }
    }

    /// A status with a short body.
    pub fn status(status: u16) -> Reply {
        Reply {
            status,
            headers: Vec::new(),
            body: b"no".to_vec(),
            cut: None,
        }
    }
}

/// A request as the handler sees it: its path with the query, where a `Range` starts, and
/// the `x-api-key` it sent.
pub struct Request {
    pub target: String,
    pub range_from: Option<u64>,
    pub api_key: Option<String>,
}

type Handler = dyn Fn(&Request) -> Reply + Send + Sync;

/// A running replay server.
pub struct Replay {
    /// `http://127.0.0.1:PORT`.
    pub base: String,
    /// Every request, as `PATH?QUERY` plus ` range=N` when it asked for one.
    pub log: Arc<Mutex<Vec<String>>>,
}

impl Replay {
    /// Serves `handler` until the test process ends.
    pub fn start(handler: impl Fn(&Request) -> Reply + Send + Sync + 'static) -> Replay {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let base = format!("http://{}", listener.local_addr().unwrap());
        let log = Arc::new(Mutex::new(Vec::new()));
        let handler: Arc<Handler> = Arc::new(handler);
        let log2 = log.clone();
        std::thread::spawn(move || {
            for stream in listener.incoming() {
                let Ok(mut stream) = stream else { continue };
                let mut reader = BufReader::new(stream.try_clone().unwrap());
                let mut first = String::new();
                if reader.read_line(&mut first).is_err() {
                    continue;
                }
                let target = first.split_whitespace().nth(1).unwrap_or("/").to_string();
                let mut range_from = None;
                let mut api_key = None;
                loop {
                    let mut line = String::new();
                    if reader.read_line(&mut line).unwrap_or(0) == 0 || line.trim().is_empty() {
                        break;
                    }
                    let lower = line.to_ascii_lowercase();
                    if lower.starts_with("x-api-key:") {
                        api_key = Some(line["x-api-key:".len()..].trim().to_string());
                    }
                    if let Some(r) = lower.strip_prefix("range:") {
                        range_from = r
                            .trim()
                            .strip_prefix("bytes=")
                            .and_then(|r| r.split('-').next())
                            .and_then(|n| n.parse().ok());
                    }
                }
                log2.lock().unwrap().push(match range_from {
                    Some(n) => format!("{target} range={n}"),
                    None => target.clone(),
                });
                let reply = handler(&Request {
                    target,
                    range_from,
                    api_key,
                });
                let mut head = format!(
                    "HTTP/1.1 {} X\r\nContent-Length: {}\r\nConnection: close\r\n",
                    reply.status,
                    reply.body.len()
                );
                for (k, v) in &reply.headers {
                    head += &format!("{k}: {v}\r\n");
                }
                head += "\r\n";
                let sent = reply.cut.unwrap_or(reply.body.len()).min(reply.body.len());
                let _ = stream.write_all(head.as_bytes());
                let _ = stream.write_all(&reply.body[..sent]);
                let _ = stream.flush();
            }
        });
        Replay { base, log }
    }

    /// The requests so far.
    pub fn requests(&self) -> Vec<String> {
        self.log.lock().unwrap().clone()
    }

    /// Forgets the requests so far.
    pub fn clear(&self) {
        self.log.lock().unwrap().clear();
    }
}

/// The value of `key` in a target's query.
pub fn query(target: &str, key: &str) -> Option<String> {
    let q = target.split_once('?')?.1;
    q.split('&')
        .filter_map(|kv| kv.split_once('='))
        .find(|(k, _)| *k == key)
        .map(|(_, v)| v.to_string())
}
