//! Tests of eenf-dsp's `sampling` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_core::EventBatch;
use eenf_dsp::sampling::*;

fn batch(ev: &[(i64, bool)]) -> EventBatch {
    let mut b = EventBatch::default();
    for &(t, p) in ev {
        b.push(t, 0, 0, p);
    }
    b
}

fn run(method: SamplingMethod, parts: &[&[(i64, bool)]]) -> Vec<i8> {
    let mut s = TemporalSampler::new(method, 1000);
    for p in parts {
        s.push(&batch(p)).unwrap();
    }
    s.finish()
        .unwrap()
        .values
        .iter()
        .map(|&v| v as i8)
        .collect()
}

// events: t=0 (+,+,-), t=400 (-), t=2500 (-,-), t=2600 (+), t=3000 (+)
const EV: &[(i64, bool)] = &[
    (0, true),
    (0, true),
    (0, false),
    (400, false),
    (2500, false),
    (2500, false),
    (2600, true),
    (3000, true),
];

#[test]
fn paper_takes_the_nearest_future_group() {
    // t_0=0 → group at 0 (+1); t_1=1000 → next group ≥1000 is 2500 (−1); t_2=2000 → 2500;
    // t_3=3000 → group at 3000 (+1)
    assert_eq!(run(SamplingMethod::Paper, &[EV]), vec![1, -1, -1, 1]);
}

#[test]
fn authors_takes_the_last_group_in_the_bin_and_repeats_when_empty() {
    // bin0 [0,1000): last group 400 (−1); bin1 empty → repeat −1; bin2: last group 2600 (+1);
    // bin3: 3000 (+1)
    assert_eq!(run(SamplingMethod::Authors, &[EV]), vec![-1, -1, 1, 1]);
}

#[test]
fn block_votes_over_the_bin() {
    // bin0: +1+1−1−1 = 0; bin1: empty 0; bin2: −1−1+1 = −1; bin3: +1
    assert_eq!(run(SamplingMethod::Block, &[EV]), vec![0, 0, -1, 1]);
}

#[test]
fn batch_boundaries_do_not_change_the_result() {
    for method in [
        SamplingMethod::Paper,
        SamplingMethod::Authors,
        SamplingMethod::Block,
        SamplingMethod::Sum,
    ] {
        let whole = run(method, &[EV]);
        for cut in 1..EV.len() {
            // cuts inside a group of equal timestamps too (cut = 1, 2, 5)
            assert_eq!(
                run(method, &[&EV[..cut], &EV[cut..]]),
                whole,
                "{method:?} cut {cut}"
            );
        }
        let singles: Vec<&[(i64, bool)]> = EV.chunks(1).collect();
        assert_eq!(run(method, &singles), whole, "{method:?} one by one");
    }
}

#[test]
fn a_wild_timestamp_is_an_error_not_an_allocation() {
    let mut s = TemporalSampler::new(SamplingMethod::Block, 1000);
    let e = s.push(&batch(&[(0, true), (i64::MAX / 2, true)]));
    assert!(e.is_err());
}

#[test]
fn sum_counts_every_event() {
    let ev = [(0, true), (0, true), (0, true), (500, false), (1500, true)];
    assert_eq!(run(SamplingMethod::Sum, &[&ev]), vec![2, 1]);
    // the vote of the same bins is only their sign
    assert_eq!(run(SamplingMethod::Block, &[&ev]), vec![1, 1]);
}

#[test]
fn auto_samples_scan_groups_as_the_paper_and_single_stamps_as_a_vote_over_the_bin() {
    let stream = |groups: usize, per: usize, step: i64| {
        let mut b = EventBatch::default();
        for g in 0..groups {
            for k in 0..per {
                b.push(g as i64 * step, 0, 0, (g + k) % 3 == 0);
            }
        }
        b
    };
    let pick = |b: &EventBatch| {
        let mut s = TemporalSampler::new(SamplingMethod::Auto, 1000);
        s.push(b).unwrap();
        let seq = s.finish().unwrap();
        assert!(seq.reason.is_some());
        seq.method
    };
    // a DVXplorer: hundreds of events per 200 µs scan
    assert_eq!(pick(&stream(500, 300, 200)), SamplingMethod::Paper);
    // a quiet DVXplorer: a couple of events per scan, still on the scan clock
    assert_eq!(pick(&stream(5000, 2, 200)), SamplingMethod::Paper);
    // a DVS128: events at random, ~80 µs apart on average
    let mut b = EventBatch::default();
    let (mut t, mut s) = (0i64, 0x9e37_79b9_7f4a_7c15u64);
    for k in 0..20_000 {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let u = ((s >> 11) as f64 + 1.0) / (1u64 << 53) as f64;
        t += (-80.0 * u.ln()).round() as i64;
        b.push(t, 0, 0, k % 2 == 0);
    }
    let g = Grouping::measure(&b.t);
    assert!((0.1..0.25).contains(&g.short_share), "{g:?}");
    assert_eq!(pick(&b), SamplingMethod::Block);
    // a busy Prophesee sensor: ten events in every µs
    assert_eq!(pick(&stream(20_000, 10, 1)), SamplingMethod::Block);
    // the paper's sampler on such a stream would vote with one timestamp's few events
    let g = Grouping::measure(&stream(20_000, 10, 1).t);
    assert!(!g.is_scanned() && (g.events_per_timestamp - 10.0).abs() < 1e-9);
}
