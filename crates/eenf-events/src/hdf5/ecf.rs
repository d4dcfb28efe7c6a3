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

#[cfg(test)]
mod tests {
    //! The decoder cases of `ecf_codec_test.cpp`, their buffers built as its macros build them.
    use super::*;

    #[derive(Debug, Clone, Copy, PartialEq)]
    struct Ev {
        x: u16,
        y: u16,
        p: u8,
        t: u64,
    }

    fn ev(x: u16, y: u16, p: u8, t: u64) -> Ev {
        Ev { x, y, p, t }
    }

    fn header(n: usize, yxp: bool, xp: bool) -> Vec<u8> {
        (((n as u32) << 2) | ((yxp as u32) << 1) | xp as u32)
            .to_le_bytes()
            .to_vec()
    }

    fn rle_t(t: u8, c: u8) -> u8 {
        (t << 4) | c
    }

    fn rle_y(y: u16, c: u16) -> Vec<u8> {
        ((y << 5) | c).to_le_bytes().to_vec()
    }

    fn rle_p(p: u8, c: u8) -> u8 {
        (p << 7) | c
    }

    fn mask_x(x: u16, m: u16) -> Vec<u8> {
        ((x << 5) | m).to_le_bytes().to_vec()
    }

    /// Four events packed as y, x, p into three `u32`s (missing ones empty).
    fn pack_yxp(e: &[Ev]) -> Vec<u8> {
        let v = |i: usize| {
            e.get(i)
                .map(|e| ((e.y as u32) << 12) | ((e.x as u32) << 1) | e.p as u32)
                .unwrap_or(0)
        };
        [
            (v(0) << 8) | (v(1) & 0xFF),
            ((v(1) >> 8) << 16) | (v(2) & 0xFFFF),
            ((v(2) >> 16) << 24) | (v(3) & 0xFF_FFFF),
        ]
        .iter()
        .flat_map(|w| w.to_le_bytes())
        .collect()
    }

    /// Four events packed as x, p into three `u16`s.
    fn pack_xp(e: &[Ev]) -> Vec<u8> {
        let v = |i: usize| e.get(i).map(|e| (e.x << 1) | e.p as u16).unwrap_or(0);
        [
            (v(0) << 4) | (v(1) & 0x0F),
            ((v(1) >> 4) << 8) | (v(2) & 0xFF),
            ((v(2) >> 8) << 12) | (v(3) & 0x0FFF),
        ]
        .iter()
        .flat_map(|w| w.to_le_bytes())
        .collect()
    }

    fn decoded(buf: &[u8]) -> Vec<Ev> {
        let out = decode(buf).unwrap();
        out.chunks_exact(RECORD)
            .map(|r| Ev {
                x: u16::from_le_bytes([r[0], r[1]]),
                y: u16::from_le_bytes([r[2], r[3]]),
                p: i16::from_le_bytes([r[4], r[5]]) as u8,
                t: i64::from_le_bytes(r[8..16].try_into().unwrap()) as u64,
            })
            .collect()
    }

    /// The codec test's `std::mt19937` stand-in: any fixed sequence of coordinates will do.
    fn coords(n: usize, seed: u64) -> Vec<(u16, u16)> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (((s >> 33) % 1280) as u16, ((s >> 17) % 720) as u16)
            })
            .collect()
    }

    #[test]
    fn one_event_packed_y_x_and_p() {
        for e in [ev(0, 0, 0, 0), ev(1, 2, 0, 4)] {
            let mut buf = header(1, true, false);
            buf.extend(e.t.to_le_bytes());
            buf.push(rle_t(0, 1));
            buf.extend(pack_yxp(&[e]));
            assert_eq!(decoded(&buf), vec![e]);
        }
    }

    #[test]
    fn up_to_four_events_same_t_same_y_x_and_p_packed() {
        for j in 2..=4usize {
            let es: Vec<Ev> = (0..j).map(|i| ev(i as u16 * 10, 23, 1, 10_000)).collect();
            let mut buf = header(j, false, true);
            buf.extend(10_000u64.to_le_bytes());
            buf.push(rle_t(0, j as u8));
            buf.extend(rle_y(23, j as u16));
            buf.extend(pack_xp(&es));
            assert_eq!(decoded(&buf), es, "{j}");
        }
    }

    #[test]
    fn up_to_six_events_same_t_same_y_x_masked() {
        for j in 2..=6usize {
            let es: Vec<Ev> = (0..j).map(|i| ev(19 + i as u16, 23, 0, 13_875)).collect();
            let mut buf = header(j, false, false);
            buf.extend(13_875u64.to_le_bytes());
            buf.push(rle_t(0, j as u8));
            buf.extend(rle_y(23, j as u16));
            buf.extend(mask_x(19, (1 << 5) - (1 << (6 - j))));
            buf.push(rle_p(0, j as u8));
            assert_eq!(decoded(&buf), es, "{j}");
        }
    }

    #[test]
    fn long_runs_take_their_counts_from_the_next_bytes() {
        // more than 15 events at one time, y, x and p packed
        for n in [16usize, 25, 254, 255, 256, 312, 1891, 18923, 65535] {
            let es: Vec<Ev> = coords(n, 42)
                .into_iter()
                .map(|(x, y)| ev(x, y, 1, 10_000))
                .collect();
            let mut buf = header(n, true, false);
            buf.extend(10_000u64.to_le_bytes());
            buf.push(rle_t(0, 0x0F));
            buf.extend((n as u16).to_le_bytes());
            for four in es.chunks(4) {
                buf.extend(pack_yxp(four));
            }
            assert_eq!(decoded(&buf), es, "{n}");
        }
        // more than 31 events on one row, x and p packed
        for n in [32usize, 43, 254, 255, 256, 312, 1891, 18923, 65535] {
            let es: Vec<Ev> = coords(n, 7)
                .into_iter()
                .map(|(x, _)| ev(x, 873, 1, 10_000))
                .collect();
            let mut buf = header(n, false, true);
            buf.extend(10_000u64.to_le_bytes());
            buf.push(rle_t(0, 0x0F));
            buf.extend((n as u16).to_le_bytes());
            buf.extend(rle_y(873, 0x1F));
            buf.extend((n as u16).to_le_bytes());
            for four in es.chunks(4) {
                buf.extend(pack_xp(four));
            }
            assert_eq!(decoded(&buf), es, "{n}");
        }
        // more than 127 events of one polarity, x masked
        for n in [128usize, 133, 254, 255, 256, 312, 1891, 18923, 65535] {
            let es: Vec<Ev> = (0..n)
                .map(|i| ev((i % 1278) as u16, 873, 1, 10_000))
                .collect();
            let mut buf = header(n, false, false);
            buf.extend(10_000u64.to_le_bytes());
            buf.push(rle_t(0, 0x0F));
            buf.extend((n as u16).to_le_bytes());
            buf.extend(rle_y(873, 0x1F));
            buf.extend((n as u16).to_le_bytes());
            for six in es.chunks(6) {
                // runs of x, x+1, … within a 6-event group (1278 is a multiple of 6)
                buf.extend(mask_x(six[0].x, (1 << 5) - (1 << (6 - six.len()))));
            }
            buf.push(rle_p(1, 0x7F));
            buf.extend((n as u16).to_le_bytes());
            assert_eq!(decoded(&buf), es, "{n}");
        }
    }

    #[test]
    fn time_steps_of_15_us_and_more_are_nibble_runs() {
        // t0 = 5; events at 5, 5+3, then +300 (nibbles 0xC, 0x2, 0x1), then +1
        let es = [
            ev(1, 1, 1, 5),
            ev(2, 1, 1, 8),
            ev(3, 1, 1, 308),
            ev(4, 1, 1, 309),
        ];
        let mut buf = header(4, true, false);
        buf.extend(5u64.to_le_bytes());
        buf.push(rle_t(0, 1));
        buf.push(rle_t(3, 1));
        buf.extend([0xF0 | 0xC, 0xF0 | 0x2, 0xF0 | 0x1]);
        buf.push(rle_t(0, 1));
        buf.push(rle_t(1, 1));
        buf.extend(pack_yxp(&es));
        assert_eq!(decoded(&buf), es.to_vec());
    }

    #[test]
    fn too_many_events_and_cut_chunks_are_errors() {
        let mut buf = header(100_000, true, false);
        buf.extend(0u64.to_le_bytes());
        buf.push(rle_t(0, 1));
        buf.extend(pack_yxp(&[ev(0, 0, 0, 0)]));
        assert!(decode(&buf).unwrap_err().contains("100000 events"));
        let e = ev(1, 2, 0, 4);
        let mut buf = header(1, true, false);
        buf.extend(e.t.to_le_bytes());
        buf.push(rle_t(0, 1));
        buf.extend(pack_yxp(&[e]));
        for cut in 0..buf.len() {
            assert!(decode(&buf[..cut]).is_err(), "{cut}");
        }
    }
}
