//! Tests of eenf-dsp's `edits/null` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_dsp::edits::null::*;

#[test]
fn the_normal_tail_matches_scipy_and_its_asymptote() {
    // scipy.stats.norm.logcdf
    assert!((ln_normal_cdf(0.0) - 0.5f64.ln()).abs() < 1e-12);
    assert!((ln_normal_cdf(-5.0) - (-15.064998393988725)).abs() < 1e-9);
    assert!((ln_normal_cdf(-29.99) - (-454.02096)).abs() < 1e-3);
    assert!((ln_normal_cdf(-30.01) - (-454.62163)).abs() < 1e-3);
}

#[test]
fn with_no_noise_the_stray_rate_is_the_measured_tail() {
    let m = NullModel::new(3, 2.0, None);
    let x = 3.0f64.to_radians();
    let want = 3.7e3 * (-3.0f64 / 0.262).exp();
    assert!((m.stray_rate(x, 0.0) / want - 1.0).abs() < 1e-9);
    // a little noise raises it, a great deal of noise leaves the field to decide
    assert!(m.stray_rate(x, 1e-6) > want);
    let noisy = m.stray_rate(0.5, 0.01);
    assert!(noisy < m.noise_rate(0.25 / 0.01), "{noisy}");
}

#[test]
fn the_smallest_jump_grows_with_the_noise_and_the_side() {
    let clean = NullModel::new(3, 2.0, None)
        .min_jump(1e8, 0.05)
        .to_degrees();
    // the stray alone at 2 s: its tail b·ln(A/rate) beyond its bulk
    let want = 0.262 * (3.7e3f64 / 0.05).ln();
    assert!(
        clean >= want - 0.05 && clean < want + 0.5,
        "{clean} vs {want}"
    );
    let noisy = NullModel::new(3, 2.0, None).min_jump(100.0, 0.05);
    assert!(noisy > 0.3, "{noisy}");
    let long = NullModel::new(3, 10.0, None)
        .min_jump(1e8, 0.05)
        .to_degrees();
    assert!(long > 3.0 * clean, "{long}");
    // a recording whose own stray is twice the calibration's
    let wide = NullModel::new(3, 2.0, Some(0.28))
        .min_jump(1e8, 0.05)
        .to_degrees();
    assert!((wide / clean - 2.0).abs() < 0.05, "{wide} vs {clean}");
    assert!(NullModel::new(3, 2.0, None)
        .min_jump(1e-3, 0.05)
        .is_infinite());
}
