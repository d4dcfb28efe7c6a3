//! What a simulated sensor is: its pixel circuit, its readout, a run's settings, and what a
//! run produced.

use crate::lamp::{Lamp, LampKind};
use crate::scene::{fan, person, walker, Region, Scene, SceneConfig, SceneKind, Shake, MAX_LAMPS};

/// The pixel circuit.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PixelConfig {
    /// Dark current, as the irradiance of a white surface it equals (indoor light = 1).
    pub dark: f64,
    /// Mean ON/OFF contrast threshold (log units).
    pub threshold: f64,
    /// Per-pixel standard deviation of the thresholds (drawn once).
    pub threshold_spread: f64,
    /// Refractory period after an event, µs.
    pub refractory_us: i64,
    /// Photoreceptor cut-off in bright light, Hz (0 = an ideal, instantaneous photoreceptor).
    pub bandwidth_hz: f64,
    /// Irradiance at which the cut-off has fallen to half: below it the cut-off falls in
    /// proportion to the photocurrent, so dim pixels low-pass the flicker.
    pub bandwidth_knee: f64,
    /// Shot-noise events per pixel per second at irradiance 1; the rate grows as
    /// 1 / irradiance in dim light.
    pub shot_noise_hz: f64,
    /// Upper bound of the shot-noise rate per pixel, Hz.
    pub shot_noise_max_hz: f64,
    /// Leak events (ON) per pixel per second: the reference drifts down (mean over pixels).
    pub leak_hz: f64,
    /// Share of pixels that are hot (at least one when > 0).
    pub hot_pixel_fraction: f64,
    /// Events per second of a hot pixel (80 % ON).
    pub hot_pixel_hz: f64,
    /// Irradiance at which the photoreceptor saturates (its output stops rising).
    pub saturation: f64,
}

impl Default for PixelConfig {
    fn default() -> Self {
        PixelConfig {
            dark: 0.005,
            threshold: 0.2,
            threshold_spread: 0.03,
            refractory_us: 100,
            bandwidth_hz: 3000.0,
            bandwidth_knee: 0.1,
            shot_noise_hz: 0.02,
            shot_noise_max_hz: 5.0,
            leak_hz: 0.1,
            hot_pixel_fraction: 1e-4,
            hot_pixel_hz: 100.0,
            saturation: 40.0,
        }
    }
}

/// How events leave the sensor.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Readout {
    /// iniVation DVXplorer-like: the array is read in scans; every event of a scan has the
    /// scan's timestamp. At most `max_rate_mev_s` million events per second leave; the rest
    /// wait in a FIFO of `fifo_events` (delayed to later scans) or are dropped.
    Dvxplorer {
        /// Scan period, µs.
        scan_period_us: i64,
        /// Random jitter of each scan's time, ± µs.
        scan_jitter_us: i64,
        /// Readout bandwidth, million events per second.
        max_rate_mev_s: f64,
        /// Events that can wait for a later scan.
        fifo_events: usize,
    },
    /// Prophesee-like: each event has its own µs timestamp (the threshold crossing,
    /// interpolated within the simulation step); above `max_rate_mev_s` the event-rate
    /// controller drops events.
    Prophesee {
        /// Simulation step, µs.
        step_us: i64,
        /// Event-rate controller limit, million events per second.
        max_rate_mev_s: f64,
    },
    /// DVS128-like (jAER): an AER arbiter serves the pixels one event at a time, each
    /// stamped with its own µs time when served, so no two events share a timestamp and a
    /// burst leaves spread out at the bus rate (Lichtsteiner et al. 2008: ~1 M events/s).
    Dvs128 {
        /// Simulation step, µs.
        step_us: i64,
        /// Bus rate, million events per second (one event per 1/rate µs).
        max_rate_mev_s: f64,
    },
}

impl Readout {
    /// The DVXplorer default: 200 µs scans (±20 µs), 100 M events/s, a FIFO of one scan.
    pub fn dvxplorer() -> Self {
        Readout::Dvxplorer {
            scan_period_us: 200,
            scan_jitter_us: 20,
            max_rate_mev_s: 100.0,
            fifo_events: 20_000,
        }
    }

    /// The Prophesee default: 50 µs steps, 1000 M events/s.
    pub fn prophesee() -> Self {
        Readout::Prophesee {
            step_us: 50,
            max_rate_mev_s: 1000.0,
        }
    }

    /// The DVS128 default: 50 µs steps, a 1 M events/s arbiter.
    pub fn dvs128() -> Self {
        Readout::Dvs128 {
            step_us: 50,
            max_rate_mev_s: 1.0,
        }
    }

    /// `dvxplorer`, `prophesee` or `dvs128` with defaults.
    pub fn named(name: &str) -> Option<Self> {
        match name {
            "dvxplorer" => Some(Self::dvxplorer()),
            "prophesee" => Some(Self::prophesee()),
            "dvs128" => Some(Self::dvs128()),
            _ => None,
        }
    }

    /// The simulation step (DVXplorer: the scan period), µs.
    pub fn step_us(&self) -> i64 {
        match *self {
            Readout::Dvxplorer { scan_period_us, .. } => scan_period_us.max(1),
            Readout::Prophesee { step_us, .. } | Readout::Dvs128 { step_us, .. } => step_us.max(1),
        }
    }

    pub(super) fn max_rate(&self) -> f64 {
        match *self {
            Readout::Dvxplorer { max_rate_mev_s, .. }
            | Readout::Prophesee { max_rate_mev_s, .. }
            | Readout::Dvs128 { max_rate_mev_s, .. } => max_rate_mev_s * 1e6,
        }
    }
}

/// Every parameter of a simulated recording: scene, lamps, pixels and readout. Written beside
/// each recording, with the seed, so that it can be made again.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SimConfig {
    /// Sensor width, pixels.
    pub width: u16,
    /// Sensor height, pixels.
    pub height: u16,
    /// Length of the recording, s.
    pub duration_s: f64,
    /// Absolute time of the recording's start, µs since the Unix epoch.
    pub start_us: i64,
    /// Random seed: same seed, same recording.
    pub seed: u64,
    /// The scene classes this configuration was made from (informational).
    pub kinds: Vec<SceneKind>,
    /// The lamps (at most 3).
    pub lamps: Vec<Lamp>,
    /// Share of the scene's light that does not flicker (daylight, DC sources).
    pub ambient: f64,
    /// Overall light level: 1 = an indoor room (a white surface then has irradiance 1).
    pub illumination: f64,
    /// Objects, shake, window and bulb.
    pub scene: SceneConfig,
    /// The pixel circuit.
    pub pixel: PixelConfig,
    /// The readout.
    pub readout: Readout,
    /// Motion is sampled every this many µs and interpolated linearly in between.
    pub motion_step_us: i64,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig {
            width: 64,
            height: 48,
            duration_s: 60.0,
            // 2022-08-17 08:10:00 UTC (16:10 in Wuhan, where the shared references were made)
            start_us: 1_660_723_800_000_000,
            seed: 1,
            kinds: vec![SceneKind::Static],
            lamps: vec![Lamp {
                kind: LampKind::named("led").unwrap(),
                phase_deg: 0.0,
                share: 1.0,
            }],
            ambient: 0.2,
            illumination: 1.0,
            scene: SceneConfig::default(),
            pixel: PixelConfig::default(),
            readout: Readout::dvxplorer(),
            motion_step_us: 2000,
        }
    }
}

impl SimConfig {
    /// Applies the scene classes `kinds` (mixes allowed) to this configuration.
    pub fn with_kinds(mut self, kinds: &[SceneKind]) -> Self {
        for kind in kinds {
            match kind {
                SceneKind::Static => {}
                SceneKind::DynamicObject => {
                    self.scene.objects.push(walker());
                    self.scene.objects.push(fan());
                }
                SceneKind::DynamicCamera => self.scene.shake = Some(Shake::default()),
                SceneKind::ExtremeDim => {
                    // ~3 lux on a white wall, where an indoor room has ~300
                    self.illumination = 0.01;
                    self.ambient = 0.02;
                }
                SceneKind::ExtremeBright => {
                    self.illumination = 3.0;
                    self.scene.window = Some(Region {
                        rect: (0.55, 0.05, 0.95, 0.5),
                        gain: 20.0,
                    });
                    self.scene.bulb = Some(Region {
                        rect: (0.1, 0.08, 0.22, 0.2),
                        gain: 60.0,
                    });
                }
                SceneKind::LampSpot => {
                    // daylight everywhere; the lamp's light counts only in its pool, where it
                    // is about as bright as the daylight (elsewhere 10⁻⁴ of the light)
                    self.ambient = 0.9999;
                    self.scene.bulb = Some(Region {
                        rect: (0.12, 0.58, 0.34, 0.81),
                        gain: 20_000.0,
                    });
                    self.scene.objects.push(person());
                }
            }
        }
        self.kinds = kinds.to_vec();
        self
    }

    /// The configured scene laid out for a `w` × `h` view (its texture and lamp pools are
    /// placed in fractions of the view, so any resolution sees the same room), with the shares
    /// of the lamps it uses.
    pub fn scene_at(&self, w: usize, h: usize) -> (Scene, Vec<f64>) {
        let shares: Vec<f64> = self.lamps.iter().take(MAX_LAMPS).map(|l| l.share).collect();
        let scene = Scene::new(
            &self.scene,
            w,
            h,
            &shares,
            self.ambient,
            self.illumination,
            self.seed,
        );
        (scene, shares)
    }

    /// Why this configuration cannot be simulated, if it cannot.
    pub fn check(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 {
            return Err("the sensor needs at least one pixel".into());
        }
        if !(self.duration_s > 0.0 && self.duration_s.is_finite()) {
            return Err("the duration must be positive".into());
        }
        if self.lamps.is_empty() || self.lamps.len() > MAX_LAMPS {
            return Err(format!("a scene holds 1 to {MAX_LAMPS} lamps"));
        }
        if !(0.0..1.0).contains(&self.ambient) {
            return Err("the ambient share must be in [0, 1)".into());
        }
        if !(self.illumination > 0.0 && self.illumination.is_finite()) {
            return Err("the illumination must be positive".into());
        }
        if self.pixel.threshold.is_nan() || self.pixel.threshold <= 0.0 {
            return Err("the contrast threshold must be positive".into());
        }
        if self.readout.step_us() > 50_000 {
            return Err("the readout step must be at most 50 ms".into());
        }
        Ok(())
    }
}

/// What a run produced.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct SimStats {
    /// Events written.
    pub events: u64,
    /// ON events written.
    pub on_events: u64,
    /// Shot-noise and hot-pixel events generated.
    pub noise_events: u64,
    /// Events that waited for a later scan (readout bandwidth).
    pub delayed_events: u64,
    /// Events dropped by the readout (FIFO full, or the event-rate controller).
    pub dropped_events: u64,
    /// Readout scans (or simulation steps) simulated.
    pub scans: u64,
}
