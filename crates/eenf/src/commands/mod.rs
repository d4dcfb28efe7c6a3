//! One module per command.

pub mod args;
pub mod bench;
pub mod compare;
pub mod convert;
pub mod demo;
pub mod extract;
pub mod flicker_map;
pub mod info;
pub mod matching;
pub mod refdb;
pub mod reference;
pub mod simulate;
pub mod simulate_dataset;
pub mod video;
