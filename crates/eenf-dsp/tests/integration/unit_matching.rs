//! Tests of eenf-dsp's `matching` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_dsp::matching::*;

/// The ranking statistic from CC and RMSE, computed directly.
fn statistic(score: Score, cc: f64, rmse: f64) -> f64 {
    let z = cc.clamp(-0.999_999, 0.999_999).atanh();
    match score {
        Score::Cc => z,
        // 1 µHz floor: an exact copy does not make the score infinite
        Score::Combined => z - rmse.max(1e-6).ln(),
    }
}

/// A grid-like random walk with some fast wiggle, `n` values at 1 s.
fn enf(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed.wrapping_mul(0x9e3779b97f4a7c15) | 1;
    let mut g = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let (mut x, mut v) = (0.0, 0.0);
    (0..n)
        .map(|_| {
            v = 0.95 * v + 0.0006 * g();
            x = 0.999 * x + v;
            50.0 + x + 0.02 * g()
        })
        .collect()
}

#[test]
fn finds_a_noisy_clip_and_calls_it_significant() {
    let reference = enf(200_000, 1);
    let at = 123_457;
    let noise = enf(600, 9);
    let clip: Vec<f64> = reference[at..at + 600]
        .iter()
        .zip(&noise)
        .map(|(r, n)| r + 0.1 * (n - 50.0))
        .collect();
    let res = match_trace(&clip, &reference[..], &MatchOptions::default()).unwrap();
    let best = res.candidates[0];
    assert_eq!(best.offset.round() as usize, at, "{res:?}");
    assert!(best.agreement.cc > 0.9, "{best:?}");
    assert!(best.p_value < DEFAULT_ALPHA, "{best:?}");
    assert!(res.candidates[1].p_value > best.p_value);
}

#[test]
fn ffts_agree_with_direct_scores_including_gaps() {
    let mut reference = enf(70_000, 3);
    for v in &mut reference[30_000..30_050] {
        *v = f64::NAN;
    }
    let clip = reference[32_768 - 100..32_768 + 200].to_vec(); // straddles a block edge
    let filled = fill_gaps(&clip);
    let mean = filled.iter().sum::<f64>() / filled.len() as f64;
    let q: Vec<f64> = filled.iter().map(|v| v - mean).collect();
    let r_mean = 50.0;
    let cc = scores_all(&q, mean - r_mean, &reference[..], r_mean, 240, Score::Cc).unwrap();
    let comb = scores_all(
        &q,
        mean - r_mean,
        &reference[..],
        r_mean,
        240,
        Score::Combined,
    )
    .unwrap();
    for k in [0, 1, 29_990, 30_010, 32_468, 32_469, 32_668, 65_437, 69_700] {
        let a = score_offset(&filled, &reference[..], k).unwrap().unwrap();
        let (direct, direct_rmse) = (a.cc, a.rmse_hz);
        let gaps = reference[k..k + 300].iter().filter(|v| v.is_nan()).count();
        if 300 - gaps >= 240 {
            let want = statistic(Score::Cc, direct, direct_rmse);
            // keys are f32: a CC of 0.999999 (the exact copy) keeps six digits
            let got = key_to_statistic(Score::Cc, cc[k] as f64);
            assert!((got - want).abs() < 2e-2, "k {k}: {got} vs {want}");
            let want = statistic(Score::Combined, direct, direct_rmse);
            // at the exact copy the RMSE is ~1 µHz, where running sums and direct sums
            // differ in the last digits of the logarithm's argument
            let got = key_to_statistic(Score::Combined, comb[k] as f64);
            assert!((got - want).abs() < 2e-2, "k {k}: {got} vs {want}");
        }
    }
}

#[test]
fn a_short_flat_clip_is_not_significant() {
    let reference = enf(100_000, 5);
    // 20 s of nearly nothing: noise only
    let clip: Vec<f64> = enf(20, 77)
        .iter()
        .map(|v| 50.0 + (v - 50.0) * 0.01)
        .collect();
    let res = match_trace(&clip, &reference[..], &MatchOptions::default()).unwrap();
    assert!(res.candidates[0].p_value > 0.01, "{:?}", res.candidates[0]);
}

#[test]
fn gap_filling_and_tail_fit() {
    let f = fill_gaps(&[f64::NAN, 1.0, f64::NAN, 3.0, f64::NAN]);
    assert_eq!(f, vec![1.0, 1.0, 2.0, 3.0, 3.0]);
    // maxima 10, 9, 8, …: k = 3, u = 8, mean excess 1.5; a score at u is beaten by the
    // 3 blocks at or above it; one far above has a tiny p
    let t = TailFit::new((0..12).map(|i| 10.0 - i as f64).collect());
    assert_eq!((t.k, t.u, t.beta), (3, 8.0, 1.5));
    assert!((t.p_value(8.0) - (1.0 - (-3f64).exp())).abs() < 1e-12);
    assert!(t.p_value(8.0 + 1.5 * 15.0) < 1e-5);
}

#[test]
fn best_offsets_equal_a_plain_greedy_pick() {
    // rough keys with plateaus (ties), NaN holes and peaks near chunk borders
    let mut x = 1u64;
    let keys: Vec<f32> = (0..50_000)
        .map(|i| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            if i % 997 < 30 {
                f32::NAN
            } else {
                ((x >> 40) % 500) as f32 + if i % 4096 < 3 { 1000.0 } else { 0.0 }
            }
        })
        .collect();
    for (top, exclusion) in [(1, 60), (5, 60), (12, 5000), (7, 1)] {
        let mut plain: Vec<usize> = Vec::new();
        while plain.len() < top {
            let next = (0..keys.len())
                .filter(|&k| keys[k].is_finite())
                .filter(|&k| plain.iter().all(|p| p.abs_diff(k) >= exclusion))
                .max_by(|&a, &b| keys[a].total_cmp(&keys[b]).then(b.cmp(&a)));
            match next {
                Some(k) => plain.push(k),
                None => break,
            }
        }
        assert_eq!(
            best_offsets(&keys, top, exclusion),
            plain,
            "{top} {exclusion}"
        );
    }
    assert!(best_offsets(&[f32::NAN; 10], 3, 2).is_empty());
}

/// A reference read only through `read`, noting the longest stretch asked for.
struct Counted<'a> {
    values: &'a [f64],
    longest: std::sync::atomic::AtomicUsize,
}

impl ReferenceValues for Counted<'_> {
    fn len(&self) -> usize {
        self.values.len()
    }
    fn read(&self, start: usize, dst: &mut [f64]) -> Result<(), MatchError> {
        self.longest
            .fetch_max(dst.len(), std::sync::atomic::Ordering::Relaxed);
        dst.copy_from_slice(&self.values[start..start + dst.len()]);
        Ok(())
    }
}

#[test]
fn the_search_a_block_at_a_time_gives_the_exhaustive_answer() {
    let mut reference = enf(400_000, 11);
    for v in &mut reference[150_000..150_400] {
        *v = f64::NAN;
    }
    let (at, m) = (271_828, 600);
    let noise = enf(m, 4);
    let clip: Vec<f64> = reference[at..at + m]
        .iter()
        .zip(&noise)
        .map(|(r, n)| r + 0.2 * (n - 50.0))
        .collect();
    for score in [Score::Combined, Score::Cc] {
        let opts = MatchOptions {
            top: 6,
            score,
            verify: Some(100_000),
            ..MatchOptions::default()
        };
        let counted = Counted {
            values: &reference,
            longest: 0.into(),
        };
        let res = match_trace(&clip, &counted, &opts).unwrap();
        // never more than a block of the reference at once
        let longest = counted.longest.into_inner();
        assert!(longest <= 1 << 16, "{longest}");
        // every offset's key in memory, then the same picks, null and rank from them
        let filled = fill_gaps(&clip);
        let mean = filled.iter().sum::<f64>() / m as f64;
        let q: Vec<f64> = filled.iter().map(|v| v - mean).collect();
        let r_mean = reference[..].finite_mean().unwrap();
        let keys = scores_all(&q, mean - r_mean, &reference[..], r_mean, 480, score).unwrap();
        let picks = best_offsets(&keys, opts.top, opts.exclusion);
        let got: Vec<usize> = res
            .candidates
            .iter()
            .map(|c| c.offset.round() as usize)
            .collect();
        assert_eq!(got, picks, "{score:?}");
        assert_eq!(picks[0], at);
        let stat = |k: f32| key_to_statistic(score, k as f64);
        let bl = res.block_len;
        let maxima: Vec<f64> = keys
            .chunks(bl)
            .enumerate()
            .filter(|(i, _)| (i + 1) * bl + m <= at || i * bl > at + m)
            .filter_map(|(_, c)| {
                c.iter()
                    .copied()
                    .filter(|v| v.is_finite())
                    .max_by(f32::total_cmp)
            })
            .map(stat)
            .collect();
        assert_eq!(res.null_blocks, maxima.len());
        let tail = TailFit::new(maxima);
        for c in &res.candidates {
            let k = c.offset.round() as usize;
            assert_eq!(c.p_value, tail.p_value(stat(keys[k])), "{score:?} at {k}");
        }
        let v = res.verification.unwrap();
        let key = keys[100_000];
        let better = (0..keys.len())
            .filter(|&i| keys[i] > key && i.abs_diff(100_000) >= opts.exclusion)
            .count();
        assert_eq!((v.rank, v.p_value), (better + 1, tail.p_value(stat(key))));
        assert_eq!(res.offsets, keys.iter().filter(|v| v.is_finite()).count());
    }
}
