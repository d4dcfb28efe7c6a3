//! One file, every question at once: what it is, its ENF trace, when it was recorded (against
//! reference stores) and whether it was edited. This is what the page (`eenf serve`) runs on an
//! upload; each step is the library function the matching command runs.
//!
//! Only the trace is required: a search or an edits test that cannot be done (a trace too
//! short for the stores, a video without sound) is reported beside the others, not as the
//! analysis's failure.

use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use crate::edits::{file_edits, trace_edits, EditInput, EditReport};
use crate::error::{OptionError, Result};
use crate::locate::{locate, Located, MatchQuery};
use crate::options::{
    AudioSettings, EditSettings, ExtractSettings, MatchSettings, OptionSet, TrackerSettings,
    VideoSettings,
};
use crate::progress::Progress;
use crate::trace::Trace;

/// What a file is read as.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum FileKind {
    /// An event recording or container (found from its content).
    Events,
    /// A video (V-ENF from its flicker).
    Video,
    /// An ENF trace (CSV or JSON).
    Trace,
    /// Sound: a mains recording or any recording's hum.
    Sound,
}

/// Extensions read as video: Y4M natively, the rest through ffmpeg.
const VIDEO_EXTENSIONS: [&str; 11] = [
    "y4m", "mp4", "mov", "mkv", "webm", "avi", "m4v", "mts", "m2ts", "3gp", "mpg",
];

impl FileKind {
    /// An event file when its content says so, a trace when its name ends in .csv or .json, a
    /// video by its extension, else sound.
    pub fn of(path: &Path) -> FileKind {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .unwrap_or_default();
        if ext == "csv" || ext == "json" {
            FileKind::Trace
        } else if eenf_events::probe(path).is_ok() {
            FileKind::Events
        } else if VIDEO_EXTENSIONS.contains(&ext.as_str()) {
            FileKind::Video
        } else {
            FileKind::Sound
        }
    }

    /// Its name, as the JSON gives it.
    pub fn name(self) -> &'static str {
        match self {
            FileKind::Events => "events",
            FileKind::Video => "video",
            FileKind::Trace => "trace",
            FileKind::Sound => "sound",
        }
    }
}

/// Every option an analysis takes, one set per step (each at its defaults unless given).
#[derive(Debug, Clone, Default)]
pub struct AnalysisSettings {
    /// E-ENF (`extract`).
    pub extract: ExtractSettings,
    /// How a sound is read (`reference`).
    pub audio: AudioSettings,
    /// The hum's tracker (`reference`).
    pub tracker: TrackerSettings,
    /// V-ENF (`video`).
    pub video: VideoSettings,
    /// The search (`match`): `verify` is a claimed start time.
    pub matching: MatchSettings,
    /// The edits test (`edits`).
    pub edits: EditSettings,
}

impl AnalysisSettings {
    /// Fills the sets from a JSON object of options: each name goes to every set that has it
    /// (`nominal` sets the grid of every step), then each set is checked.
    pub fn from_json(json: &str) -> std::result::Result<Self, OptionError> {
        let mut s = AnalysisSettings::default();
        crate::options::apply_json_to_all(&mut s.sets(), json)?;
        Ok(s)
    }

    fn sets(&mut self) -> [&mut dyn OptionSet; 6] {
        [
            &mut self.extract,
            &mut self.audio,
            &mut self.tracker,
            &mut self.video,
            &mut self.matching,
            &mut self.edits,
        ]
    }

    /// Every option of every step, as text (for a report that must name each parameter).
    pub fn describe(&self) -> String {
        format!("{self:#?}")
    }
}

/// One store's answer to `match`.
pub struct StoreMatch {
    /// The store searched.
    pub store: PathBuf,
    /// The candidates, or why there are none.
    pub result: Result<Located>,
}

/// All that an analysis found.
pub struct Analysis {
    /// What the file was read as.
    pub kind: FileKind,
    /// What the file holds: `eenf info --json` for event files; for the rest, what tracing
    /// read (the trace's provenance).
    pub about: Value,
    /// The ENF trace.
    pub trace: Trace,
    /// Where in the view the flicker is (event files only; as `flicker-map`).
    pub flicker_map: Option<Result<crate::flicker_map::FlickerMap>>,
    /// `match` against each store, in the order given.
    pub matches: Vec<StoreMatch>,
    /// The search's query (its `alpha` is the verdict's level).
    pub query: MatchQuery,
    /// `edits`: its report, or why it could not be run.
    pub edits: Result<EditReport>,
    /// Seconds the analysis took.
    pub seconds: f64,
}

/// Analyses the file at `path`: reads it as `kind` (or as [`FileKind::of`] finds), traces it,
/// searches `stores` and tests it for edits. Fails only when no trace can be made.
pub fn analyse(
    path: &Path,
    kind: Option<FileKind>,
    settings: &AnalysisSettings,
    stores: &[PathBuf],
    progress: &Progress,
) -> Result<Analysis> {
    let start = std::time::Instant::now();
    let kind = kind.unwrap_or_else(|| FileKind::of(path));
    let mut flicker_map = None;
    let (trace, about) = match kind {
        FileKind::Events => {
            let open = settings.extract.input.open_options();
            let found = crate::inspect::inspect(path, &open)?;
            let opts = settings.extract.options()?;
            let trace = crate::extract::extract_file(path, &opts, progress)?;
            let rec = crate::recording::Recording::file(path);
            flicker_map = Some(crate::flicker_map::flicker_map(&rec, &open, None, progress));
            (trace, found.to_json(path))
        }
        FileKind::Video => {
            let trace = crate::video::trace_video(path, &settings.video.options()?, progress)?;
            let about = provenance(&trace);
            (trace, about)
        }
        FileKind::Sound => {
            let (audio, tracker) = (&settings.audio, &settings.tracker);
            let bar = progress.spinner("tracing the hum");
            let trace = crate::mains::audio_trace(
                path,
                &audio.options(),
                &audio.hum(tracker),
                tracker.nominal,
                &tracker.params()?,
            );
            bar.finish_and_clear();
            let trace = trace?;
            let about = provenance(&trace);
            (trace, about)
        }
        FileKind::Trace => {
            let trace = Trace::read(path, None)?;
            let about = json!({"values": trace.enf_hz.len(), "step_s": trace.step_s});
            (trace, about)
        }
    };
    let query = settings.matching.query()?;
    let matches = stores
        .iter()
        .map(|store| StoreMatch {
            store: store.clone(),
            result: locate(
                &trace,
                path,
                store,
                settings.matching.tz.as_ref(),
                &query,
                progress,
            ),
        })
        .collect();
    let edits = edits_of(path, kind, &trace, settings, progress);
    Ok(Analysis {
        kind,
        about,
        trace,
        flicker_map,
        matches,
        query,
        edits,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// The edits test as the file allows: on the hum's phase for sound and events, on the
/// frequency steps alone for a trace or a video.
fn edits_of(
    path: &Path,
    kind: FileKind,
    trace: &Trace,
    settings: &AnalysisSettings,
    progress: &Progress,
) -> Result<EditReport> {
    let mut opts = settings.edits.options()?;
    match kind {
        FileKind::Video | FileKind::Trace => trace_edits(trace, path, &opts.params),
        FileKind::Events | FileKind::Sound => {
            opts.input = if kind == FileKind::Events {
                EditInput::Events
            } else {
                EditInput::Audio
            };
            let bar = progress.spinner("testing for edits");
            let r = file_edits(path, &opts, progress);
            bar.finish_and_clear();
            r
        }
    }
}

/// A trace's provenance (what was read and how) without its values.
fn provenance(trace: &Trace) -> Value {
    let mut v = trace.to_json_value();
    if let Some(map) = v.as_object_mut() {
        for k in ["time_s", "enf_hz", "snr_db", "harmonics", "selected"] {
            map.remove(k);
        }
    }
    v
}

impl Analysis {
    /// Estimates that are numbers (not gaps).
    pub fn estimates(&self) -> usize {
        self.trace.finite().count()
    }

    /// The whole analysis as JSON: `kind`, `about`, `trace` (as `extract --json` writes it),
    /// `matches` (each store's `match --json`, or its `error`), `edits` (as `edits --json`, or
    /// its `error`), `seconds`.
    pub fn to_json(&self, name: &Path) -> Value {
        let matches: Vec<Value> = self
            .matches
            .iter()
            .map(|m| match &m.result {
                Ok(l) => json!({"store": m.store, "result": l.to_json(name, self.query.alpha)}),
                Err(e) => json!({"store": m.store, "error": e.report()}),
            })
            .collect();
        let edits = match &self.edits {
            Ok(r) => serde_json::to_value(r).unwrap_or(Value::Null),
            Err(e) => json!({"error": e.report()}),
        };
        json!({
            "kind": self.kind,
            "about": self.about,
            "grid_hz": self.trace.grid().map(|g| g.hz()),
            "estimates": self.estimates(),
            "line": self.trace.line_text(),
            "notices": self.trace.notices(),
            "trace": self.trace.to_json_value(),
            "flicker_map": match &self.flicker_map {
                None => Value::Null,
                Some(Ok(m)) => serde_json::to_value(m).unwrap_or(Value::Null),
                Some(Err(e)) => json!({"error": e.report()}),
            },
            "matches": matches,
            "edits": edits,
            "seconds": self.seconds,
        })
    }
}
