//! Events in HDF5 files, read with a pure-Rust HDF5 reader (`hdf5-reader`; no libhdf5) and
//! eenf's own registry of the filters event data sets use: deflate (built in), zstd (32015),
//! blosc (32001, through c-blosc built in) and Prophesee's ECF (0x8ECF, [`ecf`]).
//!
//! The layouts are found by what the file holds, not by its name:
//! - a group with datasets `x`, `y`, `p` (or `polarity`) and `t` of integers: DSEC and TUM-VIE
//!   (`/events`), M3ED (`/prophesee/left`, `/prophesee/right`); a scalar `t_offset` in the
//!   group or above it (DSEC) is added to `t` (µs);
//! - a compound dataset `events` with fields `x`, `y`, `p`, `t`: Prophesee's `/CD/events`, its
//!   sensor size in the root attribute `geometry` (`640x480`);
//! - an N × 4 dataset `events` of floats: MVSEC (`/davis/left/events`: x, y, t in seconds,
//!   polarity ±1).
//!
//! A file with several cameras (M3ED, MVSEC) lists them in [`crate::StreamInfo::cameras`];
//! the first is read unless [`crate::OpenOptions::camera`] names another. Events are read a
//! slice at a time, the chunks of a slice decoded on all cores: memory stays flat however long
//! the recording.
//!
//! What a file claims bounds nothing until it is read: a chunk larger than
//! [`filters::MAX_CHUNK`] is refused before any is decoded, and rows a chunked dataset claims
//! but does not store (HDF5 reads them as the fill value: one row repeated) end the events
//! with an error, however many rows were claimed.

pub mod ecf;
mod filters;

use std::path::{Path, PathBuf};

use hdf5_reader::group::Group;
use hdf5_reader::{Dataset, Datatype, Hdf5File, SliceInfo, SliceInfoElem};

use crate::error::{io_err, EventError, Result};
use crate::{EventBatch, EventReader, Source, StreamInfo};

/// The first bytes of an HDF5 file (at offset 0; files with a user block are not sniffed).
pub const MAGIC: &[u8] = b"\x89HDF\r\n\x1a\n";
const FORMAT: &str = "HDF5";
/// Events read per slice.
const SLICE: u64 = 1 << 20;
/// How deep groups are searched for events.
const MAX_DEPTH: usize = 6;
/// Rows of one value in a slice that mean the rows are not stored (no camera repeats one
/// event at one time this often).
pub const FILL_RUN: usize = 16;

/// How a camera's events are stored.
enum Layout {
    /// One dataset per field (DSEC, TUM-VIE, M3ED).
    Columns {
        /// x, y, p, t.
        xypt: Box<[Dataset; 4]>,
        t_offset: i64,
    },
    /// One compound dataset (Prophesee `CD/events`).
    Compound {
        events: Dataset,
        fields: CompoundFields,
    },
    /// An N × 4 table of floats: x, y, t (s), p (MVSEC).
    Table { events: Dataset },
}

/// Where the fields of a compound event record are, and their types.
#[derive(Debug, Clone)]
struct CompoundFields {
    size: usize,
    x: (usize, Datatype),
    y: (usize, Datatype),
    p: (usize, Datatype),
    t: (usize, Datatype),
}

/// A camera found in the file: its group's path and how its events are stored.
struct Camera {
    name: String,
    layout: Layout,
    len: u64,
    width: Option<u16>,
    height: Option<u16>,
}

/// The reader of one camera of an HDF5 file.
pub struct Hdf5Reader {
    path: PathBuf,
    /// Keeps the file alive (its datasets refer to it) and a copy of what had no name.
    _file: Hdf5File,
    _copy: Option<tempfile::TempPath>,
    camera: Camera,
    /// Compound datasets are read a chunk at a time.
    chunks: Option<hdf5_reader::DatasetChunkIterator>,
    pos: u64,
    info: StreamInfo,
    done: bool,
    /// The row from which the file stores no rows, once a slice found it.
    unstored: Option<u64>,
}

fn h5err(path: &Path, e: hdf5_reader::error::Error) -> EventError {
    EventError::Damaged {
        path: path.to_path_buf(),
        format: FORMAT,
        reason: e.to_string(),
    }
}

/// A reader of the HDF5 file in `src` (named `path`): camera `camera` (default the first).
pub fn reader(
    mut src: Box<dyn Source>,
    path: &Path,
    camera: Option<u8>,
) -> Result<Box<dyn EventReader>> {
    let io = |e| io_err(path, e);
    // the HDF5 reader opens files by name: a pipe's content goes to a named temporary file
    let mut copy = None;
    if !std::fs::metadata(path).is_ok_and(|m| m.is_file()) {
        let mut tmp = tempfile::NamedTempFile::new().map_err(io)?;
        std::io::copy(&mut src, tmp.as_file_mut()).map_err(io)?;
        copy = Some(tmp.into_temp_path());
    }
    let name: &Path = copy.as_deref().unwrap_or(path);
    let opts = hdf5_reader::OpenOptions::default()
        .with_filter_registry(filters::registry())
        // chunks are read once, in order: a small cache keeps the one a slice ends in
        .with_chunk_cache_bytes(16 << 20);
    let file = Hdf5File::open_with_options(name, opts).map_err(|e| h5err(path, e))?;
    let root = file.root_group().map_err(|e| h5err(path, e))?;
    let geometry = root
        .attribute("geometry")
        .ok()
        .and_then(|a| a.read_string().ok())
        .and_then(|g| {
            let (w, h) = g.trim().split_once('x')?;
            Some((w.trim().parse::<u16>().ok()?, h.trim().parse::<u16>().ok()?))
        });
    let mut cameras = Vec::new();
    find_cameras(&root, "", 0, None, &mut cameras).map_err(|e| h5err(path, e))?;
    if cameras.is_empty() {
        return Err(EventError::Unfit {
            path: path.to_path_buf(),
            reason: "an HDF5 file without events eenf knows (datasets x, y, p, t in a group; a compound CD/events; an N×4 events table)".into(),
        });
    }
    let names: Vec<String> = cameras.iter().map(|c| c.name.clone()).collect();
    let pick = camera.unwrap_or(0) as usize;
    if pick >= cameras.len() {
        return Err(EventError::Unfit {
            path: path.to_path_buf(),
            reason: format!(
                "camera {pick} asked for, but the file holds {} ({})",
                cameras.len(),
                names.join(", ")
            ),
        });
    }
    let mut cam = cameras.swap_remove(pick);
    check_chunks(&cam.layout).map_err(|e| h5err(path, e))?;
    if cam.width.is_none() {
        if let Some((w, h)) = geometry {
            cam.width = Some(w);
            cam.height = Some(h);
        }
    }
    let info = StreamInfo {
        format: FORMAT,
        width: cam.width,
        height: cam.height,
        event_count: Some(cam.len),
        cameras: if names.len() > 1 { names } else { Vec::new() },
        camera: (camera.is_some()).then_some(pick as u8),
        within: Some(match &cam.layout {
            Layout::Columns { .. } => format!("group /{}", cam.name.trim_start_matches('/')),
            _ => format!("dataset /{}", cam.name),
        }),
        ..StreamInfo::default()
    };
    let chunks = match &cam.layout {
        Layout::Compound { events, .. } if events.chunks().is_some() => {
            Some(events.iter_chunks().map_err(|e| h5err(path, e))?)
        }
        _ => None,
    };
    Ok(Box::new(Hdf5Reader {
        path: path.to_path_buf(),
        _file: file,
        _copy: copy,
        camera: cam,
        chunks,
        pos: 0,
        info,
        done: false,
        unstored: None,
    }))
}

/// The cameras under `group` (at `prefix`), depth first; `t_offset` is the nearest one above.
fn find_cameras(
    group: &Group,
    prefix: &str,
    depth: usize,
    t_offset: Option<i64>,
    out: &mut Vec<Camera>,
) -> hdf5_reader::error::Result<()> {
    let (groups, datasets) = group.members()?;
    let by_name = |n: &str| datasets.iter().find(|d| leaf(d.name()) == n);
    let t_offset = by_name("t_offset")
        .and_then(|d| scalar_i64(d).ok())
        .or(t_offset);
    let here = |name: &str| {
        if prefix.is_empty() {
            name.to_string()
        } else {
            format!("{prefix}/{name}")
        }
    };
    let path = prefix.to_string();
    let columns = (
        by_name("x"),
        by_name("y"),
        by_name("p").or_else(|| by_name("polarity")),
        by_name("t").or_else(|| by_name("ts")),
    );
    if let (Some(x), Some(y), Some(p), Some(t)) = columns {
        let len = t.shape().first().copied().unwrap_or(0);
        if [x, y, p].iter().all(|d| d.shape() == t.shape()) && t.ndim() == 1 {
            // M3ED keeps the sensor size in calib/resolution
            let size = groups
                .iter()
                .find(|g| leaf(g.name()) == "calib")
                .and_then(|g| g.dataset("resolution").ok())
                .and_then(|d| d.read_array::<i32>().ok())
                .map(|a| a.iter().copied().collect::<Vec<i32>>())
                .filter(|v| v.len() == 2);
            out.push(Camera {
                name: if path.is_empty() {
                    "/".into()
                } else {
                    path.clone()
                },
                layout: Layout::Columns {
                    xypt: Box::new([x.clone(), y.clone(), p.clone(), t.clone()]),
                    t_offset: t_offset.unwrap_or(0),
                },
                len,
                width: size.as_ref().and_then(|v| u16::try_from(v[0]).ok()),
                height: size.as_ref().and_then(|v| u16::try_from(v[1]).ok()),
            });
        }
    }
    if let Some(events) = by_name("events") {
        let len = events.shape().first().copied().unwrap_or(0);
        match events.dtype() {
            Datatype::Compound { size, fields } => {
                let field = |n: &str| {
                    fields
                        .iter()
                        .find(|f| f.name == n)
                        .map(|f| (f.byte_offset as usize, f.datatype.clone()))
                };
                if let (Some(x), Some(y), Some(p), Some(t)) =
                    (field("x"), field("y"), field("p"), field("t"))
                {
                    out.push(Camera {
                        name: here("events"),
                        layout: Layout::Compound {
                            events: events.clone(),
                            fields: CompoundFields {
                                size: *size as usize,
                                x,
                                y,
                                p,
                                t,
                            },
                        },
                        len,
                        width: None,
                        height: None,
                    });
                }
            }
            Datatype::FloatingPoint { .. } if events.shape().get(1) == Some(&4) => {
                out.push(Camera {
                    name: here("events"),
                    layout: Layout::Table {
                        events: events.clone(),
                    },
                    len,
                    width: None,
                    height: None,
                });
            }
            _ => {}
        }
    }
    if depth < MAX_DEPTH {
        for g in &groups {
            find_cameras(g, &here(leaf(g.name())), depth + 1, t_offset, out)?;
        }
    }
    Ok(())
}

/// Refuses a chunk size past [`filters::MAX_CHUNK`]: a chunk is decoded whole, so its size
/// bounds the memory a slice takes.
fn check_chunks(layout: &Layout) -> hdf5_reader::error::Result<()> {
    let sets: Vec<&Dataset> = match layout {
        Layout::Columns { xypt, .. } => xypt.iter().collect(),
        Layout::Compound { events, .. } | Layout::Table { events } => vec![events],
    };
    for d in sets {
        let Some(dims) = d.chunks() else { continue };
        let bytes = dims
            .iter()
            .fold(d.raw_element_size()? as u128, |n, &k| n * u128::from(k));
        if bytes > filters::MAX_CHUNK as u128 {
            return Err(hdf5_reader::error::Error::InvalidData(format!(
                "dataset {} is stored in chunks of {:.0} MiB; eenf reads chunks up to {} MiB",
                d.name(),
                bytes as f64 / (1 << 20) as f64,
                filters::MAX_CHUNK >> 20
            )));
        }
    }
    Ok(())
}

/// Where the rows the file does not store begin in `b` (the rows from `start`): HDF5 reads
/// them as the fill value, so they end the slice as one row repeated. `None` when the slice
/// ends in real events.
pub fn stored_rows(b: &EventBatch) -> Option<usize> {
    let n = b.t.len();
    let last = n.checked_sub(1)?;
    let same = |i: usize| {
        b.t[i] == b.t[last] && b.x[i] == b.x[last] && b.y[i] == b.y[last] && b.p[i] == b.p[last]
    };
    let run = (0..n).rev().take_while(|&i| same(i)).count();
    (run >= FILL_RUN).then_some(n - run)
}

/// The error that ends the events at row `at` of the `claimed`.
pub fn not_stored(at: u64, claimed: u64) -> hdf5_reader::error::Error {
    hdf5_reader::error::Error::InvalidData(format!(
        "the file claims {claimed} rows but stores none from row {at} on (they read as one \
         value repeated): the events end there"
    ))
}

/// The last part of an HDF5 path.
fn leaf(name: &str) -> &str {
    name.rsplit('/').next().unwrap_or(name)
}

/// A scalar integer dataset's value.
fn scalar_i64(d: &Dataset) -> hdf5_reader::error::Result<i64> {
    read_numbers(d, &SliceInfo::all(d.ndim()))?
        .first_i64()
        .ok_or_else(|| hdf5_reader::error::Error::InvalidData("an empty t_offset".into()))
}

/// The numbers of a dataset's selection, in the dataset's own type.
enum Numbers {
    U8(Vec<u8>),
    I8(Vec<i8>),
    U16(Vec<u16>),
    I16(Vec<i16>),
    U32(Vec<u32>),
    I32(Vec<i32>),
    U64(Vec<u64>),
    I64(Vec<i64>),
    F32(Vec<f32>),
    F64(Vec<f64>),
}

/// Applies `$f` to the vector inside a [`Numbers`], whatever its type.
macro_rules! each {
    ($n:expr, $v:ident => $f:expr) => {
        match $n {
            Numbers::U8($v) => $f,
            Numbers::I8($v) => $f,
            Numbers::U16($v) => $f,
            Numbers::I16($v) => $f,
            Numbers::U32($v) => $f,
            Numbers::I32($v) => $f,
            Numbers::U64($v) => $f,
            Numbers::I64($v) => $f,
            Numbers::F32($v) => $f,
            Numbers::F64($v) => $f,
        }
    };
}

// `each!` writes one cast for every type, the type itself among them
#[allow(clippy::unnecessary_cast)]
impl Numbers {
    /// As coordinates: a `u16` column is handed on as it is, others are clamped.
    fn into_u16(self) -> Vec<u16> {
        match self {
            Numbers::U16(v) => v,
            n => {
                each!(n, v => v.iter().map(|&x| (x as f64).clamp(0.0, u16::MAX as f64) as u16).collect())
            }
        }
    }

    /// As times, µs, plus `offset` (floats are rounded).
    fn into_i64(self, offset: i64) -> Vec<i64> {
        match self {
            Numbers::I64(mut v) if offset == 0 => {
                v.shrink_to_fit();
                v
            }
            Numbers::F32(v) => v
                .iter()
                .map(|&x| (x as f64).round() as i64 + offset)
                .collect(),
            Numbers::F64(v) => v.iter().map(|&x| x.round() as i64 + offset).collect(),
            n => each!(n, v => v.iter().map(|&x| (x as i64).saturating_add(offset)).collect()),
        }
    }

    /// As polarities: ON when positive.
    fn into_bool(self) -> Vec<bool> {
        each!(self, v => v.iter().map(|&x| x as f64 > 0.0).collect())
    }

    fn first_i64(&self) -> Option<i64> {
        each!(self, v => v.first().map(|&x| x as i64))
    }
}

/// The numbers of `d`'s selection, its chunks decoded on all cores.
fn read_numbers(d: &Dataset, sel: &SliceInfo) -> hdf5_reader::error::Result<Numbers> {
    macro_rules! read {
        ($t:ty, $k:ident) => {
            Numbers::$k(
                d.read_slice_parallel::<$t>(sel)?
                    .into_raw_vec_and_offset()
                    .0,
            )
        };
    }
    Ok(match d.dtype() {
        Datatype::FixedPoint {
            size: 1,
            signed: false,
            ..
        } => read!(u8, U8),
        Datatype::FixedPoint {
            size: 1,
            signed: true,
            ..
        } => read!(i8, I8),
        Datatype::FixedPoint {
            size: 2,
            signed: false,
            ..
        } => read!(u16, U16),
        Datatype::FixedPoint {
            size: 2,
            signed: true,
            ..
        } => read!(i16, I16),
        Datatype::FixedPoint {
            size: 4,
            signed: false,
            ..
        } => read!(u32, U32),
        Datatype::FixedPoint {
            size: 4,
            signed: true,
            ..
        } => read!(i32, I32),
        Datatype::FixedPoint {
            size: 8,
            signed: false,
            ..
        } => read!(u64, U64),
        Datatype::FixedPoint {
            size: 8,
            signed: true,
            ..
        } => read!(i64, I64),
        Datatype::FloatingPoint { size: 4, .. } => read!(f32, F32),
        Datatype::FloatingPoint { size: 8, .. } => read!(f64, F64),
        other => {
            return Err(hdf5_reader::error::Error::InvalidData(format!(
                "dataset {} holds {other:?}, not numbers",
                d.name()
            )))
        }
    })
}

/// One field of a compound record, as `i64`.
fn field(r: &[u8], (off, dtype): &(usize, Datatype)) -> Option<i64> {
    let (size, signed, big) = match dtype {
        Datatype::FixedPoint {
            size,
            signed,
            byte_order,
        } => (
            *size as usize,
            *signed,
            *byte_order == hdf5_reader::ByteOrder::BigEndian,
        ),
        _ => return None,
    };
    let b = r.get(*off..off + size)?;
    let mut v = [0u8; 8];
    if big {
        for (i, &x) in b.iter().rev().enumerate() {
            v[i] = x;
        }
    } else {
        v[..size].copy_from_slice(b);
    }
    let u = u64::from_le_bytes(v);
    Some(if signed && size < 8 {
        let shift = 64 - 8 * size as u32;
        ((u << shift) as i64) >> shift
    } else {
        u as i64
    })
}

fn range(start: u64, end: u64) -> SliceInfoElem {
    SliceInfoElem::Slice {
        start,
        end,
        step: 1,
    }
}

impl Hdf5Reader {
    fn slice(&mut self) -> hdf5_reader::error::Result<EventBatch> {
        let (start, end) = (self.pos, (self.pos + SLICE).min(self.camera.len));
        let mut b = EventBatch::default();
        match &self.camera.layout {
            Layout::Columns { xypt, t_offset } => {
                let [x, y, p, t] = &**xypt;
                let sel = SliceInfo {
                    selections: vec![range(start, end)],
                };
                let offset = *t_offset;
                let u16s = |d| read_numbers(d, &sel).map(Numbers::into_u16);
                let ((xs, ys), (ps, ts)) = rayon::join(
                    || rayon::join(|| u16s(x), || u16s(y)),
                    || {
                        rayon::join(
                            || read_numbers(p, &sel).map(Numbers::into_bool),
                            || read_numbers(t, &sel).map(|n| n.into_i64(offset)),
                        )
                    },
                );
                (b.x, b.y, b.p, b.t) = (xs?, ys?, ps?, ts?);
                self.pos = end;
            }
            Layout::Table { events } => {
                let sel = SliceInfo {
                    selections: vec![range(start, end), range(0, 4)],
                };
                let rows = events.read_slice_parallel::<f64>(&sel)?;
                let rows = rows.as_slice().unwrap_or(&[]);
                for r in rows.chunks_exact(4) {
                    b.push(
                        (r[2] * 1e6).round() as i64,
                        r[0].clamp(0.0, u16::MAX as f64) as u16,
                        r[1].clamp(0.0, u16::MAX as f64) as u16,
                        r[3] > 0.0,
                    );
                }
                self.pos = end;
            }
            Layout::Compound { events, fields } => {
                let bytes: Vec<u8>;
                let (data, count) = match &mut self.chunks {
                    Some(chunks) => {
                        let Some(c) = chunks.next() else {
                            self.pos = self.camera.len;
                            return Ok(b);
                        };
                        let c = c?;
                        let first = c.offsets().first().copied().unwrap_or(0);
                        if first != self.pos {
                            return Err(hdf5_reader::error::Error::InvalidData(format!(
                                "a chunk at event {first} where event {} was due",
                                self.pos
                            )));
                        }
                        let n = c
                            .shape()
                            .first()
                            .copied()
                            .unwrap_or(0)
                            .min(self.camera.len - first);
                        bytes = c.bytes().to_vec();
                        (bytes, n)
                    }
                    None => {
                        // contiguous or compact: read whole (bounded by the file)
                        bytes = events.read_raw_bytes()?;
                        let n = self.camera.len;
                        (bytes, n)
                    }
                };
                for r in data.chunks_exact(fields.size.max(1)).take(count as usize) {
                    let (Some(x), Some(y), Some(p), Some(t)) = (
                        field(r, &fields.x),
                        field(r, &fields.y),
                        field(r, &fields.p),
                        field(r, &fields.t),
                    ) else {
                        return Err(hdf5_reader::error::Error::InvalidData(
                            "a compound event record whose fields are not integers".into(),
                        ));
                    };
                    b.push(
                        t,
                        x.clamp(0, u16::MAX as i64) as u16,
                        y.clamp(0, u16::MAX as i64) as u16,
                        p > 0,
                    );
                }
                self.pos += count;
            }
        }
        Ok(b)
    }
}

impl EventReader for Hdf5Reader {
    fn info(&self) -> &StreamInfo {
        &self.info
    }

    fn next_batch(&mut self) -> Result<Option<EventBatch>> {
        loop {
            if let Some(at) = self.unstored.take() {
                self.done = true;
                return Err(h5err(&self.path, not_stored(at, self.camera.len)));
            }
            if self.done || self.pos >= self.camera.len {
                break;
            }
            let start = self.pos;
            let mut slice = self.slice();
            if let (Ok(b), false) = (
                &mut slice,
                matches!(self.camera.layout, Layout::Compound { .. }),
            ) {
                // chunked compound datasets yield stored chunks only
                if let Some(kept) = stored_rows(b) {
                    b.truncate(kept);
                    self.unstored = Some(start + kept as u64);
                }
            }
            match slice {
                Ok(b) if b.is_empty() => continue,
                Ok(b) => return Ok(Some(b)),
                Err(e) => {
                    self.done = true;
                    return Err(h5err(&self.path, e));
                }
            }
        }
        self.done = true;
        Ok(None)
    }

    fn batch_offset(&self) -> Option<u64> {
        None
    }
}

/// HDF5 for probing ([`crate::registry`]): its signature.
pub const REGISTERED: crate::Registered = crate::Registered {
    probe: |head, _, _| Ok(crate::registry::by_magic(head, MAGIC, crate::Format::Hdf5)),
    open: |src, path, opts, _| reader(src, path, opts.camera),
};
