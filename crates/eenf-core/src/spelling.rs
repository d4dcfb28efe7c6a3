//! How messages name an option. The library names each option once, by its library name
//! (`max_gap`, `nominal`); each front end says how its users write it: the command line as a
//! flag (`--max-gap`), Python as a keyword argument (`max_gap=`). The front end sets its
//! spelling once, at start; messages written by the library then read as that front end's.

use std::sync::atomic::{AtomicU8, Ordering};

/// How a front end's users write an option.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Spelling {
    /// Keyword arguments: `max_gap=2`, `strict=True` (Python; also the default).
    Keywords,
    /// Command-line flags: `--max-gap 2`, `--strict`.
    Flags,
    /// The library's names as they are: `max_gap 2`, `strict` (a page's JSON fields).
    Fields,
}

static SPELLING: AtomicU8 = AtomicU8::new(0);

/// Sets how messages name options, for the whole process (a front end calls it at start).
pub fn set_spelling(s: Spelling) {
    SPELLING.store(s as u8, Ordering::Relaxed);
}

/// The spelling in force.
pub fn spelling() -> Spelling {
    match SPELLING.load(Ordering::Relaxed) {
        1 => Spelling::Flags,
        2 => Spelling::Fields,
        _ => Spelling::Keywords,
    }
}

/// The option `name` (a library name, `snake_case`) as users write it: `--max-gap`,
/// `max_gap` or `max_gap`.
pub fn option(name: &str) -> String {
    match spelling() {
        Spelling::Flags => format!("--{}", name.replace('_', "-")),
        Spelling::Keywords | Spelling::Fields => name.to_string(),
    }
}

/// The option `name` given `value`: `--nominal 50`, `nominal=50` or `nominal 50`.
pub fn option_with(name: &str, value: &str) -> String {
    match spelling() {
        Spelling::Keywords => format!("{name}={value}"),
        _ => format!("{} {value}", option(name)),
    }
}

/// The switch `name` turned on: `--strict`, `strict=True` or `strict`.
pub fn switch(name: &str) -> String {
    match spelling() {
        Spelling::Keywords => format!("{name}=True"),
        _ => option(name),
    }
}
