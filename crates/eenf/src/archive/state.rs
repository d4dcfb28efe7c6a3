//! The state of one import: rows placed on the store's steps, clock changes counted, and
//! rows that bring no later time bounded.

use eenf_core::Grid;
use eenf_dsp::resample::StepAverager;

use super::layout::{Layout, ZoneRule};
use super::{ImportReport, MAX_SPAN_S, PLAUSIBLE_HZ};
use crate::time::{LocalInstant, Zone};

/// A clock change met while reading, as the zone's wall clock gives its hour.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum ClockNote {
    Repeated(String),
    Missing(String),
}

/// The state of one import: the steps so far and the last row's instant.
pub(super) struct ImportState {
    pub(super) grid: Grid,
    pub(super) native: f64,
    pub(super) acc: StepAverager,
    pub(super) last: f64,
    /// The latest instant read, and the rows since that brought no later one.
    pub(super) latest: f64,
    pub(super) stale: u64,
    /// Offsets of whole 15-minute stretches of wall-clock time (no change inside).
    pub(super) cache: Option<(i64, f64)>,
    pub(super) clock_notes: std::collections::BTreeMap<ClockNote, u64>,
}

impl ImportState {
    pub(super) fn new(grid: Grid, step: f64, native: f64) -> Self {
        ImportState {
            grid,
            native,
            acc: StepAverager::new(step, (MAX_SPAN_S / step) as usize),
            last: f64::NEG_INFINITY,
            latest: f64::NEG_INFINITY,
            stale: 0,
            cache: None,
            clock_notes: Default::default(),
        }
    }

    /// The instant of a wall-clock time in `zone`, as rows that follow each other give it:
    /// in a repeated hour, the first passage until the clock goes back.
    pub(super) fn instant(
        &mut self,
        zone: &Zone,
        local: f64,
        report: &mut ImportReport,
    ) -> Option<f64> {
        let whole = local.floor() as i64;
        let frac = local - whole as f64;
        let bucket = whole.div_euclid(900);
        if let Some((b, off)) = self.cache {
            if b == bucket {
                return Some(local - off);
            }
        }
        let hour_label = |z: &Zone| {
            let h = whole.div_euclid(3600) * 3600;
            let t = crate::time::LocalTime::from_local_seconds(h);
            format!(
                "{}-{:02}-{:02} {:02}:00 ({})",
                t.year(),
                t.month(),
                t.day(),
                t.hour(),
                z.name()
            )
        };
        match zone.instant(whole) {
            LocalInstant::Unique(t) => {
                let start = bucket * 900;
                if zone.instant(start) == LocalInstant::Unique(start as f64 - (whole as f64 - t))
                    && zone.instant(start + 899)
                        == LocalInstant::Unique((start + 899) as f64 - (whole as f64 - t))
                {
                    self.cache = Some((bucket, whole as f64 - t));
                }
                Some(t + frac)
            }
            LocalInstant::Repeated(a, b) => {
                let first = a + frac >= self.last;
                let key = ClockNote::Repeated(hour_label(zone));
                let n = self.clock_notes.entry(key).or_insert(0);
                if first {
                    Some(a + frac)
                } else {
                    *n += 1;
                    report.second_passage += 1;
                    Some(b + frac)
                }
            }
            LocalInstant::Missing => {
                *self
                    .clock_notes
                    .entry(ClockNote::Missing(hour_label(zone)))
                    .or_insert(0) += 1;
                report.missing_times += 1;
                None
            }
        }
    }

    pub(super) fn row(
        &mut self,
        layout: &Layout,
        line: &[u8],
        report: &mut ImportReport,
        label: &str,
    ) {
        let line = line.trim_ascii();
        if line.is_empty() || line.starts_with(b"#") {
            return;
        }
        report.rows += 1;
        self.stale += 1;
        let mut fields: [&[u8]; 16] = [&[]; 16];
        let mut n = 0;
        for f in layout.split(line) {
            if n < fields.len() {
                fields[n] = f;
            }
            n += 1;
        }
        let f = &fields[..n.min(fields.len())];
        let parsed = layout.time_of(f).and_then(|(t, off)| {
            let v = layout.number(f.get(layout.value)?)?;
            Some((t, off, v))
        });
        let Some((t, off, v)) = parsed else {
            report.unreadable += 1;
            if report.unreadable == 1 {
                let shown: String = String::from_utf8_lossy(line).chars().take(80).collect();
                report.warnings.push(format!(
                    "{label}: a row that is not a time and a frequency: {shown:?}"
                ));
            }
            return;
        };
        let instant = match (off, &layout.zone) {
            (Some(o), _) => Some(t - o),
            (None, ZoneRule::Utc(_)) => Some(t),
            (None, ZoneRule::Given(z)) => self.instant(z, t, report),
            // a row without the offset its neighbours carry
            (None, ZoneRule::InRows) => None,
        };
        let Some(instant) = instant else {
            if off.is_none() && layout.zone == ZoneRule::InRows {
                report.unreadable += 1;
            }
            return;
        };
        if instant == self.last {
            report.repeated += 1;
        }
        self.last = instant;
        if instant > self.latest {
            self.latest = instant;
            self.stale = 0;
        }
        let nominal = self.grid.hz();
        let hz = layout.unit.to_hz(v, nominal);
        if (hz - nominal).abs().is_nan() || (hz - nominal).abs() > PLAUSIBLE_HZ {
            report.implausible += 1;
            return;
        }
        if self.acc.push(instant, hz) {
            report.used += 1;
        } else {
            report.far += 1;
        }
    }
}
