//! Temporary files and folders that a signal must not leave behind: every reader or writer
//! that makes one registers it here while it exists, and the front end that handles SIGINT,
//! SIGTERM and SIGHUP calls [`remove_in_progress`] before the program ends (destructors do not
//! run then).

use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// Temporary files and folders being written, removed if a signal ends the program.
static IN_PROGRESS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Marks `path` as temporary until [`forget_in_progress`]: an interrupt removes it.
pub fn register_in_progress(path: &Path) {
    if let Ok(mut v) = IN_PROGRESS.lock() {
        v.push(path.to_path_buf());
    }
}

/// `path` is no longer temporary (renamed into place, or removed).
pub fn forget_in_progress(path: &Path) {
    if let Ok(mut v) = IN_PROGRESS.lock() {
        v.retain(|p| p != path);
    }
}

/// Removes every temporary file and folder in progress (newest first). The command line calls
/// it when a signal (SIGINT, SIGTERM, SIGHUP) ends the program, so that no half-written output
/// stays behind.
pub fn remove_in_progress() {
    // the lock is held only for short pushes and removals: waiting for it is brief
    let paths = IN_PROGRESS.lock().map(|v| v.clone()).unwrap_or_default();
    for p in paths.iter().rev() {
        if p.is_dir() {
            // threads still writing into the folder can add a file while it is being emptied
            // ("directory not empty"): try again for a little while
            for _ in 0..50 {
                if std::fs::remove_dir_all(p).is_ok() || !p.exists() {
                    break;
                }
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
        } else {
            let _ = std::fs::remove_file(p);
        }
    }
}

/// A path removed on interrupts for as long as this lives (see [`register_in_progress`]).
pub struct InProgress(PathBuf);

impl InProgress {
    /// Registers `path`.
    pub fn new(path: &Path) -> Self {
        register_in_progress(path);
        InProgress(path.to_path_buf())
    }
}

impl Drop for InProgress {
    fn drop(&mut self) {
        forget_in_progress(&self.0);
    }
}
