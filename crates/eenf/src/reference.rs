//! Mains references: the ENF of a mains (or audio) recording, the reference of one recording
//! from a dataset's hourly WAVs, and the long reference series that `match` searches.

use std::path::Path;

use anyhow::{bail, Context, Result};
use eenf_dsp::hum::{MAX_HUM_HARMONIC, MIN_CLIP_S};
use eenf_dsp::matching::{
    match_trace, resample, Candidate, MatchError, MatchOptions, MatchResult, ScaledSeries, Score,
    Verification,
};
use eenf_dsp::{
    check_holds_line, choose_window, enf_from_hum_lines, plausibility, reference_enf, search_hum,
    EnfParams,
};

use crate::audio::read_wav;
use crate::audio::{AudioOptions, Sound};
use crate::dataset::hourly_references;
use crate::progress::Progress;
use crate::refdb::{RefSeries, GAP};
use crate::time::LocalTime;
use crate::trace::{AudioProvenance, HumReport, MainsProvenance, Provenance, Trace};
use eenf_core::Nominal;
use eenf_core::Signal;

/// Decides or checks the nominal frequency of a mains signal: the line detector on f0 alone.
pub fn mains_nominal(sig: &Signal, nominal: Nominal, path: &Path) -> Result<f64> {
    let err = |e: eenf_dsp::DspError| anyhow::anyhow!("{}: {e}", path.display());
    let grids = grids_of(nominal);
    let top = grids.iter().fold(0.0f64, |a, &b| a.max(b));
    if sig.fs < 2.0 * (top + 8.0) {
        bail!(
            "{}: sample rate {} Hz is too low to carry a {top} Hz mains tone",
            path.display(),
            sig.fs
        );
    }
    let search = search_hum(&sig.samples, sig.fs, 1.0, grids, 1).ok_or_else(|| {
        err(eenf_dsp::DspError::TooShort {
            duration_s: sig.samples.len() as f64 / sig.fs,
            window_s: 1.0,
        })
    })?;
    Ok(search.verdict().map_err(err)?.grid_hz)
}

/// The grids a `--nominal` leaves open.
fn grids_of(nominal: Nominal) -> &'static [f64] {
    match nominal {
        Nominal::Auto => &[50.0, 60.0],
        Nominal::Hz(50.0) => &[50.0],
        Nominal::Hz(_) => &[60.0],
    }
}

/// The reference trace of a whole mains WAV (every channel mixed, f0 alone: the method's
/// reference tracker).
pub fn reference_file(path: &Path, nominal: Nominal, params: &EnfParams) -> Result<Trace> {
    let hum = HumOptions {
        lines: MainsLines::UpTo(1),
        window_s: Some(params.window_s),
    };
    audio_trace(path, &AudioOptions::default(), &hum, nominal, params)
}

/// Which mains lines a sound is traced on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MainsLines {
    /// Those the line detector finds standing, up to [`MAX_HUM_HARMONIC`]·f0: f0 alone (the
    /// method's reference tracker) when it carries the ENF clearly, else every harmonic that
    /// stands, band by band, combined per segment by the selection rule.
    #[default]
    Auto,
    /// f0 … N·f0 (1: f0 alone, the reference tracker).
    UpTo(usize),
}

impl std::str::FromStr for MainsLines {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "auto" => Ok(MainsLines::Auto),
            _ => match s.parse::<usize>() {
                Ok(n) if (1..=MAX_HUM_HARMONIC).contains(&n) => Ok(MainsLines::UpTo(n)),
                _ => Err(format!(
                    "{s:?}: expected auto or a number of lines from 1 to {MAX_HUM_HARMONIC}"
                )),
            },
        }
    }
}

impl std::fmt::Display for MainsLines {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MainsLines::Auto => f.write_str("auto"),
            MainsLines::UpTo(n) => write!(f, "{n}"),
        }
    }
}

/// How a sound's hum is traced: its lines, and the window (`None`: chosen from the recording
/// and its hum, see [`eenf_dsp::choose_window`]; the default of `params` is the start).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HumOptions {
    /// The lines tracked.
    pub lines: MainsLines,
    /// The analysis window, s, when set.
    pub window_s: Option<f64>,
}

/// f0 alone carries the ENF when its line is the strongest and stands this high (dB over its
/// floor): mains recordings, where harmonics add nothing but distortion.
const F0_ALONE_DB: f64 = 30.0;

/// The ENF of a recording's sound (a mains recording, a voice recorder, a video's soundtrack):
/// read as `audio` says, decimated to what its lines need, and tracked as `hum` says.
pub fn audio_trace(
    path: &Path,
    audio: &AudioOptions,
    hum: &HumOptions,
    nominal: Nominal,
    params: &EnfParams,
) -> Result<Trace> {
    sound_trace(&Sound::File(path), audio, hum, nominal, params)
}

/// The ENF of a sound, from a file or from samples in memory (see [`audio_trace`]): the line
/// detector finds the grid and the harmonics that stand, a window is chosen for the clip and
/// its hum, the trace must hold its line, and it is checked against what grids do (offset,
/// steadiness).
pub fn sound_trace(
    sound: &Sound,
    audio: &AudioOptions,
    hum: &HumOptions,
    nominal: Nominal,
    params: &EnfParams,
) -> Result<Trace> {
    let path = sound.name();
    let err = |e: eenf_dsp::DspError| anyhow::anyhow!("{}: {e}", path.display());
    let grids = grids_of(nominal);
    let top_grid = grids.iter().fold(0.0f64, |a, &b| a.max(b));
    let most = match hum.lines {
        MainsLines::Auto => MAX_HUM_HARMONIC,
        MainsLines::UpTo(n) => n.max(1),
    };
    // room for every line looked for and its floor beside it
    let top_of = |k: usize| k as f64 * top_grid + params.half_band_hz.max(6.0) + 4.0;
    let first_top = match hum.lines {
        MainsLines::Auto => top_of(most),
        // as these lines were always read (a reference's rate unchanged)
        MainsLines::UpTo(n) => n as f64 * top_grid + params.half_band_hz + 4.0,
    };
    let a = sound.read(&AudioOptions {
        top_hz: Some(first_top),
        ..*audio
    })?;
    let provenance_audio = |fs: f64| AudioProvenance {
        decoder: a.decoder.to_string(),
        source_rate_hz: a.source_rate,
        rate_hz: fs,
        channels: a.channels,
        channel: audio.channel.to_string(),
        frames: a.frames,
    };
    let duration_s = a.signal.samples.len() as f64 / a.signal.fs;
    if let MainsLines::UpTo(1) = hum.lines {
        // the method's reference tracker: f0 alone, unfiltered
        let f0 = mains_nominal(&a.signal, nominal, path)?;
        let p = EnfParams {
            nominal_hz: f0,
            window_s: hum.window_s.unwrap_or(params.window_s),
            ..params.clone()
        };
        let enf = reference_enf(&a.signal.samples, a.signal.fs, &p).map_err(err)?;
        let mut t = Trace::from_mains(path, f0, &p, enf);
        if let Some(Provenance::Mains(m)) = t.provenance.as_mut() {
            // a plain mains WAV at its own rate keeps the bare provenance it always had
            if a.source_rate != a.signal.fs || a.channels > 1 || a.decoder != "symphonia" {
                m.audio = Some(provenance_audio(a.signal.fs));
            }
        }
        t.warnings.extend(a.warning.clone());
        return Ok(t);
    }
    if duration_s < MIN_CLIP_S {
        return Err(err(eenf_dsp::DspError::TooShort {
            duration_s,
            window_s: MIN_CLIP_S,
        }));
    }
    let search = search_hum(&a.signal.samples, a.signal.fs, 1.0, grids, most).ok_or_else(|| {
        anyhow::anyhow!(
            "{}: sample rate {} Hz is too low to carry a mains line with its noise floor beside it",
            path.display(),
            a.signal.fs
        )
    })?;
    let verdict = search.verdict().map_err(err)?;
    let f0 = verdict.grid_hz;
    let (window_s, window_note) = match hum.window_s {
        Some(w) => (w, None),
        None => choose_window(
            duration_s,
            params.window_s,
            verdict.strongest.db,
            search.segment_s,
        )
        .map_err(err)?,
    };
    let f0_alone = verdict.strongest.harmonic == 1 && verdict.strongest.db >= F0_ALONE_DB;
    let carriers: Vec<usize> = if f0_alone {
        vec![1]
    } else {
        verdict.carriers.clone()
    };
    let highest = carriers.iter().copied().max().unwrap_or(1);
    let sig = a.narrowed(top_of(highest));
    let p = EnfParams {
        nominal_hz: f0,
        harmonics: highest,
        window_s,
        ..params.clone()
    };
    let edge = (window_s / 2.0 / p.step_s).ceil() as usize;
    let mut trace = if f0_alone {
        let enf = reference_enf(&sig.samples, sig.fs, &p).map_err(err)?;
        Trace::from_mains(path, f0, &p, enf)
    } else {
        let estimates = enf_from_hum_lines(&sig.samples, sig.fs, &p, &carriers).map_err(err)?;
        Trace::from_mains_lines(
            path,
            f0,
            &estimates,
            MainsProvenance {
                peak: p.peak,
                window_s,
                mains_lines: carriers.len(),
                audio: None,
                hum: None,
            },
        )
    };
    check_holds_line(&trace.enf_hz, p.step_s, window_s).map_err(err)?;
    let plausibility = plausibility(&trace.enf_hz, p.step_s, f0, edge);
    if let Some(Provenance::Mains(m)) = trace.provenance.as_mut() {
        m.audio = Some(provenance_audio(sig.fs));
        m.hum = Some(HumReport {
            search,
            carriers,
            window_note,
            plausibility,
        });
    }
    trace.warnings.extend(a.warning.clone());
    Ok(trace)
}

/// The reference trace for a recording that starts at `start` (local time from its name) and
/// lasts `seconds` estimates, from a folder of hourly WAVs. Windows near the recording's ends
/// see the mains before and after it, continuing into the next hour's file when needed.
pub fn reference_for_recording(
    dir: &Path,
    start: LocalTime,
    seconds: usize,
    nominal: Nominal,
    params: &EnfParams,
) -> Result<Trace> {
    let files = hourly_references(dir)?;
    let first = start.hour_index();
    let Some(pos) = files.iter().position(|(t, _)| t.hour_index() == first) else {
        bail!(
            "{}: no reference for {} hour {:02} (expected a file like {}_Day_{:02}_00_00.wav)",
            dir.display(),
            start.date(),
            start.hour(),
            start.date(),
            start.hour()
        );
    };
    let margin = (params.window_s / 2.0).ceil() as usize + 2;
    let from = start.second_of_hour() as usize;
    let need_until = from + seconds + margin;
    let mut samples = Vec::new();
    let mut fs = 0.0;
    let mut f0 = None;
    for (k, (t, path)) in files[pos..].iter().enumerate() {
        if t.hour_index() != first + k as i64 {
            break;
        }
        let sig = read_wav(path)?;
        if k == 0 {
            fs = sig.fs;
            f0 = Some(mains_nominal(&sig, nominal, path)?);
        } else if sig.fs != fs {
            bail!(
                "{}: sample rate {} Hz differs from the previous hour's {fs} Hz",
                path.display(),
                sig.fs
            );
        }
        samples.extend_from_slice(&sig.samples);
        if samples.len() as f64 / fs >= need_until as f64 {
            break;
        }
    }
    let f0 = f0.context("no reference loaded")?;
    let have_s = samples.len() as f64 / fs;
    if (from + seconds) as f64 > have_s + 1.0 {
        bail!(
            "{}: the references cover {:.0} s from {}_{:02}:00:00; the recording needs {} s from second {from}",
            dir.display(),
            have_s,
            start.date(),
            start.hour(),
            seconds
        );
    }
    // track a slice starting on a whole second so frames fall on the hour's seconds
    let a = from.saturating_sub(margin);
    let b = ((need_until as f64 * fs) as usize).min(samples.len());
    let p = EnfParams {
        nominal_hz: f0,
        ..params.clone()
    };
    let slice = &samples[(a as f64 * fs) as usize..b];
    let trace =
        reference_enf(slice, fs, &p).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
    let off = from - a;
    let out: Vec<f64> = (0..seconds)
        .map(|i| trace.get(off + i).copied().unwrap_or(f64::NAN))
        .collect();
    Ok(Trace::from_mains(dir, f0, &p, out))
}

/// Unix time of an hourly reference's name read as local time at `tz_s` seconds east of UTC.
/// The names carry no zone, so none is assumed: without `tz_s` it is an error that says how to
/// give it.
pub fn wav_start(path: &Path, tz_s: Option<f64>) -> Result<f64> {
    let t = crate::dataset::reference_hour(path).with_context(|| {
        format!(
            "{}: the name gives no start time (expected 2022_08_17_Wed_16_00_00.wav)",
            path.display()
        )
    })?;
    let Some(tz_s) = tz_s else {
        bail!(
            "{}: its name gives a local time ({}-{:02}-{:02} {:02}:00) but not its zone: give the \
             zone with --tz (e.g. --tz +08:00 where it was recorded in China, --tz Z for UTC)",
            path.display(),
            t.year(),
            t.month(),
            t.day(),
            t.hour()
        );
    };
    Ok(t.unix_seconds(tz_s))
}

/// A long reference series that `match` searches: a store's grid, a folder of hourly WAVs, one
/// WAV, or a trace.
pub struct ReferenceSeries {
    /// Its name in results.
    pub name: String,
    /// Time of the first value: Unix seconds when `absolute`, else seconds of the trace.
    pub start: f64,
    /// Whether `start` is an absolute time.
    pub absolute: bool,
    /// The zone (seconds east of UTC) its times are also shown in, when one was given.
    pub zone_s: Option<f64>,
    /// Seconds between values.
    pub step: f64,
    /// The values.
    pub values: SeriesValues,
}

/// Reference values: in Hz, or as stored (µHz from nominal), read in place.
pub enum SeriesValues {
    /// Frequencies, Hz (NaN = gap).
    Hz(Vec<f64>),
    /// A store's integers.
    Stored {
        /// µHz from `nominal`, [`GAP`] = gap.
        values: Vec<i32>,
        /// The grid, Hz.
        nominal: f64,
    },
}

impl SeriesValues {
    fn scaled(values: &[i32], nominal: f64) -> ScaledSeries<'_> {
        ScaledSeries {
            values,
            offset_hz: nominal,
            scale_hz: 1e-6,
            gap: GAP,
        }
    }

    /// Number of values.
    pub fn len(&self) -> usize {
        match self {
            SeriesValues::Hz(v) => v.len(),
            SeriesValues::Stored { values, .. } => values.len(),
        }
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Value `i`, Hz (NaN = gap).
    pub fn get(&self, i: usize) -> f64 {
        use eenf_dsp::matching::ReferenceValues;
        match self {
            SeriesValues::Hz(v) => v[i],
            SeriesValues::Stored { values, nominal } => Self::scaled(values, *nominal).get(i),
        }
    }

    /// Where `q` (at this series' step) fits.
    pub fn search(&self, q: &[f64], opts: &MatchOptions) -> Result<MatchResult, MatchError> {
        match self {
            SeriesValues::Hz(v) => match_trace(q, &v[..], opts),
            SeriesValues::Stored { values, nominal } => {
                match_trace(q, &Self::scaled(values, *nominal), opts)
            }
        }
    }
}

impl ReferenceSeries {
    /// The time of value `offset` (fractional steps allowed): UTC, or seconds of a trace.
    pub fn time_label(&self, offset: f64) -> String {
        let t = self.start + offset * self.step;
        if self.absolute {
            match self.zone_s {
                Some(z) if z != 0.0 => {
                    format!("{} ({})", crate::time::utc(t), crate::time::local(t, z))
                }
                _ => crate::time::utc(t),
            }
        } else {
            format!("{t:.1} s")
        }
    }

    /// The `nominal` Hz series at `path`: a store (its grids of that frequency), a folder of
    /// hourly WAVs (traced, local names at `tz_s`), a WAV, or a trace file.
    pub fn load(
        path: &Path,
        nominal: f64,
        tz_s: Option<f64>,
        progress: &Progress,
    ) -> Result<Vec<Self>> {
        if path.is_dir() {
            let grids = RefSeries::grids(path)?;
            if !grids.is_empty() {
                let _lock = crate::refdb::StoreLock::shared(path)?;
                let mut out = Vec::new();
                for g in grids {
                    let meta = RefSeries::load_meta(path, &g)?;
                    if meta.nominal_hz != nominal {
                        continue; // 50 and 60 Hz are never mixed
                    }
                    let s = RefSeries::load(path, &g)?;
                    out.push(ReferenceSeries {
                        name: g,
                        start: meta.start_unix_s,
                        absolute: true,
                        zone_s: tz_s,
                        step: meta.step_s,
                        values: SeriesValues::Stored {
                            values: s.values,
                            nominal,
                        },
                    });
                }
                if out.is_empty() {
                    bail!("{}: the store holds no {nominal} Hz grid", path.display());
                }
                return Ok(out);
            }
            // a folder of hourly WAVs, assembled in memory
            let files = hourly_references(path)?;
            let bar = progress.steps(files.len() as u64, "tracking the references");
            let mut series = RefSeries::new("folder", nominal, 1.0, 0.0);
            for (_, f) in &files {
                let trace = reference_file(f, Nominal::Auto, &EnfParams::default())?;
                if trace.nominal_hz == Some(nominal) {
                    series.merge(wav_start(f, tz_s)?, 1.0, &trace.enf_hz)?;
                }
                bar.inc(1);
            }
            bar.finish_and_clear();
            if series.values.is_empty() {
                bail!("{}: no {nominal} Hz references", path.display());
            }
            return Ok(vec![ReferenceSeries {
                name: path.display().to_string(),
                start: series.meta.start_unix_s,
                absolute: true,
                zone_s: tz_s,
                step: 1.0,
                values: SeriesValues::Hz(series.hz()),
            }]);
        }
        let (start, absolute, step, hz) = if crate::wav::is_wav(path) {
            let trace = reference_file(path, Nominal::Hz(nominal), &EnfParams::default())?;
            if crate::dataset::reference_hour(path).is_some() {
                (wav_start(path, tz_s)?, true, 1.0, trace.enf_hz)
            } else {
                (0.0, false, 1.0, trace.enf_hz)
            }
        } else {
            let t = Trace::read(path, None)?;
            (
                t.time_s.first().copied().unwrap_or(0.0),
                false,
                t.step_s,
                t.enf_hz,
            )
        };
        Ok(vec![ReferenceSeries {
            name: path.display().to_string(),
            start,
            absolute,
            zone_s: tz_s,
            step,
            values: SeriesValues::Hz(hz),
        }])
    }
}

/// What `match` asks of the references.
#[derive(Debug, Clone)]
pub struct MatchQuery {
    /// Candidates to list.
    pub top: usize,
    /// What ranks offsets.
    pub score: Score,
    /// A claimed start time to check (an absolute time, or seconds for a relative reference).
    pub verify: Option<String>,
    /// A candidate is a match when its p-value is below this.
    pub alpha: f64,
}

/// One place where the trace fits.
#[derive(Debug, Clone)]
pub struct Placement {
    /// The reference series (index into the searched list).
    pub series: usize,
    /// The candidate: offset in the series' steps, agreement, p-value.
    pub candidate: Candidate,
}

/// How the claimed time of [`MatchQuery::verify`] fits.
#[derive(Debug, Clone)]
pub struct Verified {
    /// The reference series holding the claimed time.
    pub series: usize,
    /// Its score, rank and significance.
    pub verification: Verification,
}

/// The outcome of `match`: the best places over every series, best first.
#[derive(Debug, Clone)]
pub struct MatchReport {
    /// The grid searched, Hz.
    pub nominal_hz: f64,
    /// The best candidates over all series (lowest p-value, then highest CC).
    pub placements: Vec<Placement>,
    /// The claimed time's fit, when one was given and falls inside a series.
    pub verified: Option<Verified>,
    /// Seconds the search took.
    pub seconds: f64,
}

/// Where `trace` (named `name`) fits in the series `refs`, as `query` asks.
pub fn match_trace_in(
    trace: &Trace,
    name: &Path,
    refs: &[ReferenceSeries],
    query: &MatchQuery,
) -> Result<MatchReport> {
    let nominal_hz = match_grid(trace, name)?;
    let started = std::time::Instant::now();
    let mut placements = Vec::new();
    let mut verified = None;
    for (i, r) in refs.iter().enumerate() {
        let q = resample(&trace.enf_hz, trace.step_s, r.step);
        let verify = match &query.verify {
            Some(t) => {
                let at = if r.absolute {
                    crate::time::parse_time(t)?
                } else {
                    t.parse::<f64>()
                        .context("--verify with a relative reference takes seconds")?
                };
                let k = ((at - r.start) / r.step).round();
                (k >= 0.0).then_some(k as usize)
            }
            None => None,
        };
        let opts = MatchOptions {
            top: query.top,
            score: query.score,
            verify,
            ..MatchOptions::default()
        };
        let res = r
            .values
            .search(&q, &opts)
            .map_err(|e| anyhow::anyhow!("{}: {e}", name.display()))?;
        if let Some(v) = res.verification {
            verified = Some(Verified {
                series: i,
                verification: v,
            });
        }
        placements.extend(res.candidates.into_iter().map(|candidate| Placement {
            series: i,
            candidate,
        }));
    }
    placements.sort_by(|x, y| {
        let (x, y) = (&x.candidate, &y.candidate);
        x.p_value
            .total_cmp(&y.p_value)
            .then(y.agreement.cc.total_cmp(&x.agreement.cc))
    });
    placements.truncate(query.top);
    Ok(MatchReport {
        nominal_hz,
        placements,
        verified,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// The grid of a trace to be matched: it must hold two values, rising times, and a mean on a
/// 50 or 60 Hz grid.
pub fn match_grid(trace: &Trace, name: &Path) -> Result<f64> {
    if trace.enf_hz.len() < 2 {
        bail!("{}: too short to match", name.display());
    }
    if trace.step_s <= 0.0 {
        bail!("{}: times must increase", name.display());
    }
    trace.grid_hz().with_context(|| {
        format!(
            "{}: mean {:.3} Hz is neither a 50 nor a 60 Hz grid",
            name.display(),
            trace.mean_hz()
        )
    })
}

impl MatchReport {
    /// The report as `eenf match --json` prints it.
    pub fn to_json(&self, trace: &Path, refs: &[ReferenceSeries], alpha: f64) -> serde_json::Value {
        let cands: Vec<_> = self
            .placements
            .iter()
            .map(|p| {
                let (r, c) = (&refs[p.series], &p.candidate);
                serde_json::json!({"reference": r.name, "start": r.time_label(c.offset),
                    "start_s": r.start + c.offset * r.step, "offset_steps": c.offset,
                    "cc": c.agreement.cc, "mae_hz": c.agreement.mae_hz,
                    "rmse_hz": c.agreement.rmse_hz, "overlap": c.agreement.n,
                    "p_value": c.p_value, "match": c.p_value < alpha})
            })
            .collect();
        serde_json::json!({
            "trace": trace, "nominal_hz": self.nominal_hz, "alpha": alpha, "seconds": self.seconds,
            "candidates": cands,
            "verify": self.verified.as_ref().map(|v| {
                let (r, v) = (&refs[v.series], &v.verification);
                serde_json::json!({
                "time": r.time_label(v.offset as f64), "cc": v.agreement.cc,
                "mae_hz": v.agreement.mae_hz, "rmse_hz": v.agreement.rmse_hz, "rank": v.rank, "p_value": v.p_value,
                "best_fit": v.rank == 1, "consistent": v.rank == 1 && v.p_value < alpha})}),
        })
    }
}
