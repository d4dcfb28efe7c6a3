//! # eenf-sim
//!
//! Simulated event recordings of flickering scenes with ground truth, because real event data
//! with a mains reference is rare. A [`MainsPhase`] (synthetic, from a trace, or from a mains
//! recording) drives [`Lamp`]s (incandescent, fluorescent, LED, on three phases) lighting a
//! [`Scene`] (texture, moving objects, camera shake, dim or over-bright light); [`simulate`]
//! renders what an event sensor sees of it (photoreceptor bandwidth, log compression,
//! thresholds, refractory period, noise, leak, hot pixels, DVXplorer or Prophesee readout);
//! [`MainsPhase::truth`] gives the true ENF at 1 s steps. Same [`SimConfig`] and seed, same
//! events, on any number of threads.
//!
//! ```
//! use eenf_sim::{simulate, MainsPhase, SceneKind, SimConfig, SyntheticEnf};
//! let config = SimConfig { width: 16, height: 12, duration_s: 2.0, ..SimConfig::default() }
//!     .with_kinds(&[SceneKind::DynamicObject]);
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

mod camera;
mod lamp;
mod mains;
mod scene;
mod sensor;

pub use camera::{render_video, CameraConfig, VideoStats};
pub use lamp::{Lamp, LampBank, LampKind};
pub use mains::{phase_from_start, MainsError, MainsPhase, SyntheticEnf};
pub use scene::{
    person, walker, Frame, MovingObject, Pose, Region, Scene, SceneConfig, SceneKind, Shake,
    CHANNELS, MAX_LAMPS,
};
pub use sensor::{fast_ln, simulate, PixelConfig, Readout, SimConfig, SimStats};
