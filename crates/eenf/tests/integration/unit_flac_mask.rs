//! Tests of eenf's `flac_mask` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use eenf::flac_mask::*;
use std::io::{Read, Write};

/// `fLaC`, a STREAMINFO, a PICTURE whose MIME length says 4 GiB, a last PADDING.
fn flac_head() -> Vec<u8> {
    let mut b = b"fLaC".to_vec();
    b.extend([0x00, 0, 0, 34]);
    b.extend([0u8; 34]);
    let picture = [0u8, 0, 0, 3, 0xFF, 0xFF, 0xFF, 0xFF];
    b.extend([0x06, 0, 0, picture.len() as u8]);
    b.extend(picture);
    b.extend([0x81, 0, 0, 2, 0, 0]);
    b.extend(b"frames");
    b
}

fn masked(bytes: &[u8]) -> Vec<u8> {
    let mut f = tempfile::tempfile().unwrap();
    f.write_all(bytes).unwrap();
    let mut m = flac_masked(f).unwrap();
    let mut out = Vec::new();
    // read in small pieces: patches land across read boundaries
    let mut buf = [0u8; 7];
    loop {
        let n = m.read(&mut buf).unwrap();
        if n == 0 {
            break out;
        }
        out.extend(&buf[..n]);
    }
}

#[test]
fn only_the_picture_block_type_changes() {
    let bytes = flac_head();
    let out = masked(&bytes);
    let diff: Vec<usize> = (0..bytes.len()).filter(|&i| bytes[i] != out[i]).collect();
    assert_eq!(diff, vec![4 + 4 + 34]);
    assert_eq!(out[42], PADDING);
}

#[test]
fn after_an_id3_tag_too_and_other_files_untouched() {
    let mut bytes = b"ID3\x04\x00\x00\x00\x00\x00\x05".to_vec();
    bytes.extend([0u8; 5]);
    bytes.extend(flac_head());
    let out = masked(&bytes);
    assert_eq!(out[15 + 42], PADDING);
    let wav = b"RIFF\x06\x00\x00\x00WAVEfmt ".to_vec();
    assert_eq!(masked(&wav), wav);
}
