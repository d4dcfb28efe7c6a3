//! V-ENF: a conventional video's rolling-shutter flicker → a [`Trace`].

use std::path::Path;

use crate::error::Result;
use eenf_video::{video_enf, FrameSource, VideoOptions};

use crate::progress::Progress;
use crate::trace::Trace;

/// The V-ENF trace of the video at `path`; the progress bar counts frames.
pub fn trace_video(path: &Path, opts: &VideoOptions, progress: &Progress) -> Result<Trace> {
    let mut source = FrameSource::open(path)?;
    let bar = progress.steps(0, "frames");
    let analysis = video_enf(&mut source, opts, |n| bar.set_position(n))?;
    bar.finish_and_clear();
    Ok(Trace::from_video(path, &analysis, opts))
}
