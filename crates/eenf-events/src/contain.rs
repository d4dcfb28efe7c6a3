//! Panics of other people's decoders (Symphonia, zstd, liblz4's wrappers) turned into errors.
//!
//! A decoder that panics on damaged data must not take the program (or a Python interpreter)
//! down with it: [`contain`] runs it where its panic becomes the error message of the file
//! being read. The panic is not printed: a process-wide hook, installed once, stays silent
//! for panics inside [`contain`] on the thread that called it and passes every other panic
//! to the hook that was there before.

use std::cell::Cell;
use std::panic::{self, AssertUnwindSafe};
use std::sync::Once;

thread_local! {
    /// How many [`contain`] calls are under way on this thread.
    static DEPTH: Cell<usize> = const { Cell::new(0) };
}

static HOOK: Once = Once::new();

/// Runs `f`; a panic inside it becomes `Err` with the panic's message. `f`'s state is not
/// used after a panic (the caller drops the decoder with the error), hence the
/// `AssertUnwindSafe`.
pub fn contain<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    HOOK.call_once(|| {
        let previous = panic::take_hook();
        panic::set_hook(Box::new(move |info| {
            if DEPTH.with(Cell::get) == 0 {
                previous(info);
            }
        }));
    });
    DEPTH.with(|d| d.set(d.get() + 1));
    let result = panic::catch_unwind(AssertUnwindSafe(f));
    DEPTH.with(|d| d.set(d.get() - 1));
    result.map_err(|payload| {
        let message = payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "no message".into());
        format!("the decoder failed on damaged data ({message})")
    })
}
