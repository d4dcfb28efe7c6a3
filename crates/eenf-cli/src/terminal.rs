//! What the command shows on the terminal while it works: progress bars (nothing when stderr
//! is piped or `--quiet` is given), and the clean-up when a signal ends it.

use std::io::IsTerminal;
use std::sync::Arc;

use anyhow::{Context, Result};
use eenf::progress::{Progress, ProgressSink, Task, Unit};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// Draws the library's progress as indicatif bars on stderr.
struct Bars;

impl ProgressSink for Bars {
    fn start(&self, unit: Unit, total: Option<u64>, what: &str) -> Box<dyn Task> {
        let (len, template, chars) = match (unit, total) {
            (Unit::Events, Some(n)) => (
                Some(n),
                "{msg} [{bar:30}] {human_pos}/{human_len} events ({per_sec}, eta {eta})",
                true,
            ),
            (Unit::Events, None) => (
                None,
                "{spinner} {msg} {human_pos} events ({per_sec})",
                false,
            ),
            (Unit::Steps, n) => (n, "{msg} [{bar:30}] {pos}/{len} (eta {eta})", true),
            (Unit::Spinner, _) => (None, "{spinner} {msg} ({elapsed})", false),
        };
        // the templates are constants, checked by the test below
        let mut style = ProgressStyle::with_template(template).unwrap();
        if chars {
            style = style.progress_chars("=> ");
        }
        let bar =
            ProgressBar::with_draw_target(len, ProgressDrawTarget::stderr()).with_style(style);
        bar.set_message(what.to_string());
        if unit == Unit::Spinner {
            bar.enable_steady_tick(std::time::Duration::from_millis(120));
        }
        Box::new(Drawn(bar))
    }
}

struct Drawn(ProgressBar);

impl Task for Drawn {
    fn inc(&self, n: u64) {
        self.0.inc(n);
    }
    fn set_position(&self, n: u64) {
        self.0.set_position(n);
    }
    fn finish(&self) {
        self.0.finish_and_clear();
    }
}

/// Bars on stderr when it is a terminal and `quiet` is false; otherwise nothing is drawn.
pub fn progress(quiet: bool) -> Progress {
    if !quiet && std::io::stderr().is_terminal() {
        Progress::to(Arc::new(Bars))
    } else {
        Progress::hidden()
    }
}

/// On SIGINT, SIGTERM or SIGHUP: removes every temporary output in progress, then ends the
/// program with the usual status (128 + the signal). Call once, early in `main`.
pub fn clean_up_on_signals() -> Result<()> {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])
        .context("cannot install the signal handlers")?;
    std::thread::spawn(move || {
        if let Some(sig) = signals.forever().next() {
            eenf::output::remove_in_progress();
            std::process::exit(128 + sig);
        }
    });
    Ok(())
}

/// Says on stderr that a file was written, the same way for every command and kind of file
/// (`trace written to out.csv`).
pub fn announce(what: &str, path: &std::path::Path) {
    eprintln!("{what} written to {}", path.display());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_of_bar_is_drawn_without_a_panic() {
        for (unit, total) in [
            (Unit::Events, Some(10)),
            (Unit::Events, None),
            (Unit::Steps, Some(3)),
            (Unit::Spinner, None),
        ] {
            let t = Bars.start(unit, total, "work");
            t.inc(1);
            t.set_position(2);
            t.finish();
        }
    }
}
