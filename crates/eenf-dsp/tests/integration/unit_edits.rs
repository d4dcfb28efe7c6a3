//! Tests of eenf-dsp's `edits` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_dsp::edits::*;

/// Hum whose ENF wanders slowly, at lines 1–3, in white noise; `cut` removes a stretch.
fn hum(seconds: f64, fs: f64, noise: f64, cut: Option<(f64, f64)>, seed: u64) -> Vec<f64> {
    let mut rnd = crate::test_noise(seed);
    let n = (seconds * fs) as usize;
    let mut phase = 0.0;
    let mut out = Vec::with_capacity(n);
    let mut t = 0.0;
    let (cut_at, cut_len) = cut.unwrap_or((f64::INFINITY, 0.0));
    let mut skipped = false;
    while out.len() < n {
        if !skipped && t >= cut_at {
            // advance the hum's phase through the removed stretch
            let steps = (cut_len * fs) as usize;
            for i in 0..steps {
                let tt = t + i as f64 / fs;
                phase += std::f64::consts::TAU * (50.0 + 0.02 * (tt / 37.0).sin()) / fs;
            }
            t += steps as f64 / fs;
            skipped = true;
        }
        let f = 50.0 + 0.02 * (t / 37.0).sin();
        phase += std::f64::consts::TAU * f / fs;
        out.push(
            0.01 * phase.cos()
                + 0.004 * (2.0 * phase + 0.3).cos()
                + 0.003 * (3.0 * phase + 1.1).cos()
                + noise * rnd(),
        );
        t += 1.0 / fs;
    }
    out
}

#[test]
fn a_cut_is_found_where_it_is_and_none_elsewhere() {
    let fs = 400.0;
    let p = EditParams::default();
    // 0.0137 s removed: a jump of 0.0137·50·360 ≈ 247° of the fundamental
    let x = hum(120.0, fs, 0.02, Some((61.3, 0.0137)), 3);
    let bb = baseband(&x, fs, 50.0, &[1, 2, 3]);
    let scan = scan_phase(&bb, &p).unwrap();
    assert_eq!(scan.jumps.len(), 1, "{:?}", scan.jumps);
    let at = scan.jumps[0].block as f64 * scan.block_s;
    assert!((at - 61.3).abs() <= 0.3, "found at {at}");
    let jump = scan.jumps[0].jump_rad.to_degrees();
    // whole samples are removed: 5 of them, 12.5 ms, 225° of 50 Hz
    let truth = wrap(((0.0137f64 * fs).floor() / fs * 50.0 * 360.0).to_radians()).to_degrees();
    assert!((jump - truth).abs() < 25.0, "jump {jump} vs {truth}");
    // the side is never shorter than the shortest gap asked for
    let wide = EditParams {
        min_gap_s: 5.0,
        ..EditParams::default()
    };
    let side = scan_phase(&bb, &wide).unwrap().side_s;
    assert!(side >= 5.0 - 1e-9, "side {side}");
    let clean = hum(120.0, fs, 0.02, None, 4);
    let scan = scan_phase(&baseband(&clean, fs, 50.0, &[1, 2, 3]), &p).unwrap();
    assert!(scan.jumps.is_empty(), "{:?}", scan.jumps);
}

#[test]
fn the_coarse_enf_follows_the_hum() {
    let fs = 400.0;
    let x = hum(60.0, fs, 0.002, None, 5);
    let bb = baseband(&x, fs, 50.0, &[1, 2, 3]);
    let c = coarse_offsets(&bb);
    for (b, v) in c.iter().enumerate().skip(100).step_by(50).take(8) {
        let t = b as f64 * bb.block_s;
        let truth = 0.02 * (t / 37.0).sin();
        assert!((v - truth).abs() < 0.002, "at {t} s: {v} vs {truth}");
    }
}
