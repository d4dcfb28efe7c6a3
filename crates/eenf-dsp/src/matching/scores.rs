//! The score of a trace against every offset of a reference, one overlap-save FFT block at a
//! time: a block's keys depend on that block alone, so any block can be scored again later and
//! gives the very same numbers (what lets the search keep maxima rather than every key).

use std::sync::Arc;

use realfft::num_complex::Complex64;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};

use super::{rank_key, score_at, MatchError, ReferenceValues, Score};

/// The trace prepared for scoring against one reference: its spectrum, norms and the block
/// layout. Offsets `b·hop … b·hop + hop − 1` are block `b`'s.
pub(crate) struct Scorer<'a, R: ?Sized> {
    reference: &'a R,
    m: usize,
    /// Offsets scored: `reference.len() − m + 1`.
    pub n_off: usize,
    block: usize,
    /// Offsets per block.
    pub hop: usize,
    fwd: Arc<dyn RealToComplex<f64>>,
    inv: Arc<dyn ComplexToReal<f64>>,
    qspec: Vec<Complex64>,
    formula: KeyFormula,
    q_raw: Vec<f64>,
    r_mean: f64,
    min_valid: usize,
    score: Score,
}

/// One worker's buffers for [`Scorer::block_keys`].
pub(crate) struct Buffers {
    seg: Vec<f64>,
    raw: Vec<f64>,
    buf: Vec<f64>,
    spec: Vec<Complex64>,
    s1: Vec<Complex64>,
    s2: Vec<Complex64>,
    /// Running window sums of r and r², per offset.
    s: Vec<f64>,
    ss: Vec<f64>,
}

impl<'a, R: ReferenceValues + ?Sized> Scorer<'a, R> {
    /// `q`: the trace, no gaps, zero mean; `q_mean`: its mean relative to `r_mean`, the
    /// reference's own mean (subtracted on the fly to keep the running sums well conditioned).
    /// Windows with fewer than `min_valid` reference values have no score.
    pub fn new(
        q: &[f64],
        q_mean: f64,
        reference: &'a R,
        r_mean: f64,
        min_valid: usize,
        score: Score,
    ) -> Self {
        let m = q.len();
        let block = (4 * m).next_power_of_two().max(1 << 15);
        let mut planner = RealFftPlanner::<f64>::new();
        let fwd = planner.plan_fft_forward(block);
        let inv = planner.plan_fft_inverse(block);
        let mut qbuf = vec![0.0; block];
        qbuf[..m].copy_from_slice(q);
        let mut qspec = fwd.make_output_vec();
        fwd.process(&mut qbuf, &mut qspec).expect("sized by plan");
        let qspec = qspec.iter().map(|c| c.conj() / block as f64).collect();
        Scorer {
            reference,
            m,
            n_off: reference.len() - m + 1,
            block,
            hop: block - m + 1,
            fwd,
            inv,
            qspec,
            formula: KeyFormula {
                q_norm: q.iter().map(|v| v * v).sum::<f64>().sqrt(),
                // Σ (q + q_mean)² for the RMSE
                q_abs_sq: q.iter().map(|v| (v + q_mean) * (v + q_mean)).sum::<f64>(),
                q_mean,
                inv_m: 1.0 / m as f64,
            },
            // the trace in the reference's own units, for windows with gaps
            q_raw: q.iter().map(|v| v + q_mean + r_mean).collect(),
            r_mean,
            min_valid,
            score,
        }
    }

    /// Number of blocks.
    pub fn blocks(&self) -> usize {
        self.n_off.div_ceil(self.hop)
    }

    /// Fresh buffers for one worker.
    pub fn buffers(&self) -> Buffers {
        Buffers {
            seg: vec![f64::NAN; self.block],
            raw: vec![f64::NAN; self.block],
            buf: self.fwd.make_input_vec(),
            spec: self.fwd.make_output_vec(),
            s1: self.fwd.make_scratch_vec(),
            s2: self.inv.make_scratch_vec(),
            s: vec![0.0; self.hop],
            ss: vec![0.0; self.hop],
        }
    }

    /// The keys of block `bi` into `dst` (cleared first): NaN where an offset has no score.
    pub fn block_keys(
        &self,
        bi: usize,
        b: &mut Buffers,
        dst: &mut Vec<f32>,
    ) -> Result<(), MatchError> {
        crate::simd::fast(
            #[inline(always)]
            || self.block_keys_inline(bi, b, dst),
        )
    }

    /// [`Self::block_keys`], inlined into its builds for each processor.
    #[inline(always)]
    fn block_keys_inline(
        &self,
        bi: usize,
        b: &mut Buffers,
        dst: &mut Vec<f32>,
    ) -> Result<(), MatchError> {
        let (m, r) = (self.m, self.reference);
        let start = bi * self.hop;
        let count = self.hop.min(self.n_off - start);
        dst.clear();
        dst.resize(count, f32::NAN);
        // the block's values (NaN for gaps and past the end), then relative to the mean
        let have = (start + self.block).min(r.len()) - start;
        // its own values: its offsets' first ones, and the last block's to the end
        let own = if bi + 1 == self.blocks() {
            have
        } else {
            self.hop
        };
        r.read_in_pass(start, &mut b.raw[..have], own)?;
        b.raw[have..].fill(f64::NAN);
        // gaps count as zero in the FFT; their windows are redone below
        let mut finite = true;
        for ((d, z), &v) in b.seg.iter_mut().zip(b.buf.iter_mut()).zip(&b.raw) {
            let x = v - self.r_mean;
            *d = x;
            *z = if x.is_finite() { x } else { 0.0 };
            finite &= x.is_finite();
        }
        self.fwd
            .process_with_scratch(&mut b.buf, &mut b.spec, &mut b.s1)
            .expect("sized by plan");
        for (a, q) in b.spec.iter_mut().zip(&self.qspec) {
            *a *= q;
        }
        self.inv
            .process_with_scratch(&mut b.spec, &mut b.buf, &mut b.s2)
            .expect("sized by plan");
        let count = dst.len();
        let formula = &self.formula;
        if finite || b.seg[..count + m - 1].iter().all(|v| v.is_finite()) {
            // no gap under any window: the running sums first, then every key from them in a
            // loop without branches (the formula of the loop below)
            let seg = &b.seg;
            let (sums, sq_sums) = (&mut b.s[..count], &mut b.ss[..count]);
            // what each window gains over the one before (the value entering it less the one
            // leaving it), for every offset at once in a loop the compiler vectorises
            for (((d, dd), &old), &new) in sums[1..]
                .iter_mut()
                .zip(&mut sq_sums[1..])
                .zip(&seg[..count - 1])
                .zip(&seg[m..m + count - 1])
            {
                *d = new - old;
                *dd = new * new - old * old;
            }
            // then the sums: four stretches, each from its first window's sum in full
            let len = count.div_ceil(4);
            let mut lanes: [&mut [f64]; 4] = Default::default();
            let mut sq_lanes: [&mut [f64]; 4] = Default::default();
            let stretches = sums.chunks_mut(len).zip(sq_sums.chunks_mut(len));
            for (l, (s, ss)) in stretches.enumerate() {
                (lanes[l], sq_lanes[l]) = (s, ss);
            }
            let firsts = window_sums(seg, m, len, lanes.iter().filter(|l| !l.is_empty()).count());
            for (l, (a, aa)) in firsts.into_iter().enumerate() {
                if let (Some(s), Some(ss)) = (lanes[l].first_mut(), sq_lanes[l].first_mut()) {
                    (*s, *ss) = (a, aa);
                }
            }
            accumulate(lanes);
            accumulate(sq_lanes);
            formula.keys(self.score, &b.buf[..count], sums, sq_sums, dst);
            return Ok(());
        }
        let (seg, xc) = (&b.seg, &b.buf);
        // running window sums of r, r² and the gap count
        let (mut s, mut ss, mut gaps) = (0.0f64, 0.0f64, 0usize);
        for &v in &seg[..m] {
            if v.is_finite() {
                s += v;
                ss += v * v;
            } else {
                gaps += 1;
            }
        }
        for (k, o) in dst.iter_mut().enumerate() {
            if k > 0 {
                let (old, new) = (seg[k - 1], seg[k + m - 1]);
                if old.is_finite() {
                    s -= old;
                    ss -= old * old;
                } else {
                    gaps -= 1;
                }
                if new.is_finite() {
                    s += new;
                    ss += new * new;
                } else {
                    gaps += 1;
                }
            }
            *o = if gaps == 0 {
                formula.key(self.score, xc[k], s, ss)
            } else if m - gaps >= self.min_valid {
                let a = score_at(&self.q_raw, &b.raw[k..k + m]);
                // a flat window (var = 0) gives a non-finite CC and no score
                if a.cc.is_finite() && a.rmse_hz.is_finite() {
                    rank_key(self.score, a.cc, a.rmse_hz) as f32
                } else {
                    f32::NAN
                }
            } else {
                f32::NAN
            };
        }
        Ok(())
    }
}

/// Σv and Σv² over the windows of `m` values starting at 0, `len`, 2·`len` and 3·`len` of
/// `seg` (the first `lanes` of them; the others 0), each summed in order, the four side by
/// side (eight chains of additions in flight, not two: an hour-long trace's windows are long).
#[inline(always)]
fn window_sums(seg: &[f64], m: usize, len: usize, lanes: usize) -> [(f64, f64); 4] {
    let mut out = [(0.0, 0.0); 4];
    if lanes == 4 {
        let [a, b, c, d] = [0, 1, 2, 3].map(|l| &seg[l * len..l * len + m]);
        for (((&va, &vb), &vc), &vd) in a.iter().zip(b).zip(c).zip(d) {
            for (o, v) in out.iter_mut().zip([va, vb, vc, vd]) {
                o.0 += v;
                o.1 += v * v;
            }
        }
        return out;
    }
    for (l, o) in out.iter_mut().enumerate().take(lanes) {
        for &v in &seg[l * len..l * len + m] {
            o.0 += v;
            o.1 += v * v;
        }
    }
    out
}

/// Turns each of four stretches of gains into running sums from its first value, the four
/// slid side by side: four chains of additions in flight, not one.
#[inline(always)]
fn accumulate(lanes: [&mut [f64]; 4]) {
    let full = lanes.iter().map(|l| l.len()).min().unwrap_or(0);
    let [a, b, c, d] = lanes;
    if full > 1 {
        let (mut sa, mut sb, mut sc, mut sd) = (a[0], b[0], c[0], d[0]);
        let (a1, b1, c1, d1) = (
            &mut a[1..full],
            &mut b[1..full],
            &mut c[1..full],
            &mut d[1..full],
        );
        for (((xa, xb), xc), xd) in a1.iter_mut().zip(b1).zip(c1).zip(d1) {
            sa += *xa;
            sb += *xb;
            sc += *xc;
            sd += *xd;
            (*xa, *xb, *xc, *xd) = (sa, sb, sc, sd);
        }
    }
    // the longer stretches' ends
    for l in [a, b, c, d] {
        for k in full.max(1)..l.len() {
            l[k] += l[k - 1];
        }
    }
}

/// The key of a window without gaps from its cross-correlation `x` with the trace and its
/// sums `s` = Σr, `ss` = Σr²: [`rank_key`]'s value, in one square root and one division.
struct KeyFormula {
    q_norm: f64,
    q_abs_sq: f64,
    q_mean: f64,
    inv_m: f64,
}

impl KeyFormula {
    /// The key for `score`.
    fn key(&self, score: Score, x: f64, s: f64, ss: f64) -> f32 {
        match score {
            Score::Combined => self.key_of::<true>(x, s, ss),
            Score::Cc => self.key_of::<false>(x, s, ss),
        }
    }

    #[inline(always)]
    fn key_of<const COMBINED: bool>(&self, x: f64, s: f64, ss: f64) -> f32 {
        // CC = x / d, d = |q|·|r − r̄|; clamped to ±0.999999 as rank_key does, by clamping x
        let d = self.q_norm * (ss - s * s * self.inv_m).sqrt();
        // (max and min, not clamp: d may be NaN, and then there is no score)
        let x_c = x.max(-0.999_999 * d).min(0.999_999 * d);
        let key = if COMBINED {
            // Σ(q − r)² = Σq² − 2Σq·r + Σr², with Σq·r = Σ(q − q̄)·r + q̄·Σr; RMSE ≥ 1e-6
            let sse = self.q_abs_sq - 2.0 * (x + self.q_mean * s) + ss;
            let e2 = (sse * self.inv_m).max(1e-12);
            // (1 + CC) / ((1 − CC)·RMSE²)
            (d + x_c) / ((d - x_c) * e2)
        } else {
            x_c / d
        };
        // a flat window (d = 0) or a NaN has no score
        if d > 0.0 && key.is_finite() {
            key as f32
        } else {
            f32::NAN
        }
    }

    /// The keys of a block without gaps into `dst`, in a loop without branches that the
    /// compiler vectorises (each operation correctly rounded: the numbers of [`Self::key`]).
    #[inline(always)]
    fn keys(&self, score: Score, xc: &[f64], s: &[f64], ss: &[f64], dst: &mut [f32]) {
        match score {
            Score::Combined => self.keys_of::<true>(xc, s, ss, dst),
            Score::Cc => self.keys_of::<false>(xc, s, ss, dst),
        }
    }

    #[inline(always)]
    fn keys_of<const COMBINED: bool>(&self, xc: &[f64], s: &[f64], ss: &[f64], dst: &mut [f32]) {
        for (((o, &x), &s), &ss) in dst.iter_mut().zip(xc).zip(s).zip(ss) {
            *o = self.key_of::<COMBINED>(x, s, ss);
        }
    }
}
