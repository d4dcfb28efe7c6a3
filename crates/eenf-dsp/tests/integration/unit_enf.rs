//! Tests of eenf-dsp's `enf` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_dsp::enf::*;

fn band(harmonic: usize, snr_db: &[f64]) -> HarmonicEstimates {
    HarmonicEstimates {
        harmonic,
        center_hz: 100.0 * harmonic as f64,
        enf_hz: vec![50.0; snr_db.len()],
        snr_db: snr_db.to_vec(),
    }
}

#[test]
fn bands_above_the_bar_are_heard_and_else_only_the_strongest() {
    // segment 0: bands 1 and 2 clear 12 dB; segment 1: none does, band 3 is strongest
    let h = [
        band(1, &[20.0, 14.0, 9.0, 10.0]),
        band(2, &[13.0, 12.0, 8.0, 8.0]),
        band(3, &[5.0, 6.0, 10.0, 11.0]),
    ];
    let a = audibility(&h, 2);
    assert_eq!(
        a,
        vec![vec![true, false], vec![true, false], vec![false, true]]
    );
    // a band with no finite estimate in a segment is never heard
    let h = [band(1, &[f64::NAN, f64::NAN]), band(2, &[3.0, 4.0])];
    assert_eq!(audibility(&h, 2), vec![vec![false], vec![true]]);
}
