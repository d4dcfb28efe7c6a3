//! E-ENF: an event recording → its polarity sequence → a [`Trace`].

use eenf_core::spelling::option;
use std::path::Path;

use crate::error::{error, fail, Error, Result};
use eenf_dsp::{
    check_line, choose_window, clock_offset_note, decimate, decimation_for, detect_nominal,
    enf_from_flicker, flicker_line, flicker_lines, flicker_search, stronger, EnfParams,
    FlickerLine, Grouping, HumSearch, PolaritySequence, SamplingMethod, TemporalSampler,
};
use eenf_events::{EventReader, OpenOptions, StreamInfo};

use crate::flicker_map::{flicker_map_of, TileMask};
use crate::progress::Progress;
use crate::recording::{Peeked, Recording};
use crate::trace::{EventsProvenance, Trace};
use eenf_core::{Grid, Nominal};

/// How events become a trace.
#[derive(Debug, Clone)]
pub struct ExtractOptions {
    /// Temporal sampling (`Auto` chooses from the stream).
    pub sampling: SamplingMethod,
    /// Sampling interval, µs (`None`: the sampling's own, see
    /// [`SamplingMethod::default_dt_us`]).
    pub dt_us: Option<i64>,
    /// Grid frequency.
    pub nominal: Nominal,
    /// Everything after sampling (`nominal_hz` is set from `nominal`).
    pub params: EnfParams,
    /// How to read the file: the chip of an old jAER file, the camera of a stereo pair (by
    /// default the one whose flicker is stronger).
    pub open: OpenOptions,
    /// Trace only the tiles of pixels that flicker (see [`crate::flicker_map`]) when events
    /// are stamped one by one; scan-grouped streams (DVXplorer) are always read whole.
    pub flicker_tiles: bool,
    /// True when `params.window_s` was asked for: it is kept. Otherwise a weak line that the
    /// recording is long enough for gets a longer window ([`eenf_dsp::choose_window`]).
    pub window_given: bool,
}

impl Default for ExtractOptions {
    fn default() -> Self {
        ExtractOptions {
            sampling: SamplingMethod::Auto,
            dt_us: None,
            nominal: Nominal::Auto,
            params: EnfParams::default(),
            open: OpenOptions::default(),
            flicker_tiles: true,
            window_given: false,
        }
    }
}

/// The shortest recording traced, s: below it a window holds too few flicker periods to place
/// the line.
pub const MIN_WINDOW_S: f64 = 2.0;

/// A file read into its flicker signal.
pub struct Sampled {
    /// What its header said.
    pub info: StreamInfo,
    /// Events read.
    pub events: u64,
    /// The flicker signal.
    pub seq: PolaritySequence,
    /// The camera read, when the file holds several.
    pub camera: Option<u8>,
    /// What had to be decided on the way (camera, chip), for the user.
    pub notes: Vec<String>,
    /// What ended the stream before the file's end (damage, a wild timestamp).
    pub damage: Option<eenf_events::Damage>,
    /// The recording's flicker lines near 100 and 120 Hz, measured one way wherever a line is
    /// reported (`info`, `extract`, `flicker-map`): in the 1 ms ON − OFF sums of the events
    /// traced (the tiles that flicker, where those are kept), whatever sampling traces them.
    /// `None` when shorter than a second.
    pub lines: Option<[FlickerLine; 2]>,
    /// The search over those sums' lines at 2k·f0 that decides the grid
    /// ([`eenf_dsp::flicker_search`]).
    pub search: Option<HumSearch>,
}

/// Reads `rec` (as `open` says) into a flicker signal sampled with `sampling` every `dt_us`.
pub fn sample_with(
    rec: &Recording,
    open: &OpenOptions,
    sampling: SamplingMethod,
    dt_us: i64,
    progress: &Progress,
) -> Result<Sampled> {
    let reader = rec.open(open)?;
    sample_reader(reader, rec.name(), sampling, Some(dt_us), None, progress)
}

/// Reads an opened recording (`path` names it) to its end into a flicker signal.
fn sample_reader(
    mut reader: Box<dyn eenf_events::EventReader>,
    path: &Path,
    sampling: SamplingMethod,
    dt_us: Option<i64>,
    mask: Option<&TileMask>,
    progress: &Progress,
) -> Result<Sampled> {
    let info = reader.info().clone();
    let bar = progress.events(info.event_count, "reading events");
    let mut sampler = TemporalSampler::with_interval(sampling, dt_us);
    // the line is measured on the events traced, whatever the sampling
    // (a sampler that already makes the 1 ms sums is the measure itself: no second one)
    let is_measure = sampling == SamplingMethod::Sum && dt_us == Some(1000);
    let mut measure = (!is_measure).then(|| TemporalSampler::new(SamplingMethod::Sum, 1000));
    let mut kept = eenf_events::EventBatch::default();
    let mut events = 0u64;
    while let Some(batch) = reader.next_batch()? {
        events += batch.len() as u64;
        let batch = match mask {
            Some(m) => {
                m.filter(&batch, &mut kept);
                &kept
            }
            None => &batch,
        };
        if measure.as_mut().is_some_and(|m| m.push(batch).is_err()) {
            measure = None;
        }
        sampler
            .push(batch)
            .map_err(|e| Error::from(e).context(path.display()))?;
        bar.inc(batch.len() as u64);
    }
    bar.finish_and_clear();
    let damage = reader.damage().cloned();
    if events == 0 {
        match damage {
            Some(d) => fail!(Method, "{}", d.message),
            None => fail!(Method, "{}: the event stream is empty", path.display()),
        }
    }
    let seq = sampler
        .finish()
        .map_err(|e| Error::from(e).context(path.display()))?;
    let measured = if is_measure {
        flicker_search(&seq.signal(), seq.fs())
    } else {
        measure
            .and_then(|m| m.finish().ok())
            .and_then(|m| flicker_search(&m.signal(), m.fs()))
    };
    let (lines, search) = match measured {
        Some((lines, search)) => (Some(lines), search),
        None => (None, None),
    };
    let mut notes = info.notes.clone();
    notes.extend(mask.map(TileMask::describe));
    Ok(Sampled {
        notes,
        camera: info.camera,
        info,
        events,
        seq,
        damage,
        lines,
        search,
    })
}

/// The flicker line of one camera of `rec`, in its 1 ms signal sampled with `method`.
pub fn camera_line(
    rec: &Recording,
    open: &OpenOptions,
    camera: u8,
    method: SamplingMethod,
) -> Result<Option<FlickerLine>> {
    let one = OpenOptions {
        camera: Some(camera),
        ..open.clone()
    };
    let s = sample_with(rec, &one, method, 1000, &Progress::hidden())?;
    Ok(flicker_line(&s.seq.signal(), s.seq.fs()))
}

/// The flicker line of `path` at `grid`, measured as the issue of
/// real recordings calibrates scenes: the whole recording's 1 ms ON − OFF sums, Hann window,
/// the peak near 2·grid over the median magnitude in 80–140 Hz. `None` when the recording is
/// too short to measure.
pub fn grid_line(path: &Path, open: &OpenOptions, grid: Grid) -> Result<Option<FlickerLine>> {
    let s = sample_with(
        &Recording::file(path),
        open,
        SamplingMethod::Sum,
        1000,
        &Progress::hidden(),
    )?;
    let lines = flicker_lines(&s.seq.signal(), s.seq.fs());
    Ok(lines.map(|l| line_at(l, grid)))
}

/// Of the lines near 100 and 120 Hz (`flicker_lines`), the one of `grid`.
fn line_at([fifty, sixty]: [FlickerLine; 2], grid: Grid) -> FlickerLine {
    match grid {
        Grid::Hz50 => fifty,
        Grid::Hz60 => sixty,
    }
}

/// Reads a recording into its flicker signal. A file with several cameras (a stereo pair,
/// whose cameras run on two clocks) is read for the camera `opts.open` names, else for the one
/// whose flicker line stands higher: never a mix of both.
pub fn sample_recording(
    rec: &Recording,
    opts: &ExtractOptions,
    progress: &Progress,
) -> Result<Sampled> {
    sample_chosen(rec, opts, (opts.sampling, opts.dt_us), progress)
}

/// The flicker lines near 100 and 120 Hz of the events `opts` would trace (the camera and the
/// tiles extraction chooses), measured as extraction measures them ([`Sampled::lines`]): what
/// `info` reports as the line E-ENF sees. `None` when shorter than a second.
pub fn traced_lines(
    rec: &Recording,
    opts: &ExtractOptions,
    progress: &Progress,
) -> Result<Option<[FlickerLine; 2]>> {
    // the measure's own 1 ms sums are all that is sampled
    Ok(sample_chosen(rec, opts, (SamplingMethod::Sum, Some(1000)), progress)?.lines)
}

/// [`sample_recording`] with the camera and tiles `opts` choose, sampled as `sampler` says.
fn sample_chosen(
    rec: &Recording,
    opts: &ExtractOptions,
    (sampling, dt_us): (SamplingMethod, Option<i64>),
    progress: &Progress,
) -> Result<Sampled> {
    let path = rec.name();
    let reader = rec.open(&opts.open)?;
    let cameras = reader.info().cameras.len();
    // the reader opened above serves when it is the one to read
    let (reader, open, note) = if cameras < 2 || opts.open.camera.is_some() {
        (Some(reader), opts.open.clone(), None)
    } else {
        let mut best: Option<(u8, (bool, f64))> = None;
        let mut heard = Vec::new();
        for c in 0..cameras.min(u8::MAX as usize) as u8 {
            let line = camera_line(rec, &opts.open, c, SamplingMethod::Sum)?;
            let rank = line.map_or((false, f64::NEG_INFINITY), |l| eenf_dsp::flicker::rank(&l));
            heard.push(match line {
                Some(l) => format!("camera {c}: {:.3} Hz, {}", l.hz, l.strength()),
                None => format!("camera {c}: no line"),
            });
            if best.is_none_or(|b| rank > b.1) {
                best = Some((c, rank));
            }
        }
        let camera = best.map_or(0, |b| b.0);
        let note = format!(
            "{cameras} cameras: camera {camera} traced, its flicker stands highest ({}); {} picks another",
            heard.join("; "),
            option("camera")
        );
        let open = OpenOptions {
            camera: Some(camera),
            ..opts.open.clone()
        };
        (None, open, Some(note))
    };
    // one read for the flicker map (when tiles are wanted) and one for the trace; a file whose
    // reader is already open is read on from it
    let reader = Peeked::new(match reader {
        Some(r) => r,
        None => rec.open(&open)?,
    })?;
    let (reader, mask, whole): (Box<dyn EventReader>, _, _) = if wants_tiles(opts, &reader) {
        let map = flicker_map_of(Box::new(reader), path, None, progress)?;
        (rec.open(&open)?, TileMask::from_map(&map), map.whole)
    } else {
        (Box::new(reader), None, None)
    };
    let mut s = sample_reader(reader, path, sampling, dt_us, mask.as_ref(), progress)?;
    // tiles are kept to raise the line; where they lose a line the whole sensor shows, every
    // pixel is traced instead
    let stands = |l: &Option<[FlickerLine; 2]>| l.is_some_and(|l| l.iter().any(|l| l.stands));
    if let (Some(_), Some(w)) = (&mask, whole.filter(|w| w.stands)) {
        if !stands(&s.lines) {
            let tiles = s.lines.map(stronger);
            s = sample_reader(rec.open(&open)?, path, sampling, dt_us, None, progress)?;
            s.notes.push(format!(
                "the flicker tiles' line does not stand ({}): every pixel traced, where it does ({:.3} Hz, {})",
                tiles.map_or("too short to measure".into(), |l| format!("{:.3} Hz, {}", l.hz, l.strength())),
                w.hz,
                w.strength()
            ));
        }
    }
    s.notes.extend(note);
    Ok(s)
}

/// Whether to trace only the tiles that flicker: when `opts` asks for them, the header gives
/// the sensor's size, and the stream stamps its events one by one (a DVXplorer's scans are
/// sampled whole, as the paper does, and are left alone).
fn wants_tiles(opts: &ExtractOptions, reader: &Peeked) -> bool {
    if !opts.flicker_tiles
        || !matches!(
            opts.sampling,
            SamplingMethod::Auto | SamplingMethod::Block | SamplingMethod::Sum
        )
        || reader.info().width.is_none()
    {
        return false;
    }
    match reader.first() {
        None => false,
        Some(first) => {
            !(opts.sampling == SamplingMethod::Auto && Grouping::measure(&first.t).is_scanned())
        }
    }
}

/// Reads an event file into its flicker signal (see [`sample_recording`]).
pub fn sample_file(path: &Path, opts: &ExtractOptions, progress: &Progress) -> Result<Sampled> {
    sample_recording(&Recording::file(path), opts, progress)
}

/// E-ENF from an event file.
pub fn extract_file(path: &Path, opts: &ExtractOptions, progress: &Progress) -> Result<Trace> {
    extract(&Recording::file(path), opts, progress)
}

/// E-ENF from a recording: a file, or events in memory.
pub fn extract(rec: &Recording, opts: &ExtractOptions, progress: &Progress) -> Result<Trace> {
    let path = rec.name();
    let s = sample_recording(rec, opts, progress)?;
    // when what was left before the damage is not enough, the error says why so little was read
    let damage = s.damage.as_ref().map(|d| d.message.clone());
    extract_sampled(path, s, opts, progress).map_err(|e| match damage {
        Some(d) => error!(
            Method,
            "{} (only the events before the damage were read: {d})",
            e.report()
        ),
        None => e,
    })
}

/// The grid of a flicker signal: that of the line that stands among the recording's strongest
/// near 100 and 120 Hz (`lines`, see [`Sampled::lines`]), or checked against `nominal`. Also
/// returns the line, and a note when the line sits off twice the grid by more than a grid
/// wanders (a camera clock that runs off).
fn decide_grid(
    x: &[f64],
    fs: f64,
    lines: Option<[FlickerLine; 2]>,
    nominal: Nominal,
    harmonics: usize,
) -> std::result::Result<(f64, Option<FlickerLine>, Option<String>), eenf_dsp::DspError> {
    let line = match (nominal, lines) {
        (_, None) => None,
        (Nominal::Auto, Some(l)) => Some(stronger(l)),
        (Nominal::Grid(g), Some(l)) => Some(line_at(l, g)),
    };
    let f0 = match (nominal, line) {
        (Nominal::Auto, Some(l)) if l.stands => l.grid_hz,
        (Nominal::Auto, Some(l)) => {
            return Err(eenf_dsp::DspError::NoTone(format!(
                "no mains flicker: the strongest line near 100 or 120 Hz, at {:.3} Hz, does not stand: {}",
                l.hz,
                l.strength()
            )))
        }
        // too short or sampled too slowly for the whole-recording line: the older local test
        (Nominal::Auto, None) => detect_nominal(x, fs, 2.0)?,
        (Nominal::Grid(g), l) => {
            let f = g.hz();
            // the flicker line may be weak at 2f0 yet strong at a higher harmonic
            let ok = l.is_some_and(|l| l.stands)
                || (1..=harmonics.max(1)).any(|m| check_line(x, fs, f, 2.0 * m as f64).is_ok());
            if !ok {
                check_line(x, fs, f, 2.0)?;
            }
            f
        }
    };
    let note = line
        .filter(|l| l.stands)
        .and_then(|l| clock_offset_note(l.hz, 2.0 * l.grid_hz));
    Ok((f0, line, note))
}

/// The flicker signal of `seq`, brought down to the lowest rate that keeps every band up to
/// `top_hz` (anti-aliased, so that the flicker's higher harmonics do not fold onto them), and
/// that rate.
pub fn flicker_signal(seq: &PolaritySequence, top_hz: f64) -> (Vec<f64>, f64) {
    let (factor, cutoff) = decimation_for(seq.fs(), top_hz);
    if factor > 1 {
        (
            decimate(&seq.signal(), seq.fs(), factor, cutoff),
            seq.fs() / factor as f64,
        )
    } else {
        (seq.signal(), seq.fs())
    }
}

/// E-ENF from a flicker signal already read from `path`.
pub fn extract_sampled(
    path: &Path,
    s: Sampled,
    opts: &ExtractOptions,
    progress: &Progress,
) -> Result<Trace> {
    let seq = &s.seq;
    let mut params = opts.params.clone();
    // a finely sampled signal is brought down to the rate its bands need, without letting
    // the flicker's higher harmonics fold onto them
    // undecided: the higher grid's bands, which hold the lower's
    let grid = opts.nominal.hz().unwrap_or(60.0);
    let top = 2.0 * grid * params.harmonics.max(1) as f64 + params.half_band_hz;
    let (x, fs) = flicker_signal(seq, top);
    let mut notes = s.notes;
    let err = |e: eenf_dsp::DspError| Error::from(e).context(path.display());
    let duration = seq.duration_s();
    if duration < params.window_s {
        if duration < MIN_WINDOW_S {
            return Err(err(eenf_dsp::DspError::TooShort {
                duration_s: duration,
                window_s: MIN_WINDOW_S,
            }));
        }
        // a window that fits: as long as the recording allows, to a tenth of a second
        let window = ((duration * 10.0).floor() / 10.0).max(MIN_WINDOW_S);
        notes.push(format!(
            "the recording lasts {duration:.2} s, shorter than the {} s window: traced with a {window} s window (frequency resolution {:.3} Hz on the flicker, {:.3} Hz on the ENF)",
            params.window_s,
            1.0 / window,
            0.5 / window
        ));
        params.window_s = window;
    }
    let (f0, line, note) =
        decide_grid(&x, fs, s.lines, opts.nominal, params.harmonics).map_err(err)?;
    params.nominal_hz = f0;
    // a line that stands over the whole recording but weakly: a longer window, where the
    // recording holds it, rather than a window that follows the noise
    if let (false, Some(search)) = (
        opts.window_given || duration < opts.params.window_s,
        &s.search,
    ) {
        if let Some(db) = search.of_grid(f0).map(|l| l.db).next() {
            let (window, why) =
                choose_window(duration, params.window_s, db, search.segment_s).map_err(err)?;
            params.window_s = window;
            notes.extend(why);
        }
    }
    // a clock that runs off is a warning as well as a note: every estimate is off by as much
    let warnings: Vec<String> = note.iter().cloned().collect();
    notes.extend(note);
    let spin = progress.spinner("tracking the ENF");
    // the signal already converted above is tracked as it is (no second copy)
    let estimates = enf_from_flicker(&x, fs, &params).map_err(err)?;
    spin.finish_and_clear();
    let provenance = EventsProvenance {
        format: s.info.format.to_string(),
        start_t_us: seq.t0_us,
        start_utc: crate::time::utc_micros(seq.t0_us),
        events: s.events,
        duration_s: duration,
        sampling: seq.method,
        sampling_reason: seq.reason.clone(),
        dt_us: seq.dt_us,
        params,
        camera: s.camera,
        flicker: line,
        notes,
        damage: s.damage.map(|d| d.to_string()),
    };
    let mut trace = Trace::from_events(path, &estimates, provenance);
    trace.warnings.extend(warnings);
    Ok(trace)
}
