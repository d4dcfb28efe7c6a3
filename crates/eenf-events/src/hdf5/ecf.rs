//! Prophesee's ECF ("event compression format", HDF5 filter 0x8ECF) decoder, written from the
//! codec published with Prophesee's HDF5 plugin (prophesee-ai/hdf5_ecf, `ecf_codec.cpp`) and
//! checked against that codec's own test vectors (`ecf_codec_test.cpp`).
//!
//! One compressed chunk holds at most 65,535 CD events:
//! - a `u32` header: the event count × 4, bit 1 "y, x and p packed", bit 0 "x and p packed";
//! - times: a `u64` origin, then bytes `t:4 | count:4`: `t` µs are added, and the time repeats
//!   `count` times (`count` 15: a `u16` count follows); a byte whose `t` is 15 starts a run of
//!   such bytes whose low nibbles, least significant first, are a larger step;
//! - then either 32-bit words packing four `y:11 x:11 p:1` values (24 bits each) into three
//!   words, or run-length `u16`s of `y:11 | count:5` (31: a `u16` count follows) followed by
//!   either 16-bit words packing four `x:11 p:1` values into three, or `u16`s of `x:11 |
//!   mask:5` (the mask's bits, high first, add x+1 … x+5) and run-length bytes of
//!   `p:1 | count:7` (127: a `u16` count follows).
//!
//! The output is what the filter hands back to HDF5: 16-byte records `u16 x, u16 y, i16 p, pad,
//! i64 t`, the layout of Prophesee's `CD/events`.

/// The most events one chunk may hold.
pub const MAX_EVENTS: usize = 65_535;
/// Bytes of one decoded event record.
pub const RECORD: usize = 16;

/// A cursor that refuses to read past the end of the compressed bytes.
struct Bytes<'a> {
    b: &'a [u8],
    i: usize,
}

impl Bytes<'_> {
    fn u8(&mut self) -> Result<u8, String> {
        let v = *self.b.get(self.i).ok_or_else(cut)?;
        self.i += 1;
        Ok(v)
    }
    fn u16(&mut self) -> Result<u16, String> {
        Ok(u16::from_le_bytes([self.u8()?, self.u8()?]))
    }
    fn u32(&mut self) -> Result<u32, String> {
        Ok(u32::from_le_bytes([
            self.u8()?,
            self.u8()?,
            self.u8()?,
            self.u8()?,
        ]))
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(self.u32()? as u64 | (self.u32()? as u64) << 32)
    }
}

fn cut() -> String {
    "an ECF chunk cut short".into()
}

/// Repeats `v` `count` times into `out`, never past `n` values.
fn run<T: Copy>(out: &mut Vec<T>, v: T, count: usize, n: usize) {
    let k = count.min(n - out.len());
    out.extend(std::iter::repeat_n(v, k));
}

/// Decodes one ECF chunk into 16-byte CD event records.
pub fn decode(chunk: &[u8]) -> Result<Vec<u8>, String> {
    let mut b = Bytes { b: chunk, i: 0 };
    let head = b.u32()?;
    let n = (head >> 2) as usize;
    if n > MAX_EVENTS {
        return Err(format!("an ECF chunk of {n} events (at most {MAX_EVENTS})"));
    }
    let yxp_packed = head & 2 != 0;
    let xp_packed = head & 1 != 0;
    // times
    let mut ts: Vec<u64> = Vec::with_capacity(n);
    let mut t = b.u64()?;
    while ts.len() < n {
        let v = b.u8()?;
        let (dt, c) = (v >> 4, (v & 0x0F) as usize);
        if dt != 0x0F {
            t = t.wrapping_add(dt as u64);
            let c = if c == 0x0F { b.u16()? as usize } else { c };
            run(&mut ts, t, c, n);
            if c == 0 && ts.len() < n && b.i >= chunk.len() {
                return Err(cut());
            }
        } else {
            // a step of nibbles, least significant first, up to the next byte not marked 15
            let mut step = 0u64;
            let mut v = v;
            let mut j = 0;
            while v >> 4 == 0x0F {
                if j == 16 {
                    return Err("an ECF time step longer than 64 bits".into());
                }
                step |= ((v & 0x0F) as u64) << (4 * j);
                j += 1;
                v = *chunk.get(b.i).ok_or_else(cut)?;
                if v >> 4 == 0x0F {
                    b.i += 1;
                }
            }
            t = t.wrapping_add(step);
        }
    }
    let mut ys: Vec<u16> = Vec::with_capacity(n);
    let mut xs: Vec<u16> = Vec::with_capacity(n + 5);
    let mut ps: Vec<u8> = Vec::with_capacity(n + 3);
    if yxp_packed {
        while xs.len() < n {
            let w = [b.u32()?, b.u32()?, b.u32()?];
            let vs = [
                w[0] >> 8,
                (w[0] & 0xFF) | ((w[1] >> 16) << 8),
                (w[1] & 0xFFFF) | ((w[2] >> 24) << 16),
                w[2] & 0xFF_FFFF,
            ];
            for v in vs {
                ys.push(((v >> 12) & 0x7FF) as u16);
                xs.push(((v >> 1) & 0x7FF) as u16);
                ps.push((v & 1) as u8);
            }
        }
    } else {
        while ys.len() < n {
            let v = b.u16()?;
            let c = (v & 0x1F) as usize;
            let c = if c == 0x1F { b.u16()? as usize } else { c };
            run(&mut ys, v >> 5, c, n);
        }
        if xp_packed {
            while xs.len() < n {
                let w = [b.u16()?, b.u16()?, b.u16()?];
                let vs = [
                    w[0] >> 4,
                    (w[0] & 0x0F) | ((w[1] >> 8) << 4),
                    (w[1] & 0xFF) | ((w[2] >> 12) << 8),
                    w[2] & 0x0FFF,
                ];
                for v in vs {
                    xs.push(v >> 1);
                    ps.push((v & 1) as u8);
                }
            }
        } else {
            while xs.len() < n {
                let v = b.u16()?;
                let x = v >> 5;
                xs.push(x);
                for j in 0..5 {
                    if v & (1 << (4 - j)) != 0 {
                        xs.push(x.wrapping_add(j + 1));
                    }
                }
            }
            while ps.len() < n {
                let v = b.u8()?;
                let c = (v & 0x7F) as usize;
                let c = if c == 0x7F { b.u16()? as usize } else { c };
                run(&mut ps, v >> 7, c, n);
            }
        }
    }
    let mut out = vec![0u8; n * RECORD];
    for (i, r) in out.chunks_exact_mut(RECORD).enumerate() {
        r[0..2].copy_from_slice(&xs[i].to_le_bytes());
        r[2..4].copy_from_slice(&ys[i].to_le_bytes());
        r[4..6].copy_from_slice(&(ps[i] as i16).to_le_bytes());
        r[8..16].copy_from_slice(&(ts[i] as i64).to_le_bytes());
    }
    Ok(out)
}
