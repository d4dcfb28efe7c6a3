//! Zero-phase filtering with second-order sections, matching scipy.signal.sosfiltfilt:
//! odd extension of 3·(2·sections + 1) samples at each end, steady-state initial conditions
//! scaled by the first sample, forward then backward.

use crate::butter::Section;

/// Steady-state of one direct-form-II-transposed section for a unit step (scipy lfilter_zi).
fn section_zi(s: &Section) -> [f64; 2] {
    let (b0, b1, b2, a1, a2) = (s[0], s[1], s[2], s[4], s[5]);
    let bb0 = b1 - a1 * b0;
    let bb1 = b2 - a2 * b0;
    let z0 = (bb0 + bb1) / (1.0 + a1 + a2);
    [z0, bb1 - a2 * z0]
}

/// Initial states of all sections for a unit step input (scipy sosfilt_zi).
pub fn sosfilt_zi(sos: &[Section]) -> Vec<[f64; 2]> {
    let mut scale = 1.0;
    sos.iter()
        .map(|s| {
            let z = section_zi(s);
            let out = [z[0] * scale, z[1] * scale];
            scale *= (s[0] + s[1] + s[2]) / (s[3] + s[4] + s[5]);
            out
        })
        .collect()
}

/// Filters `x` in place through all sections, starting from states `zi` scaled by `x0`.
fn sosfilt_inplace(sos: &[Section], zi: &[[f64; 2]], x0: f64, x: &mut [f64]) {
    for (s, z) in sos.iter().zip(zi) {
        let (b0, b1, b2, a1, a2) = (s[0], s[1], s[2], s[4], s[5]);
        let (mut z0, mut z1) = (z[0] * x0, z[1] * x0);
        for v in x.iter_mut() {
            let xin = *v;
            let y = b0 * xin + z0;
            z0 = b1 * xin - a1 * y + z1;
            z1 = b2 * xin - a2 * y;
            *v = y;
        }
    }
}

/// Zero-phase (forward-backward) filtering of `x`; the output has the length of `x`.
pub fn sosfiltfilt(sos: &[Section], x: &[f64]) -> Vec<f64> {
    let n = x.len();
    if n == 0 {
        return Vec::new();
    }
    let zero_b2 = sos.iter().filter(|s| s[2] == 0.0).count();
    let zero_a2 = sos.iter().filter(|s| s[5] == 0.0).count();
    let ntaps = 2 * sos.len() + 1 - zero_b2.min(zero_a2);
    // scipy refuses inputs shorter than the padding; shorten it instead
    let pad = (3 * ntaps).min(n - 1);
    let mut ext = Vec::with_capacity(n + 2 * pad);
    ext.extend((1..=pad).rev().map(|i| 2.0 * x[0] - x[i]));
    ext.extend_from_slice(x);
    ext.extend((1..=pad).map(|i| 2.0 * x[n - 1] - x[n - 1 - i]));
    let zi = sosfilt_zi(sos);
    let x0 = ext[0];
    sosfilt_inplace(sos, &zi, x0, &mut ext);
    ext.reverse();
    let y0 = ext[0];
    sosfilt_inplace(sos, &zi, y0, &mut ext);
    ext.reverse();
    ext[pad..pad + n].to_vec()
}
