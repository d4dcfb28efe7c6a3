//! AEDAT 4.0 writer: event packets of a fixed size, compressed in parallel, a FileDataTable at
//! the end, and the header's table position patched in by [`Aedat4Writer::finish`] (so the
//! sink must seek). Writing whole or not at all is the caller's: see `eenf::output`.

use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::flatbuf::Builder;
use super::{Compression, EVENT_SIZE, MAGIC};
use crate::error::{io_err, Result};
use crate::EventBatch;
use crate::Sink;

/// Events per packet, as the DV software writes them.
pub const DEFAULT_PACKET_EVENTS: usize = 10_000;
/// Packets compressed together in parallel.
const PACKETS_PER_ROUND: usize = 32;

struct TableEntry {
    byte_offset: i64,
    size: i32,
    events: i64,
    t_start: i64,
    t_end: i64,
}

/// Writes events to an AEDAT 4.0 file with one event stream (id 0).
pub struct Aedat4Writer {
    path: PathBuf,
    file: Option<BufWriter<Box<dyn Sink>>>,
    codec: Compression,
    width: u16,
    height: u16,
    header_len: usize,
    pos: u64,
    packet_events: usize,
    pending: EventBatch,
    entries: Vec<TableEntry>,
    written: u64,
}

fn info_xml(codec: Compression, width: u16, height: u16) -> String {
    format!(
        r#"<dv version="2.0">
    <node name="outInfo" path="/outInfo/">
        <node name="0" path="/outInfo/0/">
            <attr key="compression" type="string">{}</attr>
            <attr key="originalModuleName" type="string">eenf</attr>
            <attr key="originalOutputName" type="string">events</attr>
            <attr key="typeDescription" type="string">Array of events (polarity ON/OFF).</attr>
            <attr key="typeIdentifier" type="string">EVTS</attr>
            <node name="info" path="/outInfo/0/info/">
                <attr key="sizeX" type="int">{width}</attr>
                <attr key="sizeY" type="int">{height}</attr>
                <attr key="source" type="string">eenf</attr>
            </node>
        </node>
    </node>
</dv>
"#,
        codec.name()
    )
}

fn io_header(codec: Compression, table_pos: i64, xml: &str) -> Vec<u8> {
    let mut b = Builder::new();
    let s = b.create_string(xml);
    b.start_table();
    b.add_inline(1, &table_pos.to_le_bytes(), 8);
    b.add_offset(2, s);
    b.add_inline(0, &codec.code().to_le_bytes(), 4);
    let t = b.end_table();
    b.finish(t, b"IOHE")
}

fn compress(codec: Compression, data: &[u8]) -> std::io::Result<Vec<u8>> {
    match codec {
        Compression::None => Ok(data.to_vec()),
        // lz4_flex has no high-compression mode; LZ4_HIGH files get fast-mode frames, which
        // every LZ4 frame decoder reads.
        Compression::Lz4 | Compression::Lz4High => {
            let mut enc = lz4_flex::frame::FrameEncoder::new(Vec::with_capacity(data.len() / 2));
            enc.write_all(data)?;
            enc.finish().map_err(std::io::Error::other)
        }
        Compression::Zstd => zstd::bulk::compress(data, 3),
        Compression::ZstdHigh => zstd::bulk::compress(data, 12),
    }
}

/// The EventPacket FlatBuffer (size-prefixed, identifier `EVTS`) for a slice of events.
fn event_packet(batch: &EventBatch, range: std::ops::Range<usize>) -> Vec<u8> {
    let n = range.len();
    let mut bytes = vec![0u8; n * EVENT_SIZE];
    for (rec, i) in bytes.chunks_exact_mut(EVENT_SIZE).zip(range) {
        rec[0..8].copy_from_slice(&batch.t[i].to_le_bytes());
        rec[8..10].copy_from_slice(&batch.x[i].to_le_bytes());
        rec[10..12].copy_from_slice(&batch.y[i].to_le_bytes());
        rec[12] = batch.p[i] as u8;
    }
    let mut b = Builder::new();
    let v = b.create_struct_vector(&bytes, n, 8);
    b.start_table();
    b.add_offset(0, v);
    let t = b.end_table();
    b.finish_size_prefixed(t, b"EVTS")
}

impl Aedat4Writer {
    /// Starts a plain file at `path` (created, or truncated).
    pub fn create(path: &Path, codec: Compression, width: u16, height: u16) -> Result<Self> {
        let file = std::fs::File::create(path).map_err(|e| io_err(path, e))?;
        Self::new(Box::new(file), path, codec, width, height)
    }

    /// Starts writing into `out`; `name` names it in errors.
    pub fn new(
        out: Box<dyn Sink>,
        name: &Path,
        codec: Compression,
        width: u16,
        height: u16,
    ) -> Result<Self> {
        let mut file = BufWriter::with_capacity(1 << 20, out);
        let header = io_header(codec, -1, &info_xml(codec, width, height));
        let mut head = Vec::with_capacity(18 + header.len());
        head.extend_from_slice(MAGIC);
        head.extend_from_slice(&(header.len() as u32).to_le_bytes());
        head.extend_from_slice(&header);
        file.write_all(&head).map_err(|e| io_err(name, e))?;
        Ok(Aedat4Writer {
            path: name.to_path_buf(),
            file: Some(file),
            codec,
            width,
            height,
            header_len: header.len(),
            pos: head.len() as u64,
            packet_events: DEFAULT_PACKET_EVENTS,
            pending: EventBatch::default(),
            entries: Vec::new(),
            written: 0,
        })
    }

    /// Sets the number of events per packet (default 10,000).
    pub fn with_packet_events(mut self, n: usize) -> Self {
        self.packet_events = n.max(1);
        self
    }

    /// Queues events; full packets are compressed and written as they accumulate.
    pub fn write(&mut self, batch: &EventBatch) -> Result<()> {
        self.pending.extend_from(batch);
        if self.pending.len() >= self.packet_events * PACKETS_PER_ROUND {
            self.flush_packets(false)?;
        }
        Ok(())
    }

    fn flush_packets(&mut self, all: bool) -> Result<()> {
        let n = self.pending.len();
        let full = n / self.packet_events * self.packet_events;
        let upto = if all { n } else { full };
        if upto == 0 {
            return Ok(());
        }
        let ranges: Vec<_> = (0..upto)
            .step_by(self.packet_events)
            .map(|s| s..(s + self.packet_events).min(upto))
            .collect();
        let codec = self.codec;
        let pending = &self.pending;
        let packets: Vec<std::io::Result<Vec<u8>>> = ranges
            .par_iter()
            .map(|r| compress(codec, &event_packet(pending, r.clone())))
            .collect();
        let file = self.file.as_mut().expect("writer used after finish");
        for (r, body) in ranges.iter().zip(packets) {
            let body = body.map_err(|e| io_err(&self.path, e))?;
            let mut hdr = [0u8; 8];
            hdr[4..8].copy_from_slice(&(body.len() as i32).to_le_bytes());
            file.write_all(&hdr)
                .and_then(|_| file.write_all(&body))
                .map_err(|e| io_err(&self.path, e))?;
            self.entries.push(TableEntry {
                byte_offset: self.pos as i64 + 8,
                size: body.len() as i32,
                events: r.len() as i64,
                t_start: self.pending.t[r.start],
                t_end: self.pending.t[r.end - 1],
            });
            self.pos += 8 + body.len() as u64;
            self.written += r.len() as u64;
        }
        let rest = self.pending.len() - upto;
        let mut tail = EventBatch::with_capacity(rest.max(self.packet_events));
        tail.t.extend_from_slice(&self.pending.t[upto..]);
        tail.x.extend_from_slice(&self.pending.x[upto..]);
        tail.y.extend_from_slice(&self.pending.y[upto..]);
        tail.p.extend_from_slice(&self.pending.p[upto..]);
        self.pending = tail;
        Ok(())
    }

    fn data_table(&self) -> Vec<u8> {
        let mut b = Builder::new();
        let mut rows = Vec::with_capacity(self.entries.len());
        for e in &self.entries {
            let mut header = [0u8; 8];
            header[4..8].copy_from_slice(&e.size.to_le_bytes());
            b.start_table();
            b.add_inline(0, &e.byte_offset.to_le_bytes(), 8);
            b.add_inline(2, &e.events.to_le_bytes(), 8);
            b.add_inline(3, &e.t_start.to_le_bytes(), 8);
            b.add_inline(4, &e.t_end.to_le_bytes(), 8);
            b.add_inline(1, &header, 4);
            rows.push(b.end_table());
        }
        let v = b.create_offset_vector(&rows);
        b.start_table();
        b.add_offset(0, v);
        let t = b.end_table();
        b.finish_size_prefixed(t, b"FTAB")
    }

    /// Writes the remaining events and the FileDataTable, patches the header and flushes.
    /// Returns the number of events written.
    pub fn finish(mut self) -> Result<u64> {
        self.flush_packets(true)?;
        let table = compress(self.codec, &self.data_table()).map_err(|e| io_err(&self.path, e))?;
        let table_pos = self.pos as i64;
        let header = io_header(
            self.codec,
            table_pos,
            &info_xml(self.codec, self.width, self.height),
        );
        debug_assert_eq!(header.len(), self.header_len);
        let mut file = self.file.take().expect("finish called once");
        (|| -> std::io::Result<()> {
            file.write_all(&table)?;
            file.seek(SeekFrom::Start(18))?;
            file.write_all(&header)?;
            file.flush()
        })()
        .map_err(|e| io_err(&self.path, e))?;
        Ok(self.written)
    }
}
