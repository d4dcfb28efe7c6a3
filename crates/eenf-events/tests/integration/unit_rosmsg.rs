//! Tests of eenf-events's `rosmsg` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_events::rosmsg::*;
use eenf_events::EventBatch;

#[test]
fn cdr_fields_are_aligned_from_the_encapsulation_header() {
    // header: stamp 1 s 2 ns, frame_id "ab\0"; height 2, width 3; one dvs event
    let mut m = vec![0, 1, 0, 0];
    m.extend(1u32.to_le_bytes());
    m.extend(2u32.to_le_bytes());
    m.extend(3u32.to_le_bytes());
    m.extend(b"ab\0\0"); // string + 1 pad byte for the u32 after
    m.extend(2u32.to_le_bytes());
    m.extend(3u32.to_le_bytes());
    m.extend(2u32.to_le_bytes()); // two events
    for (x, s, ns, p) in [(5u16, 7u32, 3000u32, 1u8), (6, 8, 4000, 0)] {
        while (m.len() - 4) % 2 != 0 {
            m.push(0xEE);
        }
        m.extend(x.to_le_bytes());
        m.extend(9u16.to_le_bytes());
        while (m.len() - 4) % 4 != 0 {
            m.push(0xEE);
        }
        m.extend(s.to_le_bytes());
        m.extend(ns.to_le_bytes());
        m.push(p);
    }
    let mut d = MessageDecoder::new(Kind::Events);
    let mut out = EventBatch::default();
    d.decode(&m, Serialization::Cdr, &mut out).unwrap();
    assert_eq!(out.t, vec![7_000_003, 8_000_004]);
    assert_eq!(
        (out.x, out.y, out.p),
        (vec![5, 6], vec![9, 9], vec![true, false])
    );
    assert_eq!((d.width, d.height), (Some(3), Some(2)));
    // cut anywhere: an error, never a panic
    for cut in 0..m.len() {
        let mut out = EventBatch::default();
        assert!(d.decode(&m[..cut], Serialization::Cdr, &mut out).is_err());
    }
}

#[test]
fn libcaer_clock_loops_within_a_message() {
    let word = |x: u32, y: u32, p: u32, t: i32| {
        let mut w = ((x << 17) | (y << 2) | (p << 1) | 1).to_le_bytes().to_vec();
        w.extend(t.to_le_bytes());
        w
    };
    let bytes = [word(3, 4, 1, i32::MAX - 1), word(5, 6, 0, 2)].concat();
    let mut out = EventBatch::default();
    libcaer(&bytes, 1_000_000_000, &mut out);
    let loop_us = 1i64 << 31;
    assert_eq!(
        out.t,
        vec![1_000_000 + i32::MAX as i64 - 1, 1_000_000 + loop_us + 2]
    );
    assert_eq!(
        (out.x, out.y, out.p),
        (vec![3, 5], vec![4, 6], vec![true, false])
    );
}

#[test]
fn libcaer_cmp_addresses_and_vectors() {
    // time high 1 (4096 µs), low 5; x 10; y 20 ON; base y 30 OFF; vector rows 0 and 2
    let words: [u16; 6] = [1, 0x1005, 0x2000 | 10, 0x3800 | 20, 0x4000 | 30, 0x5005];
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    let mut c = CaerCmp::default();
    let mut out = EventBatch::default();
    c.decode(&bytes, 2_000_000, 640, 480, &mut out);
    let t = 2_000 + 4096 + 5;
    assert_eq!(out.t, vec![t, t, t]);
    assert_eq!(out.x, vec![10, 10, 10]);
    assert_eq!(out.y, vec![20, 30, 32]);
    assert_eq!(out.p, vec![true, false, false]);
    // events outside the sensor are dropped
    let mut out = EventBatch::default();
    c.decode(&bytes, 0, 10, 480, &mut out);
    assert!(out.is_empty());
}

#[test]
fn mono_words() {
    let w: u64 = (1 << 63) | (7u64 << 48) | (9u64 << 32) | 5000;
    let mut out = EventBatch::default();
    mono(&w.to_le_bytes(), 1_000_000, &mut out);
    assert_eq!(
        (out.t[0], out.x[0], out.y[0], out.p[0]),
        (1_005, 9, 7, true)
    );
}
