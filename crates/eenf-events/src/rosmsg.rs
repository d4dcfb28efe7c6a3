//! The event messages of ROS 1 and ROS 2, decoded into [`EventBatch`]es: what a bag holds,
//! whichever bag it is (ROS 1 or rosbag2).
//!
//! Messages:
//! - `dvs_msgs/EventArray` and `prophesee_event_msgs/EventArray`: a header, `u32` height and
//!   width, then events of `u16 x, u16 y, time ts, bool polarity`; times are the stamps, in µs;
//! - `event_camera_msgs/EventPacket` and `event_array_msgs/EventArray`: a header, `u32` height
//!   and width, `u64` seq and time base, the encoding, `bool` is_bigendian, and the camera's own
//!   bytes, in one of the encodings of ros-event-camera/event_camera_codecs:
//!   - `evt3`: Prophesee EVT 3.0 16-bit words, through eenf's EVT 3.0 decoder, whose state
//!     (the 24-bit clock's loops) carries from one message to the next; times are the
//!     sensor's, µs;
//!   - `libcaer`: 8 bytes an event, `u32` data (x in bits 17–31, y in 2–16, polarity bit 1)
//!     and `i32` µs of the sensor's 31-bit clock; a time is the time base (ns) plus the clock,
//!     one 2³¹ µs loop added each time the clock goes back within the message;
//!   - `libcaer_cmp`: 16-bit words, a 4-bit code on top: time high (12 bits, × 4096 µs), time
//!     low (12 bits, µs), x, y + polarity, and vectors of 8 rows from a base y; times count
//!     from the message's time base (ns), events outside the sensor are dropped;
//!   - `mono`: 8 bytes an event, ns after the time base in the low 32 bits, x in bits 32–47, y
//!     in 48–62, polarity bit 63.
//!
//! Serialisations: ROS 1 (little-endian, packed) and ROS 2 CDR (a 4-byte encapsulation header
//! naming the byte order, then every field aligned to its size from the end of that header).

use crate::prophesee::Evt3;
use crate::stream::WordDecoder;
use crate::EventBatch;

/// What a message type carries, and so how it is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// An array of events with their own stamps (dvs_msgs, prophesee_event_msgs).
    Events,
    /// A packet of a camera's encoding (event_camera_msgs, event_array_msgs).
    Packet,
}

/// The kind of a message type named the ROS 1 way (`dvs_msgs/EventArray`) or the ROS 2 way
/// (`dvs_msgs/msg/EventArray`); `None` for types that carry no events.
pub fn kind_of(msg_type: &str) -> Option<Kind> {
    match msg_type.replace("/msg/", "/").as_str() {
        "dvs_msgs/EventArray" | "prophesee_event_msgs/EventArray" => Some(Kind::Events),
        "event_camera_msgs/EventPacket" | "event_array_msgs/EventArray" => Some(Kind::Packet),
        _ => None,
    }
}

/// The event message types read, for messages naming what a bag lacks.
pub const TYPES: &str =
    "dvs_msgs/EventArray, prophesee_event_msgs/EventArray, event_camera_msgs/EventPacket, event_array_msgs/EventArray";

/// How a message's bytes are laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Serialization {
    /// ROS 1: little-endian, no padding.
    Ros1,
    /// ROS 2 CDR (byte order and alignment from the encapsulation header).
    Cdr,
}

type Res<T> = std::result::Result<T, String>;

/// Why a message could not be decoded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Fault {
    /// Its bytes are damaged or cut short.
    Damaged(String),
    /// It is sound but in a form eenf does not read (an encoding, a byte order).
    Unsupported(String),
}

impl From<String> for Fault {
    fn from(s: String) -> Self {
        Fault::Damaged(s)
    }
}

impl From<&str> for Fault {
    fn from(s: &str) -> Self {
        Fault::Damaged(s.to_string())
    }
}

impl Fault {
    /// The error a reader reports for it: `damaged` for damage, else that the file does not
    /// fit what eenf reads.
    pub fn into_error(
        self,
        path: &std::path::Path,
        damaged: impl FnOnce(String) -> crate::EventError,
    ) -> crate::EventError {
        match self {
            Fault::Damaged(reason) => damaged(reason),
            Fault::Unsupported(reason) => crate::EventError::Unfit {
                path: path.to_path_buf(),
                reason,
            },
        }
    }
}

/// A cursor over one message's bytes.
struct Cursor<'a> {
    b: &'a [u8],
    i: usize,
    /// Where alignment counts from (CDR: after the encapsulation header); `None`: packed.
    origin: Option<usize>,
    big_endian: bool,
}

impl<'a> Cursor<'a> {
    fn new(b: &'a [u8], ser: Serialization) -> Res<Self> {
        match ser {
            Serialization::Ros1 => Ok(Cursor {
                b,
                i: 0,
                origin: None,
                big_endian: false,
            }),
            Serialization::Cdr => {
                // representation identifier: 0x0000 CDR big-endian, 0x0001 little-endian
                let id = b.get(..4).ok_or("a message shorter than its CDR header")?;
                if id[0] != 0 || id[1] > 1 {
                    return Err(format!(
                        "a message in the CDR representation {:#06x}, which eenf does not read",
                        u16::from_be_bytes([id[0], id[1]])
                    ));
                }
                Ok(Cursor {
                    b,
                    i: 4,
                    origin: Some(4),
                    big_endian: id[1] == 0,
                })
            }
        }
    }

    fn align(&mut self, n: usize) {
        if let Some(o) = self.origin {
            let off = (self.i - o) % n;
            if off != 0 {
                self.i += n - off;
            }
        }
    }

    fn take(&mut self, n: usize) -> Res<&'a [u8]> {
        let s = self
            .b
            .get(self.i..self.i.saturating_add(n))
            .ok_or_else(|| {
                format!(
                    "a message cut short ({} bytes, {} more wanted at byte {})",
                    self.b.len(),
                    n,
                    self.i
                )
            })?;
        self.i += n;
        Ok(s)
    }

    fn u8(&mut self) -> Res<u8> {
        Ok(self.take(1)?[0])
    }

    fn u16(&mut self) -> Res<u16> {
        self.align(2);
        let b: [u8; 2] = self.take(2)?.try_into().unwrap_or_default();
        Ok(if self.big_endian {
            u16::from_be_bytes(b)
        } else {
            u16::from_le_bytes(b)
        })
    }

    fn u32(&mut self) -> Res<u32> {
        self.align(4);
        let b: [u8; 4] = self.take(4)?.try_into().unwrap_or_default();
        Ok(if self.big_endian {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        })
    }

    fn u64(&mut self) -> Res<u64> {
        self.align(8);
        let b: [u8; 8] = self.take(8)?.try_into().unwrap_or_default();
        Ok(if self.big_endian {
            u64::from_be_bytes(b)
        } else {
            u64::from_le_bytes(b)
        })
    }

    /// A string or a `u8[]`: a `u32` length, then the bytes.
    fn bytes(&mut self) -> Res<&'a [u8]> {
        let n = self.u32()? as usize;
        self.take(n)
    }

    /// `std_msgs/Header`: ROS 1 seq, stamp and frame_id; ROS 2 stamp and frame_id.
    fn header(&mut self) -> Res<()> {
        if self.origin.is_none() {
            self.u32()?;
        }
        self.u32()?;
        self.u32()?;
        self.bytes()?;
        Ok(())
    }
}

/// Decodes the event messages of one topic, keeping what carries from one message to the
/// next (the EVT 3.0 clock, the x of `libcaer_cmp`).
pub struct MessageDecoder {
    kind: Kind,
    evt3: Evt3,
    cmp: CaerCmp,
    /// The sensor's size, from the first message that gives one.
    pub width: Option<u16>,
    /// The sensor's size, from the first message that gives one.
    pub height: Option<u16>,
    /// The encoding of the packets, once one was read.
    pub encoding: Option<String>,
}

impl MessageDecoder {
    /// A decoder of messages of `kind`.
    pub fn new(kind: Kind) -> Self {
        MessageDecoder {
            kind,
            evt3: Evt3::default(),
            cmp: CaerCmp::default(),
            width: None,
            height: None,
            encoding: None,
        }
    }

    /// Adds the packets' encoding, once known, to a topic's description `topic name (type)`.
    pub fn describe(&self, topic: &mut Option<String>) {
        if let (Some(e), Some(t)) = (&self.encoding, topic) {
            if !t.ends_with(" encoding)") && t.ends_with(')') {
                t.pop();
                t.push_str(&format!(", {e} encoding)"));
            }
        }
    }

    /// Words read that were not CD events (EVT 3.0 triggers and others), by kind.
    pub fn skipped(&self) -> Vec<(&'static str, u64)> {
        self.evt3.skipped()
    }

    /// Decodes one message into `out`.
    pub fn decode(
        &mut self,
        data: &[u8],
        ser: Serialization,
        out: &mut EventBatch,
    ) -> std::result::Result<(), Fault> {
        let mut m = Cursor::new(data, ser)?;
        m.header()?;
        let height = m.u32()?;
        let width = m.u32()?;
        if self.width.is_none() && width > 0 && width <= u16::MAX as u32 {
            self.width = Some(width as u16);
            self.height = Some(height.min(u16::MAX as u32) as u16);
        }
        match self.kind {
            Kind::Events => {
                let n = m.u32()? as usize;
                if ser == Serialization::Ros1 {
                    // packed: 13 bytes an event
                    let bytes = m.take(n.checked_mul(13).ok_or("an event count beyond reason")?)?;
                    for e in bytes.chunks_exact(13) {
                        let s = u32::from_le_bytes([e[4], e[5], e[6], e[7]]) as i64;
                        let ns = u32::from_le_bytes([e[8], e[9], e[10], e[11]]) as i64;
                        out.push(
                            s * 1_000_000 + ns / 1000,
                            u16::from_le_bytes([e[0], e[1]]),
                            u16::from_le_bytes([e[2], e[3]]),
                            e[12] != 0,
                        );
                    }
                } else {
                    // CDR: each field aligned; at least 13 bytes an event bounds the count
                    if n > data.len() / 13 {
                        return Err(Fault::Damaged(format!(
                            "{n} events announced in a {} byte message",
                            data.len()
                        )));
                    }
                    for _ in 0..n {
                        let x = m.u16()?;
                        let y = m.u16()?;
                        let s = m.u32()? as i32 as i64;
                        let ns = m.u32()? as i64;
                        let p = m.u8()? != 0;
                        out.push(s * 1_000_000 + ns / 1000, x, y, p);
                    }
                }
            }
            Kind::Packet => {
                m.u64()?; // seq
                let time_base = m.u64()?;
                let encoding = m.bytes()?;
                // CDR strings end in a NUL, counted in their length
                let encoding = encoding.strip_suffix(&[0]).unwrap_or(encoding);
                let big_endian = m.u8()? != 0;
                let bytes = m.bytes()?;
                if self.encoding.is_none() {
                    self.encoding = Some(String::from_utf8_lossy(encoding).into_owned());
                }
                if big_endian {
                    return Err(Fault::Unsupported(
                        "big-endian event packets, which eenf does not read".into(),
                    ));
                }
                match encoding {
                    b"evt3" => self.evt3.decode(&bytes[..bytes.len() / 2 * 2], out)?,
                    b"libcaer" => libcaer(bytes, time_base, out),
                    b"libcaer_cmp" => self.cmp.decode(bytes, time_base, width, height, out),
                    b"mono" => mono(bytes, time_base, out),
                    other => {
                        return Err(Fault::Unsupported(format!(
                            "packets in the {:?} encoding, which eenf does not read (it reads evt3, libcaer, libcaer_cmp, mono)",
                            String::from_utf8_lossy(other)
                        )))
                    }
                }
            }
        }
        Ok(())
    }
}

/// ns → µs, rounding down, kept in range.
fn micros(ns: u64) -> i64 {
    (ns / 1000).min(i64::MAX as u64) as i64
}

/// `libcaer`: libcaer's polarity events (`u32` data, `i32` time), 31-bit µs clock.
pub fn libcaer(bytes: &[u8], time_base: u64, out: &mut EventBatch) {
    let mut high = time_base;
    let mut last = 0u64;
    for e in bytes.chunks_exact(8) {
        let data = u32::from_le_bytes([e[0], e[1], e[2], e[3]]);
        // the clock is 31 bits: a negative value is taken as libcaer's driver takes it
        let low = i32::from_le_bytes([e[4], e[5], e[6], e[7]]) as i64 as u64;
        if low < last {
            high = high.wrapping_add((1u64 << 31) * 1000);
        }
        last = low;
        out.push(
            micros(high.wrapping_add(low.wrapping_mul(1000))),
            ((data >> 17) & 0x7FFF) as u16,
            ((data >> 2) & 0x7FFF) as u16,
            (data >> 1) & 1 == 1,
        );
    }
}

/// `mono`: one `u64` an event.
pub fn mono(bytes: &[u8], time_base: u64, out: &mut EventBatch) {
    for e in bytes.chunks_exact(8) {
        let w = u64::from_le_bytes(e.try_into().unwrap_or_default());
        out.push(
            micros(time_base.wrapping_add(w & 0xFFFF_FFFF)),
            (w >> 32) as u16,
            ((w >> 48) & 0x7FFF) as u16,
            w >> 63 == 1,
        );
    }
}

/// The state of the `libcaer_cmp` decoder: the x of the last address word, the base y and
/// polarity of the last vector, which carry across messages.
#[derive(Debug, Default)]
pub struct CaerCmp {
    x: u16,
    base_y: u16,
    polarity: bool,
}

impl CaerCmp {
    /// Appends the events of one message's `libcaer_cmp` words to `out`: stamps from
    /// `time_base` (ns), events outside a `width` × `height` sensor dropped.
    pub fn decode(
        &mut self,
        bytes: &[u8],
        time_base: u64,
        width: u32,
        height: u32,
        out: &mut EventBatch,
    ) {
        // the clock restarts with each message, from its time base
        let mut high = 0u64;
        let mut low = 0u64;
        let t = |high: u64, low: u64| micros(time_base.wrapping_add((high | low) * 1000));
        for w in bytes.chunks_exact(2) {
            let w = u16::from_le_bytes([w[0], w[1]]);
            let v = w & 0x0FFF;
            match w >> 12 {
                0 => high = (v as u64) << 12,
                1 => low = v as u64,
                2 => self.x = v & 0x7FF,
                3 => {
                    let y = v & 0x7FF;
                    if (self.x as u32) < width && (y as u32) < height {
                        out.push(t(high, low), self.x, y, v & 0x800 != 0);
                    }
                }
                4 => {
                    self.base_y = v & 0x7FF;
                    self.polarity = v & 0x800 != 0;
                }
                5 => {
                    for i in 0..8 {
                        let y = self.base_y.wrapping_add(i);
                        if v & (1 << i) != 0 && (self.x as u32) < width && (y as u32) < height {
                            out.push(t(high, low), self.x, y, self.polarity);
                        }
                    }
                    self.base_y = self.base_y.wrapping_add(8);
                }
                // codes the codec does not write (vectors of 12): skipped, as its decoder does
                _ => {}
            }
        }
    }
}
