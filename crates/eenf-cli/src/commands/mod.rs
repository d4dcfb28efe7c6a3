//! One module per command.

/// `println!` that never panics: a closed pipe ends the program quietly, a full or failing
/// stdout with a one-line error.
macro_rules! outln {
    () => {
        $crate::commands::stdout_line(format_args!(""))
    };
    ($($t:tt)*) => {
        $crate::commands::stdout_line(format_args!($($t)*))
    };
}

pub mod bench;
pub mod compare;
pub mod convert;
pub mod demo;
pub mod edits;
pub mod extract;
pub mod flicker_map;
pub mod info;
pub mod matching;
pub mod refdb;
pub mod reference;
pub mod serve;
pub mod simulate;
pub mod simulate_dataset;
pub mod video;

/// Writes one line to stdout; see [`outln!`].
pub fn stdout_line(args: std::fmt::Arguments) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|_| out.write_all(b"\n")) {
        stdout_failed(&e);
    }
}

/// Ends the program after stdout failed: quietly when the reader went away (`| head`), else
/// with one line (a full disk, `> /dev/full`).
pub fn stdout_failed(e: &std::io::Error) -> ! {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        std::process::exit(0);
    }
    eprintln!("eenf: error: stdout: {e}");
    std::process::exit(1)
}
