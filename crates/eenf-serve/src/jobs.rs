//! Analyses of uploads: queued, run one per core on blocking threads, their progress and
//! results kept for the page to poll.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use eenf::analysis::{analyse, AnalysisSettings};
use eenf::progress::{Progress, ProgressSink, Task, Unit};
use eenf_figures::report::{
    edits_verdict, figures, html_report, match_verdicts, trace_verdict, ReportFacts,
};
use serde_json::{json, Value};

/// Analyses kept for polling; the oldest finished ones go first.
const KEPT: usize = 64;

/// What the page polls: where a job is.
#[derive(Debug, Clone)]
pub(crate) enum State {
    /// Waiting for a core.
    Queued,
    /// Being analysed.
    Running,
    /// Done: what the page shows, and the report.
    Done(Arc<Finished>),
    /// Refused, in one line.
    Failed(String),
}

/// A finished analysis.
#[derive(Debug)]
pub(crate) struct Finished {
    /// What the page shows.
    pub page: Value,
    /// The report's HTML.
    pub report: String,
}

/// What the current piece of work is and how far it got.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub(crate) struct Progressed {
    what: String,
    done: u64,
    total: Option<u64>,
}

/// One upload and its analysis.
#[derive(Debug)]
pub(crate) struct Job {
    /// The name the browser gave, for display only.
    pub name: String,
    /// Bytes received.
    pub size: u64,
    /// SHA-256 of those bytes, hex.
    pub sha256: String,
    pub state: State,
    progress: Arc<Mutex<Progressed>>,
}

/// Every job, by id.
#[derive(Default)]
pub(crate) struct Jobs {
    jobs: Mutex<BTreeMap<u64, Job>>,
    next: Mutex<u64>,
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    // a job's thread that panicked leaves plain data behind, still readable
    m.lock().unwrap_or_else(|p| p.into_inner())
}

impl Jobs {
    /// Registers an upload; returns its id and the sink its analysis reports to.
    pub fn add(&self, name: String, size: u64, sha256: String) -> (u64, Progress) {
        let id = {
            let mut n = lock(&self.next);
            *n += 1;
            *n
        };
        let progress = Arc::new(Mutex::new(Progressed::default()));
        let mut jobs = lock(&self.jobs);
        while jobs.len() >= KEPT {
            let oldest = jobs
                .iter()
                .find(|(_, j)| matches!(j.state, State::Done(_) | State::Failed(_)))
                .map(|(k, _)| *k);
            match oldest {
                Some(k) => jobs.remove(&k),
                None => break,
            };
        }
        jobs.insert(
            id,
            Job {
                name,
                size,
                sha256,
                state: State::Queued,
                progress: progress.clone(),
            },
        );
        (id, Progress::to(Arc::new(JobSink(progress))))
    }

    /// Moves job `id` to `state`.
    pub fn set(&self, id: u64, state: State) {
        if let Some(j) = lock(&self.jobs).get_mut(&id) {
            j.state = state;
        }
    }

    /// Records what the upload of job `id` turned out to be.
    pub fn fill(&self, id: u64, size: u64, sha256: String) {
        if let Some(j) = lock(&self.jobs).get_mut(&id) {
            j.size = size;
            j.sha256 = sha256;
        }
    }

    /// The job's state as the page reads it (`None`: no such job).
    pub fn status(&self, id: u64) -> Option<Value> {
        let jobs = lock(&self.jobs);
        let j = jobs.get(&id)?;
        let mut v = json!({"id": id, "name": j.name, "size": j.size, "sha256": j.sha256});
        let (state, extra) = match &j.state {
            State::Queued => ("queued", json!(null)),
            State::Running => ("running", json!(*lock(&j.progress))),
            State::Done(f) => ("done", f.page.clone()),
            State::Failed(e) => ("failed", json!(e)),
        };
        v["state"] = json!(state);
        v[match state {
            "running" => "progress",
            "done" => "result",
            "failed" => "error",
            _ => "queued",
        }] = extra;
        Some(v)
    }

    /// The finished job's report and its input's name.
    pub fn report(&self, id: u64) -> Option<(String, Arc<Finished>)> {
        let jobs = lock(&self.jobs);
        let j = jobs.get(&id)?;
        match &j.state {
            State::Done(f) => Some((j.name.clone(), f.clone())),
            _ => None,
        }
    }
}

/// Progress of one job: the latest piece of work stands for all.
struct JobSink(Arc<Mutex<Progressed>>);

struct JobTask(Arc<Mutex<Progressed>>);

impl ProgressSink for JobSink {
    fn start(&self, _unit: Unit, total: Option<u64>, what: &str) -> Box<dyn Task> {
        *lock(&self.0) = Progressed {
            what: what.to_string(),
            done: 0,
            total: total.filter(|&t| t > 0),
        };
        Box::new(JobTask(self.0.clone()))
    }
}

impl Task for JobTask {
    fn inc(&self, n: u64) {
        lock(&self.0).done += n;
    }
    fn set_position(&self, n: u64) {
        lock(&self.0).done = n;
    }
    fn finish(&self) {}
}

/// `text` with the upload's path (a server-side name) replaced by the name the browser gave.
fn named(text: &str, path: &Path, name: &str) -> String {
    text.replace(&path.display().to_string(), name)
}

/// [`named`] on every string of a JSON value, in place (a name with quotes in it stays a
/// string: the JSON is never rewritten as text).
fn name_strings(v: &mut serde_json::Value, path: &Path, name: &str) {
    match v {
        serde_json::Value::String(s) => *s = named(s, path, name),
        serde_json::Value::Array(items) => {
            items.iter_mut().for_each(|x| name_strings(x, path, name))
        }
        serde_json::Value::Object(map) => {
            map.values_mut().for_each(|x| name_strings(x, path, name))
        }
        _ => {}
    }
}

/// What one analysis needs.
pub(crate) struct Request {
    pub path: PathBuf,
    pub name: String,
    pub size: u64,
    pub sha256: String,
    pub options: String,
    pub stores: Vec<PathBuf>,
}

/// Runs the analysis of `r` (on a blocking thread): the page's result and the report, or the
/// one-line error the page shows.
pub(crate) fn run(r: &Request, progress: &Progress) -> Result<Finished, String> {
    let settings = AnalysisSettings::from_json(&r.options)
        .map_err(|e| format!("{}: {}", r.name, eenf::Error::from(e).report()))?;
    let mut a = analyse(&r.path, None, &settings, &r.stores, progress)
        .map_err(|e| named(&e.report(), &r.path, &r.name))?;
    a.trace.file = Some(PathBuf::from(&r.name));
    if let Some(f) = a.about.get_mut("file") {
        *f = json!(r.name);
    }
    let figs = figures(&a, &r.name).map_err(|e| named(&e.report(), &r.path, &r.name))?;
    let name = Path::new(&r.name);
    let mut page = a.to_json(name);
    // the library's messages name the upload's server-side path: the page names the file
    name_strings(&mut page, &r.path, &r.name);
    page["verdict"] = json!(trace_verdict(&a));
    page["match_verdicts"] = json!(match_verdicts(&a)
        .iter()
        .map(|v| named(v, &r.path, &r.name))
        .collect::<Vec<_>>());
    page["edits_verdict"] = json!(named(&edits_verdict(&a), &r.path, &r.name));
    page["figures"] = json!(figs);
    let analysed_at = eenf::time::utc(
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0.0, |d| d.as_secs().min(i64::MAX as u64) as f64),
    );
    let facts = ReportFacts {
        name: &r.name,
        size: r.size,
        sha256: &r.sha256,
        analysed_at: &analysed_at,
        options: &r.options,
        settings: &settings,
    };
    let report = named(&html_report(&a, &figs, &facts), &r.path, &r.name);
    Ok(Finished { page, report })
}
