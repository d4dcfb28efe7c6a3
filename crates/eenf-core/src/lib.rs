//! # eenf-core
//!
//! The words the other eenf crates share, defined once and free of I/O: the method's defaults,
//! the batch of events that readers produce and the temporal sampler consumes, the grid a
//! recording was made on (given or detected), a sampled signal, how messages name an option,
//! and the temporary paths removed when a signal ends the program. It depends on nothing, so
//! that the signal processing needs no file format to compile.

#![forbid(unsafe_code)]

pub mod batch;
pub mod cleanup;
pub mod defaults;
pub mod grid;
pub mod signal;
pub mod spelling;

pub use batch::EventBatch;
pub use grid::{Grid, Nominal};
pub use signal::Signal;
