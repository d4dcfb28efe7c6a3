//! # eenf-cli
//!
//! The `eenf` command: its flags, its commands, its progress bars and printing; its figures
//! come from `eenf-figures`. Every
//! command parses its flags into the library's types ([`args`]), calls the library (`eenf`),
//! and prints or draws what comes back ([`commands`]); `main.rs` only dispatches. The Python
//! package reads the same option sets, so that keyword arguments have the flags' names,
//! defaults and checks.

#![forbid(unsafe_code)]

pub mod args;
// A command's flags are documented where users read them (`--help`); the option sets it
// flattens carry their own documentation in `args`.
#[allow(missing_docs)]
pub mod commands;
pub mod terminal;
