//! # eenf
//!
//! The library behind the `eenf` command (crate `eenf-cli`) and the Python package: every
//! command is a thin layer over these modules. The library knows no command line: it prints
//! nothing, draws nothing, and reports progress to a [`progress::Progress`] its caller
//! supplies; what the user should be told comes back in the results (a trace's notes and
//! warnings). The data path:
//!
//! - [`extract`]: an event recording → its polarity sequence → a [`trace::Trace`] (E-ENF);
//!   [`video`]: a video → a `Trace` (V-ENF); [`mains`]: a mains or audio recording → a `Trace`.
//! - [`reference`]: where a reference comes from ([`reference::ReferenceSource`]), the long
//!   series [`locate`] searches (`match`), and the store [`refdb`] keeps them in.
//! - [`evaluate`]: a `Trace` against its reference → an `Agreement` (CC, MAE, RMSE, max).
//! - [`edits`]: was a recording edited? Cuts and insertions from the hum's phase.
//! - [`bench`]: every method over a dataset, Table 2 and its reports; [`simulation`],
//!   [`dataset`] and [`dataset_build`]: simulated recordings and datasets with their truth.
//! - [`options`]: what each front end asks for, as option sets that check themselves.
//!
//! [`analysis`] runs all of it on one file at once (the page's upload).
//!
//! [`error`] says what went wrong, by area, for each front end to word.
//!
//! [`recording`] is what E-ENF reads (a file or events in memory); [`trace`] reads and writes
//! traces, [`output`] writes every file whole or not at all, [`time`] holds all calendar and
//! time-zone work.

#![forbid(unsafe_code)]

pub mod analysis;
pub mod archive;
pub mod audio;
pub mod bench;
pub mod dataset;
pub mod dataset_build;
pub mod edits;
pub mod error;
pub mod evaluate;
pub mod extract;
pub mod fetch;
pub mod flac_mask;
pub mod flicker_map;
pub mod inspect;
pub mod locate;
pub mod mains;
pub mod options;
pub mod output;
pub mod progress;
pub mod recording;
pub mod refdb;
pub mod reference;
pub mod simulation;
pub mod spool;
pub mod time;
pub mod trace;
pub mod video;
pub mod wav;

pub use error::{Area, Error, Result};
