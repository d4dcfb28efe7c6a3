//! # eenf-video
//!
//! V-ENF, the video baseline the paper compares E-ENF against (Su, Hajj-Ahmad, Garg and Wu,
//! ICIP 2014): the rows of a rolling-shutter frame are exposed one after another, so the mean
//! of each row samples the light's flicker at rows·fps per second. [`FrameSource`] reads Y4M
//! natively and anything else through the `ffmpeg` program; [`video_enf`] takes the scene
//! out, lays the rows on a uniform time grid (zero-padding the idle rows, or naively, or one
//! sample per frame for a global shutter), band-passes the flicker line and tracks it with
//! the same STFT tracker as E-ENF.
//!
//! ```no_run
//! use eenf_video::{video_enf, FrameSource, VideoOptions};
//! let mut source = FrameSource::open("clip_lr.y4m".as_ref()).unwrap();
//! let trace = video_enf(&mut source, &VideoOptions::default(), |_| {}).unwrap();
//! println!("{} estimates, grid {} Hz", trace.enf_hz.len(), trace.nominal_hz);
//! ```

#![forbid(unsafe_code)]

use std::path::{Path, PathBuf};

mod source;
mod venf;

pub use source::{FfmpegSource, FrameSource, VideoInfo, Y4mSource, Y4mWriter, MAX_FRAME_BYTES};
pub use venf::{
    estimate_virtual_rows, frame_alias, frame_half_band, strongest_line, video_enf,
    video_enf_from_rows, IdleRows, RowMeans, RowSampling, SceneRemoval, VideoAnalysis,
    VideoOptions,
};

/// Why a video could not be read or traced.
#[derive(Debug, thiserror::Error)]
pub enum VideoError {
    /// The file could not be read.
    // the OS message is shown once: not also as a `source` that `{:#}` would print again
    #[error("{path}: {error}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        error: std::io::Error,
    },
    /// The file is not a usable video.
    #[error("{path}: {reason}")]
    Bad {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// An external program is missing or failed.
    #[error("{path}: cannot run {tool}: {reason}")]
    Tool {
        /// The file.
        path: PathBuf,
        /// The program.
        tool: String,
        /// What went wrong.
        reason: String,
    },
    /// The video holds no trackable flicker.
    #[error("{0}")]
    Signal(String),
}

impl VideoError {
    fn io(path: &Path, source: std::io::Error) -> Self {
        VideoError::Io {
            path: path.to_path_buf(),
            error: source,
        }
    }

    fn bad(path: &Path, reason: impl Into<String>) -> Self {
        VideoError::Bad {
            path: path.to_path_buf(),
            reason: reason.into(),
        }
    }
}
