//! The event sensor: photoreceptors with an illumination-dependent bandwidth, log compression,
//! per-pixel contrast thresholds, refractory period, shot noise, leak and hot pixels, and a
//! readout (DVXplorer-like scans with a finite bandwidth, Prophesee-like µs timestamps, or a
//! DVS128-like arbiter that serves one event at a time).
//!
//! Pixels are simulated in fixed chunks of rows, in parallel; each chunk has its own random
//! stream, so the same seed gives the same recording on any number of threads.

use eenf_events::EventBatch;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal, Poisson};
use rayon::prelude::*;

use crate::lamp::{Lamp, LampBank, LampKind};
use crate::mains::MainsPhase;
use crate::scene::{
    fan, person, walker, Region, Scene, SceneConfig, SceneKind, Shake, CHANNELS, MAX_LAMPS,
};

/// Time steps simulated together (one output batch).
const WINDOW_STEPS: usize = 250;
/// Pixels per chunk (rounded to whole rows): small enough for the cache, many enough per core.
const CHUNK_PIXELS: usize = 1024;

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

    fn max_rate(&self) -> f64 {
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

/// Events of one chunk over one window, in step order, as columns (the pixel already split
/// into x and y, so that the readout copies whole runs).
#[derive(Default)]
struct ChunkEvents {
    /// Where each step's events end.
    step_end: Vec<u32>,
    x: Vec<u16>,
    y: Vec<u16>,
    on: Vec<bool>,
    /// When the threshold was crossed within the step, µs (Prophesee).
    offset_us: Vec<u16>,
    noise: u64,
}

impl ChunkEvents {
    /// The range of step `s`'s events.
    fn step_range(&self, s: usize) -> std::ops::Range<usize> {
        let start = if s == 0 { 0 } else { self.step_end[s - 1] };
        start as usize..self.step_end[s] as usize
    }
}

/// The state of a block of pixel rows, kept across windows.
struct Chunk {
    first: usize,
    len: usize,
    rng: rand::rngs::StdRng,
    /// Light coefficients at the start of the motion step, and their change over it.
    coef: [Vec<f32>; CHANNELS],
    delta: [Vec<f32>; CHANNELS],
    /// Pixel runs (start, len, index in chunk) whose `delta` is non-zero.
    moving: Vec<(usize, usize)>,
    /// Motion step now being interpolated.
    motion_k: i64,
    /// Photoreceptor output (log units), before and after the last step.
    v: Vec<f32>,
    v_old: Vec<f32>,
    irradiance: Vec<f32>,
    reference: Vec<f32>,
    c_on: Vec<f32>,
    c_off: Vec<f32>,
    leak: Vec<f32>,
    hot_hz: Vec<f32>,
    ready_at: Vec<u32>,
    /// Pixels past a threshold in this step (1) or not (0).
    candidate: Vec<u8>,
    /// Irradiance of a moving scene's pixels in this step.
    scratch: Vec<f32>,
}

/// Natural logarithm to ~1e-7 relative (the Cephes single-precision polynomial), without a
/// division or a branch, so that the compiler can vectorise the pixel loop.
#[inline(always)]
fn fast_ln(x: f32) -> f32 {
    let bits = x.to_bits();
    let mut e = ((bits >> 23) & 0xff) as i32 - 126;
    let mut m = f32::from_bits((bits & 0x007f_ffff) | 0x3f00_0000); // [0.5, 1)
                                                                    // move m to [√½, √2)
    let small = m < std::f32::consts::FRAC_1_SQRT_2;
    e -= i32::from(small);
    m = if small { m + m } else { m };
    let x = m - 1.0;
    let z = x * x;
    let mut y = 7.037_683_6e-2;
    y = y * x - 1.151_461e-1;
    y = y * x + 1.167_699_9e-1;
    y = y * x - 1.242_014_1e-1;
    y = y * x + 1.424_932_3e-1;
    y = y * x - 1.666_805_8e-1;
    y = y * x + 2.000_071_5e-1;
    y = y * x - 2.499_999_4e-1;
    y = y * x + 3.333_333e-1;
    let y = y * x * z - 0.5 * z;
    x + y + e as f32 * std::f32::consts::LN_2
}

/// The light falling on a chunk's pixels in one step: coefficients (and their change over
/// the motion step) times each channel's light.
struct Light<'a> {
    coef: [&'a [f32]; CHANNELS],
    /// The irradiance itself, when already summed (moving scenes).
    precomputed: Option<&'a [f32]>,
    light: [f32; CHANNELS],
    /// Only the first lamp channel carries light.
    one_lamp: bool,
}

/// The per-pixel arrays one step updates.
struct PixelState<'a> {
    irradiance: &'a mut [f32],
    v: &'a mut [f32],
    v_old: &'a mut [f32],
    reference: &'a mut [f32],
    leak: &'a [f32],
    c_on: &'a [f32],
    c_off: &'a [f32],
    candidate: &'a mut [u8],
    /// Keep the previous output (for interpolated timestamps).
    keep_old: bool,
    /// Store the irradiance (for the next window's noise rates).
    keep_irradiance: bool,
}

/// Log, photoreceptor low-pass, leak and threshold comparison of every pixel; with AVX-512 or
/// AVX2 when the processor has them (the same operations, so the same events). The dispatch is
/// written out rather than generated by `multiversion`: two small functions do not justify a
/// proc-macro dependency, and this is the workspace's only `unsafe`.
fn photoreceptor_pass(s: PixelState, light: &Light, pc: &PixelConsts) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the feature was detected at run time
            unsafe { photoreceptor_avx512(s, light, pc) };
            return;
        }
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            // SAFETY: the features were detected at run time
            unsafe { photoreceptor_avx2(s, light, pc) };
            return;
        }
    }
    photoreceptor_generic(s, light, pc)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx2,fma")]
unsafe fn photoreceptor_avx512(s: PixelState, light: &Light, pc: &PixelConsts) {
    photoreceptor_generic(s, light, pc)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn photoreceptor_avx2(s: PixelState, light: &Light, pc: &PixelConsts) {
    photoreceptor_generic(s, light, pc)
}

/// `out[i] = dark + Σ_c (coef_c[i] + u·delta_c[i])·light_c`: the light of a moving scene's
/// pixels between two motion steps (vectorised like the pixel loop; the slices are arguments
/// so that the compiler knows they do not overlap).
fn mix_light(
    out: &mut [f32],
    coef: [&[f32]; CHANNELS],
    delta: [&[f32]; CHANNELS],
    u: f32,
    light: [f32; CHANNELS],
    dark: f32,
) {
    #[inline(always)]
    fn generic(
        out: &mut [f32],
        coef: [&[f32]; CHANNELS],
        delta: [&[f32]; CHANNELS],
        u: f32,
        l: [f32; CHANNELS],
        dark: f32,
    ) {
        let n = out.len();
        let [c0, c1, c2, c3] = coef.map(|c| &c[..n]);
        let [d0, d1, d2, d3] = delta.map(|d| &d[..n]);
        for i in 0..n {
            out[i] = dark
                + (c0[i] + u * d0[i]) * l[0]
                + (c1[i] + u * d1[i]) * l[1]
                + (c2[i] + u * d2[i]) * l[2]
                + (c3[i] + u * d3[i]) * l[3];
        }
    }
    #[cfg(target_arch = "x86_64")]
    {
        #[target_feature(enable = "avx512f,avx2,fma")]
        unsafe fn avx512(
            out: &mut [f32],
            coef: [&[f32]; CHANNELS],
            delta: [&[f32]; CHANNELS],
            u: f32,
            l: [f32; CHANNELS],
            dark: f32,
        ) {
            generic(out, coef, delta, u, l, dark)
        }
        #[target_feature(enable = "avx2,fma")]
        unsafe fn avx2(
            out: &mut [f32],
            coef: [&[f32]; CHANNELS],
            delta: [&[f32]; CHANNELS],
            u: f32,
            l: [f32; CHANNELS],
            dark: f32,
        ) {
            generic(out, coef, delta, u, l, dark)
        }
        if std::arch::is_x86_feature_detected!("avx512f") {
            // SAFETY: the feature was detected at run time
            unsafe { avx512(out, coef, delta, u, light, dark) };
            return;
        }
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            // SAFETY: the features were detected at run time
            unsafe { avx2(out, coef, delta, u, light, dark) };
            return;
        }
    }
    generic(out, coef, delta, u, light, dark)
}

#[inline(always)]
fn photoreceptor_generic(s: PixelState, light: &Light, pc: &PixelConsts) {
    let n = s.irradiance.len();
    let [c0, c1, c2, c3] = light.coef.map(|c| &c[..n]);
    let l = light.light;
    match light.precomputed {
        Some(e) => {
            let e = &e[..n];
            photoreceptor_loop(s, pc, |i| e[i])
        }
        None if light.one_lamp => {
            photoreceptor_loop(s, pc, |i| pc.dark + c0[i] * l[0] + c3[i] * l[3])
        }
        None => photoreceptor_loop(s, pc, |i| {
            pc.dark + c0[i] * l[0] + c1[i] * l[1] + c2[i] * l[2] + c3[i] * l[3]
        }),
    }
}

#[inline(always)]
fn photoreceptor_loop(s: PixelState, pc: &PixelConsts, irradiance: impl Fn(usize) -> f32) {
    // the flags become constants, so that the vector loop has no branch
    match (s.keep_old, s.keep_irradiance) {
        (false, false) => photoreceptor_steps::<false, false>(s, pc, irradiance),
        (false, true) => photoreceptor_steps::<false, true>(s, pc, irradiance),
        (true, false) => photoreceptor_steps::<true, false>(s, pc, irradiance),
        (true, true) => photoreceptor_steps::<true, true>(s, pc, irradiance),
    }
}

#[inline(always)]
fn photoreceptor_steps<const KEEP_OLD: bool, const KEEP_IRR: bool>(
    s: PixelState,
    pc: &PixelConsts,
    irradiance: impl Fn(usize) -> f32,
) {
    let n = s.irradiance.len();
    let (irr, v, v_old, reference) = (
        s.irradiance,
        &mut s.v[..n],
        &mut s.v_old[..n],
        &mut s.reference[..n],
    );
    let (leak, c_on, c_off, cand) = (
        &s.leak[..n],
        &s.c_on[..n],
        &s.c_off[..n],
        &mut s.candidate[..n],
    );
    let (bw, knee, sat) = (pc.bw, pc.knee, pc.saturation);
    let ideal = bw <= 0.0;
    for i in 0..n {
        let e = irradiance(i).min(sat);
        if KEEP_IRR {
            irr[i] = e;
        }
        let x = fast_ln(e);
        // b/(1+b) with b = bw·e/(e+knee), in one division
        let alpha = if ideal {
            1.0
        } else {
            bw * e / (e * (1.0 + bw) + knee)
        };
        if KEEP_OLD {
            v_old[i] = v[i];
        }
        let vi = v[i] + alpha * (x - v[i]);
        v[i] = vi;
        let r = reference[i] - leak[i];
        reference[i] = r;
        let d = vi - r;
        cand[i] = u8::from(d >= c_on[i]) | u8::from(d <= -c_off[i]);
    }
}

/// Constants of one step shared by every pixel.
struct StepLight {
    /// Lamp lights and daylight (1).
    light: [f32; CHANNELS],
    /// Time, s from the start.
    t: f64,
}

struct PixelConsts {
    dark: f32,
    saturation: f32,
    /// 2π f_c Δt at full bandwidth (0 = ideal).
    bw: f32,
    knee: f32,
    refractory_steps: u32,
    step_us: i64,
    shot_hz: f32,
    shot_max_hz: f32,
    motion_step_s: f64,
    /// Prophesee readout: timestamps interpolated within the step.
    prophesee: bool,
    /// The scene has one lamp.
    one_lamp: bool,
}

impl Chunk {
    /// Moves the motion interpolation to the step holding time `t`.
    fn follow_motion(&mut self, scene: &Scene, t: f64, pc: &PixelConsts) {
        let k = (t / pc.motion_step_s).floor() as i64;
        while self.motion_k < k {
            // the end of the current motion step is the start of the next
            for &(start, len) in &self.moving {
                for c in 0..CHANNELS {
                    for i in start..start + len {
                        self.coef[c][i] += self.delta[c][i];
                        self.delta[c][i] = 0.0;
                    }
                }
            }
            self.moving.clear();
            self.motion_k += 1;
            let (t0, t1) = (
                self.motion_k as f64 * pc.motion_step_s,
                (self.motion_k + 1) as f64 * pc.motion_step_s,
            );
            let w = scene.dims().0;
            let rows = (self.first / w, (self.first + self.len).div_ceil(w));
            for b in scene.moving_boxes(t0, t1) {
                for y in b.1.max(rows.0)..b.3.min(rows.1) {
                    let start = y * w + b.0 - self.first;
                    let len = b.2 - b.0;
                    self.moving.push((start, len));
                }
            }
            let mut target: [Vec<f32>; CHANNELS] = std::array::from_fn(|_| Vec::new());
            let frame = scene.frame(t1);
            for &(start, len) in &self.moving {
                for c in target.iter_mut() {
                    c.resize(len, 0.0);
                }
                scene.render_frame(&frame, self.first + start, len, &mut target, 0);
                for (c, tc) in target.iter().enumerate() {
                    let coef = &self.coef[c][start..start + len];
                    for ((d, t), c0) in self.delta[c][start..start + len]
                        .iter_mut()
                        .zip(tc)
                        .zip(coef)
                    {
                        *d = t - c0;
                    }
                }
            }
        }
    }

    /// Simulates one window of steps; `noise` are this window's noise events (step, pixel, ON).
    fn run(
        &mut self,
        scene: &Scene,
        steps: &[StepLight],
        pc: &PixelConsts,
        first_step: u32,
    ) -> ChunkEvents {
        let n = self.len;
        let window_s = steps.len() as f64 * pc.step_us as f64 * 1e-6;
        // noise of this window: shot noise grows in dim light; hot pixels fire regardless
        let rates: Vec<f64> = (0..n)
            .map(|i| {
                let shot = (pc.shot_hz / self.irradiance[i].max(1e-9)).min(pc.shot_max_hz);
                (shot + self.hot_hz[i]) as f64
            })
            .collect();
        let total: f64 = rates.iter().sum::<f64>() * window_s;
        let count = if total > 0.0 {
            Poisson::new(total).unwrap().sample(&mut self.rng) as usize
        } else {
            0
        };
        let mut cumulative = Vec::with_capacity(n);
        let mut acc = 0.0;
        for r in &rates {
            acc += r;
            cumulative.push(acc);
        }
        let mut noise: Vec<(u16, u32, bool)> = (0..count)
            .map(|_| {
                let x = self.rng.gen::<f64>() * acc;
                let i = cumulative.partition_point(|&c| c <= x).min(n - 1);
                let p_on = if self.hot_hz[i] > 0.0 { 0.8 } else { 0.5 };
                (
                    self.rng.gen_range(0..steps.len()) as u16,
                    i as u32,
                    self.rng.gen::<f64>() < p_on,
                )
            })
            .collect();
        noise.sort_unstable();
        noise.dedup_by_key(|e| (e.0, e.1));
        let mut ni = 0;
        let mut out = ChunkEvents {
            noise: count as u64,
            ..ChunkEvents::default()
        };
        let moving = !scene.is_static();
        let width = scene.dims().0;
        let mut fired: Vec<u32> = Vec::new();
        for (s, step) in steps.iter().enumerate() {
            if moving {
                self.follow_motion(scene, step.t, pc);
            }
            let u = if moving {
                ((step.t / pc.motion_step_s) - self.motion_k as f64) as f32
            } else {
                0.0
            };
            // irradiance, log, photoreceptor low-pass and the threshold comparison: one plain
            // loop over slices, which the compiler vectorises
            if moving {
                // interpolated light of the moving scene, summed in a plain loop first (a
                // closure this large would not be inlined into the vector loop)
                mix_light(
                    &mut self.scratch[..n],
                    std::array::from_fn(|c| &self.coef[c][..n]),
                    std::array::from_fn(|c| &self.delta[c][..n]),
                    u,
                    step.light,
                    pc.dark,
                );
            }
            let light = Light {
                coef: std::array::from_fn(|c| &self.coef[c][..n]),
                precomputed: moving.then_some(&self.scratch[..n]),
                light: step.light,
                one_lamp: pc.one_lamp,
            };
            let state = PixelState {
                irradiance: &mut self.irradiance[..n],
                v: &mut self.v[..n],
                v_old: &mut self.v_old[..n],
                reference: &mut self.reference[..n],
                leak: &self.leak[..n],
                c_on: &self.c_on[..n],
                c_off: &self.c_off[..n],
                candidate: &mut self.candidate[..n],
                keep_old: pc.prophesee,
                keep_irradiance: s + 1 == steps.len(),
            };
            photoreceptor_pass(state, &light, pc);
            let scan = first_step + s as u32;
            fired.clear();
            // eight pixels' flags per word: quiet words are skipped, and in the others each
            // set byte is found without a branch per pixel
            let (cand, ready_at) = (&self.candidate[..n], &self.ready_at[..n]);
            let mut words = cand.chunks_exact(8);
            for (wi, word) in words.by_ref().enumerate() {
                let mut bits = u64::from_le_bytes(word.try_into().expect("8 bytes"));
                while bits != 0 {
                    let j = wi * 8 + (bits.trailing_zeros() / 8) as usize;
                    bits &= bits - 1;
                    if scan >= ready_at[j] {
                        fired.push(j as u32);
                    }
                }
            }
            let tail = n - words.remainder().len();
            for (j, &c) in words.remainder().iter().enumerate() {
                if c != 0 && scan >= ready_at[tail + j] {
                    fired.push((tail + j) as u32);
                }
            }
            // this step's noise events join (a pixel fires once per step)
            let noise_from = ni;
            while ni < noise.len() && noise[ni].0 as usize == s {
                ni += 1;
            }
            let step_noise = &noise[noise_from..ni];
            let mut k = 0;
            // a threshold event (polarity None: from the sign), or a noise event
            let mut emit = |i: usize, noise_on: Option<bool>, out: &mut ChunkEvents| {
                let d = self.v[i] - self.reference[i];
                let on = noise_on.unwrap_or(d > 0.0);
                let c = if on { self.c_on[i] } else { -self.c_off[i] };
                let mut offset = 0u16;
                if noise_on.is_none() {
                    // when the crossing happened within the step (Prophesee timestamps)
                    let d_old = self.v_old[i] - self.reference[i];
                    let frac = ((c - d_old) / (d - d_old)).clamp(0.0, 1.0);
                    offset = (frac * pc.step_us as f32).min(u16::MAX as f32) as u16;
                    self.ready_at[i] = scan + pc.refractory_steps;
                }
                self.reference[i] += c;
                let p = self.first + i;
                out.x.push((p % width) as u16);
                out.y.push((p / width) as u16);
                out.on.push(on);
                out.offset_us.push(offset);
            };
            for &i in &fired {
                let i = i as usize;
                // noise of pixels before this one
                while k < step_noise.len() && (step_noise[k].1 as usize) < i {
                    emit(step_noise[k].1 as usize, Some(step_noise[k].2), &mut out);
                    k += 1;
                }
                if k < step_noise.len() && step_noise[k].1 as usize == i {
                    k += 1;
                }
                emit(i, None, &mut out);
            }
            while k < step_noise.len() {
                let (_, p, on) = step_noise[k];
                k += 1;
                if k < step_noise.len() && step_noise[k].1 == p {
                    continue;
                }
                emit(p as usize, Some(on), &mut out);
            }
            out.step_end.push(out.x.len() as u32);
        }
        out
    }
}

/// Simulates `config.duration_s` of events under mains `phase`, handing each window of steps
/// to `sink` as one time-ordered batch.
pub fn simulate<E>(
    config: &SimConfig,
    mains: &MainsPhase,
    mut sink: impl FnMut(&EventBatch) -> Result<(), E>,
) -> Result<SimStats, E> {
    // the sink (usually a file writer) runs on this thread while the pixels of the next
    // window are simulated on the others
    let (tx, rx) = std::sync::mpsc::sync_channel::<EventBatch>(2);
    let (back_tx, back_rx) = std::sync::mpsc::channel::<EventBatch>();
    std::thread::scope(|scope| {
        let producer = scope.spawn(move || generate(config, mains, tx, back_rx));
        let mut result = Ok(());
        for batch in rx.iter() {
            if result.is_ok() {
                result = sink(&batch);
            }
            if result.is_err() {
                // stop the producer: it sees the closed channel
                break;
            }
            let _ = back_tx.send(batch);
        }
        drop(rx);
        let stats = producer.join().expect("the simulator thread panicked");
        result.map(|_| stats)
    })
}

/// Simulates and sends each window's events, reusing the batches that come back.
fn generate(
    config: &SimConfig,
    mains: &MainsPhase,
    tx: std::sync::mpsc::SyncSender<EventBatch>,
    recycled: std::sync::mpsc::Receiver<EventBatch>,
) -> SimStats {
    let (w, h) = (config.width as usize, config.height as usize);
    let (scene, shares) = config.scene_at(w, h);
    let mut rng = rand::rngs::StdRng::seed_from_u64(config.seed);
    let px = &config.pixel;
    let thr = Normal::new(px.threshold, px.threshold_spread.max(1e-9)).unwrap();
    let step_us = config.readout.step_us();
    let step_s = step_us as f64 * 1e-6;
    let pc = PixelConsts {
        dark: px.dark as f32,
        saturation: px.saturation as f32,
        bw: (2.0 * std::f64::consts::PI * px.bandwidth_hz * step_s) as f32,
        knee: px.bandwidth_knee as f32,
        refractory_steps: (px.refractory_us as f64 / step_us as f64).ceil() as u32,
        step_us,
        shot_hz: px.shot_noise_hz as f32,
        shot_max_hz: px.shot_noise_max_hz as f32,
        motion_step_s: config.motion_step_us.max(step_us) as f64 * 1e-6,
        prophesee: !matches!(config.readout, Readout::Dvxplorer { .. }),
        one_lamp: shares.len() == 1,
    };
    let mut bank = LampBank::new(&config.lamps[..shares.len()], mains);
    let light_now = |bank: &LampBank| {
        let mut l = [0f32; CHANNELS];
        for (k, v) in bank.light().iter().enumerate() {
            l[k] = *v as f32;
        }
        l[MAX_LAMPS] = 1.0;
        l
    };

    // pixels: thresholds, leak and hot pixels drawn once, in pixel order
    let n_hot = if px.hot_pixel_fraction > 0.0 {
        ((w * h) as f64 * px.hot_pixel_fraction).round().max(1.0) as usize
    } else {
        0
    };
    let mut hot = vec![0f32; w * h];
    for _ in 0..n_hot {
        hot[rng.gen_range(0..w * h)] = px.hot_pixel_hz as f32;
    }
    // at least 8 chunks, so that the cores share the work evenly; the split depends on the
    // size alone, never on the threads, so the output does not either
    let chunks_wanted = (w * h).div_ceil(CHUNK_PIXELS).max(8);
    let rows_per_chunk = h.div_ceil(chunks_wanted).max(1);
    let chunk_len = rows_per_chunk * w;
    let light0 = light_now(&bank);
    let mut chunks: Vec<Chunk> = (0..w * h)
        .step_by(chunk_len)
        .map(|first| {
            let len = chunk_len.min(w * h - first);
            let mut coef: [Vec<f32>; CHANNELS] = std::array::from_fn(|_| vec![0f32; len]);
            scene.render(0.0, first, len, &mut coef, 0);
            let mut c = Chunk {
                first,
                len,
                rng: rand::rngs::StdRng::seed_from_u64(rng.gen()),
                coef,
                delta: std::array::from_fn(|_| vec![0f32; len]),
                moving: Vec::new(),
                motion_k: 0,
                v: vec![0.0; len],
                v_old: vec![0.0; len],
                irradiance: vec![0.0; len],
                reference: vec![0.0; len],
                c_on: vec![0.0; len],
                c_off: vec![0.0; len],
                leak: vec![0.0; len],
                hot_hz: hot[first..first + len].to_vec(),
                ready_at: vec![0; len],
                candidate: vec![0; len],
                scratch: vec![0.0; len],
            };
            for i in 0..len {
                let mut e = px.dark as f32;
                for (coef, l) in c.coef.iter().zip(light0) {
                    e += coef[i] * l;
                }
                let e = e.min(pc.saturation);
                c.irradiance[i] = e;
                c.v[i] = fast_ln(e);
                c.c_on[i] = thr.sample(&mut rng).max(0.02) as f32;
                c.c_off[i] = thr.sample(&mut rng).max(0.02) as f32;
                // a random place between the thresholds, so pixels do not fire in lockstep
                c.reference[i] = c.v[i] - rng.gen_range(-c.c_off[i]..c.c_on[i]);
                // leak rates vary between pixels (log-normal, ±50 %)
                let spread = (0.4 * rng.sample::<f64, _>(rand_distr::StandardNormal)).exp();
                c.leak[i] = (px.leak_hz * spread * c.c_on[i] as f64 * step_s) as f32;
            }
            if !scene.is_static() {
                c.motion_k = -1;
            }
            c
        })
        .collect();
    // a moving scene starts its first interpolation at t = 0
    if !scene.is_static() {
        for c in &mut chunks {
            c.follow_motion(&scene, 0.0, &pc);
        }
    }

    let steps_total = (config.duration_s / step_s).floor() as usize;
    let (jitter_us, fifo_cap) = match config.readout {
        Readout::Dvxplorer {
            scan_jitter_us,
            fifo_events,
            ..
        } => (scan_jitter_us.clamp(0, step_us / 2 - 1).max(0), fifo_events),
        Readout::Prophesee { .. } | Readout::Dvs128 { .. } => (0, 0),
    };
    let per_step_cap = ((config.readout.max_rate() * step_s).floor() as usize).max(1);
    // own timestamps (Prophesee, DVS128) rather than the scan's
    let prophesee = !matches!(config.readout, Readout::Dvxplorer { .. });
    // DVS128: the arbiter serves one event per `service_us`; the time it is next free
    let arbiter = matches!(config.readout, Readout::Dvs128 { .. });
    let service_us = (1e6 / config.readout.max_rate()).ceil().max(1.0) as i64;
    let mut bus_free = i64::MIN;

    let mut stats = SimStats::default();
    let mut batch = EventBatch::default();
    // events waiting in the readout FIFO: (x, y, ON)
    let mut backlog: std::collections::VecDeque<(u16, u16, bool)> = Default::default();
    let mut step0 = 0usize;
    while step0 < steps_total {
        let n = WINDOW_STEPS.min(steps_total - step0);
        let mut times = Vec::with_capacity(n);
        let mut steps = Vec::with_capacity(n);
        for k in step0..step0 + n {
            let jitter = if k == 0 || jitter_us == 0 {
                0
            } else {
                rng.gen_range(-jitter_us..=jitter_us)
            };
            let t_us = k as i64 * step_us + jitter;
            let t = t_us as f64 * 1e-6;
            bank.advance_to(t, mains);
            times.push(t_us);
            steps.push(StepLight {
                light: light_now(&bank),
                t,
            });
        }
        let outputs: Vec<ChunkEvents> = chunks
            .par_iter_mut()
            .map(|c| c.run(&scene, &steps, &pc, step0 as u32))
            .collect();
        // readout: each step's events in row-major order (the chunks are row blocks)
        batch.clear();
        let mut step_events: Vec<(u16, u16, u16, bool)> = Vec::new();
        for (s, &t_abs) in times.iter().enumerate() {
            let t_abs = config.start_us + t_abs;
            let ranges: Vec<std::ops::Range<usize>> =
                outputs.iter().map(|o| o.step_range(s)).collect();
            let count: usize = ranges.iter().map(|r| r.len()).sum();
            if !prophesee && backlog.is_empty() && count <= per_step_cap {
                // the usual case: the whole scan leaves at once, copied run by run
                for (o, r) in outputs.iter().zip(&ranges) {
                    batch.t.extend(std::iter::repeat_n(t_abs, r.len()));
                    batch.x.extend_from_slice(&o.x[r.clone()]);
                    batch.y.extend_from_slice(&o.y[r.clone()]);
                    batch.p.extend_from_slice(&o.on[r.clone()]);
                }
                continue;
            }
            step_events.clear();
            for (o, r) in outputs.iter().zip(&ranges) {
                for k in r.clone() {
                    step_events.push((o.offset_us[k], o.x[k], o.y[k], o.on[k]));
                }
            }
            if arbiter {
                step_events.sort_by_key(|e| e.0);
                for &(off, x, y, on) in &step_events {
                    // served when the crossing happened, or when the bus is next free
                    let t = (t_abs - step_us + off as i64)
                        .max(config.start_us)
                        .max(bus_free);
                    bus_free = t + service_us;
                    batch.push(t, x, y, on);
                }
            } else if prophesee {
                step_events.sort_by_key(|e| e.0);
                if step_events.len() > per_step_cap {
                    stats.dropped_events += (step_events.len() - per_step_cap) as u64;
                    // the rate controller thins evenly rather than cutting the step's end
                    let keep = per_step_cap as f64 / step_events.len() as f64;
                    let mut acc = 0.0;
                    step_events.retain(|_| {
                        acc += keep;
                        if acc >= 1.0 {
                            acc -= 1.0;
                            true
                        } else {
                            false
                        }
                    });
                }
                for &(off, x, y, on) in &step_events {
                    // the crossing happened during the step that ends at t_abs
                    let t = (t_abs - step_us + off as i64).max(config.start_us);
                    batch.push(t, x, y, on);
                }
            } else {
                // waiting events leave first, then this scan's, up to the scan's capacity
                let mut budget = per_step_cap;
                while budget > 0 {
                    let Some((x, y, on)) = backlog.pop_front() else {
                        break;
                    };
                    batch.push(t_abs, x, y, on);
                    budget -= 1;
                }
                for &(_, x, y, on) in &step_events {
                    if budget > 0 {
                        batch.push(t_abs, x, y, on);
                        budget -= 1;
                    } else if backlog.len() < fifo_cap {
                        backlog.push_back((x, y, on));
                        stats.delayed_events += 1;
                    } else {
                        stats.dropped_events += 1;
                    }
                }
            }
        }
        stats.noise_events += outputs.iter().map(|o| o.noise).sum::<u64>();
        stats.events += batch.len() as u64;
        stats.on_events += batch.p.iter().filter(|&&p| p).count() as u64;
        stats.scans += n as u64;
        if !batch.is_empty() {
            let next = recycled.try_recv().unwrap_or_default();
            if tx.send(std::mem::replace(&mut batch, next)).is_err() {
                break;
            }
        }
        step0 += n;
    }
    // events still waiting when the recording stops are lost
    stats.dropped_events += backlog.len() as u64;
    stats
}

#[cfg(test)]
mod tests {
    use super::fast_ln;

    #[test]
    fn fast_ln_matches_ln() {
        let mut x = 1e-6f32;
        while x < 1e6 {
            let err = (fast_ln(x) - x.ln()).abs();
            assert!(err < 2e-6 * x.ln().abs().max(1.0), "{x}: {err}");
            x *= 1.0137;
        }
    }
}
