//! A conventional frame camera watching the same scene under the same lamps as the event
//! sensor: exposure integration, rolling-shutter row timing, camera response, shot and read
//! noise, 8-bit quantization. It renders the videos that V-ENF (the paper's baseline) reads.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::lamp::LampBank;
use crate::mains::MainsPhase;
use crate::scene::{CHANNELS, MAX_LAMPS};
use crate::sensor::SimConfig;

/// How the camera exposes and reads out its rows, and how it turns light into 8-bit values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CameraConfig {
    /// Preset name (`lr`, `hr`) or `custom`.
    pub name: String,
    /// Frame width, pixels.
    pub width: u32,
    /// Frame height (rows), pixels.
    pub height: u32,
    /// Frames per second.
    pub fps: f64,
    /// Exposure time of each row, s (a multiple of the flicker period nulls the flicker).
    pub exposure_s: f64,
    /// Time from the first row to the last row, s (0 = global shutter). The rest of the frame
    /// period is the idle gap.
    pub readout_s: f64,
    /// ISO, for the record (the noise follows from `full_scale_e`).
    pub iso: f64,
    /// Electrons that fill the 8-bit range at this gain (fewer at a higher ISO: more noise).
    pub full_scale_e: f64,
    /// Read noise, electrons rms.
    pub read_noise_e: f64,
    /// Display gamma of the response curve.
    pub gamma: f64,
    /// Output value of black, of 255.
    pub black_level: f64,
    /// Auto-exposure target: mean linear signal (of full scale) of the first frame.
    pub target: f64,
    /// Largest gain the auto-exposure may use, relative to an indoor room (dim scenes stay
    /// dark beyond it).
    pub max_gain: f64,
    /// The "power line frequency" setting of webcams: the exposure is set to a whole number of
    /// flicker periods of the nominal grid (at least one), so that the picture does not band.
    /// It nulls the flicker except for the ENF's small deviation from nominal.
    #[serde(default)]
    pub anti_flicker: bool,
    /// Constant rate factor of the H.264 coding the camera's pipeline applies (`--mp4`): about
    /// 28 for a webcam streamed at ~1 Mbit/s, 20 for a phone's ~17 Mbit/s 1080p.
    #[serde(default = "default_crf")]
    pub crf: u32,
    /// Error of the camera's clock, parts per million: frames come (1 + ppm·10⁻⁶) times a
    /// nominal period apart while the file says the nominal rate (cameras are not locked to
    /// anything; a phone's or webcam's crystal is off by tens of ppm).
    #[serde(default)]
    pub clock_ppm: f64,
    /// Whether the gain follows the scene (locked on the first frame, up to `max_gain`); off,
    /// the gain is fixed for an indoor room, as a phone set by hand to an ISO and a shutter
    /// speed: a dim scene stays dark and a bright one clips.
    #[serde(default = "default_true")]
    pub auto_exposure: bool,
    /// Random jitter of each frame's start, s rms (a phone's variable-rate video pipeline;
    /// the file's timing says nothing of it).
    #[serde(default)]
    pub frame_jitter_s: f64,
}

fn default_crf() -> u32 {
    23
}

fn default_true() -> bool {
    true
}

impl CameraConfig {
    /// A low-cost webcam like the dataset's Video-LR (Logitech C270): 640×480, 30 fps, a
    /// long exposure held at a whole number of flicker periods by its anti-flicker setting
    /// (30 ms: three periods at 50 Hz), low gain, ~30 ms readout, streamed H.264.
    pub fn lr() -> Self {
        CameraConfig {
            name: "lr".into(),
            width: 640,
            height: 480,
            fps: 30.0,
            exposure_s: 1.0 / 30.0,
            readout_s: 0.0305,
            iso: 100.0,
            full_scale_e: 6000.0,
            read_noise_e: 6.0,
            gamma: 2.2,
            black_level: 8.0,
            target: 0.35,
            max_gain: 3.0,
            anti_flicker: true,
            crf: 28,
            clock_ppm: 0.0,
            auto_exposure: true,
            frame_jitter_s: 50e-6,
        }
    }

    /// A phone camera like the dataset's Video-HR: 1920×1080, 30 fps, set by hand to ISO 1600
    /// and 1/200 s (no auto-exposure: dim scenes stay dark, bright ones clip), ~20 ms readout,
    /// frame starts jittering by 0.5 ms as a phone's variable-rate pipeline does.
    pub fn hr() -> Self {
        CameraConfig {
            name: "hr".into(),
            width: 1920,
            height: 1080,
            fps: 30.0,
            exposure_s: 0.005,
            readout_s: 0.020,
            iso: 1600.0,
            full_scale_e: 600.0,
            read_noise_e: 2.0,
            gamma: 2.2,
            black_level: 8.0,
            target: 0.35,
            max_gain: 40.0,
            anti_flicker: false,
            crf: 20,
            clock_ppm: 0.0,
            auto_exposure: false,
            frame_jitter_s: 0.5e-3,
        }
    }

    /// A preset by name.
    pub fn named(name: &str) -> Option<Self> {
        match name {
            "lr" => Some(Self::lr()),
            "hr" => Some(Self::hr()),
            _ => None,
        }
    }

    /// The same camera with its frame scaled by `factor` (rows and columns; the row timing
    /// keeps its readout time).
    pub fn scaled(mut self, factor: f64) -> Self {
        let f = factor.clamp(0.01, 1.0);
        self.width = ((self.width as f64 * f).round() as u32).max(2) & !1;
        self.height = ((self.height as f64 * f).round() as u32).max(2) & !1;
        self
    }

    /// Number of row times in one frame period (real rows plus idle ones): fs = L·fps for the
    /// rolling-shutter sampling. Infinite for a global shutter.
    pub fn virtual_rows(&self) -> f64 {
        self.height as f64 / (self.readout_s * self.fps)
    }

    /// The exposure the camera uses on a grid of `nominal_hz`: `exposure_s`, or with
    /// `anti_flicker` the nearest whole number of flicker periods 1/(2·f0) (at least one, at
    /// most what fits in a frame).
    pub fn exposure_on(&self, nominal_hz: f64) -> f64 {
        if !self.anti_flicker || nominal_hz <= 0.0 {
            return self.exposure_s;
        }
        let flicker = 1.0 / (2.0 * nominal_hz);
        let fit = (1.0 / self.fps / flicker).floor().max(1.0);
        (self.exposure_s / flicker).round().clamp(1.0, fit) * flicker
    }

    /// Checks the parameters; the reason when they make no sense.
    pub fn check(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 || self.width > 8192 || self.height > 8192 {
            return Err(format!(
                "frame size {}x{} out of range",
                self.width, self.height
            ));
        }
        if !(self.fps > 0.0 && self.fps <= 1000.0) {
            return Err(format!("frame rate {} out of range", self.fps));
        }
        let period = 1.0 / self.fps;
        if !(self.exposure_s > 0.0 && self.exposure_s <= period) {
            return Err(format!(
                "exposure {} s must lie in (0, {period:.4}] s",
                self.exposure_s
            ));
        }
        if !(self.readout_s >= 0.0 && self.readout_s < period) {
            return Err(format!(
                "readout {} s must lie in [0, {period:.4}) s",
                self.readout_s
            ));
        }
        Ok(())
    }
}

/// Lamp light integrated over time (prefix sums at a fine step), so that any exposure window
/// is averaged exactly with two look-ups.
struct LightIntegral {
    dt: f64,
    /// Time of sample 0, s.
    t0: f64,
    /// Running integrals of each lamp channel, one entry per step from `t0`.
    sums: Vec<[f64; MAX_LAMPS]>,
    bank: LampBank,
}

impl LightIntegral {
    fn new(bank: LampBank, dt: f64, t0: f64) -> Self {
        LightIntegral {
            dt,
            t0,
            sums: vec![[0.0; MAX_LAMPS]],
            bank,
        }
    }

    /// Extends the integrals to time `t`.
    fn extend_to(&mut self, t: f64, mains: &MainsPhase) {
        while self.t0 + (self.sums.len() - 1) as f64 * self.dt < t {
            let k = self.sums.len() - 1;
            // midpoint rule over the step
            self.bank
                .advance_to(self.t0 + (k as f64 + 0.5) * self.dt, mains);
            let mut next = self.sums[k];
            for (s, l) in next.iter_mut().zip(self.bank.light()) {
                *s += l * self.dt;
            }
            self.sums.push(next);
        }
    }

    /// Integral from t0 to `t` (linear between steps).
    fn at(&self, t: f64) -> [f64; MAX_LAMPS] {
        let pos = ((t - self.t0) / self.dt).max(0.0);
        let k = (pos.floor() as usize).min(self.sums.len() - 2);
        let w = pos - k as f64;
        std::array::from_fn(|c| self.sums[k][c] * (1.0 - w) + self.sums[k + 1][c] * w)
    }

    /// Mean light of each lamp over [a, b].
    fn mean(&self, a: f64, b: f64) -> [f64; MAX_LAMPS] {
        let (sa, sb) = (self.at(a), self.at(b));
        std::array::from_fn(|c| (sb[c] - sa[c]) / (b - a))
    }

    /// Drops what lies before `t` (kept to whole steps).
    fn forget_before(&mut self, t: f64) {
        let k = ((t - self.t0) / self.dt).floor();
        if k > 1.0 {
            let k = (k as usize - 1).min(self.sums.len() - 2);
            self.sums.drain(..k);
            self.t0 += k as f64 * self.dt;
        }
    }
}

/// A small counter-based generator of standard normal deviates: the noise of a row depends on
/// (seed, frame, row) only, so rows are rendered in parallel with the same result. Each
/// deviate sums four 16-bit uniforms of one 64-bit draw (Irwin–Hall, scaled to unit
/// variance): a close normal for camera noise (tails cut at 3.5σ) at a few ns a pixel, where
/// Box–Muller's log and cosine dominated the render.
fn row_rng(seed: u64, frame: u64, row: u64) -> impl FnMut() -> f32 {
    let mut s =
        seed ^ frame.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ row.wrapping_mul(0xC2B2_AE3D_27D4_EB4F);
    move || {
        s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = s;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        let sum = (z & 0xFFFF) + ((z >> 16) & 0xFFFF) + ((z >> 32) & 0xFFFF) + (z >> 48);
        // mean 4·(2^16 − 1)/2, variance 4·(2^32 − 1)/12
        (sum as f32 - 131_070.0) * (3.0f32.sqrt() / 65_536.0)
    }
}

/// What rendering a video produced.
#[derive(Debug, Clone, Default, Serialize)]
pub struct VideoStats {
    /// Frames rendered.
    pub frames: u64,
    /// Linear gain the auto-exposure locked on.
    pub gain: f64,
    /// Share of pixel values clipped at the top.
    pub saturated: f64,
    /// Exposure used, s (after the anti-flicker rounding).
    pub exposure_s: f64,
}

/// Renders `config.duration_s` of video of `config`'s scene and lamps through `camera`,
/// handing each frame's luma (row-major, `width × height` bytes) to `sink`.
pub fn render_video<E>(
    config: &SimConfig,
    camera: &CameraConfig,
    mains: &MainsPhase,
    mut sink: impl FnMut(&[u8]) -> Result<(), E>,
) -> Result<VideoStats, E> {
    let (w, h) = (camera.width as usize, camera.height as usize);
    // the same scene as the event sensor's, laid out for this frame
    let (scene, shares) = config.scene_at(w, h);
    let bank = LampBank::new(&config.lamps[..shares.len()], mains);
    let period = 1.0 / camera.fps;
    // row i starts i·T_row after row 0; the rows after the last are the idle gap
    let row_time = camera.readout_s / h as f64;
    let exposure = camera.exposure_on(mains.nominal_hz);
    let mut light = LightIntegral::new(bank, 25e-6, 0.0);
    let frames = (config.duration_s * camera.fps).floor() as u64;
    // static scenes are rendered once
    let mut coef: [Vec<f32>; CHANNELS] = std::array::from_fn(|_| vec![0f32; w * h]);
    scene.render(0.0, 0, w * h, &mut coef, 0);
    let moving = !scene.is_static();
    // auto-exposure: locked on the mean light of the view at rest
    let mean_irr = {
        // every channel at its mean light (1)
        let s: f64 = coef.iter().flatten().map(|&c| c as f64).sum();
        (s / (w * h) as f64).max(1e-12)
    };
    // the gain an indoor room (mean light ≈ 1) would get, and the cap relative to it
    let room_gain = camera.target;
    let gain = if camera.auto_exposure {
        (camera.target / mean_irr).min(room_gain * camera.max_gain)
    } else {
        room_gain
    };
    let fs_e = camera.full_scale_e;
    let read = camera.read_noise_e / fs_e;
    let black = camera.black_level;
    // response curve as a table over the linear signal in 1/4096 steps
    let curve: Vec<u8> = (0..=4096)
        .map(|k| {
            let s = k as f64 / 4096.0;
            (black + (255.0 - black) * s.powf(1.0 / camera.gamma))
                .round()
                .clamp(0.0, 255.0) as u8
        })
        .collect();
    let (gain32, inv_fs, read2) = (gain as f32, (1.0 / fs_e) as f32, (read * read) as f32);
    let mut frame = vec![0u8; w * h];
    let mut saturated = 0u64;
    let seed = config.seed ^ 0xCA3E_7A00;
    for n in 0..frames {
        let t_frame = n as f64 * period * (1.0 + camera.clock_ppm * 1e-6)
            + camera.frame_jitter_s * f64::from(row_rng(seed ^ 0x7177, n, u64::MAX)());
        // exposure of row i: [end − exposure, end], end = t_frame + exposure + i·row_time
        let last_end = t_frame + exposure + (h - 1) as f64 * row_time;
        light.extend_to(last_end + light.dt, mains);
        let row_light: Vec<[f32; CHANNELS]> = (0..h)
            .map(|i| {
                let end = t_frame + exposure + i as f64 * row_time;
                let m = light.mean(end - exposure, end);
                let mut l = [0f32; CHANNELS];
                for (d, v) in l.iter_mut().zip(m.iter().take(shares.len())) {
                    *d = *v as f32;
                }
                l[MAX_LAMPS] = 1.0;
                l
            })
            .collect();
        let scene_ref = &scene;
        let coef_ref = &coef;
        let clipped: u64 = frame
            .par_chunks_mut(w)
            .enumerate()
            .map(|(i, row)| {
                let l = row_light[i];
                let mut rng = row_rng(seed, n, i as u64);
                // a moving scene is rendered at the row's mid-exposure time
                let mut own: [Vec<f32>; CHANNELS];
                let c: [&[f32]; CHANNELS] = if moving {
                    own = std::array::from_fn(|_| vec![0f32; w]);
                    let t_mid = t_frame + exposure / 2.0 + i as f64 * row_time;
                    scene_ref.render(t_mid, i * w, w, &mut own, 0);
                    std::array::from_fn(|k| &own[k][..])
                } else {
                    std::array::from_fn(|k| &coef_ref[k][i * w..(i + 1) * w])
                };
                let mut clipped = 0u64;
                for (j, px) in row.iter_mut().enumerate() {
                    let e: f32 = (0..CHANNELS).map(|k| c[k][j] * l[k]).sum();
                    let s = e * gain32;
                    // shot noise (Gaussian approximation of Poisson) and read noise
                    let sigma = (s.max(0.0) * inv_fs + read2).sqrt();
                    let v = s + sigma * rng();
                    if v >= 1.0 {
                        clipped += 1;
                    }
                    *px = curve[(v.clamp(0.0, 1.0) * 4096.0).round() as usize];
                }
                clipped
            })
            .sum();
        saturated += clipped;
        sink(&frame)?;
        // the next frame starts after this one (jitter is far below a period)
        light.forget_before(t_frame);
    }
    Ok(VideoStats {
        frames,
        gain,
        saturated: saturated as f64 / (frames.max(1) as f64 * (w * h) as f64),
        exposure_s: exposure,
    })
}
