//! One module per command.

pub mod compare;
pub mod convert;
pub mod demo;
pub mod extract;
pub mod info;
pub mod method;
pub mod reference;
pub mod simulate;
