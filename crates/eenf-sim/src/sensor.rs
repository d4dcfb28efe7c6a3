//! A static textured scene under a flickering lamp, seen by an event sensor with per-pixel
//! log-intensity contrast thresholds, a refractory period, background noise and scan readout.

use std::f64::consts::PI;

use eenf_events::EventBatch;
use rand::{Rng, SeedableRng};
use rand_distr::{Distribution, Normal, Poisson};
use rayon::prelude::*;

use crate::mains::MainsPhase;

/// Reflectance levels of the procedural texture; pixels of one level share a log-intensity.
const LEVELS: usize = 64;
/// Scans simulated together (one output batch).
const WINDOW_SCANS: usize = 250;

/// Every parameter of the scene and the sensor.
#[derive(Debug, Clone, serde::Serialize)]
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
    /// Time constant of the lamp's response to electrical power, s (thermal inertia of an
    /// incandescent filament, or an LED driver's smoothing): sets the flicker depth.
    pub lamp_tau_s: f64,
    /// Share of the light that does not flicker (daylight, DC-driven sources).
    pub ambient: f64,
    /// Dark current, relative to the photocurrent of a white surface in full light.
    pub dark: f64,
    /// Scales all scene light (1 = normal indoor level).
    pub illumination: f64,
    /// Mean ON/OFF contrast threshold (log units).
    pub threshold: f64,
    /// Per-pixel standard deviation of the thresholds.
    pub threshold_spread: f64,
    /// Refractory period after an event, µs.
    pub refractory_us: i64,
    /// Readout scan period, µs: events of one scan share a timestamp (DVXplorer-like).
    pub scan_period_us: i64,
    /// Random jitter of each scan's time, ± µs.
    pub scan_jitter_us: i64,
    /// Background-activity noise events per pixel per second.
    pub noise_rate_hz: f64,
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
            lamp_tau_s: 0.008,
            ambient: 0.2,
            dark: 0.02,
            illumination: 1.0,
            threshold: 0.2,
            threshold_spread: 0.03,
            refractory_us: 100,
            scan_period_us: 200,
            scan_jitter_us: 20,
            noise_rate_hz: 0.1,
        }
    }
}

/// What a run produced.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct SimStats {
    /// Events written.
    pub events: u64,
    /// ON events.
    pub on_events: u64,
    /// Of which background noise.
    pub noise_events: u64,
    /// Readout scans simulated.
    pub scans: u64,
}

/// Events of one pixel chunk over one window, in scan order: (scan in window, pixel, ON).
#[derive(Default)]
struct ChunkEvents {
    scan: Vec<u16>,
    pixel: Vec<u32>,
    on: Vec<bool>,
    noise: u64,
}

#[derive(Clone, Copy)]
struct Pixel {
    level: u8,
    c_on: f32,
    c_off: f32,
    reference: f32,
    /// First scan at which the pixel may fire again.
    ready_at: u32,
}

/// The reflectance of pixel (x, y): smooth stripes and blobs, so regions differ in brightness
/// and therefore in flicker contrast once dark current is added.
fn texture(x: usize, y: usize, w: usize, h: usize, seed: u64) -> f64 {
    let (u, v) = (x as f64 / w as f64, y as f64 / h as f64);
    let s = (seed % 1000) as f64 * 0.37;
    let a = 0.5
        + 0.22 * (2.0 * PI * (3.0 * u + 1.5 * v) + s).sin()
        + 0.18 * (2.0 * PI * (5.0 * v - 2.0 * u) + 1.3 * s).sin()
        + 0.10 * (2.0 * PI * (11.0 * u * v) + 0.7 * s).cos();
    a.clamp(0.0, 1.0) * 0.95 + 0.05
}

fn level_reflectance(level: usize) -> f64 {
    0.05 + 0.95 * (level as f64 + 0.5) / LEVELS as f64
}

/// Simulates `config.duration_s` of events under mains `phase`, handing each window of scans to
/// `sink` as one time-ordered batch.
pub fn simulate<E>(
    config: &SimConfig,
    mains: &MainsPhase,
    mut sink: impl FnMut(&EventBatch) -> Result<(), E>,
) -> Result<SimStats, E> {
    let (w, h) = (config.width as usize, config.height as usize);
    let mut rng = rand::rngs::StdRng::seed_from_u64(config.seed);
    let thr = Normal::new(config.threshold, config.threshold_spread.max(1e-9)).unwrap();
    let levels: Vec<u8> = (0..w * h)
        .map(|i| {
            let r = texture(i % w, i / w, w, h, config.seed);
            (((r - 0.05) / 0.95 * LEVELS as f64) as usize).min(LEVELS - 1) as u8
        })
        .collect();

    let scan_dt = config.scan_period_us.max(1);
    let scans = (config.duration_s * 1e6 / scan_dt as f64).floor() as usize;
    let refractory_scans = (config.refractory_us as f64 / scan_dt as f64).ceil() as u32;
    // lamp: first-order response to instantaneous power cos²φ, warmed up to steady state
    let alpha = |dt: f64| 1.0 - (-dt / config.lamp_tau_s.max(1e-9)).exp();
    let mut lamp = 0.5;
    for i in 0..2000 {
        let t = -0.2 + i as f64 * 1e-4;
        let p = mains.phase_at(t).cos().powi(2);
        lamp += alpha(1e-4) * (p - lamp);
    }
    let log_table = |lamp: f64| -> [f32; LEVELS] {
        let light = config.illumination * (config.ambient + (1.0 - config.ambient) * 2.0 * lamp);
        let mut t = [0f32; LEVELS];
        for (k, v) in t.iter_mut().enumerate() {
            *v = (level_reflectance(k) * light + config.dark).ln() as f32;
        }
        t
    };
    let first = log_table(lamp);
    let mut pixels: Vec<Pixel> = levels
        .iter()
        .map(|&level| {
            let c_on = thr.sample(&mut rng).max(0.05) as f32;
            let c_off = thr.sample(&mut rng).max(0.05) as f32;
            // a random place between the thresholds, so pixels do not fire in lockstep
            let reference = first[level as usize] + rng.gen_range(-c_on..c_off);
            Pixel {
                level,
                c_on,
                c_off,
                reference,
                ready_at: 0,
            }
        })
        .collect();

    let chunk_px = (w * h).div_ceil(rayon::current_num_threads() * 4).max(256);
    let noise_per_scan = config.noise_rate_hz * scan_dt as f64 * 1e-6;
    let mut stats = SimStats::default();
    let mut prev_t = 0.0f64;
    let mut batch = EventBatch::default();
    let mut scan0 = 0usize;
    while scan0 < scans {
        let n = WINDOW_SCANS.min(scans - scan0);
        // scan times and the per-level log intensities of this window
        let mut times = Vec::with_capacity(n);
        let mut tables = Vec::with_capacity(n);
        for k in scan0..scan0 + n {
            let jitter = if k == 0 || config.scan_jitter_us == 0 {
                0
            } else {
                rng.gen_range(-config.scan_jitter_us..=config.scan_jitter_us)
            };
            let t_us = (k as i64 * scan_dt + jitter).max(0);
            let t = t_us as f64 * 1e-6;
            // integrate the lamp in sub-steps of at most 100 µs
            let steps = (((t - prev_t) / 1e-4).ceil() as usize).max(1);
            let dt = (t - prev_t) / steps as f64;
            for s in 1..=steps {
                let p = mains.phase_at(prev_t + s as f64 * dt).cos().powi(2);
                lamp += alpha(dt) * (p - lamp);
            }
            prev_t = t;
            times.push(t_us);
            tables.push(log_table(lamp));
        }
        let seeds: Vec<u64> = (0..(w * h).div_ceil(chunk_px)).map(|_| rng.gen()).collect();
        let outputs: Vec<ChunkEvents> = pixels
            .par_chunks_mut(chunk_px)
            .zip(seeds)
            .enumerate()
            .map(|(ci, (chunk, seed))| {
                let mut crng = rand::rngs::StdRng::seed_from_u64(seed);
                // background noise of this chunk and window, in scan order
                let lambda = noise_per_scan * chunk.len() as f64 * n as f64;
                let count = if lambda > 0.0 {
                    Poisson::new(lambda).unwrap().sample(&mut crng) as usize
                } else {
                    0
                };
                let mut noise: Vec<(u16, u32, bool)> = (0..count)
                    .map(|_| {
                        (
                            crng.gen_range(0..n) as u16,
                            crng.gen_range(0..chunk.len()) as u32,
                            crng.gen(),
                        )
                    })
                    .collect();
                noise.sort_unstable();
                let mut ni = 0;
                let mut out = ChunkEvents {
                    noise: count as u64,
                    ..ChunkEvents::default()
                };
                let base = (ci * chunk_px) as u32;
                for (s, table) in tables.iter().enumerate() {
                    let scan = (scan0 + s) as u32;
                    for (i, px) in chunk.iter_mut().enumerate() {
                        let l = table[px.level as usize];
                        let d = l - px.reference;
                        let noisy = ni < noise.len()
                            && noise[ni].0 as usize == s
                            && noise[ni].1 as usize == i;
                        if scan >= px.ready_at && (d >= px.c_on || d <= -px.c_off) {
                            let on = d > 0.0;
                            px.reference += if on { px.c_on } else { -px.c_off };
                            px.ready_at = scan + refractory_scans;
                            out.scan.push(s as u16);
                            out.pixel.push(base + i as u32);
                            out.on.push(on);
                        } else if noisy {
                            let on = noise[ni].2;
                            px.reference += if on { px.c_on } else { -px.c_off };
                            out.scan.push(s as u16);
                            out.pixel.push(base + i as u32);
                            out.on.push(on);
                        }
                        while ni < noise.len()
                            && noise[ni].0 as usize == s
                            && noise[ni].1 as usize <= i
                        {
                            ni += 1;
                        }
                    }
                }
                out
            })
            .collect();
        // merge the chunks scan by scan (chunks are in row-major pixel order)
        batch.clear();
        let mut ptr = vec![0usize; outputs.len()];
        for (s, &t_us) in times.iter().enumerate() {
            for (c, out) in outputs.iter().enumerate() {
                while ptr[c] < out.scan.len() && out.scan[ptr[c]] as usize == s {
                    let p = out.pixel[ptr[c]] as usize;
                    batch.push(
                        config.start_us + t_us,
                        (p % w) as u16,
                        (p / w) as u16,
                        out.on[ptr[c]],
                    );
                    ptr[c] += 1;
                }
            }
        }
        stats.noise_events += outputs.iter().map(|o| o.noise).sum::<u64>();
        stats.events += batch.len() as u64;
        stats.on_events += batch.p.iter().filter(|&&p| p).count() as u64;
        stats.scans += n as u64;
        if !batch.is_empty() {
            sink(&batch)?;
        }
        scan0 += n;
    }
    Ok(stats)
}
