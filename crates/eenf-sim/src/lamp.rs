//! Lamps on the mains: how each kind turns the voltage v(t) = cos φ(t) into light.
//!
//! Every lamp's output is normalised to a mean of 1, so a lamp's `share` alone says how much of
//! the scene's light it gives.

use std::f64::consts::PI;

use crate::mains::MainsPhase;

/// How a lamp responds to the mains.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum LampKind {
    /// A filament heated by the instantaneous power cos²φ: a thermal first-order low-pass with
    /// time constant `tau_ms`. 16 ms gives ~10 % modulation at 100 Hz (8 % at 120 Hz).
    Incandescent {
        /// Thermal time constant, ms.
        tau_ms: f64,
    },
    /// A tube on a magnetic ballast: the arc current lags the voltage by `lag_rad`, the arc goes
    /// out while |current| is below `dead` (re-ignition), and the phosphor glows on with time
    /// constant `phosphor_ms`. Deep modulation with strong 4f, 6f… harmonics.
    Fluorescent {
        /// Lag of the ballast current behind the voltage, rad.
        lag_rad: f64,
        /// Fraction of the peak below which the arc is out.
        dead: f64,
        /// Phosphor persistence, ms.
        phosphor_ms: f64,
    },
    /// An LED on a simple driver: a steady part plus a `depth` share that follows the rectified
    /// voltage |cos φ|^`sharpness` (1 = rectified sine; higher = narrower pulses, more
    /// harmonics), smoothed by the driver with time constant `smoothing_ms`.
    Led {
        /// Share of the light that follows the rectified voltage, 0..1.
        depth: f64,
        /// Exponent of the rectified voltage.
        sharpness: f64,
        /// Driver smoothing, ms.
        smoothing_ms: f64,
    },
    /// An ideal lamp whose light is 1 + depth·cos 2φ: a pure tone at 2f_e, for physics checks.
    Sinusoid {
        /// Modulation depth, 0..1.
        depth: f64,
    },
}

impl LampKind {
    /// The kind named `name` (`incandescent`, `fluorescent`, `led`, `sinusoid`) with its
    /// default parameters.
    pub fn named(name: &str) -> Option<Self> {
        Some(match name {
            "incandescent" => LampKind::Incandescent { tau_ms: 16.0 },
            "fluorescent" => LampKind::Fluorescent {
                lag_rad: 0.35,
                dead: 0.15,
                phosphor_ms: 1.0,
            },
            "led" => LampKind::Led {
                depth: 0.4,
                sharpness: 1.0,
                smoothing_ms: 0.3,
            },
            "sinusoid" => LampKind::Sinusoid { depth: 0.5 },
            _ => return None,
        })
    }

    /// The drive before smoothing at mains phase `phi` (not yet normalised).
    fn drive(&self, phi: f64) -> f64 {
        match *self {
            LampKind::Incandescent { .. } => phi.cos().powi(2),
            LampKind::Fluorescent { lag_rad, dead, .. } => {
                ((phi - lag_rad).cos().abs() - dead).max(0.0) / (1.0 - dead).max(1e-9)
            }
            LampKind::Led {
                depth, sharpness, ..
            } => (1.0 - depth) + depth * phi.cos().abs().powf(sharpness),
            LampKind::Sinusoid { depth } => 1.0 + depth * (2.0 * phi).cos(),
        }
    }

    /// Time constant of the lamp's smoothing, s (0 = none).
    fn tau_s(&self) -> f64 {
        match *self {
            LampKind::Incandescent { tau_ms } => tau_ms * 1e-3,
            LampKind::Fluorescent { phosphor_ms, .. } => phosphor_ms * 1e-3,
            LampKind::Led { smoothing_ms, .. } => smoothing_ms * 1e-3,
            LampKind::Sinusoid { .. } => 0.0,
        }
    }
}

/// A lamp in the scene.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Lamp {
    /// What kind of lamp.
    #[serde(flatten)]
    pub kind: LampKind,
    /// The supply phase it sits on, degrees (0, 120, 240 on a three-phase supply).
    pub phase_deg: f64,
    /// Its share of the flickering light (shares are relative to each other).
    pub share: f64,
}

impl Lamp {
    /// Parses `KIND[@PHASE_DEG][*SHARE]`, e.g. `led`, `fluorescent@120`, `incandescent*0.5`.
    pub fn parse(spec: &str) -> Option<Lamp> {
        let (rest, share) = match spec.split_once('*') {
            Some((r, s)) => (r, s.trim().parse().ok()?),
            None => (spec, 1.0),
        };
        let (name, phase_deg) = match rest.split_once('@') {
            Some((n, p)) => (n, p.trim().parse().ok()?),
            None => (rest, 0.0),
        };
        let kind = LampKind::named(name.trim())?;
        (share > 0.0 && f64::is_finite(share) && f64::is_finite(phase_deg)).then_some(Lamp {
            kind,
            phase_deg,
            share,
        })
    }
}

/// The lamps' light over time, advanced step by step with the mains phase. Each output has mean
/// 1 at the nominal frequency.
#[derive(Debug, Clone)]
pub struct LampBank {
    lamps: Vec<Lamp>,
    norm: Vec<f64>,
    state: Vec<f64>,
    t: f64,
}

/// Longest integration sub-step, s: fine enough for a 2 ms phosphor and 8f harmonics.
const SUB_STEP_S: f64 = 20e-6;

impl LampBank {
    /// The lamps at t = 0, their filters settled (run for half a second on the nominal phase).
    pub fn new(lamps: &[Lamp], mains: &MainsPhase) -> Self {
        let norm = lamps
            .iter()
            .map(|l| {
                // mean of the drive over one mains period
                let n = 4000;
                let mean = (0..n)
                    .map(|i| l.kind.drive(2.0 * PI * i as f64 / n as f64))
                    .sum::<f64>()
                    / n as f64;
                1.0 / mean.max(1e-12)
            })
            .collect::<Vec<_>>();
        let mut bank = LampBank {
            lamps: lamps.to_vec(),
            state: norm.clone(),
            norm,
            t: -0.5,
        };
        bank.advance_to(0.0, mains);
        bank
    }

    /// Number of lamps.
    pub fn len(&self) -> usize {
        self.lamps.len()
    }

    /// True when there are no lamps.
    pub fn is_empty(&self) -> bool {
        self.lamps.is_empty()
    }

    /// Advances every lamp to time `t` (s, ≥ the current time).
    pub fn advance_to(&mut self, t: f64, mains: &MainsPhase) {
        let span = t - self.t;
        if span <= 0.0 {
            return;
        }
        let steps = (span / SUB_STEP_S).ceil().max(1.0) as usize;
        let dt = span / steps as f64;
        for (k, lamp) in self.lamps.iter().enumerate() {
            let offset = lamp.phase_deg.to_radians();
            let tau = lamp.kind.tau_s();
            let a = if tau > 0.0 {
                1.0 - (-dt / tau).exp()
            } else {
                1.0
            };
            let mut y = self.state[k];
            for s in 1..=steps {
                let phi = mains.phase_at(self.t + s as f64 * dt) + offset;
                y += a * (self.norm[k] * lamp.kind.drive(phi) - y);
            }
            self.state[k] = y;
        }
        self.t = t;
    }

    /// Each lamp's light now.
    pub fn light(&self) -> &[f64] {
        &self.state
    }
}
