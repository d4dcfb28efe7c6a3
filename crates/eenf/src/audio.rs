//! The sound of any recording: decoded with Symphonia (WAV, FLAC, MP3, AAC/M4A, OGG/Vorbis,
//! MKV/WebM audio), or a video's soundtrack through the `ffmpeg` program; mixed to mono or one
//! channel taken; brought down to the rate the mains bands need as it streams, so that an hour
//! of 44.1 kHz audio never sits in memory at its own rate.

use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};

use crate::error::{error, fail, Context, Error, Result};
use eenf_dsp::StreamDecimator;

use crate::spool::{Spool, SpoolWriter};
use symphonia::core::audio::SampleBuffer;
use symphonia::core::codecs::{DecoderOptions, CODEC_TYPE_NULL};
use symphonia::core::errors::Error as SymError;
use symphonia::core::formats::FormatOptions;
use symphonia::core::io::MediaSourceStream;
use symphonia::core::meta::MetadataOptions;
use symphonia::core::probe::Hint;

use eenf_core::Signal;

/// Which channel of a recording is traced.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Channel {
    /// The mean of all channels.
    #[default]
    Mix,
    /// One channel, from 0.
    Index(usize),
}

impl std::str::FromStr for Channel {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "mix" => Ok(Channel::Mix),
            n => n
                .parse()
                .map(Channel::Index)
                .map_err(|_| format!("{s:?}: expected mix or a channel number from 0")),
        }
    }
}

impl std::fmt::Display for Channel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Channel::Mix => f.write_str("mix"),
            Channel::Index(i) => write!(f, "{i}"),
        }
    }
}

/// How a recording's sound is read.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AudioOptions {
    /// The channel traced.
    pub channel: Channel,
    /// Keep every band up to this frequency, Hz, and decimate to the lowest rate that does
    /// (`None`: the recording's own rate).
    pub top_hz: Option<f64>,
}

/// A recording's sound, as read.
#[derive(Debug)]
pub struct Audio {
    /// The mono signal (decimated as asked), on disk: memory stays the same whatever the
    /// recording's length.
    pub signal: Spool,
    /// The recording's own sample rate, Hz.
    pub source_rate: f64,
    /// Its channels.
    pub channels: usize,
    /// Frames decoded.
    pub frames: u64,
    /// What decoded it: `symphonia` or `ffmpeg`.
    pub decoder: &'static str,
    /// Damage the decoder skipped (packets lost), for the user.
    pub warning: Option<String>,
}

/// Mixes or picks one channel of interleaved frames and feeds the decimator.
struct Sink {
    channel: Channel,
    channels: usize,
    decimator: StreamDecimator,
    mono: Vec<f64>,
    out: Vec<f64>,
    spool: SpoolWriter,
    frames: u64,
}

impl Sink {
    fn new(channel: Channel, channels: usize, fs: f64, top_hz: Option<f64>) -> Result<Self> {
        if let Channel::Index(i) = channel {
            if i >= channels {
                fail!(
                    Input,
                    "channel {i} asked for, but the recording has {channels}"
                );
            }
        }
        // no band above Nyquist: passes through
        let decimator = StreamDecimator::new(fs, top_hz.unwrap_or(fs));
        // the decimator's delay taken back out, so sample 0 is the recording's start
        let lag = (decimator.delay_s() * decimator.fs_out()).round() as usize;
        Ok(Sink {
            channel,
            channels,
            spool: SpoolWriter::new(decimator.fs_out())?.skip(lag),
            decimator,
            mono: Vec::new(),
            out: Vec::new(),
            frames: 0,
        })
    }

    fn push(&mut self, interleaved: &[f32]) -> Result<()> {
        let ch = self.channels.max(1);
        self.mono.clear();
        match self.channel {
            Channel::Index(i) => self
                .mono
                .extend(interleaved.chunks_exact(ch).map(|f| f[i] as f64)),
            Channel::Mix if ch == 1 => self.mono.extend(interleaved.iter().map(|&v| v as f64)),
            Channel::Mix => self.mono.extend(
                interleaved
                    .chunks_exact(ch)
                    .map(|f| f.iter().map(|&v| v as f64).sum::<f64>() / ch as f64),
            ),
        }
        self.frames += self.mono.len() as u64;
        self.out.clear();
        self.decimator.push(&self.mono, &mut self.out);
        self.spool.push(&self.out)
    }
}

impl Audio {
    /// The signal brought down further, to the lowest rate that keeps every band up to
    /// `top_hz` (the same streaming FIR decimation, its delay taken back out), read and
    /// written a block at a time; `None` when no lower rate does.
    pub fn narrowed(&self, top_hz: f64) -> Result<Option<Spool>> {
        let mut d = StreamDecimator::new(self.signal.fs, top_hz);
        if d.factor() <= 1 {
            return Ok(None);
        }
        let lag = (d.delay_s() * d.fs_out()).round() as usize;
        let want = self.signal.len().div_ceil(d.factor());
        let mut out = SpoolWriter::new(d.fs_out())?.skip(lag).limit(want);
        let mut samples = Vec::new();
        const BLOCK: usize = 1 << 20;
        for lo in (0..self.signal.len()).step_by(BLOCK) {
            let block = self.signal.read(lo..(lo + BLOCK).min(self.signal.len()))?;
            samples.clear();
            d.push(&block, &mut samples);
            out.push(&samples)?;
        }
        // the tail the delay held back: flushed with zeros
        let tail = lag * d.factor() + d.factor();
        samples.clear();
        d.push(&vec![0.0; tail], &mut samples);
        out.push(&samples)?;
        out.finish().map(Some)
    }
}

/// Reads the sound of `path` as `opts` says: Symphonia first, then ffmpeg for what it cannot
/// read (video containers, other codecs). A damaged packet is skipped; a recording with no
/// sound is an error.
pub fn read_audio(path: &Path, opts: &AudioOptions) -> Result<Audio> {
    if path.is_dir() {
        fail!(Input, "{}: is a folder, not a recording", path.display());
    }
    let mut file = std::fs::File::open(path).with_context(|| format!("{}", path.display()))?;
    match container_of(&mut file) {
        // Symphonia's Matroska reader panics on cut-short files and allocates whatever a lace
        // size says (0.5.5): MKV and WebM go to ffmpeg, which reads them robustly
        Container::Matroska => {
            return read_ffmpeg(path, opts).map_err(|e| error!(Input, "{}: {e}", path.display()))
        }
        // its MP4 reader can allocate from damaged box sizes past the memory there is (an
        // abort no panic guard catches): MP4, M4A and MOV go to ffmpeg, always, so that a file
        // gives one trace whether or not ffmpeg is installed (or a clear error without it)
        Container::Mp4 => {
            return read_ffmpeg(path, opts).map_err(|e| error!(Input, "{}: {e}", path.display()))
        }
        _ => {}
    }
    // a panic inside Symphonia (damaged data it does not check) is the file's error, and
    // ffmpeg is asked next as for a format Symphonia does not read
    let symphonia = eenf_events::contain(|| read_symphonia(file, path, opts))
        .unwrap_or_else(|why| Err(Unreadable::Format(why)));
    match symphonia {
        Ok(a) => Ok(a),
        Err(Unreadable::Format(why)) => {
            read_ffmpeg(path, opts).map_err(|e| error!(Input, "{}: {why}; {e}", path.display()))
        }
        Err(Unreadable::Other(e)) => Err(e),
    }
}

/// Containers whose Symphonia readers are not trusted with damaged files.
#[derive(PartialEq)]
enum Container {
    /// Matroska and WebM (EBML magic).
    Matroska,
    /// ISO base media: MP4, M4A, MOV (`ftyp` box first).
    Mp4,
    /// Anything else.
    Other,
}

/// The container `file` starts with; the file is left at its start.
fn container_of(file: &mut std::fs::File) -> Container {
    use std::io::{Seek, SeekFrom};
    let mut head = [0u8; 8];
    let read = file.read_exact(&mut head).is_ok();
    let rewound = file.seek(SeekFrom::Start(0)).is_ok();
    match head {
        _ if !(read && rewound) => Container::Other,
        [0x1A, 0x45, 0xDF, 0xA3, ..] => Container::Matroska,
        [_, _, _, _, b'f', b't', b'y', b'p'] => Container::Mp4,
        _ => Container::Other,
    }
}

/// A recording's sound: a file (any format [`read_audio`] reads), or samples already in
/// memory (arrays from another library), which are mixed and decimated as a file's are.
#[derive(Debug, Clone, Copy)]
pub enum Sound<'a> {
    /// A sound file, or a video with sound.
    File(&'a Path),
    /// Interleaved frames of `channels` channels at `fs` Hz, named `name` in messages.
    Samples {
        /// What errors and the trace call them.
        name: &'a Path,
        /// The samples, frame after frame.
        interleaved: &'a [f32],
        /// Channels per frame.
        channels: usize,
        /// Sample rate, Hz.
        fs: f64,
    },
}

impl Sound<'_> {
    /// Its name in messages and in the trace.
    pub fn name(&self) -> &Path {
        match self {
            Sound::File(p) => p,
            Sound::Samples { name, .. } => name,
        }
    }

    /// Reads it as `opts` says.
    pub fn read(&self, opts: &AudioOptions) -> Result<Audio> {
        match *self {
            Sound::File(p) => read_audio(p, opts),
            Sound::Samples {
                name,
                interleaved,
                channels,
                fs,
            } => audio_from_samples(interleaved, channels, fs, name, opts),
        }
    }
}

/// The highest sample rate accepted for sound in memory (10 MHz: far above any recorder's,
/// and a bound on the decimator's work per sample).
pub const MAX_RATE_HZ: f64 = 10e6;

/// Sound in memory (`interleaved` frames of `channels` channels at `fs` Hz) read as `opts`
/// says, with the mix and the streaming decimation a file's sound goes through. NaN or
/// infinite samples are an error (they would spread through every filter).
pub fn audio_from_samples(
    interleaved: &[f32],
    channels: usize,
    fs: f64,
    name: &Path,
    opts: &AudioOptions,
) -> Result<Audio> {
    if !(fs.is_finite() && fs > 0.0 && fs <= MAX_RATE_HZ) {
        fail!(
            Input,
            "{}: the sample rate must be above 0 and at most {MAX_RATE_HZ} Hz, not {fs}",
            name.display()
        );
    }
    if channels == 0 || !interleaved.len().is_multiple_of(channels) {
        fail!(
            Input,
            "{}: {} samples do not make whole frames of {channels} channels",
            name.display(),
            interleaved.len()
        );
    }
    if let Some(i) = interleaved.iter().position(|v| !v.is_finite()) {
        fail!(
            Input,
            "{}: sample {} (frame {}) is {}: samples must be finite",
            name.display(),
            i,
            i / channels,
            interleaved[i]
        );
    }
    let mut sink = Sink::new(opts.channel, channels, fs, opts.top_hz)?;
    // fed in blocks as a decoder's packets would be
    for block in interleaved.chunks(channels * 4096) {
        sink.push(block)?;
    }
    finish(Some(sink), fs, name, "memory", None)
}

/// Why Symphonia could not read a file: a format it does not know (ffmpeg may), or a real
/// error (bad channel, damaged stream).
enum Unreadable {
    Format(String),
    Other(Error),
}

fn read_symphonia(
    file: std::fs::File,
    path: &Path,
    opts: &AudioOptions,
) -> std::result::Result<Audio, Unreadable> {
    let other = |e: Error| Unreadable::Other(error!(Input, "{}: {e}", path.display()));
    let file = crate::flac_mask::flac_masked(file).map_err(|why| other(Error::Input(why)))?;
    let mss = MediaSourceStream::new(Box::new(file), Default::default());
    let mut hint = Hint::new();
    if let Some(ext) = path.extension().and_then(|e| e.to_str()) {
        hint.with_extension(ext);
    }
    let probed = symphonia::default::get_probe()
        .format(
            &hint,
            mss,
            &FormatOptions::default(),
            &MetadataOptions::default(),
        )
        .map_err(|_| {
            Unreadable::Format("not WAV, FLAC, MP3 or OGG, which eenf reads itself".into())
        })?;
    let mut format = probed.format;
    let Some(track) = format
        .tracks()
        .iter()
        .find(|t| t.codec_params.codec != CODEC_TYPE_NULL && t.codec_params.sample_rate.is_some())
    else {
        return Err(Unreadable::Format(
            "no audio track eenf decodes itself".into(),
        ));
    };
    let track_id = track.id;
    let params = track.codec_params.clone();
    let mut decoder = symphonia::default::get_codecs()
        .make(&params, &DecoderOptions::default())
        .map_err(|_| Unreadable::Format("its audio codec is not one eenf decodes itself".into()))?;
    let fs = params.sample_rate.unwrap_or(0) as f64;
    if fs <= 0.0 {
        return Err(Unreadable::Other(error!(
            Input,
            "{}: its header gives a sample rate of 0 Hz",
            path.display()
        )));
    }
    let mut sink: Option<Sink> = None;
    let mut buf: Option<SampleBuffer<f32>> = None;
    let mut damaged = 0usize;
    loop {
        let packet = match format.next_packet() {
            Ok(p) => p,
            Err(SymError::IoError(e)) if e.kind() == std::io::ErrorKind::UnexpectedEof => break,
            Err(SymError::ResetRequired) => break,
            Err(e) => return Err(other(error!(Input, "damaged stream ({e})"))),
        };
        if packet.track_id() != track_id {
            continue;
        }
        let decoded = match decoder.decode(&packet) {
            Ok(d) => d,
            Err(SymError::DecodeError(_)) => {
                damaged += 1;
                continue;
            }
            Err(SymError::IoError(e)) if e.kind() == std::io::ErrorKind::UnexpectedEof => break,
            Err(e) => return Err(other(error!(Input, "cannot decode its audio ({e})"))),
        };
        let spec = *decoded.spec();
        let channels = spec.channels.count();
        if sink.is_none() {
            sink = Some(Sink::new(opts.channel, channels, fs, opts.top_hz).map_err(other)?);
        }
        let b = match &mut buf {
            Some(b) if b.capacity() >= decoded.capacity() * channels => b,
            _ => buf.insert(SampleBuffer::new(decoded.capacity() as u64, spec)),
        };
        b.copy_interleaved_ref(decoded);
        if let Some(s) = sink.as_mut() {
            if s.channels == channels {
                s.push(b.samples()).map_err(Unreadable::Other)?;
            }
        }
    }
    let warning = (damaged > 0).then(|| {
        format!(
            "{}: {damaged} damaged audio packets skipped",
            path.display()
        )
    });
    finish(sink, fs, path, "symphonia", warning).map_err(Unreadable::Other)
}

fn finish(
    sink: Option<Sink>,
    fs: f64,
    path: &Path,
    decoder: &'static str,
    warning: Option<String>,
) -> Result<Audio> {
    let Some(s) = sink.filter(|s| s.frames > 0) else {
        fail!(Input, "{}: the recording holds no sound", path.display());
    };
    Ok(Audio {
        signal: s.spool.finish()?,
        source_rate: fs,
        channels: s.channels,
        frames: s.frames,
        decoder,
        warning,
    })
}

/// The sound of `path` through ffmpeg: its first audio stream as 32-bit float frames on a
/// pipe, at its own rate and channels (probed with ffprobe), decimated as it arrives.
fn read_ffmpeg(path: &Path, opts: &AudioOptions) -> Result<Audio> {
    let probe = Command::new("ffprobe")
        .args(["-v", "error", "-select_streams", "a:0", "-show_entries"])
        .args(["stream=sample_rate,channels", "-of", "csv=p=0"])
        .arg(path)
        .output()
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => {
                error!(Input, "ffmpeg (ffprobe) is not installed, and it is needed for this file (Debian: apt install ffmpeg)")
            }
            _ => error!(Input, "ffprobe: {e}"),
        })?;
    let text = String::from_utf8_lossy(&probe.stdout);
    let mut fields = text.trim().split(',');
    let (Some(Ok(fs)), Some(Ok(channels))) = (
        fields.next().map(|v| v.trim().parse::<u32>()),
        fields.next().map(|v| v.trim().parse::<usize>()),
    ) else {
        fail!(Input, "ffmpeg finds no audio stream in it");
    };
    if fs == 0 || channels == 0 {
        fail!(Input, "ffmpeg finds no audio stream in it");
    }
    if channels > 64 {
        fail!(
            Input,
            "ffmpeg reports {channels} audio channels: a damaged header (64 at most are read)"
        );
    }
    let mut child = Command::new("ffmpeg")
        .args(["-v", "error", "-nostdin", "-i"])
        .arg(path)
        .args([
            "-map",
            "0:a:0",
            "-vn",
            "-f",
            "f32le",
            "-acodec",
            "pcm_f32le",
            "-",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| error!(Input, "ffmpeg: {e}"))?;
    // ffmpeg's messages are read on a thread of their own as they come: a pipe holds 64 KiB,
    // and ffmpeg blocked on a full stderr would never finish our stdout. The last lines are
    // kept for the error.
    let stderr = child.stderr.take().expect("piped");
    let messages = std::thread::spawn(move || last_lines(stderr, 4096));
    let result = decode_ffmpeg_output(&mut child, channels, fs, opts);
    if result.is_err() {
        let _ = child.kill();
    }
    let status = child.wait()?;
    let err = messages.join().unwrap_or_default();
    let sink = result?;
    if !status.success() {
        fail!(
            Input,
            "ffmpeg could not decode it: {}",
            err.lines().last().unwrap_or("no message")
        );
    }
    let warning = err.lines().last().map(|last| {
        format!(
            "{}: ffmpeg met damage and skipped it ({last})",
            path.display()
        )
    });
    finish(Some(sink), fs as f64, path, "ffmpeg", warning)
}

/// The last `keep` bytes (about) of what `r` gives, as text.
fn last_lines(mut r: impl Read, keep: usize) -> String {
    let mut tail: Vec<u8> = Vec::new();
    let mut buf = [0u8; 8192];
    while let Ok(n) = r.read(&mut buf) {
        if n == 0 {
            break;
        }
        tail.extend_from_slice(&buf[..n]);
        if tail.len() > 2 * keep {
            tail.drain(..tail.len() - keep);
        }
    }
    String::from_utf8_lossy(&tail).trim().to_string()
}

/// ffmpeg's float frames from its stdout, mixed and decimated.
fn decode_ffmpeg_output(
    child: &mut std::process::Child,
    channels: usize,
    fs: u32,
    opts: &AudioOptions,
) -> Result<Sink> {
    let mut sink = Sink::new(opts.channel, channels, fs as f64, opts.top_hz)?;
    let mut stdout = child.stdout.take().expect("piped");
    let mut bytes = vec![0u8; 1 << 16];
    let mut carry = 0usize;
    let mut frame = Vec::new();
    let frame_bytes = 4 * channels;
    loop {
        let n = stdout.read(&mut bytes[carry..])?;
        if n == 0 {
            break;
        }
        let have = carry + n;
        let whole = have / frame_bytes * frame_bytes;
        frame.clear();
        frame.extend(
            bytes[..whole]
                .chunks_exact(4)
                .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        );
        sink.push(&frame)?;
        bytes.copy_within(whole..have, 0);
        carry = have - whole;
    }
    Ok(sink)
}

/// Reads the first channel of a mains recording (WAV or any format [`crate::audio`] reads) at
/// its own rate.
pub fn read_wav(path: &Path) -> Result<Signal> {
    let opts = AudioOptions {
        channel: Channel::Index(0),
        top_hz: None,
    };
    let signal = read_audio(path, &opts)?.signal;
    Ok(Signal {
        fs: signal.fs,
        samples: signal.to_vec()?,
    })
}
