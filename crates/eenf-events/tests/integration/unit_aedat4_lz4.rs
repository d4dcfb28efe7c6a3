//! Tests of eenf-events's `aedat4/lz4` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf_events::aedat4::lz4::*;
use std::io::Write;

fn frame(data: &[u8], linked: bool) -> Vec<u8> {
    let info = lz4_flex::frame::FrameInfo::new()
        .block_mode(if linked {
            lz4_flex::frame::BlockMode::Linked
        } else {
            lz4_flex::frame::BlockMode::Independent
        })
        .content_checksum(true);
    let mut enc = lz4_flex::frame::FrameEncoder::with_frame_info(info, Vec::new());
    enc.write_all(data).unwrap();
    enc.finish().unwrap()
}

#[test]
fn decodes_linked_and_independent_multi_block_frames() {
    // > 64 KiB with long-range repeats, so linked blocks refer back across blocks
    let data: Vec<u8> = (0..300_000u32)
        .map(|i| ((i / 7) % 251) as u8 ^ (i % 3) as u8)
        .collect();
    for linked in [true, false] {
        let mut out = Vec::new();
        let f = frame(&data, linked);
        let n = decode_frames(&f, &mut out).unwrap();
        assert_eq!(&out[..n], &data[..]);
        // two frames back to back, into a buffer that already holds data
        let mut two = f.clone();
        two.extend_from_slice(&f);
        let n = decode_frames(&two, &mut out).unwrap();
        assert_eq!(n, 2 * data.len());
        assert_eq!(&out[data.len()..n], &data[..]);
    }
}

#[test]
fn damaged_frames_are_errors() {
    let data = vec![7u8; 100_000];
    let f = frame(&data, true);
    let mut out = Vec::new();
    for cut in [3, 5, 9, 20, f.len() - 3] {
        assert!(decode_frames(&f[..cut], &mut out).is_err(), "cut {cut}");
    }
    let mut bad = f.clone();
    bad[0] ^= 1;
    assert!(decode_frames(&bad, &mut out).is_err());
}

#[test]
fn flipped_bytes_in_linked_blocks_never_read_outside() {
    // every byte of a linked multi-block frame flipped in turn: liblz4's checked decoder
    // must return an error or some output, never crash or run past its buffers
    let data: Vec<u8> = (0..150_000u32)
        .map(|i| ((i / 5) % 241) as u8 ^ (i % 7) as u8)
        .collect();
    let f = frame(&data, true);
    let mut out = Vec::new();
    let step = (f.len() / 2000).max(1);
    for at in (0..f.len()).step_by(step) {
        for flip in [0x01u8, 0x80, 0xFF] {
            let mut bad = f.clone();
            bad[at] ^= flip;
            if let Ok(n) = decode_frames(&bad, &mut out) {
                assert!(n <= out.len());
            }
        }
    }
    // and the undamaged frame still decodes into the same (now dirty) buffer
    let n = decode_frames(&f, &mut out).unwrap();
    assert_eq!(&out[..n], &data[..]);
}
