//! Tests of eenf-events's `hdf5/ecf` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

//! The decoder cases of `ecf_codec_test.cpp`, their buffers built as its macros build them.
use eenf_events::hdf5::ecf::*;

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
