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

use crate::lamp::LampBank;
use crate::mains::MainsPhase;
use crate::scene::{Scene, CHANNELS, MAX_LAMPS};

mod config;
mod pixel;

pub use config::{PixelConfig, Readout, SimConfig, SimStats};
pub use pixel::fast_ln;
use pixel::{mix_light, photoreceptor_pass, Light, PixelConsts, PixelState, StepLight};

/// Time steps simulated together (one output batch).
const WINDOW_STEPS: usize = 250;
/// Pixels per chunk (rounded to whole rows): small enough for the cache, many enough per core.
const CHUNK_PIXELS: usize = 1024;

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
