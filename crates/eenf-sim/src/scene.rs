//! What the sensor looks at: a textured room lit by lamps and daylight, objects moving through
//! it with their shadows and highlights, and a hand-held camera's shake.
//!
//! The scene is rendered into per-pixel light coefficients, one per lamp plus one for daylight:
//! a pixel's irradiance is `Σ_k coef_k · lamp_k(t) + coef_daylight + dark`. Motion changes the
//! coefficients; the lamps change the light.

use std::f64::consts::PI;

use rand::{Rng, SeedableRng};

/// Lamps a scene can hold (each has its own coefficient channel).
pub const MAX_LAMPS: usize = 3;
/// Coefficient channels: one per lamp, then daylight.
pub const CHANNELS: usize = MAX_LAMPS + 1;

/// The scene classes of EV-ENFD and the simulator's named conditions; they can be mixed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SceneKind {
    /// Nothing moves.
    Static,
    /// A person walks across part of the view and a fan turns.
    DynamicObject,
    /// A hand-held camera: the whole view shakes.
    DynamicCamera,
    /// Night: the light is ~100 times dimmer than indoors.
    ExtremeDim,
    /// A high-dynamic-range view: a daylit window and a bare bulb, saturating parts of it.
    ExtremeBright,
    /// A daylit room where the mains light reaches only a lamp's pool (~5 % of the view)
    /// while a person walks by: the flicker lives in a few pixels, as in real recordings.
    LampSpot,
}

impl SceneKind {
    /// Every kind, in the order of their names.
    pub const ALL: [SceneKind; 6] = [
        SceneKind::Static,
        SceneKind::DynamicObject,
        SceneKind::DynamicCamera,
        SceneKind::ExtremeDim,
        SceneKind::ExtremeBright,
        SceneKind::LampSpot,
    ];

    /// The kind's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SceneKind::Static => "static",
            SceneKind::DynamicObject => "dynamic-object",
            SceneKind::DynamicCamera => "dynamic-camera",
            SceneKind::ExtremeDim => "extreme-dim",
            SceneKind::ExtremeBright => "extreme-bright",
            SceneKind::LampSpot => "lamp-spot",
        }
    }

    /// The kind called `name`.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name.trim())
    }
}

/// Something that moves through the view. Positions and sizes are fractions of the view's
/// width (x) and height (y).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum MovingObject {
    /// A person-sized textured figure walking to and fro across the view, bobbing as it
    /// steps, with a shadow on the background and a specular highlight that both move with it.
    Walker {
        /// Walking speed, view widths per second.
        speed: f64,
        /// Body width (fraction of the view width).
        width: f64,
        /// Body height (fraction of the view height).
        height: f64,
        /// Centre height of the body.
        y: f64,
        /// Share of the lamps' light left in the shadow.
        shadow: f64,
        /// Offset of the shadow, fractions of the view.
        shadow_offset: (f64, f64),
        /// Peak of the specular highlight, in units of a white surface's lamp light.
        specular: f64,
        /// Time at which it enters, s.
        phase_s: f64,
        /// How irregular the gait is: the walking speed and the step rate vary by up to
        /// 1.6× this share, slowly (0: a machine's constant pace, whose pixel crossings and
        /// steps repeat so exactly that they make spectral lines near 100–120 Hz).
        #[serde(default)]
        gait: f64,
    },
    /// A fan turning in the view: bright blades over a dark hub and the background.
    Fan {
        /// Centre (fractions of the view).
        centre: (f64, f64),
        /// Radius, fraction of the view height.
        radius: f64,
        /// Revolutions per second.
        rev_per_s: f64,
        /// Number of blades.
        blades: u32,
    },
}

/// Hand-held shake: random translation and rotation with a hand's spectrum (slow sway falling
/// as 1/f from `band_hz.0`, plus physiological tremor near 8–12 Hz).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Shake {
    /// RMS translation along each axis, fraction of the view width.
    pub translation_rms: f64,
    /// RMS rotation, degrees.
    pub rotation_rms_deg: f64,
    /// Lowest and highest frequency of the sway, Hz.
    pub band_hz: (f64, f64),
}

impl Default for Shake {
    fn default() -> Self {
        // ~2 px RMS on a 640-pixel-wide view, 0.15° roll
        Shake {
            translation_rms: 0.003,
            rotation_rms_deg: 0.15,
            band_hz: (0.3, 12.0),
        }
    }
}

/// A rectangle of the view (fractions) whose light differs.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Region {
    /// Left, top, right, bottom (fractions of the view).
    pub rect: (f64, f64, f64, f64),
    /// Multiplies the region's light (daylight for a window, lamp light for a bulb).
    pub gain: f64,
}

/// Everything in view besides the lamps.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SceneConfig {
    /// Moving objects.
    pub objects: Vec<MovingObject>,
    /// Camera shake, if hand-held.
    pub shake: Option<Shake>,
    /// A window: its daylight (non-flickering) is multiplied by `gain`.
    pub window: Option<Region>,
    /// The first lamp's bulb in view: its lamp light is multiplied by `gain`.
    pub bulb: Option<Region>,
}

impl SceneConfig {
    /// True when nothing in the view moves.
    pub fn is_static(&self) -> bool {
        self.objects.is_empty() && self.shake.is_none()
    }
}

/// The default walker of `dynamic-object` scenes: a constant pace.
pub fn walker() -> MovingObject {
    walker_with_gait(0.0)
}

/// A person's walk (`lamp-spot` scenes): [`walker`] with an irregular pace, speed and step
/// rate varying by up to ±40 %.
pub fn person() -> MovingObject {
    walker_with_gait(0.25)
}

fn walker_with_gait(gait: f64) -> MovingObject {
    MovingObject::Walker {
        speed: 0.25,
        width: 0.14,
        height: 0.55,
        y: 0.6,
        shadow: 0.35,
        shadow_offset: (0.05, 0.03),
        specular: 2.0,
        phase_s: 0.0,
        gait,
    }
}

/// The default fan of `dynamic-object` scenes.
pub fn fan() -> MovingObject {
    MovingObject::Fan {
        centre: (0.8, 0.3),
        radius: 0.16,
        rev_per_s: 7.3,
        blades: 3,
    }
}

/// A hash of three integers to [0, 1).
fn hash01(a: i64, b: i64, seed: u64) -> f64 {
    let mut x = (a as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (b as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ seed.wrapping_mul(0x1656_67B1_9E37_79F9);
    x ^= x >> 31;
    x = x.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x ^= x >> 29;
    (x >> 11) as f64 / (1u64 << 53) as f64
}

/// Smooth value noise in [0, 1) with cells of `cell` pixels.
fn value_noise(x: f64, y: f64, cell: f64, seed: u64) -> f64 {
    let (gx, gy) = (x / cell, y / cell);
    let (ix, iy) = (gx.floor() as i64, gy.floor() as i64);
    let (fx, fy) = (gx - ix as f64, gy - iy as f64);
    let s = |t: f64| t * t * (3.0 - 2.0 * t);
    let (sx, sy) = (s(fx), s(fy));
    let v00 = hash01(ix, iy, seed);
    let v10 = hash01(ix + 1, iy, seed);
    let v01 = hash01(ix, iy + 1, seed);
    let v11 = hash01(ix + 1, iy + 1, seed);
    (v00 * (1.0 - sx) + v10 * sx) * (1.0 - sy) + (v01 * (1.0 - sx) + v11 * sx) * sy
}

/// The camera pose's offset from rest at one time: translation (pixels) and roll (rad).
#[derive(Debug, Clone, Copy, Default)]
pub struct Pose {
    /// Across, pixels.
    pub dx: f64,
    /// Down, pixels.
    pub dy: f64,
    /// Roll, radians.
    pub roll: f64,
}

/// The camera pose and each object's state (position or angle) at one time.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Where the camera points, from rest.
    pub pose: Pose,
    /// (object, x or angle, bob)
    objects: Vec<(MovingObject, f64, f64)>,
}

/// Sum-of-sinusoids shake path: deterministic from the seed, cheap to evaluate anywhere.
#[derive(Debug, Clone)]
struct ShakePath {
    /// (frequency Hz, amplitude, phase) per axis: x, y, roll.
    parts: [Vec<(f64, f64, f64)>; 3],
}

impl ShakePath {
    fn new(shake: &Shake, width: f64, seed: u64) -> Self {
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed ^ 0x5a4e);
        let (lo, hi) = (shake.band_hz.0.max(0.01), shake.band_hz.1.max(0.02));
        let make = |rms: f64, rng: &mut rand::rngs::StdRng| {
            let n = 24;
            let mut parts: Vec<(f64, f64, f64)> = (0..n)
                .map(|i| {
                    let f = lo * (hi / lo).powf((i as f64 + rng.gen::<f64>()) / n as f64);
                    // sway falls as 1/f; tremor adds a bump around 10 Hz
                    let tremor = 0.5 * (-((f - 10.0) / 2.0).powi(2)).exp();
                    (f, 1.0 / f + tremor, rng.gen::<f64>() * 2.0 * PI)
                })
                .collect();
            let power: f64 = parts.iter().map(|p| p.1 * p.1 / 2.0).sum();
            let scale = rms / power.sqrt().max(1e-12);
            for p in &mut parts {
                p.1 *= scale;
            }
            parts
        };
        let t_rms = shake.translation_rms * width;
        let r_rms = shake.rotation_rms_deg.to_radians();
        ShakePath {
            parts: [
                make(t_rms, &mut rng),
                make(t_rms, &mut rng),
                make(r_rms, &mut rng),
            ],
        }
    }

    fn at(&self, t: f64) -> Pose {
        let eval = |p: &[(f64, f64, f64)]| {
            p.iter()
                .map(|&(f, a, ph)| a * (2.0 * PI * f * t + ph).sin())
                .sum::<f64>()
        };
        Pose {
            dx: eval(&self.parts[0]),
            dy: eval(&self.parts[1]),
            roll: eval(&self.parts[2]),
        }
    }

    /// The largest displacement the path can reach, pixels (bound, not RMS).
    fn reach(&self, width: f64, height: f64) -> f64 {
        let peak = |p: &[(f64, f64, f64)]| p.iter().map(|x| x.1.abs()).sum::<f64>();
        peak(&self.parts[0]).max(peak(&self.parts[1])) + peak(&self.parts[2]) * width.hypot(height)
    }
}

/// A rendered scene: the reflectance texture of the room, the lamps' light falloff and the
/// objects, ready to give any pixel's light coefficients at any time.
#[derive(Debug, Clone)]
pub struct Scene {
    width: usize,
    height: usize,
    margin: usize,
    /// Reflectance of the room, (width + 2·margin) × (height + 2·margin).
    texture: Vec<f32>,
    tex_w: usize,
    /// Each lamp's light at each pixel (falloff from its position), scaled by its share.
    lamp_weight: Vec<Vec<f32>>,
    /// Daylight at a white surface.
    daylight: f32,
    config: SceneConfig,
    shake: Option<ShakePath>,
    /// The walker's clothes: stripes over noise, CLOTH × CLOTH over its body (and head).
    cloth: Vec<f32>,
}

/// Side of the walker's clothes texture.
const CLOTH: usize = 96;

impl Scene {
    /// Builds the scene for a `width` × `height` sensor: `shares` are the lamps' shares,
    /// `ambient` the daylight share of the light, `illumination` the overall light level.
    pub fn new(
        config: &SceneConfig,
        width: usize,
        height: usize,
        shares: &[f64],
        ambient: f64,
        illumination: f64,
        seed: u64,
    ) -> Self {
        let shake = config
            .shake
            .as_ref()
            .map(|s| ShakePath::new(s, width as f64, seed));
        let margin = shake
            .as_ref()
            .map(|s| s.reach(width as f64, height as f64).ceil() as usize + 2)
            .unwrap_or(1);
        let (tw, th) = (width + 2 * margin, height + 2 * margin);
        let scale = width.max(height) as f64;
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed ^ 0x7e47);
        // posters and furniture: flat rectangles with hard edges
        let rects: Vec<(f64, f64, f64, f64, f64)> = (0..6)
            .map(|_| {
                let (x, y) = (rng.gen::<f64>(), rng.gen::<f64>());
                let (w, h) = (
                    0.08 + 0.25 * rng.gen::<f64>(),
                    0.08 + 0.3 * rng.gen::<f64>(),
                );
                (x, y, x + w, y + h, 0.08 + 0.85 * rng.gen::<f64>())
            })
            .collect();
        let mut texture = Vec::with_capacity(tw * th);
        for ty in 0..th {
            for tx in 0..tw {
                let (x, y) = (tx as f64 - margin as f64, ty as f64 - margin as f64);
                let (u, v) = (x / width as f64, y / height as f64);
                let mut r = 0.45 * value_noise(x, y, scale / 5.0, seed)
                    + 0.3 * value_noise(x, y, scale / 14.0, seed + 1)
                    + 0.15 * value_noise(x, y, scale / 40.0, seed + 2)
                    + 0.1 * value_noise(x, y, 2.5, seed + 3);
                for &(x0, y0, x1, y1, refl) in &rects {
                    if u >= x0 && u < x1 && v >= y0 && v < y1 {
                        r = 0.7 * refl + 0.3 * r;
                    }
                }
                texture.push((0.04 + 0.91 * r.clamp(0.0, 1.0)) as f32);
            }
        }
        // lamps: broad pools of light from different places, with a floor of bounce light
        let total_share: f64 = shares.iter().sum::<f64>().max(1e-12);
        let lamp_weight: Vec<Vec<f32>> = shares
            .iter()
            .enumerate()
            .map(|(k, &share)| {
                let cx = (k as f64 + 0.5) / shares.len() as f64 + 0.1 * (rng.gen::<f64>() - 0.5);
                let cy = 0.2 + 0.4 * rng.gen::<f64>();
                let raw: Vec<f64> = (0..width * height)
                    .map(|i| {
                        let (u, v) = (
                            (i % width) as f64 / width as f64,
                            (i / width) as f64 / height as f64,
                        );
                        0.3 + 0.7 * (-((u - cx).powi(2) + (v - cy).powi(2)) / 0.25).exp()
                    })
                    .collect();
                let mean = raw.iter().sum::<f64>() / raw.len() as f64;
                let gain = illumination * (1.0 - ambient) * share / total_share / mean;
                raw.iter().map(|w| (w * gain) as f32).collect()
            })
            .collect();
        Scene {
            width,
            height,
            margin,
            texture,
            tex_w: tw,
            lamp_weight,
            daylight: (illumination * ambient) as f32,
            config: config.clone(),
            shake,
            cloth: (0..CLOTH * CLOTH)
                .map(|i| {
                    // body coordinates: x across the width, y from the head down, both 0..1
                    let (x, y) = (
                        (i % CLOTH) as f64 / CLOTH as f64,
                        (i / CLOTH) as f64 / CLOTH as f64,
                    );
                    let stripes = 0.5 + 0.5 * (2.0 * PI * (y * 9.0 * 1.6 + x * 0.4)).sin();
                    let noise = value_noise(x * 40.0, y * 90.0, 6.0, seed + 9);
                    (0.1 + 0.5 * stripes * (0.5 + 0.5 * noise)) as f32
                })
                .collect(),
        }
    }

    /// The walker's clothes at body coordinates (fractions of its width and height from its
    /// centre), nearest texel.
    fn cloth(&self, x: f64, y: f64) -> f32 {
        let tx = (((x + 0.5) * CLOTH as f64) as isize).clamp(0, CLOTH as isize - 1) as usize;
        let ty = (((y + 0.8) / 1.4 * CLOTH as f64) as isize).clamp(0, CLOTH as isize - 1) as usize;
        self.cloth[ty * CLOTH + tx]
    }

    /// Width and height, pixels.
    pub fn dims(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// True when the coefficients never change.
    pub fn is_static(&self) -> bool {
        self.config.is_static()
    }

    /// Room reflectance at view position (x, y) in pixels (bilinear).
    fn room(&self, x: f64, y: f64) -> f64 {
        let m = self.margin as f64;
        let max_x = (self.tex_w - 2) as f64;
        let max_y = (self.texture.len() / self.tex_w - 2) as f64;
        let (fx, fy) = ((x + m).clamp(0.0, max_x), (y + m).clamp(0.0, max_y));
        let (ix, iy) = (fx as usize, fy as usize);
        let (ax, ay) = ((fx - ix as f64) as f32, (fy - iy as f64) as f32);
        let i = iy * self.tex_w + ix;
        let t = &self.texture;
        let top = t[i] + (t[i + 1] - t[i]) * ax;
        let bottom = t[i + self.tex_w] + (t[i + self.tex_w + 1] - t[i + self.tex_w]) * ax;
        (top + (bottom - top) * ay) as f64
    }

    /// Where the walker is at `t`: body centre x (fraction) and bob (fraction).
    fn walker_pos(speed: f64, width: f64, phase_s: f64, gait: f64, t: f64) -> (f64, f64) {
        // an irregular pace: time warped by slow, incommensurate swings (a pure function
        // of t, so the motion interpolation can ask for any instant)
        let swing = |f: f64, phase: f64| (2.0 * PI * f * t + phase).sin() / (2.0 * PI * f);
        let walk_t = t + gait * (swing(0.11, 0.0) + 0.6 * swing(0.23, 1.3));
        let step_t = t + gait * swing(0.17, 0.4);
        // to and fro across the view, entering from outside it
        let span = 1.0 + 2.0 * width;
        let period = 2.0 * span / speed.max(1e-6);
        let s = ((walk_t + phase_s) / period).rem_euclid(1.0) * 2.0 * span;
        let x = if s < span { s } else { 2.0 * span - s } - width;
        (x, 0.015 * (2.0 * PI * 1.8 * step_t).sin())
    }

    /// Pixel boxes `(x0, y0, x1, y1)` (half-open) that the objects, their shadows and
    /// highlights may touch between `t0` and `t1`; the whole view when the camera shakes.
    pub fn moving_boxes(&self, t0: f64, t1: f64) -> Vec<(usize, usize, usize, usize)> {
        let (w, h) = (self.width as f64, self.height as f64);
        if self.shake.is_some() {
            return vec![(0, 0, self.width, self.height)];
        }
        let clip = |x0: f64, y0: f64, x1: f64, y1: f64| {
            let cx = |v: f64| ((v * w).max(0.0) as usize).min(self.width);
            let cy = |v: f64| ((v * h).max(0.0) as usize).min(self.height);
            (
                cx(x0),
                cy(y0),
                (cx(x1) + 2).min(self.width),
                (cy(y1) + 2).min(self.height),
            )
        };
        self.config
            .objects
            .iter()
            .map(|o| match *o {
                MovingObject::Walker {
                    speed,
                    width,
                    height,
                    y,
                    shadow_offset,
                    phase_s,
                    gait,
                    ..
                } => {
                    let (xa, _) = Self::walker_pos(speed, width, phase_s, gait, t0);
                    let (xb, _) = Self::walker_pos(speed, width, phase_s, gait, t1);
                    // a turn between t0 and t1 stays within the step's travel of both ends
                    let travel = speed * (1.0 + 1.6 * gait.abs()) * (t1 - t0);
                    let left = xa.min(xb) - width / 2.0 - travel - 0.01;
                    let right = xa.max(xb) + width / 2.0 + travel + shadow_offset.0.max(0.0) + 0.01;
                    let top = y - height / 2.0 - 0.7 * width * w / h - 0.03;
                    let bottom = y + height / 2.0 + shadow_offset.1.max(0.0) + 0.03;
                    clip(left, top, right, bottom)
                }
                MovingObject::Fan { centre, radius, .. } => {
                    let rx = radius * h / w;
                    clip(
                        centre.0 - rx - 0.01,
                        centre.1 - radius - 0.01,
                        centre.0 + rx + 0.01,
                        centre.1 + radius + 0.01,
                    )
                }
            })
            .filter(|b| b.0 < b.2 && b.1 < b.3)
            .collect()
    }

    /// Where the camera and the objects are at time `t`.
    pub fn frame(&self, t: f64) -> Frame {
        Frame {
            pose: self.shake.as_ref().map(|s| s.at(t)).unwrap_or_default(),
            objects: self
                .config
                .objects
                .iter()
                .map(|o| match *o {
                    MovingObject::Walker {
                        speed,
                        width,
                        phase_s,
                        gait,
                        ..
                    } => {
                        let (x, bob) = Self::walker_pos(speed, width, phase_s, gait, t);
                        (*o, x, bob)
                    }
                    MovingObject::Fan { rev_per_s, .. } => (*o, 2.0 * PI * rev_per_s * t, 0.0),
                })
                .collect(),
        }
    }

    /// The light coefficients of the `n` pixels from `first` (row-major) at time `t`, written
    /// from `at` on: `out[k][at + j]` for lamp k, `out[MAX_LAMPS][at + j]` for daylight.
    pub fn render(
        &self,
        t: f64,
        first: usize,
        n: usize,
        out: &mut [Vec<f32>; CHANNELS],
        at: usize,
    ) {
        self.render_frame(&self.frame(t), first, n, out, at)
    }

    /// [`Scene::render`] for a frame already placed (one frame serves many pixel runs).
    pub fn render_frame(
        &self,
        frame: &Frame,
        first: usize,
        n: usize,
        out: &mut [Vec<f32>; CHANNELS],
        at: usize,
    ) {
        let pose = frame.pose;
        let (w, h) = (self.width as f64, self.height as f64);
        let (cx, cy) = (w / 2.0, h / 2.0);
        let (sin_r, cos_r) = pose.roll.sin_cos();
        let objects = &frame.objects;
        // column and row followed step by step (a division per pixel costs more than the rest)
        let (mut col, mut row) = (first % self.width, first / self.width);
        for j in 0..n {
            let p = first + j;
            let (px, py) = (col as f64 + 0.5, row as f64 + 0.5);
            col += 1;
            if col == self.width {
                col = 0;
                row += 1;
            }
            // the world point this pixel sees
            let (x, y) = if self.shake.is_some() {
                let (rx, ry) = (px - cx, py - cy);
                (
                    cx + cos_r * rx - sin_r * ry + pose.dx,
                    cy + sin_r * rx + cos_r * ry + pose.dy,
                )
            } else {
                (px, py)
            };
            let (u, v) = (x / w, y / h);
            let mut refl = self.room(x - 0.5, y - 0.5);
            let mut lamp_refl = refl; // what the lamps light (shadows fall here)
            let mut specular = 0.0;
            let mut covered = false;
            for &(o, a, b) in objects {
                match o {
                    MovingObject::Walker {
                        width,
                        height,
                        y: yc,
                        shadow,
                        shadow_offset,
                        specular: spec,
                        ..
                    } => {
                        let inside = |u: f64, v: f64| {
                            // body and head lie within half a width of the centre line
                            if (u - a).abs() >= width / 2.0 {
                                return false;
                            }
                            let yc = yc + b;
                            let body = (u - a).abs() < width / 2.0 && (v - yc).abs() < height / 2.0;
                            let head_r = 0.35 * width;
                            let head_v = yc - height / 2.0 - head_r * w / h;
                            let head = ((u - a) * w).hypot((v - head_v) * h) < head_r * w;
                            body || head
                        };
                        if !covered && inside(u, v) {
                            covered = true;
                            // clothes: stripes over a texture carried with the body
                            let (ou, ov) = (u - a, v - (yc + b));
                            refl = self.cloth(ou / width, ov / height) as f64;
                            lamp_refl = refl;
                            let (su, sv) = (a + 0.2 * width, yc + b - 0.3 * height);
                            let d2 = ((u - su) * w).powi(2) + ((v - sv) * h).powi(2);
                            let sigma = 0.08 * width * w;
                            if d2 < 16.0 * sigma * sigma {
                                specular = spec * (-d2 / (2.0 * sigma * sigma)).exp();
                            }
                        } else if !covered && inside(u - shadow_offset.0, v - shadow_offset.1) {
                            lamp_refl *= shadow;
                        }
                    }
                    MovingObject::Fan {
                        centre,
                        radius,
                        blades,
                        ..
                    } => {
                        let (dx, dy) = ((u - centre.0) * w, (v - centre.1) * h);
                        let r_px = radius * h;
                        if covered || dx.abs() >= r_px || dy.abs() >= r_px {
                            continue;
                        }
                        let rho = dx.hypot(dy) / r_px;
                        if rho < 1.0 {
                            if rho < 0.18 {
                                covered = true;
                                refl = 0.15;
                                lamp_refl = refl;
                            } else {
                                let angle = dy.atan2(dx) - a;
                                let blade = (blades as f64 * angle / (2.0 * PI)).rem_euclid(1.0);
                                if blade < 0.35 {
                                    covered = true;
                                    refl = 0.85 - 0.3 * rho;
                                    lamp_refl = refl;
                                }
                            }
                        }
                    }
                }
            }
            let in_rect =
                |r: &Region| u >= r.rect.0 && u < r.rect.2 && v >= r.rect.1 && v < r.rect.3;
            let mut day = self.daylight as f64 * refl;
            if let Some(win) = &self.config.window {
                if !covered && in_rect(win) {
                    day = self.daylight.max(0.05) as f64 * win.gain * 0.9;
                    lamp_refl *= 0.2;
                }
            }
            let mut bulb = 1.0;
            if let Some(b) = &self.config.bulb {
                if !covered && in_rect(b) {
                    bulb = b.gain;
                }
            }
            for (k, weights) in self.lamp_weight.iter().enumerate() {
                let gain = if k == 0 { bulb } else { 1.0 };
                out[k][at + j] = (weights[p] as f64 * (lamp_refl + specular) * gain) as f32;
            }
            for c in out.iter_mut().take(MAX_LAMPS).skip(self.lamp_weight.len()) {
                c[at + j] = 0.0;
            }
            out[MAX_LAMPS][at + j] = day as f32;
        }
    }
}
