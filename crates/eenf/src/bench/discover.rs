//! The recordings of a dataset: an EV-ENFD-like tree, or a manifest CSV.

use std::path::{Path, PathBuf};

use crate::error::{fail, Context, Error, Missing, Result};
use serde::Serialize;

/// One recording of a dataset to score: its event file, class, reference and videos.
#[derive(Debug, Clone, Serialize)]
pub struct DatasetEntry {
    /// The event file.
    pub path: PathBuf,
    /// Its class (`static`, `dynamic`, `extreme`, or any folder name).
    pub class: String,
    /// Its reference: a folder of hourly WAVs, a WAV, or a trace.
    pub reference: PathBuf,
    /// Seconds into the reference where the recording starts (a WAV or trace reference).
    pub offset_s: f64,
    /// Its videos (`<stem>_lr.*`, `<stem>_hr.*`).
    pub videos: Vec<PathBuf>,
    /// Its length if the manifest says it, s (for the memory budget).
    pub duration_s: Option<f64>,
    /// Its flicker line's prominence if the manifest says it (the calibration measure:
    /// whole-recording 1 ms ON − OFF sums, peak near 2f0 over the 80–140 Hz median).
    pub prominence: Option<f64>,
}

/// The prominence bands `bench --by prominence` groups recordings into.
pub const PROMINENCE_BANDS: [(f64, &str); 4] = [
    (0.0, "prominence <10"),
    (10.0, "prominence 10-15"),
    (15.0, "prominence 15-20"),
    (20.0, "prominence >=20"),
];

/// Regroups recordings by the prominence of their flicker line (from the manifest) instead
/// of their class. Fails when a recording has none.
pub fn group_by_prominence(recs: &mut [DatasetEntry]) -> Result<()> {
    for r in recs.iter_mut() {
        let Some(p) = r.prominence else {
            fail!(
                Input,
                "{}: the manifest gives no prominence (simulate-dataset writes one)",
                r.path.display()
            );
        };
        let band = PROMINENCE_BANDS.iter().rev().find(|b| p >= b.0);
        r.class = band.map_or(PROMINENCE_BANDS[0].1, |b| b.1).to_string();
    }
    recs.sort_by(|a, b| {
        class_rank(&a.class)
            .cmp(&class_rank(&b.class))
            .then(a.path.cmp(&b.path))
    });
    Ok(())
}

impl DatasetEntry {
    /// The recording's name for tables: `class/stem`.
    pub fn name(&self) -> String {
        let stem = self.path.file_stem().unwrap_or_default().to_string_lossy();
        format!("{}/{stem}", self.class)
    }

    /// Its video from camera `lr` or `hr`: the coded one (MP4, …) when there are several, as
    /// that is what a camera delivers; else the Y4M.
    pub fn video(&self, camera: &str) -> Option<&Path> {
        let suffix = format!("_{camera}");
        let mut found: Vec<&PathBuf> = self
            .videos
            .iter()
            .filter(|v| {
                v.file_stem()
                    .and_then(|s| s.to_str())
                    .is_some_and(|s| s.ends_with(&suffix))
            })
            .collect();
        found.sort_by_key(|v| is_y4m(v));
        found.first().map(|p| p.as_path())
    }
}

fn is_y4m(p: &Path) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("y4m"))
}

/// File extensions of event recordings looked for in a dataset tree.
const EVENT_EXTENSIONS: [&str; 5] = ["aedat4", "aedat", "raw", "dat", "evt"];
/// File extensions of videos looked for beside them.
const VIDEO_EXTENSIONS: [&str; 6] = ["y4m", "mp4", "mkv", "avi", "mov", "webm"];

fn has_extension(p: &Path, list: &[&str]) -> bool {
    p.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| list.iter().any(|x| e.eq_ignore_ascii_case(x)))
}

/// The recordings of `dataset`: a manifest CSV, or a folder laid out like the EV-ENFD (one
/// folder per class holding event files and their `<stem>_lr.*`/`<stem>_hr.*` videos, and
/// `ENF_Reference/` with hourly WAVs).
pub fn discover(dataset: &Path) -> Result<Vec<DatasetEntry>> {
    crate::dataset::check_complete(dataset)?;
    if dataset.is_dir() {
        scan_tree(dataset)
    } else if dataset.is_file() {
        read_manifest(dataset)
    } else {
        fail!(
            Input,
            "{}: no such dataset folder or manifest",
            dataset.display()
        )
    }
}

/// Class folders first in the paper's order, then the others alphabetically.
pub fn class_rank(class: &str) -> (usize, String) {
    let known = ["static", "dynamic", "extreme"];
    if let Some(k) = PROMINENCE_BANDS.iter().position(|b| b.1 == class) {
        return (known.len() + 1 + k, class.to_string());
    }
    (
        known
            .iter()
            .position(|k| *k == class)
            .unwrap_or(known.len()),
        class.to_string(),
    )
}

/// A name starting with a dot.
fn is_hidden(p: &Path) -> bool {
    p.file_name()
        .is_some_and(|n| n.to_string_lossy().starts_with('.'))
}

fn scan_tree(dir: &Path) -> Result<Vec<DatasetEntry>> {
    let references = dir.join("ENF_Reference");
    if !references.is_dir() {
        fail!(Input,
            "{}: no ENF_Reference folder (an EV-ENFD-like tree has one folder per class and ENF_Reference/ with the hourly WAVs; or pass a manifest CSV)",
            dir.display()
        );
    }
    let mut out = Vec::new();
    let mut classes: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("{}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir() && p.file_name() != Some("ENF_Reference".as_ref()))
        .filter(|p| !is_hidden(p))
        .collect();
    classes.sort();
    for class_dir in classes {
        let class = class_dir.file_name().unwrap().to_string_lossy().to_string();
        let mut files: Vec<PathBuf> = std::fs::read_dir(&class_dir)
            .with_context(|| format!("{}", class_dir.display()))?
            .filter_map(|e| e.ok().map(|e| e.path()))
            // hidden names are temporary files of a run in progress or killed, never recordings
            .filter(|p| p.is_file() && !is_hidden(p))
            .collect();
        files.sort();
        for f in files.iter().filter(|f| has_extension(f, &EVENT_EXTENSIONS)) {
            let stem = f
                .file_stem()
                .unwrap_or_default()
                .to_string_lossy()
                .to_string();
            let videos = files
                .iter()
                .filter(|v| has_extension(v, &VIDEO_EXTENSIONS))
                .filter(|v| {
                    let s = v.file_stem().unwrap_or_default().to_string_lossy();
                    s == format!("{stem}_lr") || s == format!("{stem}_hr")
                })
                .cloned()
                .collect();
            out.push(DatasetEntry {
                path: f.clone(),
                class: class.clone(),
                reference: references.clone(),
                offset_s: 0.0,
                videos,
                duration_s: None,
                prominence: None,
            });
        }
    }
    if out.is_empty() {
        fail!(
            Input,
            "{}: no event recordings ({}) in its class folders",
            dir.display(),
            EVENT_EXTENSIONS.join(", ")
        );
    }
    out.sort_by(|a, b| {
        class_rank(&a.class)
            .cmp(&class_rank(&b.class))
            .then(a.path.cmp(&b.path))
    });
    Ok(out)
}

/// Reads a manifest: a CSV with a header holding at least `recording`, `class` and
/// `reference`, and optionally `offset_s` (seconds into the reference) and `videos`
/// (`;`-separated). Paths are relative to the manifest's folder.
pub fn read_manifest(path: &Path) -> Result<Vec<DatasetEntry>> {
    let base = path.parent().unwrap_or(Path::new("."));
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_path(path)
        .with_context(|| format!("{}", path.display()))?;
    let headers = reader
        .headers()
        .with_context(|| format!("{}: no CSV header", path.display()))?
        .clone();
    let col = |name: &str| headers.iter().position(|h| h == name);
    let (Some(rec_c), Some(class_c), Some(ref_c)) =
        (col("recording"), col("class"), col("reference"))
    else {
        fail!(Input,
            "{}: a manifest needs the columns recording, class, reference (and optionally offset_s, videos); found {:?}",
            path.display(),
            headers.iter().collect::<Vec<_>>()
        );
    };
    let (off_c, vid_c, dur_c) = (col("offset_s"), col("videos"), col("duration_s"));
    let prom_c = col("prominence");
    let mut out = Vec::new();
    for (i, row) in reader.records().enumerate() {
        let line = i + 2;
        let row = row.with_context(|| format!("{}: line {line}", path.display()))?;
        let get = |c: usize| row.get(c).unwrap_or("").to_string();
        let field = |c: Option<usize>| c.map(get).unwrap_or_default();
        let recording = get(rec_c);
        if recording.is_empty() {
            fail!(Input, "{}: line {line}: empty recording", path.display());
        }
        let offset_s = match field(off_c).as_str() {
            "" => 0.0,
            s => s
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .or_fail(Error::Input, || {
                    format!(
                        "{}: line {line}: offset_s {s:?} is not a number",
                        path.display()
                    )
                })?,
        };
        let videos = field(vid_c)
            .split(';')
            .map(str::trim)
            .filter(|v| !v.is_empty())
            .map(|v| base.join(v))
            .collect();
        out.push(DatasetEntry {
            path: base.join(&recording),
            class: match get(class_c) {
                c if c.is_empty() => "unclassified".into(),
                c => c,
            },
            reference: base.join(get(ref_c)),
            offset_s,
            videos,
            duration_s: field(dur_c).parse().ok(),
            prominence: field(prom_c).parse().ok().filter(|p: &f64| p.is_finite()),
        });
    }
    if out.is_empty() {
        fail!(
            Input,
            "{}: the manifest lists no recordings",
            path.display()
        );
    }
    Ok(out)
}
