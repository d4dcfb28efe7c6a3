//! The integration tests of `eenf`, one test binary (each file was its own binary,
//! linking the whole workspace again).

mod common;

mod audio_harmonics;
mod edits_events;
mod shared_edits;
mod shared_edits_null;
mod shared_edits_real;
mod shared_real_audio;
mod shared_reference;
