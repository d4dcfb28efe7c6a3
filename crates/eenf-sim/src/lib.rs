//! # eenf-sim
//!
//! Simulated event recordings of flickering scenes with ground truth, because real event data
//! with a mains reference is rare. A [`MainsPhase`] (synthetic, or taken from a mains
//! recording) drives a lamp; [`simulate`] renders what an event sensor sees of a textured
//! scene under it; [`MainsPhase::truth`] gives the true ENF at 1 s steps.
//!
//! ```
//! use eenf_sim::{simulate, MainsPhase, SimConfig, SyntheticEnf};
//! let config = SimConfig { width: 16, height: 12, duration_s: 2.0, ..SimConfig::default() };
//! let mains = MainsPhase::synthetic(50.0, config.duration_s, SyntheticEnf::default(), 1);
//! let mut events = 0;
//! let stats = simulate(&config, &mains, |batch| {
//!     events += batch.len();
//!     Ok::<(), ()>(())
//! })
//! .unwrap();
//! assert_eq!(stats.events as usize, events);
//! assert!(events > 1000);
//! ```

mod mains;
mod sensor;

pub use mains::{MainsError, MainsPhase, SyntheticEnf};
pub use sensor::{simulate, SimConfig, SimStats};
