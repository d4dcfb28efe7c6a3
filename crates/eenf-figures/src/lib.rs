//! # eenf-figures
//!
//! The figures of eenf, drawn with plotters as PNG or SVG (chosen by the file's extension) and
//! written whole or not at all: an estimate against its reference with the error underneath
//! ([`plot_comparison`], [`plot_methods`]), a trace's harmonics with the one chosen per segment
//! ([`plot_extraction`]), spectrograms, a benchmark's summary, the flicker map of an event
//! recording and the hum's phase with the edits found in it. The command line draws them; the
//! Python package and a page are to draw the same ones, so they live here rather than in a front
//! end. [`report`] words an analysis's verdicts and writes the report a page offers.

#![forbid(unsafe_code)]

mod bench;
mod comparison;
mod draw;
mod edits;
mod extraction;
mod flicker_map;
pub mod report;
mod spectrogram;
mod summary;

pub use bench::write_plots;
pub use comparison::{comparison_svg, plot_comparison, plot_methods, Series};
pub use draw::title_name;
pub use edits::{edits_svg, plot_edits};
pub use extraction::{extraction_svg, plot_extraction};
pub use flicker_map::{flicker_map_svg, flicker_map_title, plot_flicker_map};
pub use spectrogram::plot_spectrogram;
pub use summary::{plot_summary, SummaryBar};
