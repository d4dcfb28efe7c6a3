//! # eenf-serve
//!
//! `eenf serve`: a local web page over the library. Choose or drop a file (events, sound,
//! video or a trace); the page shows what it is, its ENF trace, when it was recorded (against
//! the stores given) and whether it was edited, and offers a report to download.
//!
//! Safe by default, as Jupyter is: it binds 127.0.0.1, and every request must carry the random
//! token of the URL printed at start (as `?token=`, the `X-Eenf-Token` header, or the cookie the
//! page sets). Uploads are streamed to a private temporary folder under a size cap, named by
//! the server (the browser's name is only displayed) and removed once analysed. One analysis
//! runs per core; the rest wait. A file the library refuses gives its one-line error on the
//! page, and the server goes on.
//!
//! The page is `page/index.html`, `app.js` and `app.css`, built into the binary: it works
//! offline and loads nothing from elsewhere.

#![forbid(unsafe_code)]

mod jobs;
mod upload;

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::sync::Arc;

use axum::body::Body;
use axum::extract::{DefaultBodyLimit, Multipart, Path as UrlPath, Request, State as Shared};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use serde_json::json;
use tokio::sync::Semaphore;

use jobs::{Jobs, State};

/// The page's files, built in.
const INDEX_HTML: &str = include_str!("page/index.html");
const APP_JS: &str = include_str!("page/app.js");
const APP_CSS: &str = include_str!("page/app.css");

/// The default cap on an upload, bytes (2 GiB: an hour of events or a long video).
pub const DEFAULT_MAX_UPLOAD: u64 = 2 << 30;

/// How the server runs.
#[derive(Debug, Clone)]
pub struct ServeOptions {
    /// Reference stores searched for every upload (`match`).
    pub stores: Vec<PathBuf>,
    /// The address to listen on (127.0.0.1 by default).
    pub bind: IpAddr,
    /// The port (0: any free one).
    pub port: u16,
    /// The largest upload taken, bytes.
    pub max_upload: u64,
    /// Analyses run at once (the rest wait): by default one per core.
    pub workers: usize,
    /// Where uploads are kept while analysed (a private folder is made inside; by default the
    /// system's temporary folder).
    pub temp_dir: Option<PathBuf>,
    /// The token (by default a random one).
    pub token: Option<String>,
}

impl Default for ServeOptions {
    fn default() -> Self {
        ServeOptions {
            stores: Vec::new(),
            bind: IpAddr::V4(Ipv4Addr::LOCALHOST),
            port: 8750,
            max_upload: DEFAULT_MAX_UPLOAD,
            workers: std::thread::available_parallelism().map_or(1, |n| n.get()),
            temp_dir: None,
            token: None,
        }
    }
}

/// Why the server could not start.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// A store given does not open.
    #[error("{0}")]
    Store(String),
    /// The address cannot be listened on, or the temporary folder made.
    #[error("{what}: {source}")]
    Io {
        /// What was being done.
        what: String,
        /// Why it failed.
        source: std::io::Error,
    },
}

struct Inner {
    token: String,
    stores: Vec<PathBuf>,
    max_upload: u64,
    dir: tempfile::TempDir,
    jobs: Jobs,
    cores: Arc<Semaphore>,
}

type AppState = Arc<Inner>;

/// A server bound to its address, not yet serving.
pub struct Server {
    listener: tokio::net::TcpListener,
    state: AppState,
    addr: SocketAddr,
}

impl Server {
    /// Checks the stores, makes the upload folder and binds the address (inside a tokio
    /// runtime).
    pub async fn bind(opts: ServeOptions) -> Result<Server, ServeError> {
        // the page's options are the library's names (`window`, `verify`)
        eenf_core::spelling::set_spelling(eenf_core::spelling::Spelling::Fields);
        for s in &opts.stores {
            if !s.exists() {
                return Err(ServeError::Store(format!(
                    "{}: no such reference store",
                    s.display()
                )));
            }
        }
        let io = |what: String| move |source| ServeError::Io { what, source };
        let dir = match &opts.temp_dir {
            Some(d) => tempfile::Builder::new().prefix("eenf-serve-").tempdir_in(d),
            None => tempfile::Builder::new().prefix("eenf-serve-").tempdir(),
        }
        .map_err(io("cannot make a folder for uploads".into()))?;
        let addr = SocketAddr::new(opts.bind, opts.port);
        let listener = tokio::net::TcpListener::bind(addr)
            .await
            .map_err(io(format!("cannot listen on {addr}")))?;
        let addr = listener
            .local_addr()
            .map_err(io(format!("cannot listen on {addr}")))?;
        let token = opts.token.clone().unwrap_or_else(random_token);
        let state = Arc::new(Inner {
            token,
            stores: opts.stores.clone(),
            max_upload: opts.max_upload,
            dir,
            jobs: Jobs::default(),
            cores: Arc::new(Semaphore::new(opts.workers.max(1))),
        });
        Ok(Server {
            listener,
            state,
            addr,
        })
    }

    /// The address it listens on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// The token every request must carry.
    pub fn token(&self) -> &str {
        &self.state.token
    }

    /// The page's URL, with its token.
    pub fn url(&self) -> String {
        let host = match self.addr.ip() {
            IpAddr::V6(ip) => format!("[{ip}]"),
            ip => ip.to_string(),
        };
        format!(
            "http://{host}:{}/?token={}",
            self.addr.port(),
            self.state.token
        )
    }

    /// Serves until `stop` completes; uploads still kept are removed with their folder.
    pub async fn run(
        self,
        stop: impl std::future::Future<Output = ()> + Send + 'static,
    ) -> std::io::Result<()> {
        let app = router(self.state.clone());
        axum::serve(self.listener, app)
            .with_graceful_shutdown(stop)
            .await
    }
}

fn router(state: AppState) -> Router {
    // the body may hold the file and a few small fields beside it
    let body_limit =
        usize::try_from(state.max_upload.saturating_add(1 << 20)).unwrap_or(usize::MAX);
    Router::new()
        .route("/", get(page))
        .route(
            "/app.js",
            get(|| async { asset(APP_JS, "text/javascript") }),
        )
        .route("/app.css", get(|| async { asset(APP_CSS, "text/css") }))
        .route("/api/config", get(config))
        .route("/api/analyses", post(upload))
        .route("/api/analyses/{id}", get(status))
        .route("/api/analyses/{id}/report", get(report))
        .layer(DefaultBodyLimit::max(body_limit))
        .layer(middleware::from_fn_with_state(state.clone(), require_token))
        .with_state(state)
}

/// 32 hex digits from the system's random source.
fn random_token() -> String {
    use rand::RngCore;
    let mut b = [0u8; 16];
    rand::rngs::OsRng.fill_bytes(&mut b);
    b.iter().map(|x| format!("{x:02x}")).collect()
}

/// Equal strings, compared in time that does not depend on where they differ.
fn same(a: &str, b: &str) -> bool {
    a.len() == b.len() && a.bytes().zip(b.bytes()).fold(0u8, |d, (x, y)| d | (x ^ y)) == 0
}

/// The token a request carries: `?token=`, the `X-Eenf-Token` header, or the page's cookie.
fn token_of(req: &Request) -> Option<String> {
    let from_query = req.uri().query().and_then(|q| {
        q.split('&')
            .find_map(|kv| kv.strip_prefix("token="))
            .map(str::to_string)
    });
    let headers = req.headers();
    let from_header = headers
        .get("x-eenf-token")
        .and_then(|v| v.to_str().ok())
        .map(str::to_string);
    let from_cookie = headers
        .get_all(header::COOKIE)
        .iter()
        .filter_map(|v| v.to_str().ok())
        .flat_map(|c| c.split(';'))
        .find_map(|kv| kv.trim().strip_prefix("eenf_token=").map(str::to_string));
    from_query.or(from_header).or(from_cookie)
}

/// 401 without a token, 403 with a wrong one; the right one passes (and the page's cookie is
/// set, so that the page's own requests carry it).
async fn require_token(Shared(state): Shared<AppState>, req: Request, next: Next) -> Response {
    match token_of(&req) {
        None => (
            StatusCode::UNAUTHORIZED,
            "eenf serve: this page needs its token: open the URL `eenf serve` printed\n",
        )
            .into_response(),
        Some(t) if !same(&t, &state.token) => {
            (StatusCode::FORBIDDEN, "eenf serve: wrong token\n").into_response()
        }
        Some(_) => {
            let mut res = next.run(req).await;
            let cookie = format!(
                "eenf_token={}; Path=/; HttpOnly; SameSite=Strict",
                state.token
            );
            if let Ok(v) = HeaderValue::from_str(&cookie) {
                res.headers_mut().insert(header::SET_COOKIE, v);
            }
            res
        }
    }
}

fn asset(body: &'static str, kind: &'static str) -> Response {
    (
        [
            (header::CONTENT_TYPE, kind),
            (header::CACHE_CONTROL, "no-store"),
        ],
        body,
    )
        .into_response()
}

async fn page() -> Response {
    let mut res = asset(INDEX_HTML, "text/html; charset=utf-8");
    // the page runs only its own script and styles, and is framed by nobody
    res.headers_mut().insert(
        header::CONTENT_SECURITY_POLICY,
        HeaderValue::from_static(
            "default-src 'self'; img-src 'self' data:; style-src 'self' 'unsafe-inline'; frame-ancestors 'none'",
        ),
    );
    res
}

async fn config(Shared(state): Shared<AppState>) -> Json<serde_json::Value> {
    Json(json!({
        "version": env!("CARGO_PKG_VERSION"),
        "stores": state.stores,
        "max_upload": state.max_upload,
    }))
}

fn fail(code: StatusCode, message: String) -> Response {
    (code, Json(json!({ "error": message }))).into_response()
}

/// `POST /api/analyses`: a multipart form with `file` (the recording) and optionally
/// `options` (a JSON object of the library's options, e.g. `{"verify": "2022-08-17T09:20:34Z"}`).
/// Answers `{"id": N}` at once; the analysis waits for a core.
async fn upload(Shared(state): Shared<AppState>, mut form: Multipart) -> Response {
    let mut options = "{}".to_string();
    let mut received = None;
    loop {
        let field = match form.next_field().await {
            Ok(Some(f)) => f,
            Ok(None) => break,
            Err(e) => {
                return fail(
                    StatusCode::BAD_REQUEST,
                    format!("the upload broke off: {e}"),
                )
            }
        };
        match field.name() {
            Some("options") => match field.text().await {
                Ok(t) if t.len() <= 64 << 10 => options = t,
                Ok(_) => return fail(StatusCode::BAD_REQUEST, "options: too long".into()),
                Err(e) => return fail(StatusCode::BAD_REQUEST, format!("options: {e}")),
            },
            Some("file") if received.is_none() => {
                let name = upload::display_name(field.file_name());
                let ext = upload::extension_for(&name);
                let (id, progress) = state.jobs.add(name.clone(), 0, String::new());
                match upload::receive(field, state.dir.path(), id, ext, state.max_upload).await {
                    Ok(r) => received = Some((id, name, r, progress)),
                    Err(e) => {
                        let (code, msg) = match e {
                            upload::UploadError::TooLarge(cap) => (
                                StatusCode::PAYLOAD_TOO_LARGE,
                                format!("{name}: larger than this server takes ({cap} bytes; see --max-upload)"),
                            ),
                            upload::UploadError::Broken(m) => {
                                (StatusCode::BAD_REQUEST, format!("{name}: {m}"))
                            }
                        };
                        state.jobs.set(id, State::Failed(msg.clone()));
                        return fail(code, msg);
                    }
                }
            }
            _ => {} // other fields are ignored (their bytes are drained by the parser)
        }
    }
    let Some((id, name, r, progress)) = received else {
        return fail(StatusCode::BAD_REQUEST, "no file in the upload".into());
    };
    state.jobs.fill(id, r.size, r.sha256.clone());
    let request = jobs::Request {
        path: r.path,
        name,
        size: r.size,
        sha256: r.sha256,
        options,
        stores: state.stores.clone(),
    };
    let st = state.clone();
    tokio::spawn(async move {
        let permit = st.cores.clone().acquire_owned().await;
        st.jobs.set(id, State::Running);
        let path = request.path.clone();
        let ran = tokio::task::spawn_blocking(move || jobs::run(&request, &progress)).await;
        drop(permit);
        let _ = tokio::fs::remove_file(&path).await;
        st.jobs.set(
            id,
            match ran {
                Ok(Ok(done)) => State::Done(Arc::new(done)),
                Ok(Err(msg)) => State::Failed(msg),
                Err(_) => State::Failed(
                    "the analysis stopped on an internal error (the server goes on)".into(),
                ),
            },
        );
    });
    (StatusCode::ACCEPTED, Json(json!({ "id": id }))).into_response()
}

async fn status(Shared(state): Shared<AppState>, UrlPath(id): UrlPath<u64>) -> Response {
    match state.jobs.status(id) {
        Some(v) => Json(v).into_response(),
        None => fail(StatusCode::NOT_FOUND, format!("no analysis {id}")),
    }
}

async fn report(Shared(state): Shared<AppState>, UrlPath(id): UrlPath<u64>) -> Response {
    let Some((name, done)) = state.jobs.report(id) else {
        return fail(StatusCode::NOT_FOUND, format!("no finished analysis {id}"));
    };
    // the download's name is built from safe characters of the input's name only
    let stem: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .take(80)
        .collect();
    let mut headers = HeaderMap::new();
    headers.insert(
        header::CONTENT_TYPE,
        HeaderValue::from_static("text/html; charset=utf-8"),
    );
    if let Ok(v) =
        HeaderValue::from_str(&format!("attachment; filename=\"eenf-report-{stem}.html\""))
    {
        headers.insert(header::CONTENT_DISPOSITION, v);
    }
    (headers, Body::from(done.report.clone())).into_response()
}

/// Serves until Ctrl-C or SIGTERM, on a runtime of its own: `announce` gets the page's URL
/// once the address is bound (the command prints it as its first line).
pub fn serve(opts: ServeOptions, announce: impl FnOnce(&Server)) -> Result<(), ServeError> {
    let rt = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(|source| ServeError::Io {
            what: "cannot start the server".into(),
            source,
        })?;
    let result = rt.block_on(async {
        let server = Server::bind(opts).await?;
        announce(&server);
        server
            .run(stop_signal())
            .await
            .map_err(|source| ServeError::Io {
                what: "the server stopped".into(),
                source,
            })
    });
    // analyses still running are not waited for: their uploads go with the folder, and the
    // library's temporary outputs are removed
    rt.shutdown_timeout(std::time::Duration::from_millis(500));
    eenf::output::remove_in_progress();
    result
}

/// Ctrl-C, or SIGTERM where there is one.
async fn stop_signal() {
    let ctrl_c = async {
        let _ = tokio::signal::ctrl_c().await;
    };
    #[cfg(unix)]
    {
        use tokio::signal::unix::{signal, SignalKind};
        match (
            signal(SignalKind::terminate()),
            signal(SignalKind::hangup()),
        ) {
            (Ok(mut term), Ok(mut hup)) => {
                tokio::select! {
                    _ = ctrl_c => {},
                    _ = term.recv() => {},
                    _ = hup.recv() => {},
                }
            }
            _ => ctrl_c.await,
        }
    }
    #[cfg(not(unix))]
    ctrl_c.await;
}
