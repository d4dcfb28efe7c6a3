//! # eenf (library part of the command-line tool)
//!
//! The commands of `eenf` are thin wrappers over these functions, which tests and benchmarks
//! call directly: [`pipeline::extract_file`] (event file → ENF trace),
//! [`pipeline::reference_file`] (mains WAV → reference trace),
//! [`pipeline::reference_for_recording`] (a dataset's hourly references → the reference of one
//! recording), [`pipeline::align`], [`evaluate::compare`] (a trace against its reference) and
//! [`bench`] (a whole dataset, every method).

pub mod bench;
pub mod dataset;
pub mod evaluate;
pub mod output;
pub mod pipeline;
pub mod plot;
pub mod progress;
pub mod refdb;
pub mod simulation;
pub mod wav;
