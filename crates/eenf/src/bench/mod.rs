//! Evaluating methods over a dataset, as the paper's Table 2 does: the recordings of an
//! EV-ENFD-like tree or a manifest ([`discover`]), each traced by E-ENF and by V-ENF on its
//! videos under one or more [`settings`], scored against its reference ([`run`]), and
//! summarised per class and method in tables, files and figures ([`report`]).

pub mod discover;
pub mod report;
pub mod run;
pub mod settings;

use crate::error::{rule, Result};
use eenf_core::spelling::option;
use serde::Serialize;

pub use discover::{class_rank, discover, group_by_prominence, DatasetEntry, PROMINENCE_BANDS};
pub use run::{evaluate, run_all, summarize, ClassSummary, Outcome, Run};
pub use settings::{sweep, Settings};

/// An ENF method and the data it reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum Method {
    /// E-ENF on the event recording.
    #[serde(rename = "e-enf")]
    EEnf,
    /// V-ENF on the low-resolution (webcam) video.
    #[serde(rename = "v-enf-lr")]
    VEnfLr,
    /// V-ENF on the high-resolution (phone) video.
    #[serde(rename = "v-enf-hr")]
    VEnfHr,
}

impl Method {
    /// Every method, in the paper's row order.
    pub const ALL: [Method; 3] = [Method::VEnfLr, Method::VEnfHr, Method::EEnf];

    /// Command-line names, in the order of [`Method::ALL`].
    pub const NAMES: [&'static str; 3] = ["v-enf-lr", "v-enf-hr", "e-enf"];

    /// `e-enf`, `v-enf-lr`, `v-enf-hr`.
    pub fn name(self) -> &'static str {
        Self::NAMES[Self::ALL.iter().position(|m| *m == self).unwrap_or(0)]
    }

    /// The data and method as the paper's Table 2 names them.
    pub fn label(self) -> &'static str {
        match self {
            Method::EEnf => "Events, E-ENF",
            Method::VEnfLr => "Video-LR, V-ENF",
            Method::VEnfHr => "Video-HR, V-ENF",
        }
    }

    /// Parses a comma-separated list.
    pub fn parse_list(s: &str) -> Result<Vec<Method>> {
        let mut out = Vec::new();
        for name in s.split(',').map(str::trim).filter(|n| !n.is_empty()) {
            let m: Method = name
                .parse()
                .map_err(|e| rule("methods", format!("{}: {e}", option("methods"))))?;
            if !out.contains(&m) {
                out.push(m);
            }
        }
        if out.is_empty() {
            return Err(rule("methods", format!("{}: no method given", option("methods"))).into());
        }
        out.sort_by_key(|m| Method::ALL.iter().position(|a| a == m));
        Ok(out)
    }

    /// The video suffix this method reads (`lr`, `hr`), if any.
    pub fn camera(self) -> Option<&'static str> {
        match self {
            Method::EEnf => None,
            Method::VEnfLr => Some("lr"),
            Method::VEnfHr => Some("hr"),
        }
    }

    /// The methods whose input some recording of `recs` has (E-ENF always; a video method
    /// when a recording has that camera's video), and those left out.
    pub fn available(recs: &[DatasetEntry]) -> (Vec<Method>, Vec<Method>) {
        Method::ALL.into_iter().partition(|m| match m.camera() {
            None => true,
            Some(camera) => recs.iter().any(|r| r.video(camera).is_some()),
        })
    }
}

/// One class's cell of the paper's table: (class, mean CC, mean MAE in mHz).
pub type PaperCell = (&'static str, f64, f64);

/// The paper's Table 2 (mean CC, MAE in mHz; real EV-ENFD), per method and class.
pub const PAPER_TABLE2: [(Method, [PaperCell; 3]); 3] = [
    (
        Method::VEnfLr,
        [
            ("static", 0.6434, 13.7),
            ("dynamic", 0.3970, 24.2),
            ("extreme", 0.0557, 32.7),
        ],
    ),
    (
        Method::VEnfHr,
        [
            ("static", 0.8906, 6.2),
            ("dynamic", 0.7538, 11.1),
            ("extreme", 0.7602, 10.1),
        ],
    ),
    (
        Method::EEnf,
        [
            ("static", 0.9862, 1.9),
            ("dynamic", 0.9553, 2.1),
            ("extreme", 0.9867, 2.0),
        ],
    ),
];

/// The paper's (CC, MAE mHz) for a method and class.
pub fn paper_value(method: Method, class: &str) -> Option<(f64, f64)> {
    PAPER_TABLE2
        .iter()
        .find(|(m, _)| *m == method)
        .and_then(|(_, cells)| cells.iter().find(|c| c.0 == class))
        .map(|c| (c.1, c.2))
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Method {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| format!("unknown method {s:?} (e-enf, v-enf-lr, v-enf-hr)"))
    }
}
