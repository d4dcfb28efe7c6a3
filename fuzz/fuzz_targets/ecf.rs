#![no_main]
//! Fuzz target: Prophesee's ECF chunk decoder on its own (any bytes: an error or at most
//! 65,535 events, never a panic or more).

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if let Ok(out) = eenf_events::hdf5::ecf::decode(data) {
        assert!(out.len() <= eenf_events::hdf5::ecf::MAX_EVENTS * eenf_events::hdf5::ecf::RECORD);
    }
});
