//! The integration tests of `eenf-cli`, one test binary (each file was its own binary,
//! linking the whole workspace again).

mod cli;
#[path = "../../../eenf/tests/integration/common.rs"]
mod common;

mod cli_archives;
mod cli_audio;
mod cli_bench;
mod cli_edits;
mod cli_end_to_end;
mod cli_errors;
mod cli_fetch;
mod cli_flags;
mod cli_option_docs;
mod cli_reliability;
mod cli_serve;
mod cli_simulation;
mod memory_inputs;
mod replay;
mod shared_archives;
mod shared_matching;
mod shared_real_flicker;
mod shared_simulation;
