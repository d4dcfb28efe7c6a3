//! Butterworth band-pass design, following scipy.signal.butter(..., output="sos") step by step
//! (analog prototype → band-pass transform → bilinear transform → second-order sections with
//! scipy's "nearest" pairing), so coefficients agree with scipy to rounding.

use std::f64::consts::PI;

/// A complex number, kept local: the design needs only a handful of operations.
#[derive(Debug, Clone, Copy, PartialEq)]
struct C {
    re: f64,
    im: f64,
}

impl C {
    fn new(re: f64, im: f64) -> Self {
        C { re, im }
    }
    fn add(self, o: C) -> C {
        C::new(self.re + o.re, self.im + o.im)
    }
    fn sub(self, o: C) -> C {
        C::new(self.re - o.re, self.im - o.im)
    }
    fn mul(self, o: C) -> C {
        C::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
    fn div(self, o: C) -> C {
        let d = o.re * o.re + o.im * o.im;
        C::new(
            (self.re * o.re + self.im * o.im) / d,
            (self.im * o.re - self.re * o.im) / d,
        )
    }
    fn scale(self, s: f64) -> C {
        C::new(self.re * s, self.im * s)
    }
    fn abs(self) -> f64 {
        self.re.hypot(self.im)
    }
    fn sqrt(self) -> C {
        // principal square root, as numpy's
        let r = self.abs();
        let re = ((r + self.re) / 2.0).sqrt();
        let im = ((r - self.re) / 2.0).sqrt().copysign(self.im);
        C::new(re, im)
    }
}

/// One second-order section `[b0, b1, b2, a0, a1, a2]` (a0 = 1), as scipy's `sos` rows.
pub type Section = [f64; 6];

/// Second-order sections of a band-pass Butterworth filter of `order` (the band-pass has
/// 2·order poles) with edges `low`..`high` Hz at sampling rate `fs`.
///
/// Panics if the band is not inside (0, fs/2); callers check harmonics against Nyquist.
pub fn butter_bandpass(order: usize, low: f64, high: f64, fs: f64) -> Vec<Section> {
    assert!(
        0.0 < low && low < high && high < fs / 2.0,
        "band {low}..{high} Hz must lie inside (0, {} Hz)",
        fs / 2.0
    );
    // analog prototype (buttap)
    let n = order as i64;
    let proto: Vec<C> = (0..order as i64)
        .map(|i| {
            let m = (-n + 1 + 2 * i) as f64;
            let a = PI * m / (2.0 * n as f64);
            C::new(-a.cos(), -a.sin())
        })
        .collect();
    // pre-warp, with scipy's internal fs = 2
    let fs_int = 2.0;
    let warp = |f: f64| 2.0 * fs_int * (PI * (2.0 * f / fs) / fs_int).tan();
    let (w1, w2) = (warp(low), warp(high));
    let bw = w2 - w1;
    let wo = (w1 * w2).sqrt();
    // lp2bp_zpk
    let mut poles = Vec::with_capacity(2 * order);
    let wo2 = C::new(wo * wo, 0.0);
    let lp: Vec<C> = proto.iter().map(|p| p.scale(bw / 2.0)).collect();
    for p in &lp {
        poles.push(p.add(p.mul(*p).sub(wo2).sqrt()));
    }
    for p in &lp {
        poles.push(p.sub(p.mul(*p).sub(wo2).sqrt()));
    }
    let mut k = bw.powi(order as i32);
    // bilinear_zpk: zeros at s = 0 map to z = 1, the `order` zeros at infinity to z = -1
    let fs2 = C::new(2.0 * fs_int, 0.0);
    let mut num = C::new(1.0, 0.0);
    let mut den = C::new(1.0, 0.0);
    for _ in 0..order {
        num = num.mul(fs2); // (fs2 - 0)
    }
    for p in &poles {
        den = den.mul(fs2.sub(*p));
    }
    k *= num.div(den).re;
    let zpoles: Vec<C> = poles.iter().map(|p| fs2.add(*p).div(fs2.sub(*p))).collect();
    let mut zeros: Vec<f64> = std::iter::repeat_n(1.0, order)
        .chain(std::iter::repeat_n(-1.0, order))
        .collect();
    zpk2sos_nearest(&mut zeros, zpoles, k)
}

/// Second-order sections of a low-pass Butterworth filter of even `order` with cutoff `cutoff`
/// Hz (−3 dB) at sampling rate `fs`: scipy's `butter(order, cutoff, fs=fs, output="sos")`.
///
/// Panics if `order` is odd or zero, or the cutoff is not inside (0, fs/2).
pub fn butter_lowpass(order: usize, cutoff: f64, fs: f64) -> Vec<Section> {
    assert!(
        order > 0 && order.is_multiple_of(2),
        "order {order} must be even"
    );
    assert!(
        0.0 < cutoff && cutoff < fs / 2.0,
        "cutoff {cutoff} Hz must lie inside (0, {} Hz)",
        fs / 2.0
    );
    let n = order as i64;
    let fs_int = 2.0;
    let wc = 2.0 * fs_int * (PI * (2.0 * cutoff / fs) / fs_int).tan();
    // analog prototype (buttap), scaled to the warped cutoff (lp2lp_zpk)
    let poles: Vec<C> = (0..n)
        .map(|i| {
            let a = PI * (-n + 1 + 2 * i) as f64 / (2.0 * n as f64);
            C::new(-a.cos(), -a.sin()).scale(wc)
        })
        .collect();
    // bilinear_zpk: no finite zeros; the `order` zeros at infinity map to z = -1
    let fs2 = C::new(2.0 * fs_int, 0.0);
    let den = poles
        .iter()
        .fold(C::new(1.0, 0.0), |d, p| d.mul(fs2.sub(*p)));
    let k = wc.powi(order as i32) * C::new(1.0, 0.0).div(den).re;
    let zpoles: Vec<C> = poles.iter().map(|p| fs2.add(*p).div(fs2.sub(*p))).collect();
    let mut zeros = vec![-1.0; order];
    zpk2sos_nearest(&mut zeros, zpoles, k)
}

/// scipy's zpk2sos with pairing "nearest", for real zeros and complex-conjugate poles (the
/// band-pass case): sections are filled from the last, each taking the remaining pole closest to
/// the unit circle and the two real zeros nearest to it; the gain goes into the first section.
fn zpk2sos_nearest(zeros: &mut Vec<f64>, poles: Vec<C>, k: f64) -> Vec<Section> {
    // one of each conjugate pair (scipy's _cplxreal keeps the positive-imaginary one)
    let mut half: Vec<C> = poles.into_iter().filter(|p| p.im > 0.0).collect();
    let n_sections = half.len();
    let mut sos = vec![[0.0; 6]; n_sections];
    for si in (0..n_sections).rev() {
        let p1 = half.remove(first_min(half.iter().map(|p| (1.0 - p.abs()).abs())));
        let take_nearest = |zs: &mut Vec<f64>| {
            zs.remove(first_min(zs.iter().map(|z| C::new(*z, 0.0).sub(p1).abs())))
        };
        let z1 = take_nearest(zeros);
        let z2 = take_nearest(zeros);
        sos[si] = [
            1.0,
            -(z1 + z2),
            z1 * z2,
            1.0,
            -2.0 * p1.re,
            p1.re * p1.re + p1.im * p1.im,
        ];
    }
    for c in &mut sos[0][..3] {
        *c *= k;
    }
    sos
}

/// Index of the first smallest value (numpy's argmin, which scipy's pairing relies on).
fn first_min(values: impl Iterator<Item = f64>) -> usize {
    values
        .enumerate()
        .fold(
            (0, f64::INFINITY),
            |best, (i, v)| if v < best.1 { (i, v) } else { best },
        )
        .0
}

/// Multiplies sections into one transfer function `(b, a)`, for comparison with `filtfilt`.
pub fn sos_to_ba(sos: &[Section]) -> (Vec<f64>, Vec<f64>) {
    let conv = |acc: &[f64], s: &[f64]| {
        let mut out = vec![0.0; acc.len() + 2];
        for (i, a) in acc.iter().enumerate() {
            for (j, c) in s.iter().enumerate() {
                out[i + j] += a * c;
            }
        }
        out
    };
    let mut b = vec![1.0];
    let mut a = vec![1.0];
    for s in sos {
        b = conv(&b, &s[..3]);
        a = conv(&a, &s[3..]);
    }
    (b, a)
}
