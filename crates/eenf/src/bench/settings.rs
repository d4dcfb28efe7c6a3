//! The settings of a benchmark run, and `--sweep key=v1,v2,…` ablations over them.

use crate::error::{rule, Error, Missing, Result};
use eenf_core::spelling::option;
use eenf_video::VideoOptions;

use crate::extract::ExtractOptions;

/// The settings of one run over the dataset.
#[derive(Debug, Clone)]
pub struct Settings {
    /// What a `--sweep` set (key, value) for this run; empty for the defaults.
    pub label: Vec<(String, String)>,
    /// E-ENF options.
    pub extract: ExtractOptions,
    /// V-ENF options.
    pub video: VideoOptions,
}

impl Settings {
    /// `harmonics=2, peak=paper`, or `defaults`.
    pub fn describe(&self) -> String {
        if self.label.is_empty() {
            "defaults".into()
        } else {
            self.label
                .iter()
                .map(|(k, v)| format!("{k}={v}"))
                .collect::<Vec<_>>()
                .join(", ")
        }
    }

    /// Sets `key` to `value` (enum values parsed as the command line parses them).
    fn set(&mut self, key: &str, value: &str) -> Result<()> {
        let bad = || {
            rule(
                "sweep",
                format!("{} {key}={value}: not a valid value", option("sweep")),
            )
        };
        let p = &mut self.extract.params;
        match key {
            "harmonics" => p.harmonics = value.parse().ok().filter(|h| *h >= 1).ok_or_else(bad)?,
            "sampling" => self.extract.sampling = value.parse().map_err(|_| bad())?,
            "peak" => {
                let peak = value.parse().map_err(|_| bad())?;
                p.peak = peak;
                self.video.params.peak = peak;
            }
            "window" => {
                let w: f64 = value.parse().ok().filter(|w| *w > 0.0).ok_or_else(bad)?;
                p.window_s = w;
                self.video.params.window_s = w;
            }
            "dt-us" => {
                self.extract.dt_us = match value {
                    "auto" => None,
                    v => Some(
                        v.parse()
                            .ok()
                            .filter(|d| (10..=1_000_000).contains(d))
                            .ok_or_else(bad)?,
                    ),
                }
            }
            "selection" => p.selection = value.parse().map_err(|_| bad())?,
            "tiles" => {
                self.extract.flicker_tiles = match value {
                    "flicker" => true,
                    "all" => false,
                    _ => return Err(bad().into()),
                }
            }
            "segment" => p.segment_len = value.parse().ok().filter(|s| *s >= 1).ok_or_else(bad)?,
            "median-len" => p.median_len = value.parse().map_err(|_| bad())?,
            "scene-removal" => self.video.scene_removal = value.parse().map_err(|_| bad())?,
            "video-sampling" => self.video.sampling = value.parse().map_err(|_| bad())?,
            _ => return Err(rule("sweep", format!("{} {key}: unknown setting (harmonics, sampling, peak, window, dt-us, selection, tiles, segment, median-len, scene-removal, video-sampling)", option("sweep"))).into()),
        }
        self.label.push((key.to_string(), value.to_string()));
        Ok(())
    }
}

/// Parses `key=v1,v2,…` sweeps into every combination of `base` with those values (the first
/// sweep varies slowest).
pub fn sweep(base: &Settings, sweeps: &[String]) -> Result<Vec<Settings>> {
    let mut out = vec![base.clone()];
    for s in sweeps {
        let (key, values) = s.split_once('=').or_fail(Error::Input, || {
            format!("{} {s:?}: expected key=value,value,…", option("sweep"))
        })?;
        let values: Vec<&str> = values
            .split(',')
            .map(str::trim)
            .filter(|v| !v.is_empty())
            .collect();
        if values.is_empty() {
            return Err(rule("sweep", format!("{} {s:?}: no values", option("sweep"))).into());
        }
        let mut next = Vec::new();
        for settings in &out {
            for v in &values {
                let mut s2 = settings.clone();
                s2.set(key.trim(), v)?;
                next.push(s2);
            }
        }
        out = next;
    }
    Ok(out)
}
