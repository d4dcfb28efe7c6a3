//! The library's errors: one type, [`Error`], whose variants say which area refused (an
//! option, the operating system, an input file, the method, the store, a reference, an
//! archive, a simulation, an output) and keep the causes as a chain of `source`s. The library
//! words nothing for a front end: the command line prints [`Error::report`] on one line with
//! its exit code, Python picks an exception class from [`Error::io_kind`] and
//! [`Error::area`], a page an HTTP status.
//!
//! A cause is wrapped, not flattened, so that `report` reads as before the wrapping
//! ("FILE: line 3: invalid float literal") and a front end can still find the OS's error in
//! it (a closed pipe ends the command quietly).

use std::fmt::Display;

use eenf_core::spelling::{option, spelling, Spelling};

/// A result whose error is the library's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Why the library refused or failed. Every message names the file or option it is about.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An option, or a combination of options, refused; it names the option.
    #[error(transparent)]
    Option(#[from] OptionError),
    /// The operating system refused: a file missing or unreadable, a folder, a closed pipe.
    #[error(transparent)]
    Os(#[from] std::io::Error),
    /// An event file cannot be read or written.
    #[error(transparent)]
    Events(#[from] eenf_events::EventError),
    /// A video cannot be read or traced.
    #[error(transparent)]
    Video(#[from] eenf_video::VideoError),
    /// The signal processing refused its input (too short, no line to follow).
    #[error(transparent)]
    Dsp(#[from] eenf_dsp::DspError),
    /// Events too far apart in time to sample (a corrupt timestamp).
    #[error(transparent)]
    Sampling(#[from] eenf_dsp::sampling::SamplingError),
    /// Matching refused its input.
    #[error(transparent)]
    Match(#[from] eenf_dsp::matching::MatchError),
    /// The simulator refused its configuration.
    #[error(transparent)]
    Mains(#[from] eenf_sim::MainsError),
    /// An input that is not what it must be: a trace, a sound, a manifest, a table.
    #[error("{0}")]
    Input(String),
    /// The method cannot answer on this input: too short, no line, too few values.
    #[error("{0}")]
    Method(String),
    /// A reference store that is locked, damaged or would grow past its bounds.
    #[error("{0}")]
    Store(String),
    /// No reference fits: none covers the time, none of the grid.
    #[error("{0}")]
    Reference(String),
    /// A grid operator's archive that cannot be read as a frequency table.
    #[error("{0}")]
    Archive(String),
    /// A simulation that cannot be built as asked.
    #[error("{0}")]
    Simulation(String),
    /// A grid operator's server that did not give what was asked (no network, an HTTP error,
    /// a body cut short, a format that changed).
    #[error("{0}")]
    Fetch(String),
    /// An output that cannot be written where it was asked to go.
    #[error("{0}")]
    Output(String),
    /// A cause from a parser or decoder the library uses (CSV, JSON, WAV, zip, 7z, a number).
    #[error(transparent)]
    Other(Box<dyn std::error::Error + Send + Sync>),
    /// What the library was doing when `source` happened ("FILE: line 3").
    #[error("{context}")]
    Context {
        /// What was being done, or the file it was done to.
        context: String,
        /// The cause.
        #[source]
        source: Box<Error>,
    },
}

/// The area an [`Error`] comes from, for a front end to choose its words, exit code,
/// exception class or HTTP status.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Area {
    /// An option refused ([`Error::Option`]).
    Option,
    /// The operating system ([`Error::Os`]).
    Os,
    /// An input file ([`Error::Input`], [`Error::Events`], [`Error::Video`], a parser's cause).
    Input,
    /// The method ([`Error::Method`], [`Error::Dsp`], [`Error::Sampling`], [`Error::Match`]).
    Method,
    /// The reference store ([`Error::Store`]).
    Store,
    /// References ([`Error::Reference`]).
    Reference,
    /// Grid archives ([`Error::Archive`]).
    Archive,
    /// Simulation ([`Error::Simulation`], [`Error::Mains`]).
    Simulation,
    /// Downloads from grid operators ([`Error::Fetch`]).
    Fetch,
    /// An output ([`Error::Output`]).
    Output,
}

impl Error {
    /// This error with what was being done when it happened, shown before it.
    pub fn context(self, context: impl Display) -> Error {
        Error::Context {
            context: context.to_string(),
            source: Box::new(self),
        }
    }

    /// A cause from a parser or decoder the library uses, kept whole.
    pub fn other(e: impl std::error::Error + Send + Sync + 'static) -> Error {
        Error::Other(Box::new(e))
    }

    /// The innermost error of the library's own (past the contexts).
    pub fn root(&self) -> &Error {
        match self {
            Error::Context { source, .. } => source.root(),
            e => e,
        }
    }

    /// Where it comes from (past the contexts).
    pub fn area(&self) -> Area {
        match self.root() {
            Error::Option(_) => Area::Option,
            Error::Os(_) => Area::Os,
            Error::Input(_) | Error::Events(_) | Error::Video(_) | Error::Other(_) => Area::Input,
            Error::Method(_) | Error::Dsp(_) | Error::Sampling(_) | Error::Match(_) => Area::Method,
            Error::Store(_) => Area::Store,
            Error::Reference(_) => Area::Reference,
            Error::Archive(_) => Area::Archive,
            Error::Simulation(_) | Error::Mains(_) => Area::Simulation,
            Error::Output(_) => Area::Output,
            Error::Fetch(_) => Area::Fetch,
            Error::Context { .. } => unreachable!("root() passes every context"),
        }
    }

    /// The OS error's kind when the operating system refused (a missing file, a folder, a
    /// closed pipe), wherever it sits: in an event reader's, a video reader's, a CSV or JSON
    /// writer's error.
    pub fn io_kind(&self) -> Option<std::io::ErrorKind> {
        match self.root() {
            Error::Os(e) => Some(e.kind()),
            Error::Events(eenf_events::EventError::Io { error, .. }) => Some(error.kind()),
            Error::Video(eenf_video::VideoError::Io { error, .. }) => Some(error.kind()),
            Error::Other(e) => {
                if let Some(e) = e.downcast_ref::<std::io::Error>() {
                    Some(e.kind())
                } else if let Some(e) = e.downcast_ref::<csv::Error>() {
                    match e.kind() {
                        csv::ErrorKind::Io(e) => Some(e.kind()),
                        _ => None,
                    }
                } else if let Some(e) = e.downcast_ref::<serde_json::Error>() {
                    e.io_error_kind()
                } else {
                    None
                }
            }
            _ => None,
        }
    }

    /// The option it is about (its library name), when an option was refused.
    pub fn option(&self) -> Option<&str> {
        match self.root() {
            Error::Option(e) => e.option(),
            _ => None,
        }
    }

    /// The error and its causes on one line, joined by ": " ("FILE: line 3: invalid float
    /// literal"), as the command line prints it and Python's exceptions carry it.
    pub fn report(&self) -> String {
        let mut text = self.to_string();
        let mut cause = std::error::Error::source(self);
        while let Some(c) = cause {
            text.push_str(": ");
            text.push_str(&c.to_string());
            cause = c.source();
        }
        text
    }
}

/// Why an option set was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OptionError {
    /// A name that none of the sets has.
    #[error("{}", unknown_words(.0))]
    Unknown(String),
    /// A value that cannot be read as its option's type, or lies outside its range.
    #[error("{}", invalid_words(.name, .value, .reason))]
    Invalid {
        /// The option's library name.
        name: &'static str,
        /// The value given, as text.
        value: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A value that breaks a rule about it or about another option.
    #[error("{rule}")]
    Rule {
        /// The option's library name.
        name: &'static str,
        /// The rule, in words (options named by the spelling in force).
        rule: String,
    },
    /// Options given as something other than a JSON object of names and values.
    #[error("options must be a JSON object of names and values: {0}")]
    NotAnObject(String),
}

fn unknown_words(name: &str) -> String {
    match spelling() {
        Spelling::Keywords => format!("unexpected keyword argument '{name}'"),
        Spelling::Flags => format!("unexpected argument '{}'", option(name)),
        Spelling::Fields => format!("unexpected field '{name}'"),
    }
}

fn invalid_words(name: &str, value: &str, reason: &str) -> String {
    format!("invalid value '{value}' for '{}': {reason}", option(name))
}

impl OptionError {
    /// The library name of the option it is about (none for an unknown name).
    pub fn option(&self) -> Option<&str> {
        match self {
            OptionError::Unknown(n) => Some(n),
            OptionError::Invalid { name, .. } | OptionError::Rule { name, .. } => Some(name),
            OptionError::NotAnObject(_) => None,
        }
    }
}

/// A broken rule about option `name` (its library name), in words.
pub(crate) fn rule(name: &'static str, rule: impl Into<String>) -> OptionError {
    OptionError::Rule {
        name,
        rule: rule.into(),
    }
}

macro_rules! other_causes {
    ($($t:ty),* $(,)?) => {$(
        impl From<$t> for Error {
            fn from(e: $t) -> Error {
                Error::other(e)
            }
        }
    )*};
}

other_causes!(
    csv::Error,
    serde_json::Error,
    hound::Error,
    zip::result::ZipError,
    sevenz_rust2::Error,
    jiff::Error,
    std::num::ParseFloatError,
    std::num::ParseIntError,
    std::str::Utf8Error,
    std::string::FromUtf8Error,
    rayon::ThreadPoolBuildError,
);

/// What the library was doing when an error happened, added to any result whose error the
/// library can hold: `.context("FILE")`, `.with_context(|| format!(...))`.
pub trait Context<T> {
    /// The error, if any, with `context` before it.
    fn context(self, context: impl Display) -> Result<T>;
    /// The error, if any, with the context `f` words (only on error).
    fn with_context<C: Display>(self, f: impl FnOnce() -> C) -> Result<T>;
}

impl<T, E: Into<Error>> Context<T> for std::result::Result<T, E> {
    fn context(self, context: impl Display) -> Result<T> {
        self.map_err(|e| e.into().context(context))
    }

    fn with_context<C: Display>(self, f: impl FnOnce() -> C) -> Result<T> {
        self.map_err(|e| e.into().context(f()))
    }
}

/// `return Err(Error::$area(format!(...)))`: the library's `bail!`, naming its area.
macro_rules! fail {
    ($area:ident, $($arg:tt)*) => {
        return Err($crate::error::Error::$area(format!($($arg)*)).into())
    };
}
pub(crate) use fail;

/// `Error::$area(format!(...))`: the library's `anyhow!`, naming its area.
macro_rules! error {
    ($area:ident, $($arg:tt)*) => {
        $crate::error::Error::$area(format!($($arg)*))
    };
}
pub(crate) use error;

/// A missing value as an error of its area: `.or_fail(Error::Input, || format!(...))`.
pub trait Missing<T> {
    /// The value, or the error `area` words with `f`'s text.
    fn or_fail<C: Display>(self, area: fn(String) -> Error, f: impl FnOnce() -> C) -> Result<T>;
}

impl<T> Missing<T> for Option<T> {
    fn or_fail<C: Display>(self, area: fn(String) -> Error, f: impl FnOnce() -> C) -> Result<T> {
        self.ok_or_else(|| area(f().to_string()))
    }
}
