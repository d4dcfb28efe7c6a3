//! The EV-ENFD naming: recordings `dvSave-YYYY_MM_DD_HH_MM_SS.*` (local start time) and hourly
//! references `YYYY_MM_DD_Day_HH_00_00.wav`.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

/// A local wall-clock start time taken from a file name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct StartTime {
    /// Year.
    pub year: u32,
    /// Month 1–12.
    pub month: u32,
    /// Day 1–31.
    pub day: u32,
    /// Hour 0–23.
    pub hour: u32,
    /// Minute.
    pub minute: u32,
    /// Second.
    pub second: u32,
}

impl StartTime {
    /// Seconds into the hour.
    pub fn second_of_hour(&self) -> u32 {
        self.minute * 60 + self.second
    }

    /// The date prefix `YYYY_MM_DD`.
    pub fn date(&self) -> String {
        format!("{:04}_{:02}_{:02}", self.year, self.month, self.day)
    }

    /// The wall-clock time `seconds` after 1970-01-01 00:00 (local time, no zone).
    pub fn from_local_seconds(seconds: i64) -> Self {
        let days = seconds.div_euclid(86_400);
        let sod = seconds.rem_euclid(86_400) as u32;
        // civil from days (Howard Hinnant's algorithm)
        let z = days + 719_468;
        let era = z.div_euclid(146_097);
        let doe = z - era * 146_097;
        let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
        let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
        let mp = (5 * doy + 2) / 153;
        let day = (doy - (153 * mp + 2) / 5 + 1) as u32;
        let month = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
        let year = (yoe + era * 400 + i64::from(month <= 2)) as u32;
        StartTime {
            year,
            month,
            day,
            hour: sod / 3600,
            minute: sod / 60 % 60,
            second: sod % 60,
        }
    }

    /// Seconds after 1970-01-01 00:00 of this wall-clock time.
    pub fn local_seconds(&self) -> i64 {
        crate::pipeline::days_from_civil(self.year as i64, self.month, self.day) * 86_400
            + (self.hour * 3600 + self.minute * 60 + self.second) as i64
    }

    /// `Mon`…`Sun`.
    pub fn weekday(&self) -> &'static str {
        let days = crate::pipeline::days_from_civil(self.year as i64, self.month, self.day);
        // 1970-01-01 was a Thursday
        ["Thu", "Fri", "Sat", "Sun", "Mon", "Tue", "Wed"][days.rem_euclid(7) as usize]
    }

    /// The dataset's recording name, `dvSave-YYYY_MM_DD_HH_MM_SS.<ext>`.
    pub fn recording_name(&self, ext: &str) -> String {
        format!(
            "dvSave-{}_{:02}_{:02}_{:02}.{ext}",
            self.date(),
            self.hour,
            self.minute,
            self.second
        )
    }

    /// The dataset's name of the hourly reference holding this time,
    /// `YYYY_MM_DD_Day_HH_00_00.wav`.
    pub fn reference_name(&self) -> String {
        format!(
            "{}_{}_{:02}_00_00.wav",
            self.date(),
            self.weekday(),
            self.hour
        )
    }
}

/// Finds `dvSave-YYYY_MM_DD_HH_MM_SS` in a path's file name.
pub fn recording_start(path: &Path) -> Option<StartTime> {
    let name = path.file_name()?.to_str()?;
    let i = name.find("dvSave-")?;
    let digits: Vec<u32> = name[i + 7..]
        .split(['_', '.', '-'])
        .take(6)
        .map(|s| s.parse().ok())
        .collect::<Option<Vec<u32>>>()?;
    if digits.len() < 6 {
        return None;
    }
    let t = StartTime {
        year: digits[0],
        month: digits[1],
        day: digits[2],
        hour: digits[3],
        minute: digits[4],
        second: digits[5],
    };
    (t.month >= 1
        && t.month <= 12
        && t.day >= 1
        && t.day <= 31
        && t.hour < 24
        && t.minute < 60
        && t.second < 60)
        .then_some(t)
}

/// The start time of an hourly reference named `YYYY_MM_DD_Day_HH_00_00.wav`.
pub fn reference_hour(path: &Path) -> Option<StartTime> {
    let stem = path.file_stem()?.to_str()?;
    let parts: Vec<&str> = stem.split('_').collect();
    if parts.len() != 7 {
        return None;
    }
    let n = |s: &str| s.parse::<u32>().ok();
    Some(StartTime {
        year: n(parts[0])?,
        month: n(parts[1])?,
        day: n(parts[2])?,
        hour: n(parts[4])?,
        minute: n(parts[5])?,
        second: n(parts[6])?,
    })
}

/// The hourly reference WAVs of a folder, sorted by time.
pub fn hourly_references(dir: &Path) -> Result<Vec<(StartTime, PathBuf)>> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).with_context(|| format!("{}", dir.display()))? {
        let p = entry?.path();
        if p.extension()
            .and_then(|e| e.to_str())
            .map(|e| e.eq_ignore_ascii_case("wav"))
            != Some(true)
        {
            continue;
        }
        if let Some(t) = reference_hour(&p) {
            out.push((t, p));
        }
    }
    out.sort();
    if out.is_empty() {
        bail!(
            "{}: no hourly reference WAVs named like 2022_08_17_Wed_16_00_00.wav",
            dir.display()
        );
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_dataset_names() {
        let t = recording_start(Path::new("static/dvSave-2022_08_17_16_54_30.aedat4")).unwrap();
        assert_eq!((t.hour, t.second_of_hour()), (16, 54 * 60 + 30));
        assert_eq!(t.date(), "2022_08_17");
        assert!(recording_start(Path::new("dvSave-2022_13_17_16_54_30.aedat4")).is_none());
        let r = reference_hour(Path::new("x/2022_08_17_Wed_17_00_00.wav")).unwrap();
        assert_eq!((r.day, r.hour, r.minute), (17, 17, 0));
        assert!(reference_hour(Path::new("notes.wav")).is_none());
        // names made from times read back as those times
        let t = StartTime::from_local_seconds(r.local_seconds() + 754);
        assert_eq!(
            t.recording_name("aedat4"),
            "dvSave-2022_08_17_17_12_34.aedat4"
        );
        assert_eq!(t.reference_name(), "2022_08_17_Wed_17_00_00.wav");
        let leap = StartTime::from_local_seconds(
            crate::pipeline::days_from_civil(2024, 2, 29) * 86_400 + 3661,
        );
        assert_eq!(
            (leap.month, leap.day, leap.hour, leap.minute),
            (2, 29, 1, 1)
        );
        assert_eq!(leap.weekday(), "Thu");
    }
}
