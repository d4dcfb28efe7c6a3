//! # eenf
//!
//! The library behind the `eenf` command: every command is a thin layer over these modules,
//! which tests, benchmarks and (later) the Python package call directly. The data path:
//!
//! - [`extract`]: an event recording → its polarity sequence → a [`trace::Trace`] (E-ENF);
//!   [`video`]: a video → a `Trace` (V-ENF); [`reference`]: a mains recording → a `Trace`.
//! - [`evaluate`]: a `Trace` against its reference → an `Agreement` (CC, MAE, RMSE, max).
//! - [`refdb`] and [`reference::ReferenceSeries`]: long references that `match` searches.
//! - [`bench`]: every method over a dataset, Table 2 and figures; [`simulation`] and
//!   [`dataset`]: simulated recordings and datasets with their truth.
//!
//! [`args`] holds the option sets of the command line, parsed into the library's types, which the
//! `eenf` command and the Python package share (names, defaults, checks and messages).
//! [`trace`] reads and writes traces, [`output`] writes every file whole or not at all,
//! [`time`] holds all calendar and time-zone work.

#![forbid(unsafe_code)]

pub mod args;
pub mod audio;
pub mod bench;
pub mod dataset;
pub mod evaluate;
pub mod extract;
pub mod flicker_map;
pub mod inspect;
pub mod output;
pub mod plot;
pub mod progress;
pub mod refdb;
pub mod reference;
pub mod simulation;
pub mod time;
pub mod trace;
pub mod video;
pub mod wav;
