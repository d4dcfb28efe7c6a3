//! The options of tracing sound and video, of the edits test, of matching and of building a
//! reference store.

use eenf_core::spelling::option;
use eenf_core::{defaults, Nominal};
use eenf_dsp::matching::{Score, DEFAULT_ALPHA};
use eenf_dsp::{EnfParams, PeakMethod};
use eenf_video::{IdleRows, RowSampling, SceneRemoval, VideoOptions};
use serde_json::Value;

use super::events::{widen, InputSettings};
use super::{counted, limits, maybe, named, number, rule, switch, text, whole, within};
use super::{OptionError, OptionSet, TrackerSettings};
use crate::archive::{ArchiveFormat, ArchiveOptions, DateOrder, ValueUnit};
use crate::audio::{AudioOptions, Channel};
use crate::edits::{EditInput, EditOptions, EditParams};
use crate::extract::ExtractOptions;
use crate::mains::{HumOptions, MainsLines};
use crate::time::Zone;

/// How a recording's sound is read and which mains lines are tracked (`reference`, `audio`).
#[derive(Debug, Clone)]
pub struct AudioSettings {
    /// `channel`: the channel traced, or the mix of all.
    pub channel: Channel,
    /// `harmonics`: the mains lines tracked.
    pub harmonics: MainsLines,
}

impl Default for AudioSettings {
    fn default() -> Self {
        AudioSettings {
            channel: Channel::Mix,
            harmonics: MainsLines::Auto,
        }
    }
}

impl OptionSet for AudioSettings {
    fn set(&mut self, name: &str, v: &Value) -> Result<bool, OptionError> {
        match name {
            "channel" => self.channel = named("channel", v)?,
            "harmonics" => self.harmonics = named("harmonics", v)?,
            _ => return Ok(false),
        }
        Ok(true)
    }

    fn check(&self) -> Result<(), OptionError> {
        Ok(())
    }
}

impl AudioSettings {
    /// How the hum is traced: these lines, and the tracker's window if one was given.
    pub fn hum(&self, tracker: &TrackerSettings) -> HumOptions {
        HumOptions {
            lines: self.harmonics,
            window_s: tracker.window,
        }
    }

    /// The reading options (the rate follows from the harmonics tracked).
    pub fn options(&self) -> AudioOptions {
        AudioOptions {
            channel: self.channel,
            top_hz: None,
        }
    }
}

/// The options of V-ENF (`video`).
#[derive(Debug, Clone)]
pub struct VideoSettings {
    /// `nominal`: the grid, 50, 60 or detected.
    pub nominal: Nominal,
    /// `readout_ms`: the sensor's readout time, ms.
    pub readout_ms: Option<f64>,
    /// `idle`: `auto` estimates the idle rows from the flicker's ripple.
    pub idle: Option<String>,
    /// `virtual_rows`: rows per frame period, real plus idle.
    pub virtual_rows: Option<f64>,
    /// `sampling`: how rows are sampled.
    pub sampling: RowSampling,
    /// `scene_removal`: how the scene is taken out.
    pub scene_removal: SceneRemoval,
    /// `peak`: how each window's peak is refined.
    pub peak: PeakMethod,
    /// `window`: STFT window, s.
    pub window: f64,
}

impl Default for VideoSettings {
    fn default() -> Self {
        VideoSettings {
            nominal: Nominal::Auto,
            readout_ms: None,
            idle: None,
            virtual_rows: None,
            sampling: RowSampling::Auto(IdleRows::Auto),
            scene_removal: SceneRemoval::Paper,
            peak: PeakMethod::Exact,
            window: defaults::WINDOW_S,
        }
    }
}

impl OptionSet for VideoSettings {
    fn set(&mut self, name: &str, v: &Value) -> Result<bool, OptionError> {
        match name {
            "nominal" => self.nominal = named("nominal", v)?,
            "readout_ms" => self.readout_ms = maybe("readout_ms", v, number)?,
            "idle" => self.idle = maybe("idle", v, text)?,
            "virtual_rows" => self.virtual_rows = maybe("virtual_rows", v, number)?,
            "sampling" => self.sampling = named("sampling", v)?,
            "scene_removal" => self.scene_removal = named("scene_removal", v)?,
            "peak" => self.peak = named("peak", v)?,
            "window" => self.window = number("window", v)?,
            _ => return Ok(false),
        }
        Ok(true)
    }

    fn check(&self) -> Result<(), OptionError> {
        let conflict = |a: &'static str, b: &str| {
            rule(
                a,
                format!("{} cannot be used with {}", option(a), option(b)),
            )
        };
        if self.readout_ms.is_some() && self.idle.is_some() {
            return Err(conflict("readout_ms", "idle"));
        }
        if self.readout_ms.is_some() && self.virtual_rows.is_some() {
            return Err(conflict("readout_ms", "virtual_rows"));
        }
        if self.virtual_rows.is_some() && self.idle.is_some() {
            return Err(conflict("virtual_rows", "idle"));
        }
        if let Some(idle) = self.idle.as_deref().filter(|i| *i != "auto") {
            return Err(super::OptionError::Invalid {
                name: "idle",
                value: idle.to_string(),
                reason: "expected auto".into(),
            });
        }
        if let Some(ms) = self.readout_ms {
            within("readout_ms", ms, limits::READOUT_MS)?;
        }
        if let Some(rows) = self.virtual_rows {
            within("virtual_rows", rows, limits::VIRTUAL_ROWS)?;
        }
        within("window", self.window, limits::WINDOW_S)
    }
}

impl VideoSettings {
    /// The V-ENF options these settings ask for.
    pub fn options(&self) -> Result<VideoOptions, OptionError> {
        self.check()?;
        let nominal_hz = self.nominal.hz();
        let positive = |name: &'static str, v: f64| {
            rule(name, format!("{} must be positive, not {v}", option(name)))
        };
        let idle = match (self.readout_ms, self.virtual_rows) {
            (Some(ms), _) if ms > 0.0 => IdleRows::ReadoutS(ms / 1e3),
            (Some(ms), _) => return Err(positive("readout_ms", ms)),
            (None, Some(l)) if l > 0.0 => IdleRows::VirtualRows(l),
            (None, Some(l)) => return Err(positive("virtual_rows", l)),
            (None, None) => IdleRows::Auto,
        };
        let sampling = self.sampling.with_idle_rows(idle);
        let params = EnfParams {
            nominal_hz: nominal_hz.unwrap_or(50.0),
            window_s: self.window,
            peak: self.peak,
            ..EnfParams::default()
        };
        Ok(VideoOptions {
            nominal_hz,
            sampling,
            scene_removal: self.scene_removal,
            params,
        })
    }
}

/// The options of the search for where a trace fits (`match`).
#[derive(Debug, Clone)]
pub struct MatchSettings {
    /// `top`: candidates listed.
    pub top: usize,
    /// `verify`: a claimed start time to check.
    pub verify: Option<String>,
    /// `score`: the ranking score.
    pub score: Score,
    /// `alpha`: a candidate is a match when its p-value is below this.
    pub alpha: f64,
    /// `tz`: the zone of local times in references, and of the results beside UTC.
    pub tz: Option<Zone>,
}

impl Default for MatchSettings {
    fn default() -> Self {
        MatchSettings {
            top: 5,
            verify: None,
            score: Score::Combined,
            alpha: DEFAULT_ALPHA,
            tz: None,
        }
    }
}

impl OptionSet for MatchSettings {
    fn set(&mut self, name: &str, v: &Value) -> Result<bool, OptionError> {
        match name {
            "top" => self.top = whole("top", v)?,
            "verify" => self.verify = maybe("verify", v, text)?,
            "score" => self.score = named("score", v)?,
            "alpha" => self.alpha = number("alpha", v)?,
            "tz" => self.tz = maybe("tz", v, named)?,
            _ => return Ok(false),
        }
        Ok(true)
    }

    fn check(&self) -> Result<(), OptionError> {
        counted("top", self.top as u64, widen(limits::TOP))?;
        within("alpha", self.alpha, limits::ALPHA)
    }
}

impl MatchSettings {
    /// What the search asks for.
    pub fn query(&self) -> Result<crate::locate::MatchQuery, OptionError> {
        self.check()?;
        Ok(crate::locate::MatchQuery {
            top: self.top,
            score: self.score,
            verify: self.verify.clone(),
            alpha: self.alpha,
        })
    }
}

/// The options of the edits test (`edits`).
#[derive(Debug, Clone)]
pub struct EditSettings {
    /// `nominal`: the grid, 50, 60 or detected.
    pub nominal: Nominal,
    /// `side`: the longest stretch fitted on each side of a boundary, s.
    pub side: f64,
    /// `min_gap`: the shortest stretch between two edits told apart, s.
    pub min_gap: f64,
    /// `false_alarms`: false alarms allowed per hour of unedited recording.
    pub false_alarms: f64,
    /// `weak_jump`: the phase jump, degrees, below which a stretch is reported as too weak.
    pub weak_jump: f64,
    /// `step_z`: a frequency step is reported at this many robust standard deviations.
    pub step_z: f64,
    /// `channel`: the channel of a sound, or the mix of all.
    pub channel: Channel,
    /// `index_step`: seconds between the values of an `index,value` CSV.
    pub index_step: Option<f64>,
    /// `kind`: what the file is.
    pub kind: EditInput,
    /// How an event file is read.
    pub input: InputSettings,
}

impl Default for EditSettings {
    fn default() -> Self {
        let p = EditParams::default();
        EditSettings {
            nominal: Nominal::Auto,
            side: p.side_s,
            min_gap: p.min_gap_s,
            false_alarms: p.false_alarms_per_hour,
            weak_jump: p.weak_jump_deg,
            step_z: p.frequency_step_z,
            channel: Channel::Mix,
            index_step: None,
            kind: EditInput::Auto,
            input: InputSettings::default(),
        }
    }
}

impl OptionSet for EditSettings {
    fn set(&mut self, name: &str, v: &Value) -> Result<bool, OptionError> {
        match name {
            "nominal" => self.nominal = named("nominal", v)?,
            "side" => self.side = number("side", v)?,
            "min_gap" => self.min_gap = number("min_gap", v)?,
            "false_alarms" => self.false_alarms = number("false_alarms", v)?,
            "weak_jump" => self.weak_jump = number("weak_jump", v)?,
            "step_z" => self.step_z = number("step_z", v)?,
            "channel" => self.channel = named("channel", v)?,
            "index_step" => self.index_step = maybe("index_step", v, number)?,
            "kind" => self.kind = named("kind", v)?,
            _ => return self.input.set(name, v),
        }
        Ok(true)
    }

    fn check(&self) -> Result<(), OptionError> {
        within("side", self.side, limits::SIDE_S)?;
        within("min_gap", self.min_gap, limits::MIN_GAP_S)?;
        within("false_alarms", self.false_alarms, limits::FALSE_ALARMS)?;
        within("weak_jump", self.weak_jump, limits::WEAK_JUMP_DEG)?;
        within("step_z", self.step_z, limits::STEP_Z)?;
        if let Some(s) = self.index_step {
            within("index_step", s, limits::INDEX_STEP_S)?;
        }
        self.input.check()
    }
}

impl EditSettings {
    /// The test's parameters.
    pub fn params(&self) -> EditParams {
        EditParams {
            side_s: self.side,
            min_gap_s: self.min_gap.min(self.side),
            false_alarms_per_hour: self.false_alarms,
            weak_jump_deg: self.weak_jump,
            frequency_step_z: self.step_z,
        }
    }

    /// Everything `edits` needs: the test, the grid, how sound and events are read.
    pub fn options(&self) -> Result<EditOptions, OptionError> {
        self.check()?;
        Ok(EditOptions {
            params: self.params(),
            input: self.kind,
            index_step_s: self.index_step,
            audio: AudioOptions {
                channel: self.channel,
                top_hz: None,
            },
            extract: ExtractOptions {
                nominal: self.nominal,
                open: self.input.open_options(),
                ..ExtractOptions::default()
            },
        })
    }
}

/// How `refdb build` reads its inputs and where their values go.
#[derive(Debug, Clone)]
pub struct StoreInputSettings {
    /// `grid`: the grid's name in the store (default: `grid50` or `grid60` from the data).
    pub grid: Option<String>,
    /// `tz`: the zone of local times.
    pub tz: Option<Zone>,
    /// `format`: the layout of grid archives.
    pub format: ArchiveFormat,
    /// `value_unit`: what an archive's value column holds.
    pub value_unit: ValueUnit,
    /// `date_order`: the order of day and month in an archive's dates.
    pub date_order: DateOrder,
    /// `nominal`: the grid of archives that give deviations.
    pub nominal: Nominal,
    /// `start`: the start time of the first trace CSV.
    pub start: Option<String>,
    /// `no_wait`: fail at once when another build is changing the store.
    pub no_wait: bool,
    /// `index_step`: seconds between the values of `index,value` CSVs.
    pub index_step: Option<f64>,
}

impl Default for StoreInputSettings {
    fn default() -> Self {
        StoreInputSettings {
            grid: None,
            tz: None,
            format: ArchiveFormat::Auto,
            value_unit: ValueUnit::Auto,
            date_order: DateOrder::Auto,
            nominal: Nominal::Auto,
            start: None,
            no_wait: false,
            index_step: None,
        }
    }
}

impl OptionSet for StoreInputSettings {
    fn set(&mut self, name: &str, v: &Value) -> Result<bool, OptionError> {
        match name {
            "grid" => self.grid = maybe("grid", v, text)?,
            "tz" => self.tz = maybe("tz", v, named)?,
            "format" => self.format = named("format", v)?,
            "value_unit" => self.value_unit = named("value_unit", v)?,
            "date_order" => self.date_order = named("date_order", v)?,
            "nominal" => self.nominal = named("nominal", v)?,
            "start" => self.start = maybe("start", v, text)?,
            "no_wait" => self.no_wait = switch("no_wait", v)?,
            "index_step" | "step" => self.index_step = maybe("index_step", v, number)?,
            _ => return Ok(false),
        }
        Ok(true)
    }

    fn check(&self) -> Result<(), OptionError> {
        match self.index_step {
            Some(s) => within("index_step", s, limits::INDEX_STEP_S),
            None => Ok(()),
        }
    }
}

impl StoreInputSettings {
    /// The build of `inputs`, as the library takes it.
    pub fn build(&self, inputs: Vec<String>) -> Result<crate::reference::StoreBuild, OptionError> {
        self.check()?;
        let start = match self.start.as_deref() {
            Some(s) => Some(crate::time::parse_time(s).map_err(|e| rule("start", e.report()))?),
            None => None,
        };
        Ok(crate::reference::StoreBuild {
            inputs,
            grid: self.grid.clone(),
            zone: self.tz.clone(),
            archive: ArchiveOptions {
                format: self.format,
                zone: None,
                unit: self.value_unit,
                date_order: self.date_order,
                grid: self.nominal.grid(),
            },
            start,
            index_step_s: self.index_step,
            wait: !self.no_wait,
            fetched: None,
        })
    }
}
