//! jAER AEDAT 2.0 and AEDAT 3.1 readers. See `docs/formats.md`.

use eenf_core::spelling::option;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use crate::error::io_err;
use crate::stream::{read_text_header, Skips, Unwrap, WordDecoder, WordStream};
use crate::{EventBatch, EventError, EventReader, Result, Source, StreamInfo};

/// How a jAER chip packs DVS addresses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Addressing {
    /// DAVIS240/346/640: y 30..22, x 21..12, polarity 11, external 10, bit 31 = APS/IMU.
    Davis,
    /// DVS128: x 7..1, y 14..8, polarity 0.
    Dvs128,
}

/// A chip by name (`DVS128`, `DAVIS240`, … as jAER names them, any case): addressing,
/// width, height.
fn chip_named(name: &str) -> Option<(Addressing, u16, u16)> {
    let lower = name.to_ascii_lowercase();
    Some(if lower.contains("davis346") {
        (Addressing::Davis, 346, 260)
    } else if lower.contains("davis240") {
        (Addressing::Davis, 240, 180)
    } else if lower.contains("davis640") {
        (Addressing::Davis, 640, 480)
    } else if lower.contains("dvs128") || lower.contains("tmpdiff128") {
        (Addressing::Dvs128, 128, 128)
    } else {
        return None;
    })
}

/// The chip named in `# AEChip:`: addressing, width, height, name.
fn chip(lines: &[String]) -> Option<(Addressing, u16, u16, String)> {
    let line = lines.iter().find(|l| l.starts_with("AEChip:"))?;
    let name = line["AEChip:".len()..].trim().to_string();
    let (a, w, h) = chip_named(&name)?;
    Some((a, w, h, name))
}

/// The chip that the first addresses of a file without `# AEChip:` fit. DVS128 addresses use
/// 16 bits (x 7..1, y 14..8, bit 15 external or the eye); DAVIS addresses put y in bits 30..22
/// and mark APS/IMU samples with bit 31. The DAVIS whose array holds the largest x and y wins.
fn infer_chip(addresses: &[u32]) -> Option<(Addressing, u16, u16, String)> {
    if addresses.is_empty() {
        return None;
    }
    if addresses.iter().all(|&a| a < 1 << 16) {
        return Some((Addressing::Dvs128, 128, 128, "DVS128".into()));
    }
    let dvs = addresses
        .iter()
        .filter(|&&a| a >> 31 == 0 && (a >> 10) & 1 == 0);
    let (mx, my) = dvs.fold((0, 0), |(x, y), &a| {
        (x.max((a >> 12) & 0x3FF), y.max((a >> 22) & 0x1FF))
    });
    for (name, w, h) in [
        ("DAVIS240", 240, 180),
        ("DAVIS346", 346, 260),
        ("DAVIS640", 640, 480),
    ] {
        if mx < w && my < h {
            return Some((Addressing::Davis, w as u16, h as u16, name.into()));
        }
    }
    None
}

/// Addresses looked at to infer a chip and find a stereo pair.
const PEEK_WORDS: usize = 65_536;

/// The addresses of the first events after the header.
fn peek_addresses(src: &mut dyn Source, path: &Path, start: u64) -> Result<Vec<u32>> {
    src.seek(SeekFrom::Start(start))
        .map_err(|e| io_err(path, e))?;
    let mut bytes = Vec::new();
    src.take((PEEK_WORDS * 8) as u64)
        .read_to_end(&mut bytes)
        .map_err(|e| io_err(path, e))?;
    Ok(bytes
        .chunks_exact(8)
        .map(|w| u32::from_be_bytes([w[0], w[1], w[2], w[3]]))
        .collect())
}

/// Share of DVS128 addresses with bit 15 set above which (and below one minus which) the file
/// is a stereo pair: an external-event flag is rare, an eye is about half the events.
const STEREO_SHARE: f64 = 0.05;

/// AEDAT 2.0 decoder: big-endian (address, timestamp) pairs.
pub(crate) struct Aedat2 {
    addressing: Addressing,
    height: u16,
    unwrap: Unwrap,
    skips: Skips,
    /// A DVS128 stereo pair: bit 15 is the eye, not an external event.
    stereo: bool,
    /// The eye kept, when one was picked.
    camera: Option<u8>,
}

impl WordDecoder for Aedat2 {
    const WORD: usize = 8;

    fn decode(&mut self, chunk: &[u8], out: &mut EventBatch) -> std::result::Result<(), String> {
        for r in chunk.chunks_exact(8) {
            let addr = u32::from_be_bytes(r[0..4].try_into().unwrap());
            let ts = u32::from_be_bytes(r[4..8].try_into().unwrap()) as u64;
            let (x, y_raw, on) = match self.addressing {
                Addressing::Davis => {
                    if addr >> 31 == 1 {
                        self.skips.other += 1; // APS sample or IMU
                        continue;
                    }
                    if (addr >> 10) & 1 == 1 {
                        self.skips.triggers += 1;
                        continue;
                    }
                    (
                        (addr >> 12) & 0x3FF,
                        (addr >> 22) & 0x1FF,
                        (addr >> 11) & 1 == 1,
                    )
                }
                Addressing::Dvs128 => {
                    let bit15 = (addr >> 15) & 1;
                    if !self.stereo && bit15 == 1 {
                        self.skips.triggers += 1; // an external input event
                        continue;
                    }
                    if self.stereo && self.camera.is_some_and(|c| u32::from(c) != bit15) {
                        self.skips.other_camera += 1;
                        continue;
                    }
                    ((addr >> 1) & 0x7F, (addr >> 8) & 0x7F, addr & 1 == 1)
                }
            };
            if y_raw >= self.height as u32 {
                return Err(format!("y {y_raw} outside the chip's {} rows", self.height));
            }
            let t = self.unwrap.next(ts, 32) as i64;
            // jAER counts rows from the lower-left; eenf from the top-left
            out.push(t, x as u16, self.height - 1 - y_raw as u16, on);
        }
        Ok(())
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        self.skips.list()
    }
}

/// Opens an AEDAT 2.0 file.
pub fn open_aedat2(path: &Path) -> Result<Box<dyn EventReader>> {
    let src = Box::new(std::fs::File::open(path).map_err(|e| io_err(path, e))?);
    aedat2_with(src, path, &crate::OpenOptions::default())
}

/// Reads AEDAT 2.0 from `src` (named `path` in errors): the chip from `opts`, else the header's
/// `# AEChip:` line, else inferred from the first addresses (with a note); a DVS128 stereo
/// pair is reported as two cameras, and `opts.camera` keeps one of them.
pub fn aedat2_with(
    mut src: Box<dyn Source>,
    path: &Path,
    opts: &crate::OpenOptions,
) -> Result<Box<dyn EventReader>> {
    let header = read_text_header(src.as_mut(), path, b"#", None, "AEDAT 2.0")?;
    let addresses = peek_addresses(src.as_mut(), path, header.data_start)?;
    let mut notes = Vec::new();
    let named = header
        .lines
        .iter()
        .find(|l| l.starts_with("AEChip:"))
        .cloned()
        .unwrap_or_else(|| "no AEChip line".into());
    let found = match &opts.chip {
        Some(name) => match chip_named(name) {
            Some((a, w, h)) => {
                notes.push(format!("chip {name} as asked (the header has {named})"));
                Some((a, w, h, name.clone()))
            }
            None => {
                return Err(EventError::Unfit {
                    path: path.to_path_buf(),
                    reason: format!(
                        "unknown chip {name:?}; known: DVS128, DAVIS240, DAVIS346, DAVIS640"
                    ),
                })
            }
        },
        None => chip(&header.lines).or_else(|| {
            let inferred = infer_chip(&addresses)?;
            notes.push(format!(
                "{named}: chip inferred from the addresses as {} ({} overrides)",
                inferred.3,
                option("chip")
            ));
            Some(inferred)
        }),
    };
    let Some((addressing, w, h, _name)) = found else {
        return Err(EventError::Corrupt {
            path: path.to_path_buf(),
            format: "AEDAT 2.0",
            offset: 0,
            reason: format!(
                "unknown chip ({named}); known: DAVIS240, DAVIS346, DAVIS640, DVS128 (name it with {})",
                option("chip")
            ),
        });
    };
    let eye = addresses.iter().filter(|&&a| (a >> 15) & 1 == 1).count() as f64
        / addresses.len().max(1) as f64;
    let stereo = addressing == Addressing::Dvs128
        && addresses.len() >= 100
        && (STEREO_SHARE..=1.0 - STEREO_SHARE).contains(&eye);
    let cameras = if stereo {
        vec![
            "camera 0: address bit 15 clear".to_string(),
            "camera 1: address bit 15 set".to_string(),
        ]
    } else {
        Vec::new()
    };
    if stereo {
        notes.push(format!(
            "a stereo pair: {:.0} % of the events from camera 1 (address bit 15), each camera on its own clock",
            100.0 * eye
        ));
    }
    let info = StreamInfo {
        format: "AEDAT 2.0",
        width: Some(w),
        height: Some(h),
        cameras,
        camera: if stereo { opts.camera } else { None },
        notes,
        ..StreamInfo::default()
    };
    Ok(Box::new(WordStream::new(
        src,
        path,
        header.data_start,
        Aedat2 {
            addressing,
            height: h,
            unwrap: Unwrap::default(),
            skips: Skips::default(),
            stereo,
            camera: opts.camera,
        },
        info,
    )?))
}

const FORMAT31: &str = "AEDAT 3.1";
/// Largest packet payload accepted.
const MAX_PACKET: u64 = 1 << 30;

/// Reads AEDAT 3.1 packet by packet; polarity packets become events, others are skipped.
pub struct Aedat31Reader {
    path: PathBuf,
    file: BufReader<Box<dyn Source>>,
    pos: u64,
    len: u64,
    info: StreamInfo,
    payload: Vec<u8>,
    skipped_packets: u64,
    invalid: u64,
    /// Byte offset of the packet of the batch handed out last.
    batch_at: u64,
}

/// Opens an AEDAT 3.1 file.
pub fn open_aedat31(path: &Path) -> Result<Box<dyn EventReader>> {
    aedat31_from(
        Box::new(std::fs::File::open(path).map_err(|e| io_err(path, e))?),
        path,
    )
}

/// Reads AEDAT 3.1 from `src` (named `path` in errors).
pub fn aedat31_from(mut f: Box<dyn Source>, path: &Path) -> Result<Box<dyn EventReader>> {
    let header = read_text_header(f.as_mut(), path, b"#", Some(b"#!END-HEADER"), FORMAT31)?;
    if !header.lines.iter().any(|l| l.starts_with("!END-HEADER")) {
        return Err(EventError::Truncated {
            path: path.to_path_buf(),
            format: FORMAT31,
            offset: header.data_start,
            reason: "no #!END-HEADER line".into(),
        });
    }
    let len = f.seek(SeekFrom::End(0)).map_err(|e| io_err(path, e))?;
    f.seek(SeekFrom::Start(header.data_start))
        .map_err(|e| io_err(path, e))?;
    // the header names the camera, not its size; sizes come from the data
    let source = header
        .lines
        .iter()
        .find_map(|l| l.strip_prefix("Source ").map(|s| s.to_string()));
    let info = StreamInfo {
        format: FORMAT31,
        streams: source
            .map(|s| {
                vec![crate::StreamDesc {
                    id: 0,
                    kind: "POLARITY".into(),
                    source: Some(
                        s.split_once(':')
                            .map(|p| p.1.trim().to_string())
                            .unwrap_or(s),
                    ),
                    ..crate::StreamDesc::default()
                }]
            })
            .unwrap_or_default(),
        ..StreamInfo::default()
    };
    Ok(Box::new(Aedat31Reader {
        path: path.to_path_buf(),
        file: BufReader::with_capacity(1 << 20, f),
        pos: header.data_start,
        len,
        info,
        payload: Vec::new(),
        skipped_packets: 0,
        invalid: 0,
        batch_at: header.data_start,
    }))
}

impl Aedat31Reader {
    fn err(&self, truncated: bool, offset: u64, reason: String) -> EventError {
        if truncated {
            EventError::Truncated {
                path: self.path.clone(),
                format: FORMAT31,
                offset,
                reason,
            }
        } else {
            EventError::Corrupt {
                path: self.path.clone(),
                format: FORMAT31,
                offset,
                reason,
            }
        }
    }
}

impl EventReader for Aedat31Reader {
    fn info(&self) -> &StreamInfo {
        &self.info
    }

    fn next_batch(&mut self) -> Result<Option<EventBatch>> {
        loop {
            if self.pos >= self.len {
                return Ok(None);
            }
            let at = self.pos;
            if self.len - at < 28 {
                self.pos = self.len;
                return Err(self.err(true, at, "packet header cut short".into()));
            }
            let mut h = [0u8; 28];
            self.file
                .read_exact(&mut h)
                .map_err(|e| io_err(&self.path, e))?;
            let i32_at = |k: usize| i32::from_le_bytes(h[k..k + 4].try_into().unwrap());
            let kind = i16::from_le_bytes([h[0], h[1]]);
            let (size, overflow, capacity, number) =
                (i32_at(4), i32_at(12), i32_at(16), i32_at(20));
            if size <= 0 || capacity < 0 || number < 0 || number > capacity {
                self.pos = self.len;
                return Err(self.err(
                    false,
                    at,
                    format!("packet header with event size {size}, capacity {capacity}, number {number}"),
                ));
            }
            let bytes = size as u64 * capacity as u64;
            if bytes > MAX_PACKET {
                self.pos = self.len;
                return Err(self.err(false, at, format!("packet of {bytes} bytes")));
            }
            if bytes > self.len - at - 28 {
                self.pos = self.len;
                return Err(self.err(
                    true,
                    at,
                    format!("packet of {bytes} bytes, only {} left", self.len - at - 28),
                ));
            }
            self.pos = at + 28 + bytes;
            if kind != 1 || size < 8 {
                self.skipped_packets += 1;
                self.file
                    .seek_relative(bytes as i64)
                    .map_err(|e| io_err(&self.path, e))?;
                continue;
            }
            self.payload.resize(bytes as usize, 0);
            self.file
                .read_exact(&mut self.payload)
                .map_err(|e| io_err(&self.path, e))?;
            let mut batch = EventBatch::with_capacity(number as usize);
            let high = (overflow as u32 as u64) << 31;
            for e in self
                .payload
                .chunks_exact(size as usize)
                .take(number as usize)
            {
                let data = u32::from_le_bytes(e[0..4].try_into().unwrap());
                let ts = u32::from_le_bytes(e[4..8].try_into().unwrap()) as u64 & 0x7FFF_FFFF;
                if data & 1 == 0 {
                    self.invalid += 1;
                    continue;
                }
                batch.push(
                    (high | ts) as i64,
                    ((data >> 17) & 0x7FFF) as u16,
                    ((data >> 2) & 0x7FFF) as u16,
                    (data >> 1) & 1 == 1,
                );
            }
            if !batch.is_empty() {
                self.batch_at = at;
                return Ok(Some(batch));
            }
        }
    }

    fn batch_offset(&self) -> Option<u64> {
        Some(self.batch_at)
    }

    fn skipped(&self) -> Vec<(&'static str, u64)> {
        [
            ("non-polarity packets", self.skipped_packets),
            ("invalid events", self.invalid),
        ]
        .into_iter()
        .filter(|(_, n)| *n > 0)
        .collect()
    }
}

/// jAER AEDAT 2.0 for probing ([`crate::registry`]): its `#!AER-DAT2.0` line.
pub const AEDAT2: crate::Registered = crate::Registered {
    probe: |head, _, _| {
        Ok(crate::registry::by_magic(
            head,
            b"#!AER-DAT2.0",
            crate::Format::Aedat2,
        ))
    },
    open: |src, path, opts, _| aedat2_with(src, path, opts),
};

/// jAER AEDAT 3.1 for probing ([`crate::registry`]): its `#!AER-DAT3` line.
pub const AEDAT31: crate::Registered = crate::Registered {
    probe: |head, _, _| {
        Ok(crate::registry::by_magic(
            head,
            b"#!AER-DAT3",
            crate::Format::Aedat31,
        ))
    },
    open: |src, path, _, _| aedat31_from(src, path),
};
