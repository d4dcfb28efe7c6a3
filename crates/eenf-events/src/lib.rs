//! # eenf-events
//!
//! The event model of eenf and the readers and writers of event-camera files.
//!
//! Events come in [`EventBatch`]es (struct-of-arrays: `t` µs, `x`, `y`, polarity), streamed
//! from the file with memory that does not grow with the recording. [`open`] looks at the
//! file's content (not its name) and picks the reader.
//!
//! ```no_run
//! let mut reader = eenf_events::open(std::path::Path::new("recording.aedat4"))?;
//! println!("{} {:?}x{:?}", reader.info().format, reader.info().width, reader.info().height);
//! let mut on = 0usize;
//! while let Some(batch) = reader.next_batch()? {
//!     on += batch.p.iter().filter(|&&p| p).count();
//! }
//! println!("{on} ON events");
//! # Ok::<(), eenf_events::EventError>(())
//! ```

// `unsafe` only in the calls into liblz4 (`aedat4::lz4`) and c-blosc (`hdf5::filters`), which
// allow it there
#![deny(unsafe_code)]

pub mod aedat4;
pub mod atis;
pub mod contain;
mod error;
pub mod eventstream;
mod guard;
pub mod hdf5;
mod held;
pub mod jaer;
pub mod memory;
mod prefetch;
pub mod prophesee;
pub mod registry;
pub mod rosbag;
pub mod rosbag2;
pub mod rosmsg;
pub mod spool;
mod stream;
pub mod text;
pub mod writers;

use std::io::{Read, Seek, SeekFrom};
use std::path::Path;

pub use aedat4::{Aedat4Reader, Aedat4Writer, Compression};
pub use contain::contain;
pub use eenf_core::EventBatch;
pub use error::{EventError, Result};
pub use guard::{Damage, DamageKind, DEFAULT_MAX_GAP_US};
pub use memory::open_events;
pub use registry::{Probed, Registered};
pub use text::TextReader;

/// The formats this version reads, for error messages.
pub const SUPPORTED: &str = "AEDAT 4.0 (.aedat4), Prophesee EVT 2.0/2.1/3.0 (.raw) and DAT (.dat), jAER AEDAT 2.0/3.1 (.aedat), ROS 1 bags (.bag) and rosbag2 folders (.db3, .mcap) of event messages, Event Stream 2 DVS (.es), HDF5 (DSEC, M3ED, MVSEC, TUM-VIE, Prophesee CD/events), ATIS .bin (N-MNIST, N-Caltech101), text (t x y p)";

/// One data stream declared by a file (AEDAT4 files can carry events, frames, IMU, triggers).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct StreamDesc {
    /// Stream id used in the packet headers.
    pub id: i32,
    /// Type identifier: `EVTS`, `FRME`, `IMUS`, `TRIG`.
    pub kind: String,
    /// Sensor width, when declared.
    pub width: Option<u16>,
    /// Sensor height, when declared.
    pub height: Option<u16>,
    /// Camera name, when declared; the topic, in a bag.
    pub source: Option<String>,
    /// Messages of the stream, when the container counts them (a bag's topics).
    pub messages: Option<u64>,
}

/// What a reader knows about a recording before reading its events.
#[derive(Debug, Clone, Default)]
pub struct StreamInfo {
    /// Format name, e.g. `AEDAT 4.0`.
    pub format: &'static str,
    /// Packet compression, when the format has one.
    pub codec: Option<String>,
    /// Sensor width, when the header says.
    pub width: Option<u16>,
    /// Sensor height, when the header says.
    pub height: Option<u16>,
    /// Streams declared in the header.
    pub streams: Vec<StreamDesc>,
    /// Number of events, when known without reading them (AEDAT4 FileDataTable).
    pub event_count: Option<u64>,
    /// First timestamp (µs), when known up front.
    pub first_t: Option<i64>,
    /// Last timestamp (µs), when known up front.
    pub last_t: Option<i64>,
    /// True when the file carries an index (FileDataTable).
    pub indexed: bool,
    /// The cameras of a file that holds several (a jAER stereo pair), by number; empty for one.
    pub cameras: Vec<String>,
    /// The camera read, when there are several and one was picked.
    pub camera: Option<u8>,
    /// Where in a container the events come from: `topic /dvs/events (dvs_msgs/EventArray)`
    /// in a bag (with the camera encoding of its packets), `group /events` or `dataset
    /// /CD/events` in an HDF5 file.
    pub within: Option<String>,
    /// What the reader had to infer or assume (e.g. a chip not named in the header).
    pub notes: Vec<String>,
}

/// How to read files that leave something open.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct OpenOptions {
    /// The chip of a jAER AEDAT 2.0 file (`DVS128`, `DAVIS240`, `DAVIS346`, `DAVIS640`),
    /// overriding its `# AEChip:` line or the chip inferred from its addresses.
    pub chip: Option<String>,
    /// In a file with several cameras (a jAER stereo pair), read only this one (0, 1, …).
    pub camera: Option<u8>,
    /// Damage and wild timestamps are errors: by default the stream ends there, with the
    /// events before them and a [`Damage`] report.
    pub strict: bool,
    /// The largest step of a timestamp between two events, µs, forwards or backwards
    /// (default [`DEFAULT_MAX_GAP_US`]); a larger one ends the stream.
    pub max_gap_us: Option<i64>,
    /// In a container of several topics (a ROS bag), the topic to read (default: the first
    /// topic of event messages).
    pub topic: Option<String>,
}

/// A source of event batches.
pub trait EventReader: Send {
    /// What the header said.
    fn info(&self) -> &StreamInfo;
    /// The next batch of events, `None` at the end. Events before damage are delivered before
    /// the error that reports it.
    fn next_batch(&mut self) -> Result<Option<EventBatch>>;
    /// Words or packets read so far that were not events (triggers, IMU, APS…), by kind.
    fn skipped(&self) -> Vec<(&'static str, u64)> {
        Vec::new()
    }
    /// Byte offset where the data of the batch handed out last starts, when the reader knows.
    fn batch_offset(&self) -> Option<u64> {
        None
    }
    /// What ended the stream early (damage, a wild timestamp), once the stream has ended.
    fn damage(&self) -> Option<&Damage> {
        None
    }
}

/// The formats eenf recognises by content.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// iniVation AEDAT 4.0.
    Aedat4,
    /// Prophesee RAW or DAT (the encoding is in the `% ` header).
    Prophesee(prophesee::ProphFormat),
    /// jAER AEDAT 2.0.
    Aedat2,
    /// jAER AEDAT 3.1.
    Aedat31,
    /// Plain text `t x y p`.
    Text,
    /// Event Stream 2.x (`.es`).
    EventStream,
    /// The ATIS `.bin` of N-MNIST and N-Caltech101 (no header: told by its content).
    AtisBin,
    /// A ROS 1 bag (format 2.0) of event messages.
    RosBag,
    /// A rosbag2 of event messages: its folder, or one storage file (SQLite or MCAP).
    Rosbag2,
    /// HDF5 (DSEC, M3ED, MVSEC, TUM-VIE, Prophesee's own).
    Hdf5,
}

/// Every format read from a byte stream, in probing order (a rosbag2 folder is told by its
/// files, before any probe).
pub const FORMATS: &[Registered] = &[
    aedat4::REGISTERED,
    jaer::AEDAT2,
    jaer::AEDAT31,
    eventstream::REGISTERED,
    rosbag::REGISTERED,
    rosbag2::REGISTERED,
    hdf5::REGISTERED,
    prophesee::REGISTERED,
    text::REGISTERED,
    atis::REGISTERED,
];

/// A byte stream a reader can read: a file, a `Cursor<Vec<u8>>`, stdin read into memory.
pub trait Source: Read + Seek + Send {}
impl<T: Read + Seek + Send> Source for T {}

/// Where a writer's bytes go: a file, a temporary file, a `Cursor<Vec<u8>>`.
pub trait Sink: std::io::Write + Seek + Send {}
impl<T: std::io::Write + Seek + Send> Sink for T {}

/// Bytes looked at to decide a format.
const HEAD: usize = 4096;

/// Decides the format of the file at `path` from its first bytes (`-`: stdin); a folder is a
/// rosbag2 when it holds its storage files.
pub fn probe(path: &Path) -> Result<Format> {
    if path.is_dir() {
        return folder_format(path);
    }
    let mut f = open_file(path)?;
    Ok(probe_source(f.as_mut(), path)?.format)
}

/// Opens `path` for reading as a seekable byte stream; `-` is stdin. What cannot seek (a pipe,
/// a FIFO, a terminal) is first copied into an unnamed temporary file (on disk: memory stays
/// flat), once per name: every later open of the same name reads that copy again, so every
/// format, and every command that reads a file twice, works from a pipe.
pub fn open_file(path: &Path) -> Result<Box<dyn Source>> {
    use std::collections::HashMap;
    use std::sync::Mutex;
    static SPOOLED: Mutex<Option<HashMap<std::path::PathBuf, std::fs::File>>> = Mutex::new(None);
    let io = |e| error::io_err(path, e);
    let stdin = path.as_os_str() == "-";
    let file = if stdin {
        None
    } else {
        let f = std::fs::File::open(path).map_err(io)?;
        if f.metadata().map_err(io)?.is_file() {
            return Ok(Box::new(f));
        }
        Some(f)
    };
    let mut cache = SPOOLED.lock().unwrap_or_else(|p| p.into_inner());
    let cache = cache.get_or_insert_with(HashMap::new);
    if !cache.contains_key(path) {
        // unnamed (O_TMPFILE where it can): nothing is left behind, whatever ends the program
        let mut spool = tempfile::tempfile().map_err(io)?;
        match file {
            Some(mut f) => std::io::copy(&mut f, &mut spool),
            None => std::io::copy(&mut std::io::stdin().lock(), &mut spool),
        }
        .map_err(io)?;
        cache.insert(path.to_path_buf(), spool);
    }
    reopen(&cache[path]).map_err(io)
}

/// A handle on `f` with its own offset (Linux: through `/proc/self/fd`), so that readers opened
/// one after another do not move each other; else a clone sharing the offset (readers seek to
/// where they read).
fn reopen(f: &std::fs::File) -> std::io::Result<Box<dyn Source>> {
    #[cfg(target_os = "linux")]
    {
        use std::os::fd::AsRawFd;
        if let Ok(g) = std::fs::File::open(format!("/proc/self/fd/{}", f.as_raw_fd())) {
            return Ok(Box::new(g));
        }
    }
    let mut g = f.try_clone()?;
    g.seek(SeekFrom::Start(0))?;
    Ok(Box::new(g))
}

/// The format of the folder `dir`: a rosbag2, or an error naming the folder.
fn folder_format(dir: &Path) -> Result<Format> {
    if rosbag2::is_folder(dir) {
        return Ok(Format::Rosbag2);
    }
    Err(EventError::UnknownFormat {
        path: dir.to_path_buf(),
        reason: "a folder that is not a rosbag2 (no metadata.yaml, .db3 or .mcap in it)".into(),
        supported: SUPPORTED,
    })
}

/// Decides the format of `src` (named `path` in errors) from its first bytes; leaves `src`
/// at its start.
pub fn probe_source(src: &mut dyn Source, path: &Path) -> Result<Probed> {
    probe_registered(src, path).map(|(probed, _)| probed)
}

/// The first registered format ([`FORMATS`]) whose probe recognises the head of `src`, and
/// its reader's opener; leaves `src` at its start.
fn probe_registered(src: &mut dyn Source, path: &Path) -> Result<(Probed, registry::OpenFn)> {
    let mut head = vec![0u8; HEAD];
    let mut n = 0;
    while n < head.len() {
        match src.read(&mut head[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(error::io_err(path, e)),
        }
    }
    head.truncate(n);
    src.seek(SeekFrom::Start(0))
        .map_err(|e| error::io_err(path, e))?;
    let unknown = |reason: String| EventError::UnknownFormat {
        path: path.to_path_buf(),
        reason,
        supported: SUPPORTED,
    };
    if n == 0 {
        return Err(unknown("the file is empty".into()));
    }
    let head = registry::Head {
        bytes: &head,
        cut: n == HEAD,
    };
    for format in FORMATS {
        let found = (format.probe)(&head, src, path)?;
        src.seek(SeekFrom::Start(0))
            .map_err(|e| error::io_err(path, e))?;
        if let Some(found) = found {
            return Ok((found, format.open));
        }
    }
    Err(unknown(format!(
        "unrecognised content starting with {:?}",
        String::from_utf8_lossy(&head.bytes[..n.min(16)])
    )))
}

/// Opens an event file (`-`: stdin) with the reader its content calls for.
pub fn open(path: &Path) -> Result<Box<dyn EventReader>> {
    open_with(path, &OpenOptions::default())
}

/// Opens an event file (or a rosbag2 folder) as `opts` say.
pub fn open_with(path: &Path, opts: &OpenOptions) -> Result<Box<dyn EventReader>> {
    if path.is_dir() {
        folder_format(path)?;
        check_options(Format::Rosbag2, path, opts)?;
        let reader = rosbag2::folder(path, opts.topic.as_deref())?;
        return finish(reader, Format::Rosbag2, path, opts);
    }
    let f = open_file(path)?;
    open_source_with(f, path, opts)
}

/// The reader that the content of `src` (named `path` in errors) calls for. The head is read
/// once, and the same stream is handed to the reader.
pub fn open_source(src: Box<dyn Source>, path: &Path) -> Result<Box<dyn EventReader>> {
    open_source_with(src, path, &OpenOptions::default())
}

/// [`open_source`] as `opts` say.
pub fn open_source_with(
    mut src: Box<dyn Source>,
    path: &Path,
    opts: &OpenOptions,
) -> Result<Box<dyn EventReader>> {
    let (probed, open) = probe_registered(src.as_mut(), path)?;
    let format = probed.format;
    check_options(format, path, opts)?;
    let reader = open(src, path, opts, probed)?;
    finish(reader, format, path, opts)
}

/// Refuses options that the format cannot take.
fn check_options(format: Format, path: &Path, opts: &OpenOptions) -> Result<()> {
    let option_error = |reason: &str| {
        Err(EventError::Unfit {
            path: path.to_path_buf(),
            reason: reason.into(),
        })
    };
    if opts.topic.is_some() && !matches!(format, Format::RosBag | Format::Rosbag2) {
        return option_error("a topic can be named only for ROS bags");
    }
    if opts.chip.is_some() && format != Format::Aedat2 {
        return option_error("a chip can be named only for jAER AEDAT 2.0 files");
    }
    Ok(())
}

/// The reader as every caller gets it: the camera asked for checked, damage and wild times
/// guarded, AEDAT4 read ahead.
fn finish(
    reader: Box<dyn EventReader>,
    format: Format,
    path: &Path,
    opts: &OpenOptions,
) -> Result<Box<dyn EventReader>> {
    let option_error = |reason: String| EventError::Unfit {
        path: path.to_path_buf(),
        reason,
    };
    if let Some(c) = opts.camera {
        let n = reader.info().cameras.len().max(1);
        if c as usize >= n {
            return Err(option_error(format!(
                "camera {c} asked for, but the file holds {n} camera{} (numbered from 0)",
                if n == 1 { "" } else { "s" }
            )));
        }
    }
    let guarded = guard::Guarded::new(
        reader,
        path,
        opts.strict,
        opts.max_gap_us.unwrap_or(DEFAULT_MAX_GAP_US),
    );
    // AEDAT4 packets and HDF5 slices are decoded on both cores: reading ahead on a thread of
    // its own lets the consumer's work overlap with them (about 5 % off a 60 s LZ4
    // extraction); the word formats decode on one core in small batches, where handing
    // batches across threads cost more than it saved (7–20 % slower), so they are read in line
    if matches!(format, Format::Aedat4 | Format::Hdf5) {
        return prefetch::read_ahead(Box::new(guarded), path);
    }
    Ok(Box::new(guarded))
}

/// Counts and ranges of a whole stream, from reading it to the end.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct StreamStats {
    /// Number of events.
    pub events: u64,
    /// ON events.
    pub on: u64,
    /// First timestamp (µs).
    pub first_t: Option<i64>,
    /// Last timestamp (µs).
    pub last_t: Option<i64>,
    /// Smallest and largest x.
    pub x_range: Option<(u16, u16)>,
    /// Smallest and largest y.
    pub y_range: Option<(u16, u16)>,
}

impl StreamStats {
    /// Adds a batch.
    pub fn add(&mut self, b: &EventBatch) {
        if b.is_empty() {
            return;
        }
        self.events += b.len() as u64;
        self.on += b.p.iter().filter(|&&p| p).count() as u64;
        self.first_t.get_or_insert(b.t[0]);
        self.last_t = Some(b.t[b.len() - 1]);
        let range = |v: &[u16], r: &mut Option<(u16, u16)>| {
            let lo = *v.iter().min().unwrap();
            let hi = *v.iter().max().unwrap();
            *r = Some(match *r {
                Some((a, b)) => (a.min(lo), b.max(hi)),
                None => (lo, hi),
            });
        };
        range(&b.x, &mut self.x_range);
        range(&b.y, &mut self.y_range);
    }

    /// Reads `reader` to the end.
    pub fn scan(reader: &mut dyn EventReader) -> Result<Self> {
        let mut s = StreamStats::default();
        while let Some(b) = reader.next_batch()? {
            s.add(&b);
        }
        Ok(s)
    }
}
