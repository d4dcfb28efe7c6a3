//! Tests of eenf-sim's `sensor/pixel` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_sim::fast_ln;

#[test]
fn fast_ln_matches_ln() {
    let mut x = 1e-6f32;
    while x < 1e6 {
        let err = (fast_ln(x) - x.ln()).abs();
        assert!(err < 2e-6 * x.ln().abs().max(1.0), "{x}: {err}");
        x *= 1.0137;
    }
}
