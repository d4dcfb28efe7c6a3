//! The tests of `eenf-dsp`, in one test binary: the library's own tests live here rather than in
//! `#[cfg(test)]` modules, so that `cargo test` links the library built for the demo instead of
//! compiling it a second time in test mode (a minute of a fresh clone's wait).

mod scipy_golden;
mod unit_blocks;
mod unit_chirp;
mod unit_decimate;
mod unit_edits;
mod unit_edits_null;
mod unit_enf;
mod unit_flicker;
mod unit_hum;
mod unit_matching;
mod unit_metrics;
mod unit_postprocess;
mod unit_resample;
mod unit_sampling;
mod unit_spectrogram;
mod unit_tracker;

/// Close to Gaussian noise of unit variance (a sum of twelve uniforms from xorshift64), from
/// `seed`: the tests' noise.
pub(crate) fn test_noise(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        (0..12)
            .map(|_| {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                (seed >> 11) as f64 / (1u64 << 53) as f64
            })
            .sum::<f64>()
            - 6.0
    }
}
