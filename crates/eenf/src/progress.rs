//! Progress bars on a terminal; nothing when output is piped or `--quiet` is given.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;

/// Makes progress bars, or hidden ones when nobody is watching.
#[derive(Debug, Clone, Copy)]
pub struct Progress {
    visible: bool,
}

impl Progress {
    /// Bars are shown only when stderr is a terminal and `quiet` is false.
    pub fn new(quiet: bool) -> Self {
        Progress {
            visible: !quiet && std::io::stderr().is_terminal(),
        }
    }

    /// A progress object that never draws.
    pub fn hidden() -> Self {
        Progress { visible: false }
    }

    fn target(&self) -> ProgressDrawTarget {
        if self.visible {
            ProgressDrawTarget::stderr()
        } else {
            ProgressDrawTarget::hidden()
        }
    }

    /// A bar over events (a spinner with a count when the total is unknown).
    pub fn events(&self, total: Option<u64>, what: &str) -> ProgressBar {
        let bar = match total {
            Some(n) => ProgressBar::with_draw_target(Some(n), self.target()).with_style(
                ProgressStyle::with_template(
                    "{msg} [{bar:30}] {human_pos}/{human_len} events ({per_sec}, eta {eta})",
                )
                .unwrap()
                .progress_chars("=> "),
            ),
            None => ProgressBar::with_draw_target(None, self.target()).with_style(
                ProgressStyle::with_template("{spinner} {msg} {human_pos} events ({per_sec})")
                    .unwrap(),
            ),
        };
        bar.set_message(what.to_string());
        bar
    }

    /// A bar over a number of steps.
    pub fn steps(&self, total: u64, what: &str) -> ProgressBar {
        let bar = ProgressBar::with_draw_target(Some(total), self.target()).with_style(
            ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len} (eta {eta})")
                .unwrap()
                .progress_chars("=> "),
        );
        bar.set_message(what.to_string());
        bar
    }

    /// A spinner for work of unknown length.
    pub fn spinner(&self, what: &str) -> ProgressBar {
        let bar = ProgressBar::with_draw_target(None, self.target())
            .with_style(ProgressStyle::with_template("{spinner} {msg} ({elapsed})").unwrap());
        bar.set_message(what.to_string());
        bar.enable_steady_tick(std::time::Duration::from_millis(120));
        bar
    }
}
