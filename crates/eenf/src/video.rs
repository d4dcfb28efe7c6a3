//! V-ENF: a conventional video's rolling-shutter flicker → a [`Trace`].

use std::path::Path;

use crate::error::{Error, Result};
use eenf_video::{video_enf, FrameSource, VideoError, VideoOptions};

use crate::progress::Progress;
use crate::trace::Trace;

/// The V-ENF trace of the video at `path`; the progress bar counts frames.
pub fn trace_video(path: &Path, opts: &VideoOptions, progress: &Progress) -> Result<Trace> {
    let mut source = FrameSource::open(path)?;
    let bar = progress.steps(0, "frames");
    // the reader's errors name the file; the signal's are named here
    let analysis = video_enf(&mut source, opts, |n| bar.set_position(n)).map_err(|e| match e {
        VideoError::Signal(_) => Error::from(e).context(path.display()),
        e => e.into(),
    })?;
    bar.finish_and_clear();
    Ok(Trace::from_video(path, &analysis, opts))
}
