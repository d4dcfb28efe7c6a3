//! Tests of eenf-dsp's `metrics` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_dsp::metrics::*;

#[test]
fn known_values() {
    let a = [1.0, 2.0, 3.0, 4.0];
    let b = [2.0, 4.0, 6.0, 8.0];
    let m = agreement(&a, &b).unwrap();
    assert!((m.cc - 1.0).abs() < 1e-12);
    assert!((m.mae_hz - 2.5).abs() < 1e-12);
    assert!((m.rmse_hz - 7.5f64.sqrt()).abs() < 1e-12);
    assert_eq!(m.max_err_hz, 4.0);
    let m = agreement(&a, &[4.0, 3.0, 2.0, f64::NAN]).unwrap();
    assert!((m.cc + 1.0).abs() < 1e-12);
    assert_eq!(m.n, 3);
    assert!(agreement(&[1.0], &[1.0]).is_none());
}
