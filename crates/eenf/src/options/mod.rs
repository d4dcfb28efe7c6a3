//! Option sets: what a front end asks of the library, as plain data that checks itself.
//!
//! Each set holds its options under their library names (`window`, `max_gap`) with their
//! defaults (from [`eenf_core::defaults`] and the library's own), and [`OptionSet::check`]
//! refuses a value outside its range ([`limits`]) or a combination that cannot work, before any
//! work or allocation is sized by it. Then the set turns into the library's parameters
//! (`ExtractSettings::options` gives an [`crate::extract::ExtractOptions`], ...).
//!
//! The front ends fill the sets their own way: the command line from clap's flags
//! (`eenf-cli/src/args.rs`), Python and a page from a JSON object of keyword arguments
//! ([`apply_json`]). Messages name options as [`eenf_core::spelling`] says the front end's
//! users write them.

pub mod events;
pub mod limits;
pub mod simulate;
pub mod sound;

use std::fmt;
use std::str::FromStr;

use serde_json::Value;

pub(crate) use crate::error::rule;
pub use crate::error::OptionError;
pub use events::{EventOutputSettings, ExtractSettings, InputSettings, TrackerSettings};
pub use simulate::{DatasetSettings, SimulateSettings, VideoRenderSettings};
pub use sound::{AudioSettings, EditSettings, MatchSettings, StoreInputSettings, VideoSettings};

/// A set of options that a front end fills by name and the library checks.
pub trait OptionSet: fmt::Debug {
    /// Sets option `name` from a JSON value (a number, text, true/false or null for "not
    /// given"); `Ok(false)` when the set has no option of that name.
    fn set(&mut self, name: &str, value: &Value) -> Result<bool, OptionError>;
    /// Refuses values outside their range and combinations that cannot work.
    fn check(&self) -> Result<(), OptionError>;
}

/// Fills `sets` from a JSON object of options (each name goes to the first set that has it),
/// then checks each set. A name no set has is an [`OptionError::Unknown`].
pub fn apply_json(sets: &mut [&mut dyn OptionSet], json: &str) -> Result<(), OptionError> {
    apply(sets, json, false)
}

/// As [`apply_json`], but each name goes to every set that has it: for options shared by the
/// steps of one analysis (`nominal` is the grid of each).
pub fn apply_json_to_all(sets: &mut [&mut dyn OptionSet], json: &str) -> Result<(), OptionError> {
    apply(sets, json, true)
}

fn apply(sets: &mut [&mut dyn OptionSet], json: &str, all: bool) -> Result<(), OptionError> {
    let value: Value =
        serde_json::from_str(json).map_err(|e| OptionError::NotAnObject(e.to_string()))?;
    let Value::Object(map) = value else {
        return Err(OptionError::NotAnObject(format!("got {value}")));
    };
    for (name, v) in &map {
        let mut taken = false;
        for s in sets.iter_mut() {
            if s.set(name, v)? {
                taken = true;
                if !all {
                    break;
                }
            }
        }
        if !taken {
            return Err(OptionError::Unknown(name.clone()));
        }
    }
    sets.iter().try_for_each(|s| s.check())
}

/// `v` as text: a string as it is, anything else as its JSON.
fn text_of(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

fn invalid(name: &'static str, v: &Value, reason: impl Into<String>) -> OptionError {
    OptionError::Invalid {
        name,
        value: text_of(v),
        reason: reason.into(),
    }
}

/// A number (or text that reads as one: `"nan"` and `"inf"` too, for the range check to
/// refuse by name).
pub(crate) fn number(name: &'static str, v: &Value) -> Result<f64, OptionError> {
    match v {
        Value::Number(n) => n.as_f64(),
        Value::String(s) => s.trim().parse().ok(),
        _ => None,
    }
    .ok_or_else(|| invalid(name, v, "not a number"))
}

/// A whole number of type `T` (a JSON integer, or text that reads as one).
pub(crate) fn whole<T: TryFrom<i128>>(name: &'static str, v: &Value) -> Result<T, OptionError> {
    let n: Option<i128> = match v {
        Value::Number(n) => n.as_i64().map(i128::from).or(n.as_u64().map(i128::from)),
        Value::String(s) => s.trim().parse().ok(),
        _ => None,
    };
    let n = n.ok_or_else(|| invalid(name, v, "not a whole number"))?;
    T::try_from(n).map_err(|_| invalid(name, v, "out of range"))
}

/// true or false.
pub(crate) fn switch(name: &'static str, v: &Value) -> Result<bool, OptionError> {
    v.as_bool()
        .ok_or_else(|| invalid(name, v, "expected true or false"))
}

/// Text (a number is taken as its digits: `nominal=50`).
pub(crate) fn text(name: &'static str, v: &Value) -> Result<String, OptionError> {
    match v {
        Value::String(_) | Value::Number(_) => Ok(text_of(v)),
        _ => Err(invalid(name, v, "expected text")),
    }
}

/// A value named by text, read by the type's `FromStr` (the names the command line takes).
pub(crate) fn named<T: FromStr>(name: &'static str, v: &Value) -> Result<T, OptionError>
where
    T::Err: fmt::Display,
{
    text(name, v)?
        .parse()
        .map_err(|e: T::Err| invalid(name, v, e.to_string()))
}

/// `None` for null, else the value read by `read`.
pub(crate) fn maybe<T>(
    name: &'static str,
    v: &Value,
    read: fn(&'static str, &Value) -> Result<T, OptionError>,
) -> Result<Option<T>, OptionError> {
    match v {
        Value::Null => Ok(None),
        _ => read(name, v).map(Some),
    }
}

/// Refuses `v` outside `lo..=hi` (NaN and infinities too).
pub(crate) fn within(name: &'static str, v: f64, (lo, hi): (f64, f64)) -> Result<(), OptionError> {
    let inside = v.is_finite() && (lo..=hi).contains(&v);
    inside.then_some(()).ok_or_else(|| outside(name, v, lo, hi))
}

/// Refuses a whole number outside `lo..=hi`.
pub(crate) fn counted<T: Into<i128> + Copy + fmt::Display>(
    name: &'static str,
    v: T,
    (lo, hi): (T, T),
) -> Result<(), OptionError> {
    let inside = (lo.into()..=hi.into()).contains(&v.into());
    inside.then_some(()).ok_or_else(|| outside(name, v, lo, hi))
}

/// Option `name`'s value `v` lies outside `lo..=hi`.
fn outside(
    name: &'static str,
    v: impl fmt::Display,
    lo: impl fmt::Display,
    hi: impl fmt::Display,
) -> OptionError {
    OptionError::Invalid {
        name,
        value: v.to_string(),
        reason: format!("{v} is outside {lo}..={hi}"),
    }
}

/// Each option set's options, as JSON: `{"extract": [{"name", "default", "help",
/// "choices", "switch"}, ...], ...}` (the sets: input, extract, reference, video, simulate,
/// simulate_dataset, match, write, edits, refdb_build). Written from the command line's flags, whose doc comments hold the
/// help, and kept equal to them by a test of `eenf-cli`; Python's docstrings and the page's
/// forms read it.
pub const DOCS_JSON: &str = include_str!("docs.json");
