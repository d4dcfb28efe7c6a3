//! rosbag2 recordings (<https://github.com/ros2/rosbag2>) of event messages: a folder holding
//! `metadata.yaml` and one or more storage files, read in the order the metadata lists them
//! (else by name). A storage file opens on its own too:
//! - SQLite (`.db3`, metadata versions 4 to 8): table `topics` (id, name, type,
//!   serialization_format) and table `messages` (id, topic_id, timestamp, data), read in the
//!   order they were written (by id), a page at a time;
//! - MCAP (`.mcap`, <https://mcap.dev/spec>): read as a stream by the `mcap` crate's sans-io
//!   reader (chunks uncompressed, zstd or lz4); the summary at the end, when the file has one,
//!   names the topics and counts their messages before any is read.
//!
//! Files compressed whole (`.db3.zstd`, `.mcap.zstd`) are expanded to a temporary file first;
//! messages compressed one by one (zstd) are expanded as they are read. The messages are those
//! of [`crate::rosmsg`], in CDR (or the ROS 1 serialisation, in an MCAP that says `ros1`).

use std::collections::{HashMap, VecDeque};
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{sync_channel, Receiver};
use std::sync::{Arc, OnceLock};

use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::sans_io::{SummaryReadEvent, SummaryReader, SummaryReaderOptions};

use crate::error::{io_err, EventError, Result};
use crate::held::Held;
use crate::rosmsg::{kind_of, MessageDecoder, Serialization, TYPES};
use crate::spool::NamedCopy;

pub mod folder;
use crate::{EventBatch, EventReader, Source, StreamDesc, StreamInfo};
pub use folder::{folder, is_folder, storage_files};

/// The first bytes of an SQLite database.
pub const SQLITE_MAGIC: &[u8] = b"SQLite format 3\0";
/// The first bytes of an MCAP file.
pub const MCAP_MAGIC: &[u8] = b"\x89MCAP0\r\n";
/// The first bytes of a zstd frame.
const ZSTD_MAGIC: &[u8] = &[0x28, 0xB5, 0x2F, 0xFD];
const SQLITE: &str = "rosbag2 (SQLite)";
const MCAP: &str = "rosbag2 (MCAP)";
/// The largest message accepted, expanded: 16 MiB holds a million events in the roomiest
/// encoding (dvs_msgs, 16 bytes an event), more than a camera driver publishes at once, and
/// keeps the messages in flight, their expansion and their events under 200 MB.
pub const MAX_MESSAGE: usize = 16 << 20;
/// The largest MCAP record (a chunk, compressed or not, or a record inside one).
pub const MAX_RECORD: usize = 2 * MAX_MESSAGE;
/// The size an SQLite database's header states (page size × page count, when the count is
/// valid: <https://www.sqlite.org/fileformat.html#in_header_database_size>).
fn sqlite_size(head: &[u8]) -> Option<u64> {
    let be32 = |at: usize| -> Option<u32> {
        Some(u32::from_be_bytes(head.get(at..at + 4)?.try_into().ok()?))
    };
    let page = match u16::from_be_bytes(head.get(16..18)?.try_into().ok()?) {
        1 => 65536,
        p => u64::from(p),
    };
    let (pages, change, valid_for) = (be32(28)?, be32(24)?, be32(92)?);
    (pages > 0 && change == valid_for).then(|| page * u64::from(pages))
}

/// Bytes of messages fetched from SQLite at a time, at most (and one message).
const PAGE_BYTES: usize = 4 << 20;
/// Messages fetched from SQLite at a time.
const PAGE: usize = 256;

/// A topic of a bag.
#[derive(Debug, Clone)]
struct Topic {
    /// SQLite topic id or MCAP channel id.
    id: i64,
    name: String,
    msg_type: String,
    serialization: String,
    count: Option<u64>,
}

/// One storage file, read message by message for one topic.
enum Storage {
    Sqlite(SqliteFile),
    Mcap(McapFile),
}

/// An SQLite storage file.
struct SqliteFile {
    db: rusqlite::Connection,
    /// Keeps a copy of what could not be opened by name (stdin, a `.db3.zstd`) alive.
    _copy: Option<NamedCopy>,
    topic: Option<i64>,
    entry: Option<Topic>,
    last_id: i64,
    /// Messages fetched and not yet handed on (one too large is its reason).
    page: VecDeque<Message>,
    ended: bool,
}

/// An MCAP storage file.
struct McapFile {
    /// The file, or the stream a `.mcap.zstd` expands to (read as it expands).
    src: Box<dyn Read + Send>,
    reader: LinearReader,
    /// Channel id → topic; schema id → type name.
    channels: HashMap<u16, Topic>,
    schemas: HashMap<u16, String>,
}

/// Messages of the chosen topic, and what the choice needs to know.
struct Chosen {
    name: String,
    serialization: Serialization,
}

/// The reader of one topic of a rosbag2.
pub struct Rosbag2Reader {
    path: PathBuf,
    files: Vec<PathBuf>,
    next_file: usize,
    storage: Option<Storage>,
    /// The storage file being read, on a thread of its own.
    feed: Option<Receiver<Vec<Fed>>>,
    /// What the thread handed on and the decoder has yet to take.
    fed: std::vec::IntoIter<Fed>,
    format: &'static str,
    /// The topic asked for, then the topic read.
    wanted: Option<String>,
    chosen: Option<Chosen>,
    /// The chosen topic's name, for the thread that reads the file.
    chosen_name: Arc<OnceLock<String>>,
    /// The topics that messages came from (an MCAP without a summary names no others).
    seen: Vec<Topic>,
    decoder: Option<MessageDecoder>,
    info: StreamInfo,
    held: Held,
    done: bool,
    messages: u64,
    /// The topics of the first file, kept when it ends (an MCAP without a summary names them
    /// only as they come).
    first_topics: Vec<Topic>,
}

/// A reader of the rosbag2 storage file in `src` (named `path`).
pub fn reader(
    src: Box<dyn Source>,
    path: &Path,
    topic: Option<&str>,
) -> Result<Box<dyn EventReader>> {
    start(path, vec![path.to_path_buf()], Some(src), topic)
}

fn start(
    path: &Path,
    files: Vec<PathBuf>,
    first: Option<Box<dyn Source>>,
    topic: Option<&str>,
) -> Result<Box<dyn EventReader>> {
    let mut r = Rosbag2Reader {
        path: path.to_path_buf(),
        files,
        next_file: 0,
        storage: None,
        feed: None,
        fed: Vec::new().into_iter(),
        format: SQLITE,
        wanted: topic.map(str::to_string),
        chosen: None,
        chosen_name: Arc::new(OnceLock::new()),
        seen: Vec::new(),
        decoder: None,
        info: StreamInfo::default(),
        held: Held::default(),
        done: false,
        messages: 0,
        first_topics: Vec::new(),
    };
    r.open_next(first)?;
    r.info.format = r.format;
    let topics = r.topics();
    if r.storage.is_some() {
        r.choose(&topics)?;
    }
    // the sensor's size comes with the first message: read it now, hand it out first
    let first = r.read_batch();
    r.held.hold(first);
    // an MCAP without a summary: the channels seen so far
    let topics = match (topics.is_empty(), r.first_topics.is_empty()) {
        (false, _) => topics,
        (true, true) => r.topics(),
        (true, false) => r.first_topics.clone(),
    };
    if r.chosen.is_none() && !r.held.failed() {
        return Err(r.no_topic(&topics));
    }
    r.info.streams = topics
        .iter()
        .map(|t| StreamDesc {
            id: t.id as i32,
            kind: t.msg_type.clone(),
            source: Some(t.name.clone()),
            messages: t.count,
            ..StreamDesc::default()
        })
        .collect();
    Ok(Box::new(r))
}

impl Rosbag2Reader {
    /// Opens the next storage file (`src`: the first one, already open).
    fn open_next(&mut self, src: Option<Box<dyn Source>>) -> Result<bool> {
        let Some(file) = self.files.get(self.next_file).cloned() else {
            self.storage = None;
            return Ok(false);
        };
        self.next_file += 1;
        let io = |e| io_err(&file, e);
        let mut src = match src {
            Some(s) => s,
            None => crate::open_file(&file)?,
        };
        let mut head = [0u8; 16];
        let n = read_full(&mut src, &mut head).map_err(io)?;
        src.seek(SeekFrom::Start(0)).map_err(io)?;
        let head = &head[..n];
        if head.starts_with(ZSTD_MAGIC) {
            return self.open_zstd(&file, src);
        }
        if !head.starts_with(SQLITE_MAGIC) && !head.starts_with(MCAP_MAGIC) {
            return Err(EventError::UnknownFormat {
                path: file,
                reason: "a rosbag2 storage file that is neither SQLite nor MCAP".into(),
                supported: crate::SUPPORTED,
            });
        }
        if head.starts_with(MCAP_MAGIC) {
            let channels = mcap_summary(&mut src);
            return self.open_mcap(Box::new(src), channels);
        }
        let mut copy = None;
        if !std::fs::metadata(&file).is_ok_and(|m| m.is_file()) {
            // SQLite opens files by name: a pipe's content goes to a named temporary file
            let (c, f) = crate::spool::spool(&[], &mut src, None).map_err(io)?;
            copy = Some(c);
            src = Box::new(f);
        }
        drop(src);
        self.open_sqlite(&file, copy)
    }

    /// A storage file compressed whole (rosbag2's zstd file mode), its content checked as soon
    /// as its first bytes expand: an MCAP is read as it expands; an SQLite database (which
    /// opens files by name) is expanded to a temporary file, no larger than its header states.
    fn open_zstd(&mut self, file: &Path, mut src: Box<dyn Source>) -> Result<bool> {
        let damaged = |e: std::io::Error| EventError::Damaged {
            path: file.to_path_buf(),
            format: "rosbag2 (zstd file)",
            reason: format!("it does not expand: {e}"),
        };
        let compressed = src.seek(SeekFrom::End(0)).map_err(|e| io_err(file, e))?;
        src.seek(SeekFrom::Start(0)).map_err(|e| io_err(file, e))?;
        let z = zstd::stream::read::Decoder::new(src).map_err(|e| io_err(file, e))?;
        let mut z = crate::spool::Bounded::new(
            z,
            crate::spool::expansion_bound(compressed),
            "a hundred times its compressed size and 64 MiB: not event data",
        );
        let mut head = [0u8; 100];
        let n = read_full(&mut z, &mut head).map_err(damaged)?;
        let head = &head[..n];
        if head.starts_with(MCAP_MAGIC) {
            let whole = std::io::Cursor::new(head.to_vec()).chain(z);
            return self.open_mcap(Box::new(whole), HashMap::new());
        }
        if !head.starts_with(SQLITE_MAGIC) {
            return Err(EventError::UnknownFormat {
                path: file.to_path_buf(),
                reason: "a zstd file that holds neither an SQLite nor an MCAP rosbag2".into(),
                supported: crate::SUPPORTED,
            });
        }
        let (copy, _) = crate::spool::spool(head, &mut z, sqlite_size(head)).map_err(damaged)?;
        self.open_sqlite(file, Some(copy))
    }

    /// An MCAP storage file: its summary read first when it can be (a file, not a stream).
    fn open_mcap(
        &mut self,
        src: Box<dyn Read + Send>,
        channels: HashMap<u16, Topic>,
    ) -> Result<bool> {
        self.format = MCAP;
        self.storage = Some(Storage::Mcap(McapFile {
            src,
            reader: LinearReader::new_with_options(
                LinearReaderOptions::default().with_record_length_limit(MAX_RECORD),
            ),
            channels,
            schemas: HashMap::new(),
        }));
        Ok(true)
    }

    /// An SQLite storage file, by name (`copy`'s, when it is a copy).
    fn open_sqlite(&mut self, file: &Path, copy: Option<NamedCopy>) -> Result<bool> {
        let io = |e| io_err(file, e);
        self.format = SQLITE;
        let name: &Path = copy.as_ref().map_or(file, NamedCopy::path);
        let damaged = |e: rusqlite::Error| sqlite_damage(file, e);
        // immutable: read-only folders open, and nothing (a journal, a lock) is written
        let uri = format!(
            "file:{}?immutable=1",
            percent_path(&std::path::absolute(name).map_err(io)?)
        );
        let db = rusqlite::Connection::open_with_flags(
            uri,
            rusqlite::OpenFlags::SQLITE_OPEN_READ_ONLY
                | rusqlite::OpenFlags::SQLITE_OPEN_URI
                | rusqlite::OpenFlags::SQLITE_OPEN_NO_MUTEX,
        )
        .map_err(damaged)?;
        let has_topics: bool = db
            .query_row(
                "SELECT count(*) FROM sqlite_master WHERE type='table' AND name IN ('topics','messages')",
                [],
                |r| r.get::<_, i64>(0),
            )
            .map_err(damaged)?
            == 2;
        if !has_topics {
            return Err(EventError::Unfit {
                path: file.to_path_buf(),
                reason: "an SQLite database without the tables of a rosbag2 (topics, messages)"
                    .into(),
            });
        }
        self.storage = Some(Storage::Sqlite(SqliteFile {
            db,
            _copy: copy,
            topic: None,
            entry: None,
            last_id: i64::MIN,
            page: VecDeque::new(),
            ended: false,
        }));
        Ok(true)
    }

    /// The topics of the storage file open now, with their message counts where known.
    fn topics(&self) -> Vec<Topic> {
        match &self.storage {
            Some(Storage::Sqlite(s)) => s.topics().unwrap_or_default(),
            Some(Storage::Mcap(m)) => {
                let mut t: Vec<Topic> = m.channels.values().cloned().collect();
                t.sort_by_key(|t| t.id);
                t
            }
            None => Vec::new(),
        }
    }

    /// Picks the topic to read from `topics` (of the first file).
    fn choose(&mut self, topics: &[Topic]) -> Result<()> {
        let pick = match &self.wanted {
            Some(name) => topics.iter().find(|t| &t.name == name),
            None => topics.iter().find(|t| kind_of(&t.msg_type).is_some()),
        };
        match pick {
            Some(t) => self.take(t),
            // an MCAP without a summary names its channels as they come
            None if matches!(self.storage, Some(Storage::Mcap(_))) && topics.is_empty() => Ok(()),
            None => Err(self.no_topic(topics)),
        }
    }

    /// Reads topic `t` from now on.
    fn take(&mut self, t: &Topic) -> Result<()> {
        let Some(kind) = kind_of(&t.msg_type) else {
            return Err(EventError::Unfit {
                path: self.path.clone(),
                reason: format!(
                    "topic {} carries {}, not event messages eenf reads ({TYPES})",
                    t.name, t.msg_type
                ),
            });
        };
        let serialization = match t.serialization.as_str() {
            "cdr" | "" => Serialization::Cdr,
            "ros1" => Serialization::Ros1,
            other => {
                return Err(EventError::Unfit {
                    path: self.path.clone(),
                    reason: format!(
                        "topic {} is serialised as {other:?}; eenf reads cdr and ros1",
                        t.name
                    ),
                })
            }
        };
        self.info.within = Some(format!("topic {} ({})", t.name, t.msg_type));
        let _ = self.chosen_name.set(t.name.clone());
        self.chosen = Some(Chosen {
            name: t.name.clone(),
            serialization,
        });
        if self.decoder.is_none() {
            self.decoder = Some(MessageDecoder::new(kind));
        }
        Ok(())
    }

    fn no_topic(&self, topics: &[Topic]) -> EventError {
        let listing: Vec<String> = topics
            .iter()
            .map(|t| format!("{} ({})", t.name, t.msg_type))
            .collect();
        let has = if listing.is_empty() {
            "no topics".to_string()
        } else {
            listing.join(", ")
        };
        EventError::Unfit {
            path: self.path.clone(),
            reason: match &self.wanted {
                Some(name) => format!("no topic {name:?} in the bag; it has: {has}"),
                None => format!("no topic of event messages ({TYPES}) in the bag; it has: {has}"),
            },
        }
    }

    /// The next message of the chosen topic, across the storage files (expanded, or why it
    /// could not be); `None` at the end.
    fn next_message(&mut self) -> Result<Option<Message>> {
        loop {
            if self.feed.is_none() {
                let Some(storage) = self.storage.take() else {
                    return Ok(None);
                };
                let file = match self.next_file.checked_sub(1) {
                    Some(i) => self.files[i].clone(),
                    None => self.path.clone(),
                };
                self.feed = Some(feed(storage, file, self.chosen_name.clone()));
            }
            let got = match self.fed.next() {
                Some(got) => got,
                None => match self.feed.as_ref().map(|rx| rx.recv()) {
                    Some(Ok(batch)) => {
                        self.fed = batch.into_iter();
                        continue;
                    }
                    // the thread ended without a word: taken as the end of the file
                    _ => Ok(None),
                },
            };
            match got? {
                Some((topic, data)) => {
                    if !self.seen.iter().any(|t| t.id == topic.id) {
                        self.seen.push(topic.clone());
                    }
                    if self.chosen.is_none() {
                        // an MCAP without a summary: the first channel that fits is read
                        let fits = match &self.wanted {
                            Some(w) => &topic.name == w,
                            None => kind_of(&topic.msg_type).is_some(),
                        };
                        if fits {
                            self.take(&topic)?;
                        }
                    }
                    if self.chosen.as_ref().is_some_and(|c| c.name == topic.name) {
                        return Ok(Some(data));
                    }
                }
                None => {
                    self.feed = None;
                    self.fed = Vec::new().into_iter();
                    if self.next_file == 1 {
                        self.first_topics = std::mem::take(&mut self.seen);
                        self.first_topics.sort_by_key(|t| t.id);
                    }
                    if !self.open_next(None)? {
                        return Ok(None);
                    }
                }
            }
        }
    }

    /// The next batch of the topic's events, `None` at the end.
    fn read_batch(&mut self) -> Result<Option<EventBatch>> {
        let mut batch = EventBatch::default();
        while batch.len() < 1 << 16 && !self.done {
            let msg = match self.next_message() {
                Ok(Some(m)) => m,
                Ok(None) => {
                    self.done = true;
                    break;
                }
                Err(e) => return self.fail(e, batch),
            };
            self.messages += 1;
            let data = match msg {
                Ok(d) => d,
                Err(reason) => {
                    let e = self.message_error(reason);
                    return self.fail(e, batch);
                }
            };
            let (Some(d), Some(c)) = (self.decoder.as_mut(), self.chosen.as_ref()) else {
                continue;
            };
            let decoded = d.decode(&data, c.serialization, &mut batch);
            if self.info.width.is_none() {
                self.info.width = d.width;
                self.info.height = d.height;
            }
            d.describe(&mut self.info.within);
            if let Err(fault) = decoded {
                let e = fault.into_error(&self.path, |reason| self.message_error(reason));
                return self.fail(e, batch);
            }
        }
        Ok((!batch.is_empty()).then_some(batch))
    }

    fn message_error(&self, reason: String) -> EventError {
        EventError::Damaged {
            path: self.path.clone(),
            format: self.format,
            reason: format!("message {} of the topic: {reason}", self.messages),
        }
    }

    fn fail(&mut self, e: EventError, batch: EventBatch) -> Result<Option<EventBatch>> {
        self.done = true;
        self.held.fail(e, batch)
    }
}

impl EventReader for Rosbag2Reader {
    fn info(&self) -> &StreamInfo {
        &self.info
    }

    fn next_batch(&mut self) -> Result<Option<EventBatch>> {
        match self.held.take() {
            Some(held) => held,
            None => self.read_batch(),
        }
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        self.decoder
            .as_ref()
            .map(MessageDecoder::skipped)
            .unwrap_or_default()
    }
}

/// What the thread reading a storage file hands on: a message's topic and its bytes
/// (expanded, or why they could not be), `None` at the end of the file, or the damage that
/// ended it.
/// A message's bytes, or why it cannot be read (the message is skipped, the bag goes on).
type Message = std::result::Result<Vec<u8>, String>;
type Fed = Result<Option<(Topic, Message)>>;

/// Batches in flight between the thread reading a file and the decoder.
const IN_FLIGHT: usize = 4;
/// A batch ends past this many bytes or messages: one hand-over, and one wake-up of the
/// decoder, for many small messages (metavision_driver publishes a few KiB each millisecond).
const BATCH_BYTES: usize = 1 << 20;
const BATCH_MESSAGES: usize = 256;

/// Reads `storage` (the file `file`) on a thread of its own, so that SQLite's or MCAP's work
/// (pages, chunks, zstd) runs beside the decoding of the messages: the messages of the topic
/// named in `chosen`, or of every topic until one is chosen, handed on in batches.
fn feed(storage: Storage, file: PathBuf, chosen: Arc<OnceLock<String>>) -> Receiver<Vec<Fed>> {
    let (tx, rx) = sync_channel(IN_FLIGHT);
    std::thread::spawn(move || {
        let mut storage = storage;
        let mut end = false;
        while !end {
            let mut batch = Vec::new();
            let mut bytes = 0;
            while !end && bytes < BATCH_BYTES && batch.len() < BATCH_MESSAGES {
                let item = match &mut storage {
                    Storage::Sqlite(s) => s.next_of(chosen.get(), &file),
                    Storage::Mcap(m) => m
                        .next_of(chosen.get(), &file)
                        .map(|m| m.map(|(t, data)| (t, Ok(data)))),
                };
                let item = item.map(|m| m.map(|(t, data)| (t, data.and_then(expand_message))));
                match &item {
                    Ok(Some((_, Ok(data)))) => bytes += data.len(),
                    Ok(Some(_)) => {}
                    _ => end = true,
                }
                batch.push(item);
            }
            // a send fails once the reader is dropped: nothing is left to read for
            if tx.send(batch).is_err() {
                break;
            }
        }
    });
    rx
}

/// The channels an MCAP file's summary names (none when it has no summary), `src` left at
/// its start.
fn mcap_summary(src: &mut dyn Source) -> HashMap<u16, Topic> {
    let mut channels = HashMap::new();
    let Ok(len) = src.seek(SeekFrom::End(0)) else {
        return channels;
    };
    let mut s = SummaryReader::new_with_options(
        SummaryReaderOptions::default()
            .with_file_size(len)
            .with_record_length_limit(MAX_RECORD),
    );
    let mut ok = true;
    while let Some(event) = s.next_event() {
        match event {
            Ok(SummaryReadEvent::ReadRequest(n)) => match src.read(s.insert(n)) {
                Ok(k) => s.notify_read(k),
                Err(_) => {
                    ok = false;
                    break;
                }
            },
            Ok(SummaryReadEvent::SeekRequest(to)) => match src.seek(to) {
                Ok(pos) => s.notify_seeked(pos),
                Err(_) => {
                    ok = false;
                    break;
                }
            },
            Err(_) => {
                ok = false;
                break;
            }
        }
    }
    if src.seek(SeekFrom::Start(0)).is_err() {
        return channels;
    }
    let summary = if ok { s.finish() } else { None };
    let Some(summary) = summary else {
        return channels;
    };
    let counts = summary
        .stats
        .as_ref()
        .map(|s| s.channel_message_counts.clone())
        .unwrap_or_default();
    for (id, c) in &summary.channels {
        channels.insert(
            *id,
            Topic {
                id: *id as i64,
                name: c.topic.clone(),
                msg_type: c
                    .schema
                    .as_ref()
                    .map(|s| s.name.clone())
                    .unwrap_or_default(),
                serialization: c.message_encoding.clone(),
                count: summary
                    .stats
                    .as_ref()
                    .map(|_| counts.get(id).copied().unwrap_or(0)),
            },
        );
    }
    channels
}

/// A message compressed on its own (rosbag2's message compression mode), expanded.
fn expand_message(msg: Vec<u8>) -> Message {
    if !msg.starts_with(ZSTD_MAGIC) {
        return Ok(msg);
    }
    let mut out = Vec::new();
    zstd::stream::read::Decoder::new(&msg[..])
        .and_then(|d| d.take(MAX_MESSAGE as u64 + 1).read_to_end(&mut out))
        .map_err(|e| format!("a compressed message that does not expand: {e}"))?;
    if out.len() > MAX_MESSAGE {
        return Err("a compressed message that expands past 1 GiB".into());
    }
    Ok(out)
}

fn sqlite_damage(file: &Path, e: rusqlite::Error) -> EventError {
    EventError::Damaged {
        path: file.to_path_buf(),
        format: SQLITE,
        // SQLite quotes a damaged schema's statements whole, line breaks and all
        reason: e
            .to_string()
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" "),
    }
}

/// A path written into an SQLite URI (`?`, `#` and `%` escaped).
fn percent_path(p: &Path) -> String {
    let mut out = String::new();
    for b in p.as_os_str().as_encoded_bytes() {
        match b {
            b'?' | b'#' | b'%' => out.push_str(&format!("%{b:02X}")),
            _ if b.is_ascii() => out.push(*b as char),
            _ => out.push_str(&format!("%{b:02X}")),
        }
    }
    out
}

fn read_full(src: &mut dyn Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut n = 0;
    while n < buf.len() {
        match src.read(&mut buf[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(n)
}

impl SqliteFile {
    fn topics(&self) -> rusqlite::Result<Vec<Topic>> {
        let mut counts: HashMap<i64, u64> = HashMap::new();
        let mut q = self
            .db
            .prepare("SELECT topic_id, count(*) FROM messages GROUP BY topic_id")?;
        for row in q.query_map([], |r| Ok((r.get::<_, i64>(0)?, r.get::<_, i64>(1)?)))? {
            let (id, n) = row?;
            counts.insert(id, n.max(0) as u64);
        }
        let mut q = self
            .db
            .prepare("SELECT id, name, type, serialization_format FROM topics ORDER BY id")?;
        let topics = q
            .query_map([], |r| {
                let id: i64 = r.get(0)?;
                Ok(Topic {
                    id,
                    name: r.get(1)?,
                    msg_type: r.get(2)?,
                    serialization: r.get(3)?,
                    count: Some(counts.get(&id).copied().unwrap_or(0)),
                })
            })?
            .collect();
        topics
    }

    /// The next message of the topic named `chosen` (resolved on the first call).
    fn next_of(&mut self, chosen: Option<&String>, file: &Path) -> Fed {
        if self.topic.is_none() && !self.ended {
            let topic = self
                .topics()
                .map_err(|e| sqlite_damage(file, e))?
                .into_iter()
                .find(|t| Some(&t.name) == chosen);
            self.topic = topic.as_ref().map(|t| t.id);
            self.entry = topic;
            self.ended = self.topic.is_none();
        }
        let Some(entry) = &self.entry else {
            return Ok(None);
        };
        let entry = entry.clone();
        Ok(self
            .next()
            .map_err(|e| sqlite_damage(file, e))?
            .map(|m| (entry, m)))
    }

    /// The next message of the topic, in the order they were written. A message's length is
    /// read before its bytes: one past [`MAX_MESSAGE`] is never fetched, and a page ends
    /// past [`PAGE_BYTES`].
    fn next(&mut self) -> rusqlite::Result<Option<Message>> {
        if self.page.is_empty() && !self.ended {
            let Some(topic) = self.topic else {
                return Ok(None);
            };
            let mut q = self.db.prepare_cached(
                "SELECT id, length(data), CASE WHEN length(data) <= ?4 THEN data END \
                 FROM messages WHERE topic_id = ?1 AND id > ?2 ORDER BY id LIMIT ?3",
            )?;
            let mut rows = q.query(rusqlite::params![
                topic,
                self.last_id,
                PAGE as i64,
                MAX_MESSAGE as i64
            ])?;
            let (mut n, mut bytes) = (0, 0);
            while let Some(r) = rows.next()? {
                let (id, len) = (r.get::<_, i64>(0)?, r.get::<_, Option<i64>>(1)?);
                self.last_id = id;
                n += 1;
                let data = match r.get::<_, Option<Vec<u8>>>(2)? {
                    Some(d) => Ok(d),
                    None if len.is_none() => Ok(Vec::new()),
                    None => Err(format!(
                        "a message of {} bytes (eenf reads messages up to {} MiB)",
                        len.unwrap_or(0),
                        MAX_MESSAGE >> 20
                    )),
                };
                bytes += data.as_ref().map_or(0, Vec::len);
                self.page.push_back(data);
                if bytes > PAGE_BYTES {
                    break;
                }
            }
            self.ended = n < PAGE && bytes <= PAGE_BYTES;
        }
        Ok(self.page.pop_front())
    }
}

impl McapFile {
    /// The next message of the channel of topic `chosen`, or of any channel: its topic and
    /// bytes; `None` at the end.
    fn next_of(
        &mut self,
        chosen: Option<&String>,
        file: &Path,
    ) -> Result<Option<(Topic, Vec<u8>)>> {
        let damaged = |reason: String| EventError::Damaged {
            path: file.to_path_buf(),
            format: MCAP,
            reason,
        };
        while let Some(event) = self.reader.next_event() {
            match event.map_err(|e| damaged(e.to_string()))? {
                LinearReadEvent::ReadRequest(n) => {
                    let k = self
                        .src
                        .read(self.reader.insert(n))
                        .map_err(|e| io_err(file, e))?;
                    self.reader.notify_read(k);
                }
                LinearReadEvent::Record { data, opcode } => {
                    match mcap::parse_record(opcode, data).map_err(|e| damaged(e.to_string()))? {
                        mcap::records::Record::Schema { header, .. } => {
                            self.schemas.insert(header.id, header.name);
                        }
                        mcap::records::Record::Channel(c) => {
                            let msg_type =
                                self.schemas.get(&c.schema_id).cloned().unwrap_or_default();
                            self.channels.entry(c.id).or_insert(Topic {
                                id: c.id as i64,
                                name: c.topic,
                                msg_type,
                                serialization: c.message_encoding,
                                count: None,
                            });
                        }
                        mcap::records::Record::Message { header, data } => {
                            let Some(t) = self.channels.get(&header.channel_id) else {
                                continue;
                            };
                            if chosen.is_none_or(|c| c == &t.name) {
                                return Ok(Some((t.clone(), data.into_owned())));
                            }
                        }
                        _ => {}
                    }
                }
            }
        }
        Ok(None)
    }
}

/// rosbag2 storage files for probing ([`crate::registry`]): SQLite's or MCAP's magic.
pub const REGISTERED: crate::Registered = crate::Registered {
    probe: |head, _, _| {
        let found = head.starts_with(SQLITE_MAGIC) || head.starts_with(MCAP_MAGIC);
        Ok(found.then(|| crate::Probed::of(crate::Format::Rosbag2)))
    },
    open: |src, path, opts, _| reader(src, path, opts.topic.as_deref()),
};
