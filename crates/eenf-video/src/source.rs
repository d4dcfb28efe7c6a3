//! Where frames come from: Y4M files read natively, anything else through the `ffmpeg`
//! program (raw gray frames on a pipe, size and rate from `ffprobe`). Frames stream: one is
//! held at a time.

use std::cell::Cell;
use std::fs::File;
use std::io::{BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdout, Command, Stdio};
use std::rc::Rc;

use crate::VideoError;

/// Largest frame accepted (bytes of all planes), so that a corrupt header cannot make us
/// allocate without bound.
pub const MAX_FRAME_BYTES: usize = 256 << 20;

/// Size and rate of a video.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct VideoInfo {
    /// Frame width, pixels.
    pub width: usize,
    /// Frame height, pixels.
    pub height: usize,
    /// Frames per second.
    pub fps: f64,
}

/// A stream of luma frames.
pub enum FrameSource {
    /// A YUV4MPEG2 file.
    Y4m(Y4mSource),
    /// Any other container, decoded by ffmpeg.
    Ffmpeg(FfmpegSource),
}

impl FrameSource {
    /// Opens `path`: Y4M by its signature, anything else through ffmpeg.
    pub fn open(path: &Path) -> Result<Self, VideoError> {
        let mut head = [0u8; 10];
        let n = File::open(path)
            .and_then(|mut f| f.read(&mut head))
            .map_err(|e| VideoError::io(path, e))?;
        if n == 0 {
            return Err(VideoError::bad(path, "the file is empty"));
        }
        if head[..n].starts_with(b"YUV4MPEG2") {
            Y4mSource::open(path).map(FrameSource::Y4m)
        } else {
            FfmpegSource::open(path).map(FrameSource::Ffmpeg)
        }
    }

    /// Each frame's start, s from the first, when the container's frames are not evenly
    /// spaced (a variable frame rate); `None` when they are `1/fps` apart (Y4M always).
    pub fn frame_times(&self) -> Option<&[f64]> {
        match self {
            FrameSource::Y4m(_) => None,
            FrameSource::Ffmpeg(s) => s.frame_times.as_deref(),
        }
    }

    /// Size and rate.
    pub fn info(&self) -> VideoInfo {
        match self {
            FrameSource::Y4m(s) => s.info,
            FrameSource::Ffmpeg(s) => s.info,
        }
    }

    /// The next frame's luma (`width × height` bytes, row-major), or `None` at the end.
    pub fn next_frame(&mut self) -> Result<Option<&[u8]>, VideoError> {
        match self {
            FrameSource::Y4m(s) => s.next_frame(),
            FrameSource::Ffmpeg(s) => s.next_frame(),
        }
    }
}

/// Counts the bytes read through it, to tell a clean end from a cut frame.
struct Counted<R> {
    inner: R,
    count: Rc<Cell<u64>>,
}

impl<R: Read> Read for Counted<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        self.count.set(self.count.get() + n as u64);
        Ok(n)
    }
}

/// A YUV4MPEG2 file (8-bit; gray or YUV, of which the luma plane is used).
pub struct Y4mSource {
    path: PathBuf,
    decoder: y4m::Decoder<Counted<BufReader<File>>>,
    info: VideoInfo,
    luma: Vec<u8>,
    read: Rc<Cell<u64>>,
    file_len: u64,
    frames: u64,
}

impl Y4mSource {
    /// Opens and checks the header.
    pub fn open(path: &Path) -> Result<Self, VideoError> {
        let file = File::open(path).map_err(|e| VideoError::io(path, e))?;
        let file_len = file.metadata().map_err(|e| VideoError::io(path, e))?.len();
        let read = Rc::new(Cell::new(0));
        let reader = Counted {
            inner: BufReader::with_capacity(1 << 20, file),
            count: read.clone(),
        };
        let limits = y4m::Limits {
            bytes: MAX_FRAME_BYTES,
        };
        let decoder = y4m::Decoder::new_with_limits(reader, limits).map_err(|e| match e {
            y4m::Error::OutOfMemory => VideoError::bad(
                path,
                format!("the header's frame size exceeds {MAX_FRAME_BYTES} bytes"),
            ),
            y4m::Error::UnknownColorspace => {
                VideoError::bad(path, "the header names an unknown colour space")
            }
            y4m::Error::EOF => VideoError::bad(path, "the file ends inside the header"),
            other => VideoError::bad(path, format!("not a valid Y4M header ({other})")),
        })?;
        if decoder.get_bit_depth() != 8 {
            return Err(VideoError::bad(
                path,
                format!(
                    "{}-bit Y4M is not supported (8-bit only)",
                    decoder.get_bit_depth()
                ),
            ));
        }
        let rate = decoder.get_framerate();
        if rate.num == 0 || rate.den == 0 {
            return Err(VideoError::bad(
                path,
                format!("frame rate {}:{} in the header", rate.num, rate.den),
            ));
        }
        let info = VideoInfo {
            width: decoder.get_width(),
            height: decoder.get_height(),
            fps: rate.num as f64 / rate.den as f64,
        };
        Ok(Y4mSource {
            path: path.to_path_buf(),
            decoder,
            info,
            luma: Vec::new(),
            read,
            file_len,
            frames: 0,
        })
    }

    fn next_frame(&mut self) -> Result<Option<&[u8]>, VideoError> {
        let before = self.read.get();
        match self.decoder.read_frame() {
            Ok(frame) => {
                self.luma.clear();
                self.luma.extend_from_slice(frame.get_y_plane());
                self.frames += 1;
                Ok(Some(&self.luma))
            }
            Err(y4m::Error::EOF) | Err(y4m::Error::ParseError(_))
                if before >= self.file_len && self.frames > 0 =>
            {
                Ok(None)
            }
            Err(y4m::Error::EOF) => Err(VideoError::bad(
                &self.path,
                format!(
                    "truncated: the file ends inside frame {} ({} bytes after the last whole frame)",
                    self.frames + 1,
                    self.file_len.saturating_sub(before)
                ),
            )),
            Err(y4m::Error::ParseError(_)) => Err(VideoError::bad(
                &self.path,
                format!(
                    "corrupt: frame {} does not start with a FRAME marker",
                    self.frames + 1
                ),
            )),
            Err(e) => Err(VideoError::bad(
                &self.path,
                format!("frame {}: {e}", self.frames + 1),
            )),
        }
    }
}

/// The `ffmpeg` program to run (`EENF_FFMPEG` overrides, e.g. for a build in another place).
fn ffmpeg_program(name: &str) -> String {
    let var = format!("EENF_{}", name.to_uppercase());
    std::env::var(var).unwrap_or_else(|_| name.to_string())
}

/// The error of a tool that could not be started on `path`.
fn tool_error(path: &Path, tool: &str, e: std::io::Error) -> VideoError {
    VideoError::Tool {
        path: path.to_path_buf(),
        tool: tool.to_string(),
        reason: if e.kind() == std::io::ErrorKind::NotFound {
            "it is not installed (not a Y4M file, so ffmpeg is needed; Debian: apt install ffmpeg)"
                .into()
        } else {
            e.to_string()
        },
    }
}

/// Any container ffmpeg can decode, piped as raw 8-bit gray frames.
pub struct FfmpegSource {
    path: PathBuf,
    child: Child,
    stdout: ChildStdout,
    info: VideoInfo,
    frame_times: Option<Vec<f64>>,
    frame: Vec<u8>,
    frames: u64,
}

impl FfmpegSource {
    /// Probes `path` with ffprobe and starts ffmpeg on it.
    pub fn open(path: &Path) -> Result<Self, VideoError> {
        let probe = ffmpeg_program("ffprobe");
        let out = Command::new(&probe)
            .args([
                "-v",
                "error",
                "-select_streams",
                "v:0",
                "-show_entries",
                "stream=width,height,avg_frame_rate,r_frame_rate",
                "-of",
                "default=noprint_wrappers=1",
            ])
            .arg(path)
            .output()
            .map_err(|e| tool_error(path, &probe, e))?;
        if !out.status.success() {
            let msg = String::from_utf8_lossy(&out.stderr);
            return Err(VideoError::bad(
                path,
                format!(
                    "not a video ffmpeg can read ({})",
                    msg.lines().last().unwrap_or("no details").trim()
                ),
            ));
        }
        let text = String::from_utf8_lossy(&out.stdout);
        let field = |name: &str| {
            text.lines()
                .find_map(|l| l.strip_prefix(name)?.strip_prefix('='))
                .map(str::trim)
        };
        let rate = |v: &str| {
            let (n, d) = v.split_once('/').unwrap_or((v, "1"));
            let (n, d): (f64, f64) = (n.parse().ok()?, d.parse().ok()?);
            (n > 0.0 && d > 0.0).then_some(n / d)
        };
        let width: usize = field("width").and_then(|v| v.parse().ok()).unwrap_or(0);
        let height: usize = field("height").and_then(|v| v.parse().ok()).unwrap_or(0);
        // the stream's own rate (r_frame_rate) where the average agrees with it: the average
        // counts the last frame's duration or not, and is off by tens of ppm (30.00125 for a
        // 30 fps MP4), which would move every estimate by as much
        let fps = match (
            field("r_frame_rate").and_then(rate),
            field("avg_frame_rate").and_then(rate),
        ) {
            (Some(r), Some(a)) if (r / a - 1.0).abs() < 0.01 => Some(r),
            (r, a) => a.or(r),
        };
        let Some(fps) = fps.filter(|_| width > 0 && height > 0) else {
            return Err(VideoError::bad(path, "ffprobe finds no video stream"));
        };
        if width * height > MAX_FRAME_BYTES {
            return Err(VideoError::bad(
                path,
                format!("frames of {width}x{height} are too large"),
            ));
        }
        let frame_times = uneven_frame_times(&probe, path, fps);
        let tool = ffmpeg_program("ffmpeg");
        let mut command = Command::new(&tool);
        command.args(["-v", "error", "-nostdin", "-i"]).arg(path);
        if frame_times.is_some() {
            // every frame once, as the container times it (not repeated or dropped to a
            // constant rate)
            command.args(["-fps_mode", "passthrough"]);
        }
        let mut child = command
            .args(["-map", "0:v:0", "-f", "rawvideo", "-pix_fmt", "gray", "-"])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .map_err(|e| tool_error(path, &tool, e))?;
        let stdout = child.stdout.take().expect("piped");
        Ok(FfmpegSource {
            path: path.to_path_buf(),
            child,
            stdout,
            info: VideoInfo {
                width,
                height,
                fps: frame_times
                    .as_ref()
                    .map_or(fps, |t| mean_rate(t).unwrap_or(fps)),
            },
            frame_times,
            frame: vec![0; width * height],
            frames: 0,
        })
    }

    fn next_frame(&mut self) -> Result<Option<&[u8]>, VideoError> {
        let mut filled = 0;
        while filled < self.frame.len() {
            match self.stdout.read(&mut self.frame[filled..]) {
                Ok(0) => break,
                Ok(n) => filled += n,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(VideoError::io(&self.path, e)),
            }
        }
        if filled == self.frame.len() {
            self.frames += 1;
            return Ok(Some(&self.frame));
        }
        let status = self
            .child
            .wait()
            .map_err(|e| VideoError::io(&self.path, e))?;
        if !status.success() && self.frames == 0 {
            return Err(VideoError::bad(
                &self.path,
                format!("ffmpeg could not decode it ({status})"),
            ));
        }
        Ok(None)
    }
}

impl Drop for FfmpegSource {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// At most this many frame times are read from a container (a day at 120 fps).
const MAX_FRAME_TIMES: usize = 10_368_000;

/// The presentation times of the video stream's packets (`ffprobe`), sorted and counted from
/// the first, when they are not evenly spaced at about `fps`; `None` when they are, or when
/// the container gives no usable times (then frames are taken `1/fps` apart, as before).
fn uneven_frame_times(probe: &str, path: &Path, fps: f64) -> Option<Vec<f64>> {
    let mut child = Command::new(probe)
        .args(["-v", "error", "-select_streams", "v:0"])
        .args(["-show_entries", "packet=pts_time", "-of", "csv=p=0"])
        .arg(path)
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .ok()?;
    let stdout = child.stdout.take()?;
    let mut times = Vec::new();
    let mut usable = true;
    for line in std::io::BufRead::lines(BufReader::new(stdout)) {
        let Ok(line) = line else {
            usable = false;
            break;
        };
        match line.trim().trim_end_matches(',').parse::<f64>() {
            Ok(t) if t.is_finite() && times.len() < MAX_FRAME_TIMES => times.push(t),
            _ => {
                usable = false;
                break;
            }
        }
    }
    let _ = child.kill();
    let ok = child.wait().is_ok_and(|s| s.success());
    if !(usable && ok) || times.len() < 3 {
        return None;
    }
    times.sort_by(f64::total_cmp);
    let first = times[0];
    for t in &mut times {
        *t -= first;
    }
    let n = times.len();
    // a span that the frames cannot fill (a wild timestamp) says nothing reliable
    let span = times[n - 1];
    if span.is_nan() || span <= 0.0 || span > 4.0 * n as f64 / fps {
        return None;
    }
    // even: every step within a tenth of a frame of 1/fps (a container's tick rounds each)
    let even = times
        .windows(2)
        .all(|w| ((w[1] - w[0]) * fps - 1.0).abs() < 0.1);
    (!even).then_some(times)
}

/// Frames per second over `times` (frame starts), from the first to the last.
fn mean_rate(times: &[f64]) -> Option<f64> {
    let span = times.last()? - times.first()?;
    (span > 0.0).then(|| (times.len() - 1) as f64 / span)
}

/// Writes 8-bit gray frames as a Y4M file (`C mono`), which ffmpeg and most tools read.
pub struct Y4mWriter<W: Write> {
    encoder: y4m::Encoder<W>,
    width: usize,
    height: usize,
}

impl<W: Write> Y4mWriter<W> {
    /// Starts a file of `width × height` frames at `fps` (kept as a ratio over 1001 when not
    /// whole).
    pub fn new(out: W, width: usize, height: usize, fps: f64) -> std::io::Result<Self> {
        let rate = if (fps - fps.round()).abs() < 1e-9 {
            y4m::Ratio::new(fps.round() as usize, 1)
        } else {
            y4m::Ratio::new((fps * 1001.0).round() as usize, 1001)
        };
        let encoder = y4m::encode(width, height, rate)
            .with_colorspace(y4m::Colorspace::Cmono)
            .write_header(out)
            .map_err(to_io)?;
        Ok(Y4mWriter {
            encoder,
            width,
            height,
        })
    }

    /// Appends one frame of `width × height` luma bytes.
    pub fn write_frame(&mut self, luma: &[u8]) -> std::io::Result<()> {
        assert_eq!(luma.len(), self.width * self.height, "frame size");
        let frame = y4m::Frame::new([luma, &[], &[]], None);
        self.encoder.write_frame(&frame).map_err(to_io)
    }
}

fn to_io(e: y4m::Error) -> std::io::Error {
    match e {
        y4m::Error::IoError(e) => e,
        other => std::io::Error::other(other.to_string()),
    }
}
