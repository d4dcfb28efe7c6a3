//! The one ENF trace type. E-ENF (events), V-ENF (video) and mains references all end as a
//! [`Trace`]; `compare`, `bench`, `match` and the plots take it. This module alone reads and
//! writes it: CSV (`time_s,enf_hz`, through `csv` + serde) and JSON (typed serde structs).

use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use crate::error::{error, fail, Context, Error, Missing, Result};
use eenf_core::Grid;
use eenf_dsp::{
    EnfEstimates, EnfParams, FlickerLine, HumSearch, PeakMethod, Plausibility, SamplingMethod,
};
use eenf_video::{RowSampling, SceneRemoval, VideoAnalysis, VideoOptions};
use serde::{Deserialize, Serialize};

/// Seconds between the rows of an `index,value` trace CSV unless told otherwise: the step of
/// the published 60 Hz ENF traces and of `simulate --index-step`.
pub const INDEX_STEP_S: f64 = 2.0;

/// The CSV header of trace files; checks outside the code rely on these first two columns.
pub const CSV_HEADER: &str = "time_s,enf_hz";

/// One flicker harmonic's ENF estimates (E-ENF).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HarmonicPart {
    /// Harmonic number m: the band is centred on 2m·f0.
    pub harmonic: usize,
    /// Band centre, Hz.
    pub center_hz: f64,
    /// ENF estimates on this band, Hz (NaN = none; `null` in JSON).
    #[serde(with = "nan_as_null")]
    pub enf_hz: Vec<f64>,
    /// The line's strength over the band's noise in each window, dB.
    #[serde(default, with = "nan_as_null", skip_serializing_if = "Vec::is_empty")]
    pub snr_db: Vec<f64>,
}

/// The harmonic chosen for one selection segment (E-ENF).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SelectedSegment {
    /// Start of the segment, s from the recording's start.
    pub start_s: f64,
    /// Harmonic number chosen there.
    pub harmonic: usize,
}

/// How an event recording became a trace.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventsProvenance {
    /// Format of the recording, e.g. `AEDAT 4.0`.
    pub format: String,
    /// Time of the first sample (the first event), µs as stored in the file.
    pub start_t_us: i64,
    /// The same as ISO 8601 UTC.
    pub start_utc: String,
    /// Events read.
    pub events: u64,
    /// Seconds covered by the polarity sequence.
    pub duration_s: f64,
    /// Temporal sampling used (`auto` resolved).
    pub sampling: SamplingMethod,
    /// Why `auto` chose it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampling_reason: Option<String>,
    /// Sampling interval, µs.
    pub dt_us: i64,
    /// Every parameter of the tracker (with the grid decided).
    pub params: EnfParams,
    /// The camera traced, in a file with several.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<u8>,
    /// The recording's flicker line (whole recording, Hann window), when measured.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flicker: Option<FlickerLine>,
    /// What was inferred or adapted on the way (chip, camera, window, clock).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub notes: Vec<String>,
    /// What ended the readable part of a damaged or cut-short recording early, and where.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub damage: Option<String>,
}

/// Marks a V-ENF trace in JSON (`"method": "v-enf"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum VideoMethod {
    /// Rolling-shutter V-ENF.
    #[serde(rename = "v-enf")]
    VEnf,
}

/// How a video became a trace.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VideoProvenance {
    /// Always `v-enf`.
    pub method: VideoMethod,
    /// Frame width, pixels.
    pub width: usize,
    /// Frame height, pixels.
    pub height: usize,
    /// Frame rate.
    pub fps: f64,
    /// Frames read.
    pub frames: usize,
    /// Sampling used (`auto` resolved to `zero-pad` or `global`).
    pub sampling: RowSampling,
    /// Why `auto` chose it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sampling_reason: Option<String>,
    /// True when the frames' times came from the container (a variable frame rate).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub frame_times: bool,
    /// Scene removal used.
    pub scene_removal: SceneRemoval,
    /// Rows per frame period (real and idle), when zero-padded.
    pub virtual_rows: Option<f64>,
    /// Rate of the row signal, Hz.
    pub fs_hz: f64,
    /// The flicker line found, Hz.
    pub line_hz: f64,
    /// Its height above the noise.
    pub prominence: f64,
    /// Every parameter of the tracker.
    pub params: EnfParams,
}

/// How a mains or audio recording became a trace.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MainsProvenance {
    /// Peak refinement used.
    pub peak: PeakMethod,
    /// STFT window, s.
    pub window_s: f64,
    /// Mains lines tracked (f0 … N·f0); 1 is the method's reference tracker on f0 alone.
    #[serde(default = "one")]
    pub mains_lines: usize,
    /// How the sound was read, when it was (decoder, rates, channel).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub audio: Option<AudioProvenance>,
    /// What the line detector found and what was made of it (`audio --harmonics auto`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hum: Option<HumReport>,
}

/// The hum of a recording as the line detector saw it, the lines traced, the window chosen,
/// and how the trace compares with what grids do.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HumReport {
    /// Every harmonic's line in the Welch spectrum (both grids unless one was named).
    pub search: HumSearch,
    /// The harmonics tracked (those of the grid that stand), strongest first.
    pub carriers: Vec<usize>,
    /// Why the window differs from the default, when it does.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window_note: Option<String>,
    /// Offset from nominal, spread, and the flags they raise.
    pub plausibility: Plausibility,
}

fn one() -> usize {
    1
}

/// How a recording's sound was read.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AudioProvenance {
    /// `symphonia` or `ffmpeg`.
    pub decoder: String,
    /// The recording's own sample rate, Hz.
    pub source_rate_hz: f64,
    /// The rate tracked, after decimation, Hz.
    pub rate_hz: f64,
    /// The recording's channels.
    pub channels: usize,
    /// The channel traced: `mix` or its number.
    pub channel: String,
    /// Frames decoded.
    pub frames: u64,
}

/// Where a trace came from and how it was made; `None` for a bare CSV.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Provenance {
    /// V-ENF on a video (tried first: its `method` tag is unambiguous).
    Video(VideoProvenance),
    /// E-ENF on an event recording.
    Events(EventsProvenance),
    /// A mains (or audio) recording.
    Mains(MainsProvenance),
}

/// An ENF trace: one estimate per step from the recording's start, with how it was made.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Trace {
    /// The recording traced (JSON metadata, else the trace file itself).
    pub file: Option<PathBuf>,
    /// The grid, Hz, when known.
    pub nominal_hz: Option<f64>,
    /// Seconds between estimates.
    pub step_s: f64,
    /// Seconds from the recording's start of each estimate.
    pub time_s: Vec<f64>,
    /// ENF, Hz (NaN = no estimate).
    pub enf_hz: Vec<f64>,
    /// Each estimate's line strength over its noise, dB (empty when not measured).
    pub snr_db: Vec<f64>,
    /// Per-harmonic estimates (E-ENF).
    pub harmonics: Vec<HarmonicPart>,
    /// The harmonic chosen per selection segment (E-ENF).
    pub selected: Vec<SelectedSegment>,
    /// Where it came from.
    pub provenance: Option<Provenance>,
    /// What the caller should show the user: damage a decoder skipped, for instance.
    pub warnings: Vec<String>,
}

/// The JSON layout (keys come out sorted, as `serde_json` maps keep them).
#[derive(Serialize, Deserialize)]
struct TraceJson {
    #[serde(default)]
    file: Option<PathBuf>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    nominal_hz: Option<f64>,
    #[serde(default)]
    step_s: Option<f64>,
    time_s: Vec<f64>,
    #[serde(with = "nan_as_null")]
    enf_hz: Vec<f64>,
    #[serde(default, with = "nan_as_null", skip_serializing_if = "Vec::is_empty")]
    snr_db: Vec<f64>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    harmonics: Vec<HarmonicPart>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    selected: Vec<SelectedSegment>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    warnings: Vec<String>,
}

/// Seconds `0, step, 2·step, …` for `n` estimates.
pub fn times(n: usize, step: f64) -> Vec<f64> {
    (0..n).map(|i| i as f64 * step).collect()
}

impl Trace {
    /// A trace of `enf_hz` at `step_s` from time 0.
    pub fn new(step_s: f64, enf_hz: Vec<f64>) -> Self {
        Trace {
            step_s,
            time_s: times(enf_hz.len(), step_s),
            enf_hz,
            ..Trace::default()
        }
    }

    /// The E-ENF trace of `estimates`, made from an event recording as `provenance` says.
    pub fn from_events(
        file: &Path,
        estimates: &EnfEstimates,
        provenance: EventsProvenance,
    ) -> Self {
        Trace {
            nominal_hz: Some(provenance.params.nominal_hz),
            provenance: Some(Provenance::Events(provenance)),
            ..Trace::from_estimates(file, estimates)
        }
    }

    /// The trace of a mains or audio recording whose lines were tracked band by band.
    pub fn from_mains_lines(
        file: &Path,
        grid: Grid,
        estimates: &EnfEstimates,
        provenance: MainsProvenance,
    ) -> Self {
        Trace {
            nominal_hz: Some(grid.hz()),
            provenance: Some(Provenance::Mains(provenance)),
            ..Trace::from_estimates(file, estimates)
        }
    }

    /// The values, line strengths, per-harmonic parts and selection of `estimates`.
    fn from_estimates(file: &Path, estimates: &EnfEstimates) -> Self {
        let seg = estimates.segment_len as f64 * estimates.step_s;
        Trace {
            file: Some(file.to_path_buf()),
            harmonics: estimates
                .harmonics
                .iter()
                .map(|h| HarmonicPart {
                    harmonic: h.harmonic,
                    center_hz: h.center_hz,
                    enf_hz: h.enf_hz.clone(),
                    snr_db: h.snr_db.clone(),
                })
                .collect(),
            selected: estimates
                .selected
                .iter()
                .enumerate()
                .map(|(i, &m)| SelectedSegment {
                    start_s: i as f64 * seg,
                    harmonic: m,
                })
                .collect(),
            snr_db: estimates.snr_db.clone(),
            ..Trace::new(estimates.step_s, estimates.enf_hz.clone())
        }
    }

    /// The V-ENF trace of a video analysed with `opts`.
    pub fn from_video(file: &Path, v: &VideoAnalysis, opts: &VideoOptions) -> Self {
        Trace {
            file: Some(file.to_path_buf()),
            nominal_hz: Some(v.nominal_hz),
            provenance: Some(Provenance::Video(VideoProvenance {
                method: VideoMethod::VEnf,
                width: v.info.width,
                height: v.info.height,
                fps: v.info.fps,
                frames: v.frames,
                sampling: v.sampling,
                sampling_reason: v.sampling_reason.clone(),
                frame_times: v.frame_times,
                scene_removal: v.scene_removal,
                virtual_rows: v.virtual_rows,
                fs_hz: v.fs,
                line_hz: v.line_hz,
                prominence: v.prominence,
                params: opts.params.clone(),
            })),
            warnings: v.warnings.clone(),
            ..Trace::new(v.step_s, v.enf_hz.clone())
        }
    }

    /// The reference trace of a mains recording, tracked on a `nominal_hz` grid with `params`.
    pub fn from_mains(file: &Path, grid: Grid, params: &EnfParams, enf_hz: Vec<f64>) -> Self {
        Trace {
            file: Some(file.to_path_buf()),
            nominal_hz: Some(grid.hz()),
            provenance: Some(Provenance::Mains(MainsProvenance {
                peak: params.peak,
                window_s: params.window_s,
                mains_lines: 1,
                audio: None,
                hum: None,
            })),
            ..Trace::new(params.step_s, enf_hz)
        }
    }

    /// The peak refinement the trace was made with, when it says.
    pub fn peak(&self) -> Option<PeakMethod> {
        match &self.provenance {
            Some(Provenance::Events(p)) => Some(p.params.peak),
            Some(Provenance::Video(p)) => Some(p.params.peak),
            Some(Provenance::Mains(p)) => Some(p.peak),
            None => None,
        }
    }

    /// How an event recording became this trace (E-ENF traces only).
    pub fn events(&self) -> Option<&EventsProvenance> {
        match &self.provenance {
            Some(Provenance::Events(p)) => Some(p),
            _ => None,
        }
    }

    /// Seconds per harmonic-selection segment (E-ENF), from the segments' starts.
    pub fn segment_s(&self) -> Option<f64> {
        match self.selected.as_slice() {
            [] => None,
            [_] => Some(self.time_s.len() as f64 * self.step_s),
            [a, b, ..] => Some(b.start_s - a.start_s),
        }
    }

    /// The finite estimates.
    pub fn finite(&self) -> impl Iterator<Item = f64> + '_ {
        self.enf_hz.iter().copied().filter(|v| v.is_finite())
    }

    /// The estimates whose line stands at the noise level (under
    /// [`eenf_dsp::NOISE_LEVEL_DB`]), by index; none when the trace did not measure it.
    pub fn at_noise_level(&self) -> Vec<usize> {
        (0..self.enf_hz.len())
            .filter(|&i| {
                self.enf_hz[i].is_finite()
                    && self
                        .snr_db
                        .get(i)
                        .is_some_and(|s| *s < eenf_dsp::NOISE_LEVEL_DB)
            })
            .collect()
    }

    /// What a user should know of the estimates at the noise level: how many, and when
    /// (runs of them as time spans); `None` when there are none.
    pub fn noise_note(&self) -> Option<String> {
        let at = self.at_noise_level();
        if at.is_empty() {
            return None;
        }
        let mut spans: Vec<(usize, usize)> = Vec::new();
        for &i in &at {
            match spans.last_mut() {
                Some((_, end)) if *end + 1 == i => *end = i,
                _ => spans.push((i, i)),
            }
        }
        let time = |i: usize| {
            self.time_s
                .get(i)
                .copied()
                .unwrap_or(i as f64 * self.step_s)
        };
        let mut shown: Vec<String> = spans
            .iter()
            .take(6)
            .map(|&(a, b)| match a == b {
                true => format!("{} s", time(a)),
                false => format!("{}–{} s", time(a), time(b)),
            })
            .collect();
        if spans.len() > 6 {
            shown.push(format!("and {} more stretches", spans.len() - 6));
        }
        let finite = self.enf_hz.iter().filter(|v| v.is_finite()).count();
        Some(format!(
            "{} of {finite} estimates stand at the noise level (their line under {} dB over its band; noise alone reaches about 9): {}. Their `snr_db` says which; do not rely on them",
            at.len(),
            eenf_dsp::NOISE_LEVEL_DB,
            shown.join(", ")
        ))
    }

    /// The line the trace follows and how far it stands, in words: a sound's hum lines over
    /// their floor, an event recording's flicker line; `None` for other traces.
    pub fn line_text(&self) -> Option<String> {
        match self.provenance.as_ref()? {
            Provenance::Mains(MainsProvenance { hum: Some(h), .. }) => {
                let grid = self.nominal_hz.unwrap_or(f64::NAN);
                let lines: Vec<String> = h
                    .carriers
                    .iter()
                    .filter_map(|k| {
                        h.search
                            .of_grid(grid)
                            .find(|l| l.harmonic == *k)
                            .map(|l| format!("{k} x f0 {:.1} dB", l.db))
                    })
                    .collect();
                Some(format!(
                    "hum lines traced (over their local floor, {:.1} dB needed, {:.0} s segments x {}): {}",
                    h.search.lines.first().map_or(f64::NAN, |l| l.threshold_db),
                    h.search.segment_s,
                    h.search.segments,
                    lines.join(", ")
                ))
            }
            Provenance::Events(x) => x
                .flicker
                .map(|l| format!("flicker {:.3} Hz, {}", l.hz, l.strength())),
            _ => None,
        }
    }

    /// Everything the user should be told beside the values: the trace's warnings, an event
    /// recording's notes and damage, why a sound's window changed and the flags its hum
    /// raised, and the estimates at the noise level.
    pub fn notices(&self) -> Vec<String> {
        let mut out = self.warnings.clone();
        match &self.provenance {
            Some(Provenance::Mains(MainsProvenance { hum: Some(h), .. })) => {
                out.extend(h.window_note.iter().cloned());
                out.extend(h.plausibility.flags.iter().cloned());
            }
            Some(Provenance::Events(x)) => {
                out.extend(x.notes.iter().cloned());
                out.extend(x.damage.iter().cloned());
            }
            _ => {}
        }
        out.extend(self.noise_note());
        out.dedup();
        out
    }

    /// Mean of the finite estimates (NaN when there are none).
    pub fn mean_hz(&self) -> f64 {
        let (sum, n) = self
            .finite()
            .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
        if n == 0 {
            f64::NAN
        } else {
            sum / n as f64
        }
    }

    /// The grid a trace's values lie on, from their mean.
    pub fn grid(&self) -> Option<Grid> {
        Grid::near(self.mean_hz())
    }

    /// [`Trace::grid`], or an error naming the trace `name` and its mean.
    pub fn grid_or_err(&self, name: &Path) -> Result<Grid> {
        self.grid().ok_or_else(|| {
            error!(
                Input,
                "{}: mean {:.3} Hz is neither a 50 nor a 60 Hz grid",
                name.display(),
                self.mean_hz()
            )
        })
    }

    /// Writes `time_s,enf_hz` rows (an empty field for no estimate), and `snr_db` as a third
    /// column when the trace measured it.
    pub fn write_csv(&self, w: &mut dyn Write) -> Result<()> {
        let mut out = csv::WriterBuilder::new().from_writer(w);
        let num = |v: Option<&f64>| match v {
            Some(v) if v.is_finite() => v.to_string(),
            _ => String::new(),
        };
        let with_snr = !self.snr_db.is_empty();
        let mut header: Vec<&str> = CSV_HEADER.split(',').collect();
        if with_snr {
            header.push("snr_db");
        }
        out.write_record(&header)?;
        for (i, t) in self.time_s.iter().enumerate() {
            let mut row = vec![t.to_string(), num(self.enf_hz.get(i))];
            if with_snr {
                let s = self.snr_db.get(i).copied().unwrap_or(f64::NAN);
                row.push(if s.is_finite() {
                    format!("{s:.2}")
                } else {
                    String::new()
                });
            }
            out.write_record(&row)?;
        }
        out.flush()?;
        Ok(())
    }

    /// The JSON form: the values, the per-harmonic parts and the provenance's fields.
    pub fn to_json_value(&self) -> serde_json::Value {
        let core = TraceJson {
            file: self.file.clone(),
            nominal_hz: self.nominal_hz,
            step_s: Some(self.step_s),
            time_s: self.time_s.clone(),
            enf_hz: self.enf_hz.clone(),
            snr_db: self.snr_db.clone(),
            harmonics: self.harmonics.clone(),
            selected: self.selected.clone(),
            warnings: self.warnings.clone(),
        };
        // serialising plain data into a JSON value cannot fail
        let mut v = serde_json::to_value(core).unwrap_or_default();
        if let (Some(p), Some(map)) = (&self.provenance, v.as_object_mut()) {
            if let Ok(serde_json::Value::Object(fields)) = serde_json::to_value(p) {
                map.extend(fields);
            }
        }
        v
    }

    /// Writes the JSON form, pretty-printed, with a final newline.
    pub fn write_json(&self, w: &mut dyn Write) -> Result<()> {
        serde_json::to_writer_pretty(&mut *w, &self.to_json_value())?;
        writeln!(w)?;
        Ok(())
    }

    /// Writes CSV, or JSON when `path` ends in `.json`.
    pub fn write_for(&self, path: &Path, w: &mut dyn Write) -> Result<()> {
        if path.extension().and_then(|e| e.to_str()) == Some("json") {
            self.write_json(w)
        } else {
            self.write_csv(w)
        }
    }

    /// Reads a trace file: eenf JSON, a `time_s,enf_hz` CSV, or (with `index_step_s`) an
    /// `index,value` CSV whose values are `index_step_s` apart.
    pub fn read(path: &Path, index_step_s: Option<f64>) -> Result<Trace> {
        Self::parse(&read_text(path)?, path, index_step_s)
    }

    /// Parses the text of a trace file named `path` (see [`Trace::read`]).
    pub fn parse(text: &str, path: &Path, index_step_s: Option<f64>) -> Result<Trace> {
        let trace = Self::parse_any(text, path, index_step_s)?;
        trace.check(path)?;
        Ok(trace)
    }

    /// Refuses what no ENF trace holds and what would size work by an absurd number: a step
    /// outside 1 ms .. 1 day, times that do not rise, values beyond ±1e6 (Hz or mHz).
    fn check(&self, path: &Path) -> Result<()> {
        let name = path.display();
        if !(self.step_s.is_finite() && (MIN_STEP_S..=MAX_STEP_S).contains(&self.step_s)) {
            fail!(Input,
                "{name}: its estimates are {} s apart; an ENF trace steps by {MIN_STEP_S} s to {MAX_STEP_S} s",
                self.step_s
            );
        }
        if let Some(i) = self
            .time_s
            .windows(2)
            .position(|w| !(w[1] - w[0] >= MIN_STEP_S && w[1].is_finite()))
        {
            fail!(Input,
                "{name}: time_s goes from {} to {} at estimate {}: times must rise by {MIN_STEP_S} s or more",
                self.time_s[i],
                self.time_s[i + 1],
                i + 1
            );
        }
        if let Some(i) = self.enf_hz.iter().position(|v| v.abs() > MAX_VALUE) {
            fail!(
                Input,
                "{name}: estimate {} is {:e}, beyond any frequency (or deviation) of a grid",
                i,
                self.enf_hz[i]
            );
        }
        Ok(())
    }

    fn parse_any(text: &str, path: &Path, index_step_s: Option<f64>) -> Result<Trace> {
        let trimmed = text.trim_start();
        if trimmed.starts_with('{') {
            return Self::parse_json(trimmed, path);
        }
        // `index,value` rows: without a header (the published ENF traces) or under that one
        let header = text.lines().next().unwrap_or("").to_ascii_lowercase();
        let first = header.split(',').next().unwrap_or("").trim();
        let index_rows = first.parse::<f64>().is_ok() || header.replace(' ', "") == "index,value";
        match index_step_s {
            Some(step) if index_rows => Self::parse_index_csv(text, path, step),
            _ => Self::parse_csv(text, path),
        }
    }

    fn parse_json(text: &str, path: &Path) -> Result<Trace> {
        let v: serde_json::Value = serde_json::from_str(text)
            .with_context(|| format!("{}: not valid JSON", path.display()))?;
        let core: TraceJson = serde_json::from_value(v.clone()).map_err(|e| {
            error!(
                Input,
                "{}: not an eenf trace (time_s and enf_hz arrays): {e}",
                path.display()
            )
        })?;
        if core.time_s.len() != core.enf_hz.len() {
            fail!(
                Input,
                "{}: time_s and enf_hz differ in length",
                path.display()
            );
        }
        Ok(Trace {
            step_s: core.step_s.unwrap_or_else(|| step_of(&core.time_s)),
            file: core.file,
            nominal_hz: core.nominal_hz,
            time_s: core.time_s,
            enf_hz: core.enf_hz,
            snr_db: core.snr_db,
            harmonics: core.harmonics,
            selected: core.selected,
            warnings: core.warnings,
            provenance: serde_json::from_value(v).ok(),
        })
    }

    fn parse_csv(text: &str, path: &Path) -> Result<Trace> {
        let body: String = text
            .lines()
            .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
            .flat_map(|l| [l, "\n"])
            .collect();
        let mut reader = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .flexible(true)
            .from_reader(body.as_bytes());
        let headers = reader.headers().cloned().unwrap_or_default();
        let col = |name: &str| headers.iter().position(|h| h == name);
        let (Some(ti), Some(fi)) = (col("time_s"), col("enf_hz")) else {
            fail!(
                Input,
                "{}: not a trace file (expected a CSV with header {CSV_HEADER:?} or eenf JSON)",
                path.display()
            );
        };
        let si = col("snr_db");
        let mut trace = Trace {
            file: Some(path.to_path_buf()),
            ..Trace::default()
        };
        for (n, row) in reader.records().enumerate() {
            let row = row.with_context(|| format!("{}: line {}", path.display(), n + 2))?;
            let field = |i: usize| row.get(i).unwrap_or("");
            let t: f64 = field(ti).parse().with_context(|| {
                format!(
                    "{}: line {}: bad time_s {:?}",
                    path.display(),
                    n + 2,
                    field(ti)
                )
            })?;
            let v = match field(fi) {
                "" => f64::NAN,
                s => s.parse().with_context(|| {
                    format!("{}: line {}: bad enf_hz {s:?}", path.display(), n + 2)
                })?,
            };
            trace.time_s.push(t);
            trace.enf_hz.push(v);
            if let Some(si) = si {
                trace.snr_db.push(field(si).parse().unwrap_or(f64::NAN));
            }
        }
        if trace.time_s.is_empty() {
            fail!(Input, "{}: the trace is empty", path.display());
        }
        trace.step_s = step_of(&trace.time_s);
        Ok(trace)
    }

    fn parse_index_csv(text: &str, path: &Path, step: f64) -> Result<Trace> {
        // a header row is one whose first field is not a number
        let skip = usize::from(
            text.lines()
                .next()
                .and_then(|l| l.split(',').next())
                .is_some_and(|f| f.trim().parse::<f64>().is_err()),
        );
        let mut values = Vec::new();
        for (i, line) in text.lines().enumerate().skip(skip) {
            if line.trim().is_empty() {
                continue;
            }
            let v = line
                .split(',')
                .nth(1)
                .and_then(|v| v.trim().parse::<f64>().ok())
                .or_fail(Error::Input, || {
                    format!("{}: line {}: expected index,value", path.display(), i + 1)
                })?;
            values.push(v);
        }
        Ok(Trace {
            file: Some(path.to_path_buf()),
            ..Trace::new(step, values)
        })
    }
}

/// The finest step of a trace accepted (operators publish 0.1 s at the finest).
const MIN_STEP_S: f64 = 1e-3;
/// The coarsest step of a trace accepted.
const MAX_STEP_S: f64 = 86_400.0;
/// The largest magnitude of a trace value accepted.
const MAX_VALUE: f64 = 1e6;
/// The longest line of a trace file (a trace's lines are a few dozen bytes; JSON is written
/// one value a line).
const MAX_LINE: u64 = 1 << 20;

/// The text of a trace file, read line by line: a line longer than 1 MiB (a binary file, a
/// sparse file of zeros) is an error before it is held in memory.
pub fn read_text(path: &Path) -> Result<String> {
    use std::io::BufRead;
    let file = std::fs::File::open(path).with_context(|| format!("{}", path.display()))?;
    let mut r = std::io::BufReader::new(file);
    let mut text = Vec::new();
    let mut line_no = 0usize;
    loop {
        line_no += 1;
        let start = text.len();
        let n = (&mut r)
            .take(MAX_LINE + 1)
            .read_until(b'\n', &mut text)
            .with_context(|| format!("{}", path.display()))?;
        if n == 0 {
            break;
        }
        if n as u64 > MAX_LINE && text.last() != Some(&b'\n') {
            fail!(
                Input,
                "{}: line {line_no} is longer than {} KiB: not a trace file",
                path.display(),
                MAX_LINE >> 10
            );
        }
        if text[start..].contains(&0) {
            fail!(
                Input,
                "{}: line {line_no} holds binary data: not a trace file",
                path.display()
            );
        }
    }
    String::from_utf8(text).map_err(|e| {
        error!(
            Input,
            "{}: not text (invalid UTF-8 at byte {}): not a trace file",
            path.display(),
            e.utf8_error().valid_up_to()
        )
    })
}

/// The step of a trace's times (1 s for a single value).
fn step_of(t: &[f64]) -> f64 {
    if t.len() > 1 {
        t[1] - t[0]
    } else {
        1.0
    }
}

/// NaN as JSON `null` and back.
mod nan_as_null {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer>(v: &[f64], s: S) -> Result<S::Ok, S::Error> {
        let opt: Vec<Option<f64>> = v.iter().map(|f| f.is_finite().then_some(*f)).collect();
        opt.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        let opt: Vec<Option<f64>> = Vec::deserialize(d)?;
        Ok(opt.into_iter().map(|v| v.unwrap_or(f64::NAN)).collect())
    }
}
