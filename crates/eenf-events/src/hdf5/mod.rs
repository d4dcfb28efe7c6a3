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

/// The last part of an HDF5 path.
fn leaf(name: &str) -> &str {
    name.rsplit('/').next().unwrap_or(name)
}

/// A scalar integer dataset's value.
fn scalar_i64(d: &Dataset) -> hdf5_reader::error::Result<i64> {
    let v = read_i64(d, &SliceInfo::all(d.ndim()))?;
    v.first()
        .copied()
        .ok_or_else(|| hdf5_reader::error::Error::InvalidData("an empty t_offset".into()))
}

/// Integers of any size and sign, or floats, of `d`'s selection, as `i64` (floats rounded).
fn read_i64(d: &Dataset, sel: &SliceInfo) -> hdf5_reader::error::Result<Vec<i64>> {
    macro_rules! ints {
        ($t:ty) => {
            d.read_slice_parallel::<$t>(sel)?
                .iter()
                .map(|&v| v as i64)
                .collect()
        };
    }
    Ok(match d.dtype() {
        Datatype::FixedPoint {
            size: 1,
            signed: false,
            ..
        } => ints!(u8),
        Datatype::FixedPoint {
            size: 1,
            signed: true,
            ..
        } => ints!(i8),
        Datatype::FixedPoint {
            size: 2,
            signed: false,
            ..
        } => ints!(u16),
        Datatype::FixedPoint {
            size: 2,
            signed: true,
            ..
        } => ints!(i16),
        Datatype::FixedPoint {
            size: 4,
            signed: false,
            ..
        } => ints!(u32),
        Datatype::FixedPoint {
            size: 4,
            signed: true,
            ..
        } => ints!(i32),
        Datatype::FixedPoint {
            size: 8,
            signed: false,
            ..
        } => ints!(u64),
        Datatype::FixedPoint {
            size: 8,
            signed: true,
            ..
        } => ints!(i64),
        Datatype::FloatingPoint { size: 4, .. } => d
            .read_slice_parallel::<f32>(sel)?
            .iter()
            .map(|&v| v.round() as i64)
            .collect(),
        Datatype::FloatingPoint { size: 8, .. } => d
            .read_slice_parallel::<f64>(sel)?
            .iter()
            .map(|&v| v.round() as i64)
            .collect(),
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
                let ((xs, ys), (ps, ts)) = rayon::join(
                    || rayon::join(|| read_i64(x, &sel), || read_i64(y, &sel)),
                    || rayon::join(|| read_i64(p, &sel), || read_i64(t, &sel)),
                );
                let (xs, ys, ps, ts) = (xs?, ys?, ps?, ts?);
                b.t = ts.iter().map(|&t| t.saturating_add(*t_offset)).collect();
                b.x = xs
                    .iter()
                    .map(|&v| v.clamp(0, u16::MAX as i64) as u16)
                    .collect();
                b.y = ys
                    .iter()
                    .map(|&v| v.clamp(0, u16::MAX as i64) as u16)
                    .collect();
                b.p = ps.iter().map(|&v| v > 0).collect();
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
        while !self.done && self.pos < self.camera.len {
            match self.slice() {
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
