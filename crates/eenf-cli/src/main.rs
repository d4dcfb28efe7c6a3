//! `eenf`: Electric Network Frequency from event cameras.

#![forbid(unsafe_code)]

use eenf_cli::{commands, terminal};
use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

/// Recover the Electric Network Frequency (ENF) from event-camera recordings.
///
/// Lamps on the mains flicker at twice the grid frequency; an event camera sees that flicker,
/// and eenf recovers the grid's frequency from it (the E-ENF method, CVPR 2023), builds the
/// reference from mains recordings, and compares the two.
#[derive(Parser)]
#[command(name = "eenf", version, about, long_about = None, propagate_version = true)]
struct Cli {
    /// No progress bars.
    #[arg(long, short, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Show what an event file holds: format, codec, resolution, streams, events, time span.
    Info(commands::info::Args),
    /// Convert an event file to another format (AEDAT4, EVT 2.0, EVT 3.0, DAT, text).
    Convert(commands::convert::Args),
    /// Extract the ENF trace from an event recording (E-ENF).
    Extract(commands::extract::Args),
    /// Map where in the view the mains flicker is: its line's strength per tile of pixels.
    FlickerMap(commands::flicker_map::Args),
    /// The ENF of a mains recording or of any recording's sound (WAV, FLAC, MP3, M4A, OGG, a
    /// video's soundtrack): the mains hum, f0 and optionally its harmonics.
    #[command(visible_alias = "audio")]
    Reference(commands::reference::Args),
    /// Compare an ENF trace with a reference: CC, MAE, RMSE, max error.
    Compare(commands::compare::Args),
    /// Build or inspect a reference store: long ENF series per grid for `match`.
    #[command(subcommand)]
    Refdb(commands::refdb::Cmd),
    /// Was a recording edited? Cuts and insertions from the mains hum's phase and frequency,
    /// in sound, event recordings, or (frequency steps alone) an ENF trace.
    Edits(commands::edits::Args),
    /// Find when a trace was recorded by matching it against long references.
    Match(commands::matching::Args),
    /// Extract the ENF trace from a conventional video's rolling-shutter flicker (V-ENF).
    Video(commands::video::Args),
    /// Simulate an event recording of a flickering scene, with its ground-truth ENF.
    Simulate(commands::simulate::Args),
    /// Simulate a whole EV-ENFD-like dataset: static, dynamic and extreme recordings with
    /// hourly mains references.
    SimulateDataset(commands::simulate_dataset::Args),
    /// Evaluate methods over a dataset (EV-ENFD-like folder or manifest): the paper's Table 2,
    /// per-recording scores, reports, plots and ablations.
    Bench(commands::bench::Args),
    /// A local web page: drop a file, see its ENF trace, when it was recorded and whether it
    /// was edited, download a report. Prints the page's URL (with its token) first.
    Serve(commands::serve::Args),
    /// Simulate 60 s, extract the ENF, compare it with the truth: the whole method in one go.
    Demo(commands::demo::Args),
}

/// Bytes allocated and freed once at start, so that glibc's malloc serves event batches (a few
/// MiB each) from its heap: until a freed block raises its threshold, every allocation over
/// 128 KiB is a fresh mmap, faulted in page by page and unmapped again, batch after batch
/// (about a fifth of the CPU time of an extraction). 16 MiB stays under glibc's 32 MiB cap.
const ALLOCATOR_WARM_UP: usize = 16 << 20;

fn main() -> ExitCode {
    drop(std::hint::black_box(vec![0u8; ALLOCATOR_WARM_UP]));
    // messages name options as this front end's users write them: `--max-gap`
    eenf_core::spelling::set_spelling(eenf_core::spelling::Spelling::Flags);
    // `--window -3` reaches the flag's own range check, not clap's guess that `-3` is a flag
    let matches = negative_numbers(Cli::command()).try_get_matches();
    let cli = match matches.and_then(|m| Cli::from_arg_matches(&m)) {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => e.exit(), // --help, --version
        Err(e) => {
            // clap's text whole: what is wrong, its suggestion ("a similar argument exists"),
            // the missing argument's name and the usage line; a value out of its range is one
            // line, as every other error (the pointer to --help adds nothing to it)
            let text = e.render().to_string();
            let lines: Vec<&str> = text.lines().filter(|l| !l.trim().is_empty()).collect();
            match lines[..] {
                [first, more] if more.starts_with("For more information") => {
                    eprintln!("eenf: {first}")
                }
                _ => eprintln!("eenf: {}", text.trim_end()),
            }
            return ExitCode::from(2);
        }
    };
    // the server stops on signals itself, removing its uploads
    let serving = matches!(cli.command, Command::Serve(_));
    if let Err(e) = (!serving).then(terminal::clean_up_on_signals).transpose() {
        eprintln!("eenf: warning: {e:#}");
    }
    let progress = terminal::progress(cli.quiet);
    let result = match cli.command {
        Command::Info(a) => commands::info::run(a),
        Command::Convert(a) => commands::convert::run(a, progress),
        Command::Extract(a) => commands::extract::run(a, progress),
        Command::FlickerMap(a) => commands::flicker_map::run(a, progress),
        Command::Reference(a) => commands::reference::run(a, progress),
        Command::Compare(a) => commands::compare::run(a, progress),
        Command::Refdb(c) => commands::refdb::run(c, progress),
        Command::Edits(a) => commands::edits::run(a, progress),
        Command::Match(a) => commands::matching::run(a, progress),
        Command::Video(a) => commands::video::run(a, progress),
        Command::Simulate(a) => commands::simulate::run(a, progress),
        Command::SimulateDataset(a) => commands::simulate_dataset::run(a, progress),
        Command::Bench(a) => commands::bench::run(a, progress),
        Command::Demo(a) => commands::demo::run(a, progress),
        Command::Serve(a) => commands::serve::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // a reader that went away (`| head`) ends the program quietly
            let closed = e.chain().any(|c| {
                let io = c.downcast_ref::<std::io::Error>().map(std::io::Error::kind);
                let csv = match c.downcast_ref::<csv::Error>().map(csv::Error::kind) {
                    Some(csv::ErrorKind::Io(io)) => Some(io.kind()),
                    _ => None,
                };
                let json = c
                    .downcast_ref::<serde_json::Error>()
                    .and_then(serde_json::Error::io_error_kind);
                // the library's errors find the OS's error wherever it sits in them
                let library = c
                    .downcast_ref::<eenf::Error>()
                    .and_then(eenf::Error::io_kind);
                io.or(csv).or(json).or(library) == Some(std::io::ErrorKind::BrokenPipe)
            });
            if closed {
                return ExitCode::SUCCESS;
            }
            // one line: the causes joined, each naming what it is about
            eprintln!("eenf: error: {}", plain_words(&format!("{e:#}")));
            ExitCode::FAILURE
        }
    }
}

/// `cmd` and its subcommands, taking `-3` as a value: a negative number is a value to check,
/// not a flag.
fn negative_numbers(cmd: clap::Command) -> clap::Command {
    cmd.allow_negative_numbers(true)
        .mut_subcommands(negative_numbers)
}

/// An error's text on one line (a cause that quotes a file's text may break lines), without
/// the OS's error numbers (`(os error 2)`): the words say it.
fn plain_words(text: &str) -> String {
    // control characters (a damaged file's bytes quoted back) and line separators too
    let breaks = |c: char| c.is_control() || c == '\u{2028}' || c == '\u{2029}';
    let one_line;
    let text = if text.contains(breaks) {
        one_line = text
            .split(|c: char| breaks(c) || c.is_whitespace())
            .filter(|w| !w.is_empty())
            .collect::<Vec<_>>()
            .join(" ");
        &one_line
    } else {
        text
    };
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(" (os error ") {
        out.push_str(&rest[..at]);
        let tail = &rest[at + " (os error ".len()..];
        match tail.find(')') {
            Some(end) if tail[..end].bytes().all(|b| b.is_ascii_digit()) => {
                rest = &tail[end + 1..];
            }
            _ => {
                out.push_str(" (os error ");
                rest = tail;
            }
        }
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::plain_words;

    #[test]
    fn errors_are_one_line_of_plain_words() {
        assert_eq!(
            plain_words("x.db3: damaged: CREATE TABLE t(\n  a\r\n) near \"\u{c}\" (os error 2)"),
            "x.db3: damaged: CREATE TABLE t( a ) near \" \""
        );
        assert_eq!(plain_words("a  b (os error 13)"), "a  b");
    }
}
