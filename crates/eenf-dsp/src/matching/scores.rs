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
    q_norm: f64,
    q_mean: f64,
    q_abs_sq: f64,
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
            q_norm: q.iter().map(|v| v * v).sum::<f64>().sqrt(),
            q_mean,
            // Σ (q + q_mean)² for the RMSE
            q_abs_sq: q.iter().map(|v| (v + q_mean) * (v + q_mean)).sum::<f64>(),
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
        let (m, r) = (self.m, self.reference);
        let start = bi * self.hop;
        let count = self.hop.min(self.n_off - start);
        dst.clear();
        dst.resize(count, f32::NAN);
        // the block's values (NaN for gaps and past the end), then relative to the mean
        let have = (start + self.block).min(r.len()) - start;
        r.read(start, &mut b.raw[..have])?;
        b.raw[have..].fill(f64::NAN);
        for (d, &v) in b.seg.iter_mut().zip(&b.raw) {
            *d = v - self.r_mean;
        }
        // gaps count as zero in the FFT; their windows are redone below
        for (d, &v) in b.buf.iter_mut().zip(&b.seg) {
            *d = if v.is_finite() { v } else { 0.0 };
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
        let inv_m = 1.0 / m as f64;
        if b.seg[..count + m - 1].iter().all(|v| v.is_finite()) {
            // no gap under any window: the running sums first, then every key from them in a
            // loop without branches (the formulas of the loop below)
            let (sums, sq_sums) = (&mut b.s, &mut b.ss);
            let seg = &b.seg;
            // two halves slid side by side: two chains of additions in flight, not one
            let half = count.div_ceil(2);
            let start_sums = |k: usize| {
                let (mut s, mut ss) = (0.0f64, 0.0f64);
                for &v in &seg[k..k + m] {
                    s += v;
                    ss += v * v;
                }
                (s, ss)
            };
            let ((mut s0, mut ss0), (mut s1, mut ss1)) = (start_sums(0), start_sums(half));
            sums[0] = s0;
            sq_sums[0] = ss0;
            sums[half] = s1;
            sq_sums[half] = ss1;
            for k in 1..half {
                let (old, new) = (seg[k - 1], seg[k + m - 1]);
                s0 = s0 - old + new;
                ss0 = ss0 - old * old + new * new;
                sums[k] = s0;
                sq_sums[k] = ss0;
                let j = k + half;
                if j < count {
                    let (old, new) = (seg[j - 1], seg[j + m - 1]);
                    s1 = s1 - old + new;
                    ss1 = ss1 - old * old + new * new;
                    sums[j] = s1;
                    sq_sums[j] = ss1;
                }
            }
            let sums = WindowSums {
                xc: &b.buf[..count],
                s: &sums[..count],
                ss: &sq_sums[..count],
                q_norm: self.q_norm,
                q_abs_sq: self.q_abs_sq,
                q_mean: self.q_mean,
                inv_m,
            };
            sums.keys(self.score, dst);
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
            let (cc, e) = if gaps == 0 {
                let var = ss - s * s * inv_m;
                let cc = xc[k] / (self.q_norm * var.sqrt());
                // Σ(q − r)² = Σq² − 2Σq·r + Σr², with Σq·r = Σ(q − q̄)·r + q̄·Σr
                let sse = self.q_abs_sq - 2.0 * (xc[k] + self.q_mean * s) + ss;
                (cc, (sse.max(0.0) * inv_m).sqrt())
            } else if m - gaps >= self.min_valid {
                let a = score_at(&self.q_raw, &b.raw[k..k + m]);
                (a.cc, a.rmse_hz)
            } else {
                (f64::NAN, f64::NAN)
            };
            // a flat window (var = 0) gives a non-finite CC and no score
            *o = if cc.is_finite() && e.is_finite() {
                rank_key(self.score, cc, e) as f32
            } else {
                f32::NAN
            };
        }
        Ok(())
    }
}

/// A block's cross-correlations and running window sums, from which its keys follow.
struct WindowSums<'a> {
    xc: &'a [f64],
    s: &'a [f64],
    ss: &'a [f64],
    q_norm: f64,
    q_abs_sq: f64,
    q_mean: f64,
    inv_m: f64,
}

impl WindowSums<'_> {
    /// The keys into `dst`: the operations of [`rank_key`] in a loop without branches, which
    /// the compiler vectorises (two offsets at a time in SSE2; each operation correctly
    /// rounded, so the same numbers as one at a time).
    fn keys(&self, score: Score, dst: &mut [f32]) {
        match score {
            Score::Combined => self.keys_of::<true>(dst),
            Score::Cc => self.keys_of::<false>(dst),
        }
    }

    #[inline(always)]
    fn keys_of<const COMBINED: bool>(&self, dst: &mut [f32]) {
        let (q_norm, q_abs_sq, q_mean, inv_m) =
            (self.q_norm, self.q_abs_sq, self.q_mean, self.inv_m);
        for (((o, &x), &s), &ss) in dst.iter_mut().zip(self.xc).zip(self.s).zip(self.ss) {
            let var = ss - s * s * inv_m;
            let cc = x / (q_norm * var.sqrt());
            // Σ(q − r)² = Σq² − 2Σq·r + Σr², with Σq·r = Σ(q − q̄)·r + q̄·Σr
            let sse = q_abs_sq - 2.0 * (x + q_mean * s) + ss;
            let e = (sse.max(0.0) * inv_m).sqrt();
            // as rank_key
            let c = cc.clamp(-0.999_999, 0.999_999);
            let key = if COMBINED {
                let e = e.max(1e-6);
                (1.0 + c) / ((1.0 - c) * e * e)
            } else {
                c
            };
            // a flat window (var = 0) gives a non-finite CC and no score
            *o = if cc.is_finite() && e.is_finite() {
                key as f32
            } else {
                f32::NAN
            };
        }
    }
}
