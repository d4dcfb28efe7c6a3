//! `eenf._eenf`: the native half of the Python package `eenf`.
//!
//! A thin layer: each function turns Python values into the library's types, calls the
//! library with the GIL released, and turns the result into numpy arrays, a `Trace` or a dict
//! (as JSON text, which `eenf/__init__.py` loads). Keyword arguments reach here as a JSON
//! object and fill the library's option sets (`eenf::options`), which check them: the names,
//! defaults and ranges are the command line's, and messages name keyword arguments.
//! The friendly signatures, structured arrays and plots live in `python/eenf/__init__.py`.

#![forbid(unsafe_code)]

use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use eenf::audio::Sound;
use eenf::options::{self as opts, OptionSet};
use eenf::progress::Progress;
use eenf::recording::Recording;
use eenf::trace::Trace;
use eenf_core::Nominal;
use eenf_events::{EventBatch, EventReader};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1};
use pyo3::exceptions::{PyStopIteration, PyValueError};
use pyo3::prelude::*;

/// Bytes per event record: `t` int64, `x` uint16, `y` uint16, `p` int8, packed (the dtype
/// `eenf.EVENT_DTYPE` views them as).
const RECORD: usize = 13;

/// An error of the library as a Python exception: `OSError` (the subclass Python picks for
/// the OS error's kind, e.g. `FileNotFoundError`) when a file could not be read or written,
/// `ValueError` for bad data or parameters. Messages name options as keyword arguments (the
/// module sets that spelling when it loads).
fn py_err(e: eenf::Error) -> PyErr {
    let msg = e.report();
    match e.io_kind() {
        Some(kind) => PyErr::from(std::io::Error::new(kind, msg)),
        None => PyValueError::new_err(msg),
    }
}

fn events_err(e: eenf_events::EventError) -> PyErr {
    py_err(e.into())
}

/// A refused option set as a Python exception: `ValueError`, naming the keyword argument.
fn option_err(e: opts::OptionError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// An option set of type `T` filled from keyword arguments (`options`: a JSON object), checked.
fn settings<T: OptionSet + Default>(options: &str) -> PyResult<T> {
    let mut set = T::default();
    opts::apply_json(&mut [&mut set], options).map_err(option_err)?;
    Ok(set)
}

/// The keyword arguments of an option set (`extract`, `match`, ...), as JSON text: a list of
/// `{"name", "default", "help", "choices", "switch"}`, for the docstrings and `help()`.
#[pyfunction]
fn options(what: &str) -> PyResult<String> {
    let docs: serde_json::Value =
        serde_json::from_str(opts::DOCS_JSON).map_err(|e| PyValueError::new_err(e.to_string()))?;
    docs.get(what)
        .map(|v| v.to_string())
        .ok_or_else(|| PyValueError::new_err(format!("no option set {what:?}")))
}

/// Packs events `range` of a batch into 13-byte records (see [`RECORD`]).
fn pack(b: &EventBatch, range: std::ops::Range<usize>, out: &mut Vec<u8>) {
    let start = out.len();
    out.resize(start + range.len() * RECORD, 0);
    let dst = &mut out[start..];
    for (rec, i) in dst.chunks_exact_mut(RECORD).zip(range) {
        rec[..8].copy_from_slice(&b.t[i].to_le_bytes());
        rec[8..10].copy_from_slice(&b.x[i].to_le_bytes());
        rec[10..12].copy_from_slice(&b.y[i].to_le_bytes());
        rec[12] = b.p[i] as u8;
    }
}

/// The events of a batch with `lo <= t < hi` (a batch is in time order).
fn within(b: &EventBatch, lo: i64, hi: i64) -> std::ops::Range<usize> {
    let a = b.t.partition_point(|&t| t < lo);
    let z = b.t.partition_point(|&t| t < hi);
    a..z.max(a)
}

/// Why a stream ended early, as the warning the CLI prints.
fn damage_warning(r: &dyn EventReader) -> Option<String> {
    r.damage().map(|d| d.to_string())
}

/// Reads the events of `path` with `start_s <= t - t0 < end_s` (seconds from the first
/// event) into packed records, with the warnings met (damage). The GIL is released.
#[pyfunction]
#[pyo3(signature = (path, start_s=None, end_s=None, options="{}"))]
fn read_events<'py>(
    py: Python<'py>,
    path: PathBuf,
    start_s: Option<f64>,
    end_s: Option<f64>,
    options: &str,
) -> PyResult<(Bound<'py, PyArray1<u8>>, Option<String>)> {
    let input: opts::InputSettings = settings(options)?;
    let (bytes, warning) = py.detach(|| -> PyResult<(Vec<u8>, Option<String>)> {
        let mut r = eenf_events::open_with(&path, &input.open_options()).map_err(events_err)?;
        let mut out = Vec::new();
        if let Some(n) = r.info().event_count {
            // a hint only: bounded, never trusted for the whole file
            out.reserve((n.min(1 << 24) as usize) * RECORD);
        }
        let mut t0 = None;
        while let Some(b) = r.next_batch().map_err(events_err)? {
            if b.is_empty() {
                continue;
            }
            let first = *t0.get_or_insert(b.t[0]);
            let us = |s: f64| first.saturating_add((s * 1e6).round().clamp(-9e18, 9e18) as i64);
            let (lo, hi) = (start_s.map_or(i64::MIN, us), end_s.map_or(i64::MAX, us));
            pack(&b, within(&b, lo, hi), &mut out);
            if b.t[b.len() - 1] >= hi {
                break;
            }
        }
        Ok((out, damage_warning(r.as_ref())))
    })?;
    Ok((PyArray1::from_vec(py, bytes), warning))
}

/// Streams the events of a file in batches of packed records (`eenf.iter_events`).
#[pyclass(module = "eenf._eenf")]
struct EventIterator {
    state: Mutex<IterState>,
    batch: usize,
}

/// The reader, the batch being handed out and how far, and whether its damage was reported.
struct IterState {
    reader: Box<dyn EventReader>,
    pending: EventBatch,
    at: usize,
    warned: bool,
}

#[pymethods]
impl EventIterator {
    #[new]
    #[pyo3(signature = (path, batch=1_000_000, options="{}"))]
    fn new(py: Python<'_>, path: PathBuf, batch: usize, options: &str) -> PyResult<Self> {
        if batch == 0 {
            return Err(PyValueError::new_err("batch must be at least 1"));
        }
        let input: opts::InputSettings = settings(options)?;
        let reader = py
            .detach(|| eenf_events::open_with(&path, &input.open_options()))
            .map_err(events_err)?;
        Ok(EventIterator {
            state: Mutex::new(IterState {
                reader,
                pending: EventBatch::default(),
                at: 0,
                warned: false,
            }),
            batch,
        })
    }

    /// The next records (at most `batch` events), with the warning met when the stream ended
    /// early; `StopIteration` at the end.
    fn next<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyArray1<u8>>, Option<String>)> {
        let (bytes, warning) = py.detach(|| -> PyResult<(Vec<u8>, Option<String>)> {
            let mut guard = self.state.lock().unwrap_or_else(|p| p.into_inner());
            let st = &mut *guard;
            let mut out = Vec::with_capacity(self.batch.min(1 << 20) * RECORD);
            while out.len() < self.batch * RECORD {
                if st.at >= st.pending.len() {
                    match st.reader.next_batch().map_err(events_err)? {
                        Some(next) => (st.pending, st.at) = (next, 0),
                        None => break,
                    }
                    continue;
                }
                let take = (self.batch - out.len() / RECORD).min(st.pending.len() - st.at);
                pack(&st.pending, st.at..st.at + take, &mut out);
                st.at += take;
            }
            let warning = match (out.is_empty() || st.reader.damage().is_some(), st.warned) {
                (true, false) => damage_warning(st.reader.as_ref()),
                _ => None,
            };
            st.warned |= warning.is_some();
            Ok((out, warning))
        })?;
        if bytes.is_empty() && warning.is_none() {
            return Err(PyStopIteration::new_err(()));
        }
        Ok((PyArray1::from_vec(py, bytes), warning))
    }

    /// What the file's header says (as `info()`'s first part), as JSON text.
    fn header(&self) -> String {
        let st = self.state.lock().unwrap_or_else(|p| p.into_inner());
        let i = st.reader.info();
        serde_json::json!({"format": i.format, "codec": i.codec, "width": i.width,
            "height": i.height, "event_count": i.event_count, "cameras": i.cameras,
            "notes": i.notes})
        .to_string()
    }
}

/// `eenf info --json` of a file, as JSON text. The GIL is released.
#[pyfunction]
#[pyo3(signature = (path, options="{}"))]
fn info(py: Python<'_>, path: PathBuf, options: &str) -> PyResult<String> {
    let input: opts::InputSettings = settings(options)?;
    py.detach(|| {
        let found = eenf::inspect::inspect(&path, &input.open_options())?;
        Ok(found.to_json(&path).to_string())
    })
    .map_err(py_err)
}

/// Events as columns (checked: lengths, order, addresses) in the library's batch.
fn batch_of(
    t: PyReadonlyArray1<'_, i64>,
    x: PyReadonlyArray1<'_, u16>,
    y: PyReadonlyArray1<'_, u16>,
    p: PyReadonlyArray1<'_, bool>,
) -> PyResult<EventBatch> {
    let col = |e: numpy::AsSliceError| PyValueError::new_err(format!("event columns: {e}"));
    Ok(EventBatch {
        t: t.as_slice().map_err(col)?.to_vec(),
        x: x.as_slice().map_err(col)?.to_vec(),
        y: y.as_slice().map_err(col)?.to_vec(),
        p: p.as_slice().map_err(col)?.to_vec(),
    })
}

/// An ENF trace: the library's one trace type (`eenf.Trace` wraps it).
#[pyclass(name = "NativeTrace", module = "eenf._eenf", frozen)]
struct PyTrace(Arc<Trace>);

#[pymethods]
impl PyTrace {
    /// Seconds from the recording's start of each estimate.
    #[getter]
    fn time_s<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.0.time_s)
    }

    /// ENF estimates, Hz (NaN where none).
    #[getter]
    fn enf_hz<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.0.enf_hz)
    }

    /// Each estimate's line strength over its noise, dB (empty when not measured).
    #[getter]
    fn snr_db<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.0.snr_db)
    }

    /// Per-harmonic parts: (harmonic m, band centre Hz, ENF Hz, line strength dB) each.
    #[allow(clippy::type_complexity)]
    fn harmonic_parts<'py>(
        &self,
        py: Python<'py>,
    ) -> Vec<(
        usize,
        f64,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        self.0
            .harmonics
            .iter()
            .map(|h| {
                (
                    h.harmonic,
                    h.center_hz,
                    PyArray1::from_slice(py, &h.enf_hz),
                    PyArray1::from_slice(py, &h.snr_db),
                )
            })
            .collect()
    }

    /// The JSON form (`eenf extract --json`), as text.
    fn to_json(&self) -> PyResult<String> {
        let mut out = Vec::new();
        self.0.write_json(&mut out).map_err(py_err)?;
        String::from_utf8(out).map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// The CSV form (`time_s,enf_hz`, …), as text.
    fn to_csv(&self) -> PyResult<String> {
        let mut out = Vec::new();
        self.0.write_csv(&mut out).map_err(py_err)?;
        String::from_utf8(out).map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// Writes the trace to `path` whole or not at all: JSON when it ends in `.json`, else CSV.
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let t = self.0.clone();
        py.detach(|| eenf::output::write_atomic(&path, |w| t.write_for(&path, w)))
            .map_err(py_err)
    }

    /// Reads a trace file: eenf JSON, a `time_s,enf_hz` CSV, or an `index,value` CSV with a
    /// value every `index_step` s.
    #[staticmethod]
    #[pyo3(signature = (path, index_step=None))]
    fn read(py: Python<'_>, path: PathBuf, index_step: Option<f64>) -> PyResult<Self> {
        if index_step.is_some_and(|s| s.is_nan() || s <= 0.0) {
            return Err(PyValueError::new_err("index_step must be positive"));
        }
        py.detach(|| Trace::read(&path, index_step))
            .map(|t| PyTrace(Arc::new(t)))
            .map_err(py_err)
    }

    /// A trace of `enf_hz` every `step_s` seconds from 0.
    #[staticmethod]
    fn from_values(step_s: f64, enf_hz: PyReadonlyArray1<'_, f64>) -> PyResult<Self> {
        if step_s.is_nan() || step_s <= 0.0 {
            return Err(PyValueError::new_err("step_s must be positive"));
        }
        let v = enf_hz
            .as_slice()
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        Ok(PyTrace(Arc::new(Trace::new(step_s, v.to_vec()))))
    }
}

fn traced(r: eenf::Result<Trace>) -> PyResult<PyTrace> {
    r.map(|t| PyTrace(Arc::new(t))).map_err(py_err)
}

/// E-ENF from an event file (`eenf extract`). The GIL is released.
#[pyfunction]
#[pyo3(signature = (path, options="{}"))]
fn extract(py: Python<'_>, path: PathBuf, options: &str) -> PyResult<PyTrace> {
    let set: opts::ExtractSettings = settings(options)?;
    let o = set.options().map_err(option_err)?;
    traced(py.detach(|| eenf::extract::extract(&Recording::File(path), &o, &Progress::hidden())))
}

/// E-ENF from events in memory (columns; `name` names them in messages and in the trace).
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (t, x, y, p, width, height, name, options="{}"))]
fn extract_events(
    py: Python<'_>,
    t: PyReadonlyArray1<'_, i64>,
    x: PyReadonlyArray1<'_, u16>,
    y: PyReadonlyArray1<'_, u16>,
    p: PyReadonlyArray1<'_, bool>,
    width: u16,
    height: u16,
    name: PathBuf,
    options: &str,
) -> PyResult<PyTrace> {
    let set: opts::ExtractSettings = settings(options)?;
    let o = set.options().map_err(option_err)?;
    let events = Arc::new(batch_of(t, x, y, p)?);
    let rec = Recording::Memory {
        name,
        events,
        width,
        height,
    };
    traced(py.detach(|| eenf::extract::extract(&rec, &o, &Progress::hidden())))
}

/// The ENF of a sound file (`eenf reference`). The GIL is released.
#[pyfunction]
#[pyo3(signature = (path, options="{}"))]
fn trace_sound(py: Python<'_>, path: PathBuf, options: &str) -> PyResult<PyTrace> {
    let (audio, tracker) = sound_settings(options)?;
    let params = tracker.params().map_err(option_err)?;
    traced(py.detach(|| {
        eenf::mains::sound_trace(
            &Sound::File(&path),
            &audio.options(),
            &audio.hum(&tracker),
            tracker.nominal,
            &params,
        )
    }))
}

/// The ENF of samples in memory: `interleaved` frames of `channels` channels at `fs` Hz.
#[pyfunction]
#[pyo3(signature = (interleaved, channels, fs, name, options="{}"))]
fn trace_samples(
    py: Python<'_>,
    interleaved: PyReadonlyArray1<'_, f32>,
    channels: usize,
    fs: f64,
    name: PathBuf,
    options: &str,
) -> PyResult<PyTrace> {
    let (audio, tracker) = sound_settings(options)?;
    let params = tracker.params().map_err(option_err)?;
    let samples = interleaved
        .as_slice()
        .map_err(|e| PyValueError::new_err(e.to_string()))?
        .to_vec();
    traced(py.detach(|| {
        let sound = Sound::Samples {
            name: &name,
            interleaved: &samples,
            channels,
            fs,
        };
        eenf::mains::sound_trace(
            &sound,
            &audio.options(),
            &audio.hum(&tracker),
            tracker.nominal,
            &params,
        )
    }))
}

/// `reference`'s two option sets, filled from keyword arguments and checked.
fn sound_settings(options: &str) -> PyResult<(opts::AudioSettings, opts::TrackerSettings)> {
    let (mut audio, mut tracker) = Default::default();
    opts::apply_json(&mut [&mut audio, &mut tracker], options).map_err(option_err)?;
    Ok((audio, tracker))
}

/// V-ENF from a video (`eenf video`). The GIL is released.
#[pyfunction]
#[pyo3(signature = (path, options="{}"))]
fn video(py: Python<'_>, path: PathBuf, options: &str) -> PyResult<PyTrace> {
    let set: opts::VideoSettings = settings(options)?;
    let o = set.options().map_err(option_err)?;
    traced(py.detach(|| eenf::video::trace_video(&path, &o, &Progress::hidden())))
}

/// Draws `trace` into `path` (`.png` or `.svg`) as `eenf extract --plot` does: its ENF, each
/// harmonic's and the one chosen in each segment, titled `title`. The GIL is released.
#[pyfunction]
fn plot_trace(
    py: Python<'_>,
    trace: PyRef<'_, PyTrace>,
    path: PathBuf,
    title: String,
) -> PyResult<()> {
    let t = trace.0.clone();
    py.detach(|| eenf_figures::plot_extraction(&path, &title, &t))
        .map_err(py_err)
}

/// A reference for `compare`: a trace at hand, or a file (trace, WAV, folder of hourly WAVs).
#[derive(FromPyObject)]
enum ReferenceIn<'py> {
    Trace(PyRef<'py, PyTrace>),
    Path(PathBuf),
}

/// `eenf compare`: the agreement of an estimate with its reference, as JSON text with the
/// aligned values. The GIL is released.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (estimate, name, reference, offset_s=0.0, index_step=eenf::trace::INDEX_STEP_S, nominal="auto", peak=None))]
fn compare(
    py: Python<'_>,
    estimate: PyRef<'_, PyTrace>,
    name: PathBuf,
    reference: ReferenceIn<'_>,
    offset_s: f64,
    index_step: f64,
    nominal: &str,
    peak: Option<&str>,
) -> PyResult<String> {
    if index_step.is_nan() || index_step <= 0.0 {
        return Err(PyValueError::new_err("index_step must be positive"));
    }
    let nominal: Nominal = nominal.parse().map_err(PyValueError::new_err)?;
    let est = estimate.0.clone();
    let peak = match peak {
        Some(p) => p.parse().map_err(PyValueError::new_err)?,
        None => est.peak().unwrap_or(eenf_dsp::PeakMethod::Exact),
    };
    let params = eenf_dsp::EnfParams {
        peak,
        ..eenf_dsp::EnfParams::default()
    };
    let c = match reference {
        ReferenceIn::Trace(r) => {
            let r = r.0.clone();
            py.detach(|| {
                eenf::evaluate::compare_with(&est.time_s, &est.enf_hz, &name, &r, offset_s)
            })
        }
        ReferenceIn::Path(path) => py.detach(|| {
            eenf::evaluate::compare_trace(
                &est, &name, &path, offset_s, index_step, nominal, &params,
            )
        }),
    }
    .map_err(py_err)?;
    let mut v = c.summary_json(offset_s);
    v["time_s"] = serde_json::json!(c.time_s);
    v["estimate"] = serde_json::json!(c.estimate);
    v["reference"] = serde_json::json!(c.reference);
    Ok(v.to_string())
}

/// `eenf match`: where a trace fits in long references, as `eenf match --json` prints it.
/// The GIL is released.
#[pyfunction]
#[pyo3(signature = (trace, name, reference, options="{}"))]
fn locate(
    py: Python<'_>,
    trace: PyRef<'_, PyTrace>,
    name: PathBuf,
    reference: PathBuf,
    options: &str,
) -> PyResult<String> {
    let m: opts::MatchSettings = settings(options)?;
    let query = m.query().map_err(option_err)?;
    let t = trace.0.clone();
    py.detach(|| {
        let located = eenf::locate::locate(
            &t,
            &name,
            &reference,
            m.tz.as_ref(),
            &query,
            &Progress::hidden(),
        )?;
        Ok(located.to_json(&name, query.alpha).to_string())
    })
    .map_err(py_err)
}

/// `eenf refdb build`: adds grid archives, hourly mains WAVs or trace files to the store at
/// `store` (created when missing); returns the grids changed and what each archive gave, as
/// JSON text. The GIL is released.
#[pyfunction]
#[pyo3(signature = (store, inputs, options="{}"))]
fn refdb_build(
    py: Python<'_>,
    store: PathBuf,
    inputs: Vec<String>,
    options: &str,
) -> PyResult<String> {
    let a: opts::StoreInputSettings = settings(options)?;
    let build = a.build(inputs).map_err(option_err)?;
    py.detach(|| {
        let built = eenf::reference::build_store(&store, &build, &Progress::hidden(), || {})?;
        let grids: Vec<_> = built
            .grids
            .iter()
            .map(|g| serde_json::json!({"grid": g.grid, "values": g.values}))
            .collect();
        let archives: Vec<_> = built
            .archives
            .iter()
            .map(|(p, r)| serde_json::json!({"path": p, "summary": r.to_string(), "report": r}))
            .collect();
        Ok(serde_json::json!({"store": store, "grids": grids, "archives": archives}).to_string())
    })
    .map_err(py_err)
}

/// `eenf refdb fetch`: fetches `start` to `end` (default now) of a grid operator's data
/// (`gb`, `se`, `ch`, `osf`, `fi`) into the store at `store`; returns what was fetched, as JSON
/// text. The GIL is released.
#[pyfunction]
#[pyo3(signature = (source, store, start, end=None, endpoint=None, grid=None, cache=None, retries=3, wait=true, api_key=None))]
#[allow(clippy::too_many_arguments)]
fn refdb_fetch(
    py: Python<'_>,
    source: &str,
    store: PathBuf,
    start: &str,
    end: Option<&str>,
    endpoint: Option<String>,
    grid: Option<String>,
    cache: Option<PathBuf>,
    retries: u32,
    wait: bool,
    api_key: Option<String>,
) -> PyResult<String> {
    use eenf::fetch;
    let req = (|| -> eenf::Result<fetch::FetchRequest> {
        Ok(fetch::FetchRequest {
            source: fetch::Source::parse(source)?,
            from_unix_s: fetch::parse_day_or_time(start, false)?,
            to_unix_s: match end {
                Some(t) => fetch::parse_day_or_time(t, true)?,
                None => f64::INFINITY,
            },
            store,
            cache: cache.unwrap_or_else(fetch::default_cache),
            endpoint,
            grid,
            retries,
            wait,
            api_key,
        })
    })()
    .map_err(py_err)?;
    py.detach(|| {
        Ok(fetch::fetch(&req, &Progress::hidden())?
            .to_json()
            .to_string())
    })
    .map_err(py_err)
}

/// `eenf refdb update`: brings every fetched grid of the store at `store` up to now; returns
/// what each source gave, as JSON text (a list). The GIL is released.
#[pyfunction]
#[pyo3(signature = (store, cache=None, retries=3, wait=true, api_key=None))]
fn refdb_update(
    py: Python<'_>,
    store: PathBuf,
    cache: Option<PathBuf>,
    retries: u32,
    wait: bool,
    api_key: Option<String>,
) -> PyResult<String> {
    use eenf::fetch;
    let cache = cache.unwrap_or_else(fetch::default_cache);
    py.detach(|| {
        let done = fetch::update(
            &store,
            &cache,
            retries,
            wait,
            api_key.as_deref(),
            &Progress::hidden(),
        )?;
        let list: Vec<_> = done.iter().map(|f| f.to_json()).collect();
        Ok(serde_json::Value::from(list).to_string())
    })
    .map_err(py_err)
}

/// `eenf simulate`: writes a recording and its truth; returns what was written, as JSON text.
/// The GIL is released.
#[pyfunction]
#[pyo3(signature = (options="{}"))]
fn simulate(py: Python<'_>, options: &str) -> PyResult<String> {
    let a: opts::SimulateSettings = settings(options)?;
    let recipe = a.recipe().map_err(option_err)?;
    py.detach(|| {
        let r = eenf::simulation::simulate_recording(&recipe, &Progress::hidden())?;
        Ok(serde_json::json!({
            "recording": r.sim.recording, "truth": r.sim.truth, "events": r.sim.stats.events,
            "videos": r.videos, "references": r.references,
            "width": r.config.width, "height": r.config.height,
        })
        .to_string())
    })
    .map_err(py_err)
}

/// `eenf simulate-dataset`: builds a simulated dataset into `out_dir`; returns what was
/// written, as JSON text. The GIL is released.
#[pyfunction]
#[pyo3(signature = (out_dir, options="{}"))]
fn simulate_dataset(py: Python<'_>, out_dir: PathBuf, options: &str) -> PyResult<String> {
    let a: opts::DatasetSettings = settings(options)?;
    py.detach(|| {
        let build = a.build(out_dir.clone())?;
        let mut notes = Vec::new();
        let built = eenf::dataset_build::build_dataset(&build, &Progress::hidden(), &mut |n| {
            notes.push(n)
        })?;
        Ok(serde_json::json!({
            "out_dir": out_dir,
            "manifest": out_dir.join("manifest.csv"),
            "recordings": built.recordings, "events": built.events,
            "references": built.references, "notes": notes,
        })
        .to_string())
    })
    .map_err(py_err)
}

/// Writes events (columns, checked) to `path` whole or not at all (`eenf convert`'s writers);
/// returns the number written. The GIL is released.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
#[pyo3(signature = (path, t, x, y, p, width, height, options="{}"))]
fn write_events(
    py: Python<'_>,
    path: PathBuf,
    t: PyReadonlyArray1<'_, i64>,
    x: PyReadonlyArray1<'_, u16>,
    y: PyReadonlyArray1<'_, u16>,
    p: PyReadonlyArray1<'_, bool>,
    width: u16,
    height: u16,
    options: &str,
) -> PyResult<u64> {
    let out: opts::EventOutputSettings = settings(options)?;
    let format = out.format_for(&path, None).map_err(option_err)?;
    let events = batch_of(t, x, y, p)?;
    py.detach(|| {
        eenf_events::memory::check_events(&events, width, height, &path)?;
        eenf::output::write_events(&path, format, width, height, |w| {
            for i in (0..events.len()).step_by(1 << 16) {
                let r = i..(i + (1 << 16)).min(events.len());
                let chunk = EventBatch {
                    t: events.t[r.clone()].to_vec(),
                    x: events.x[r.clone()].to_vec(),
                    y: events.y[r.clone()].to_vec(),
                    p: events.p[r].to_vec(),
                };
                w.write(&chunk)?;
            }
            Ok(())
        })
    })
    .map_err(py_err)
}

/// An edits report: its JSON, and the figure's series (time, phase deviation, strength over
/// threshold, ENF).
type EditsOut<'py> = (
    String,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
);

fn edits_out(py: Python<'_>, r: eenf::Result<eenf::edits::EditReport>) -> PyResult<EditsOut<'_>> {
    let r = r.map_err(py_err)?;
    let s = r.series.clone();
    Ok((
        r.to_json(),
        s.time_s.into_pyarray(py),
        s.phase_deg.into_pyarray(py),
        s.strength.into_pyarray(py),
        s.enf_hz.into_pyarray(py),
    ))
}

/// Edits of a file (`eenf edits`). The GIL is released.
#[pyfunction]
#[pyo3(signature = (path, options="{}"))]
fn edits<'py>(py: Python<'py>, path: PathBuf, options: &str) -> PyResult<EditsOut<'py>> {
    let a: opts::EditSettings = settings(options)?;
    let o = a.options().map_err(option_err)?;
    let r = py.detach(|| eenf::edits::file_edits(&path, &o, &Progress::hidden()));
    edits_out(py, r)
}

/// Edits of samples in memory: `interleaved` frames of `channels` channels at `fs` Hz.
#[pyfunction]
#[pyo3(signature = (interleaved, channels, fs, name, options="{}"))]
fn edits_samples<'py>(
    py: Python<'py>,
    interleaved: PyReadonlyArray1<'_, f32>,
    channels: usize,
    fs: f64,
    name: PathBuf,
    options: &str,
) -> PyResult<EditsOut<'py>> {
    let a: opts::EditSettings = settings(options)?;
    let o = a.options().map_err(option_err)?;
    let samples = interleaved
        .as_slice()
        .map_err(|e| PyValueError::new_err(e.to_string()))?
        .to_vec();
    let r = py.detach(|| {
        let sound = Sound::Samples {
            name: &name,
            interleaved: &samples,
            channels,
            fs,
        };
        eenf::edits::sound_edits(&sound, &o.audio, o.extract.nominal, &o.params)
    });
    edits_out(py, r)
}

/// The native module.
#[pymodule]
fn _eenf(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // messages name options as Python's users write them: `max_gap=`
    eenf_core::spelling::set_spelling(eenf_core::spelling::Spelling::Keywords);
    m.add("RECORD_BYTES", RECORD)?;
    m.add("VERSION", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<PyTrace>()?;
    m.add_class::<EventIterator>()?;
    m.add_function(wrap_pyfunction!(options, m)?)?;
    m.add_function(wrap_pyfunction!(read_events, m)?)?;
    m.add_function(wrap_pyfunction!(info, m)?)?;
    m.add_function(wrap_pyfunction!(extract, m)?)?;
    m.add_function(wrap_pyfunction!(extract_events, m)?)?;
    m.add_function(wrap_pyfunction!(trace_sound, m)?)?;
    m.add_function(wrap_pyfunction!(trace_samples, m)?)?;
    m.add_function(wrap_pyfunction!(video, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(plot_trace, m)?)?;
    m.add_function(wrap_pyfunction!(locate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(simulate_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(refdb_build, m)?)?;
    m.add_function(wrap_pyfunction!(refdb_fetch, m)?)?;
    m.add_function(wrap_pyfunction!(refdb_update, m)?)?;
    m.add_function(wrap_pyfunction!(write_events, m)?)?;
    m.add_function(wrap_pyfunction!(edits, m)?)?;
    m.add_function(wrap_pyfunction!(edits_samples, m)?)?;
    Ok(())
}
