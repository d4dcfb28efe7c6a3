//! The fits behind each boundary's test: a line of phase per side (running sums, O(1) per
//! stretch) and the step between two sides that share one cubic of the phase.

use rustfft::num_complex::Complex64;

use super::wrap;

/// Running sums of one line's turned-back blocks, so that a line of phase is fitted over any
/// stretch in O(1) (for each side's ENF, and to place a step).
pub(super) struct Sums {
    /// Σ z, Σ n·z, Σ |z|² up to (not including) each block.
    z: Vec<Complex64>,
    nz: Vec<Complex64>,
    p: Vec<f64>,
}

impl Sums {
    pub(super) fn new(z: &[Complex64]) -> Self {
        let len = z.len() + 1;
        let mut s = Sums {
            z: Vec::with_capacity(len),
            nz: Vec::with_capacity(len),
            p: Vec::with_capacity(len),
        };
        let zero = Complex64::new(0.0, 0.0);
        let (mut a, mut b, mut c) = (zero, zero, 0.0);
        s.z.push(a);
        s.nz.push(b);
        s.p.push(c);
        for (i, v) in z.iter().enumerate() {
            a += v;
            b += v * i as f64;
            c += v.norm_sqr();
            s.z.push(a);
            s.nz.push(b);
            s.p.push(c);
        }
        s
    }

    /// A line of phase fitted to blocks `lo..hi` (complex amplitude at the centre, slope in
    /// radians per block, linearised: the turned-back phase moves little within a side), with
    /// the residual variance per block.
    pub(super) fn fit(&self, lo: usize, hi: usize) -> SideFit {
        let m = (hi - lo) as f64;
        let s0 = self.z[hi] - self.z[lo];
        let s1 = self.nz[hi] - self.nz[lo];
        let p = self.p[hi] - self.p[lo];
        let centre = (lo + hi - 1) as f64 / 2.0;
        let a = s0 / m;
        let s1c = s1 - s0 * centre;
        let ss = m * (m * m - 1.0) / 12.0;
        let amp2 = a.norm_sqr().max(1e-300);
        let slope = (s1c * a.conj()).im / (amp2 * ss);
        let residual = ((p - m * amp2 - amp2 * slope * slope * ss) / (m - 2.0)).max(1e-300);
        SideFit {
            amp: a,
            slope,
            noise: residual,
            len: m,
        }
    }
}

/// A line of phase fitted to one side of a boundary.
#[derive(Debug, Clone, Copy)]
pub(super) struct SideFit {
    pub(super) amp: Complex64,
    pub(super) slope: f64,
    pub(super) noise: f64,
    pub(super) len: f64,
}

impl SideFit {
    /// Variance of the slope, rad² per block².
    pub(super) fn slope_variance(&self) -> f64 {
        let m = self.len;
        let phase_var = self.noise / (2.0 * self.amp.norm_sqr().max(1e-300));
        12.0 * phase_var / (m * (m * m - 1.0))
    }
}

/// The phase step of one line's turned-back blocks at `tau`, fitted over `lo..tau` and
/// `tau..hi`: each side's mean phase (its complex mean: any step, up to ±180°, is measured
/// whole), and one cubic of the phase deviation shared by both sides, since the ENF is smooth
/// across a boundary that is not an edit. On real mains phase a shared cubic over ±10 s
/// misses by 0.8° (median) and 3.1° (99th percentile), where a line per side misses by 1.6°
/// and 7.7° and a parabola per side costs 27 % more noise. Returns the step (rad) and its
/// variance; each side's noise is measured from its own residuals.
pub(super) fn step_fit(z: &[Complex64], lo: usize, tau: usize, hi: usize) -> (f64, f64) {
    const P: usize = STEP_DEGREE;
    #[derive(Clone, Copy)]
    struct Side {
        m: f64,
        /// Σ u^j, j = 0..2P
        pu: [f64; 2 * P + 1],
        /// Σ u^j·w, j = 1..P
        pw: [f64; P],
        ww: f64,
    }
    let scale = ((hi - lo) as f64 / 2.0).max(1.0);
    let mean = |a: usize, b: usize| z[a..b].iter().sum::<Complex64>() / (b - a) as f64;
    let (al, ar) = (mean(lo, tau), mean(tau, hi));
    let side = |a: usize, b: usize, amp: Complex64| -> Side {
        let mut s = Side {
            m: (b - a) as f64,
            pu: [0.0; 2 * P + 1],
            pw: [0.0; P],
            ww: 0.0,
        };
        let amp2 = amp.norm_sqr().max(1e-300);
        for (n, v) in z[a..b].iter().enumerate() {
            let u = ((a + n) as f64 - tau as f64 + 0.5) / scale;
            let w = (v * amp.conj()).im / amp2;
            let mut p = 1.0;
            for j in 0..=2 * P {
                s.pu[j] += p;
                if (1..=P).contains(&j) {
                    s.pw[j - 1] += p * w;
                }
                p *= u;
            }
            s.ww += w * w;
        }
        s
    };
    let (sl, sr) = (side(lo, tau, al), side(tau, hi, ar));
    // each side's normal matrix of the demeaned powers u … u^P (w sums to zero per side)
    let normal = |s: &Side| -> [[f64; P]; P] {
        std::array::from_fn(|i| {
            std::array::from_fn(|j| s.pu[i + j + 2] - s.pu[i + 1] * s.pu[j + 1] / s.m)
        })
    };
    let (gl, gr) = (normal(&sl), normal(&sr));
    let solve = |vl: f64, vr: f64| -> ([f64; P], [[f64; P]; P]) {
        let g: [[f64; P]; P] =
            std::array::from_fn(|i| std::array::from_fn(|j| gl[i][j] / vl + gr[i][j] / vr));
        let b: [f64; P] = std::array::from_fn(|i| sl.pw[i] / vl + sr.pw[i] / vr);
        let inv = invert(&g);
        let p = std::array::from_fn(|i| (0..P).map(|j| inv[i][j] * b[j]).sum());
        (p, inv)
    };
    // the sides' phase noise: first from all their spread, then from what the fit leaves
    let spread = |s: &Side| (s.ww / (s.m - 1.0).max(1.0)).max(1e-300);
    let (mut vl, mut vr) = (spread(&sl), spread(&sr));
    let (mut p, mut inv) = solve(vl, vr);
    let dof = 1.0 + P as f64 / 2.0;
    for _ in 0..2 {
        let resid = |s: &Side, g: &[[f64; P]; P]| -> f64 {
            let pb: f64 = (0..P).map(|i| p[i] * s.pw[i]).sum();
            let pgp: f64 = (0..P)
                .map(|i| (0..P).map(|j| p[i] * g[i][j] * p[j]).sum::<f64>())
                .sum();
            ((s.ww - 2.0 * pb + pgp) / (s.m - dof).max(1.0)).max(1e-300)
        };
        vl = resid(&sl, &gl);
        vr = resid(&sr, &gr);
        (p, inv) = solve(vl, vr);
    }
    // the polynomial's part of the difference between the sides' mean phases
    let g: [f64; P] = std::array::from_fn(|j| sr.pu[j + 1] / sr.m - sl.pu[j + 1] / sl.m);
    let poly: f64 = (0..P).map(|j| p[j] * g[j]).sum();
    let step = wrap((ar * al.conj()).arg() - poly);
    let gig: f64 = (0..P)
        .map(|i| (0..P).map(|j| g[i] * inv[i][j] * g[j]).sum::<f64>())
        .sum();
    (step, vl / sl.m + vr / sr.m + gig.max(0.0))
}

/// The degree of the polynomial shared by both sides of a boundary.
const STEP_DEGREE: usize = 3;

/// The inverse of a small symmetric positive-definite matrix (Gauss–Jordan with partial
/// pivoting); a singular one gives zeros (no polynomial term: each side's mean alone).
fn invert<const N: usize>(a: &[[f64; N]; N]) -> [[f64; N]; N] {
    let mut m = *a;
    let mut inv: [[f64; N]; N] =
        std::array::from_fn(|i| std::array::from_fn(|j| (i == j) as u8 as f64));
    for c in 0..N {
        let piv = (c..N)
            .max_by(|&x, &y| m[x][c].abs().total_cmp(&m[y][c].abs()))
            .unwrap_or(c);
        if m[piv][c].is_nan() || m[piv][c].abs() <= 1e-300 {
            return [[0.0; N]; N];
        }
        m.swap(c, piv);
        inv.swap(c, piv);
        let d = m[c][c];
        for j in 0..N {
            m[c][j] /= d;
            inv[c][j] /= d;
        }
        for r in 0..N {
            if r != c {
                let f = m[r][c];
                if f != 0.0 {
                    for j in 0..N {
                        m[r][j] -= f * m[c][j];
                        inv[r][j] -= f * inv[c][j];
                    }
                }
            }
        }
    }
    inv
}
