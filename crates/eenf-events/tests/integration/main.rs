//! The integration tests of `eenf-events`, one test binary (each file was its own binary,
//! linking the whole workspace again).

mod aedat4_roundtrip;
mod shared_fixtures;
mod writers_roundtrip;
