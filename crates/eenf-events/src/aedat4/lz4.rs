//! The LZ4 frame format, decoded block by block straight into a reused output buffer
//! (`lz4_flex`'s streaming decoder copies every byte once more through its own buffer).
//! Blocks without history go through liblz4's bounds-checked `LZ4_decompress_safe` (the `lz4`
//! crate); linked blocks, which need the blocks before as a dictionary, through `lz4_flex`.

/// The LZ4 frame magic number.
const MAGIC: u32 = 0x184D_2204;
/// Largest decompressed packet accepted.
const MAX_OUTPUT: usize = 1 << 30;
/// Linked blocks may refer back this far.
const WINDOW: usize = 64 * 1024;

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    b.get(at..at + 4)
        .map(|s| u32::from_le_bytes(s.try_into().unwrap()))
}

/// Decodes all LZ4 frames in `input` into `out` (grown as needed, never shrunk) and returns the
/// number of bytes produced.
pub(crate) fn decode_frames(input: &[u8], out: &mut Vec<u8>) -> Result<usize, String> {
    let mut pos = 0;
    let mut n = 0;
    while pos < input.len() {
        let magic = u32_at(input, pos).ok_or("LZ4 frame header cut short")?;
        if magic & 0xFFFF_FFF0 == 0x184D_2A50 {
            // skippable frame
            let len = u32_at(input, pos + 4).ok_or("LZ4 skippable frame cut short")? as usize;
            pos = pos
                .checked_add(8 + len)
                .filter(|&p| p <= input.len())
                .ok_or("LZ4 skippable frame cut short")?;
            continue;
        }
        if magic != MAGIC {
            return Err(format!("not an LZ4 frame (magic {magic:#010x})"));
        }
        let flg = *input.get(pos + 4).ok_or("LZ4 frame header cut short")?;
        let bd = *input.get(pos + 5).ok_or("LZ4 frame header cut short")?;
        if flg >> 6 != 1 {
            return Err(format!("unsupported LZ4 frame version {}", flg >> 6));
        }
        let independent = flg & 0x20 != 0;
        let block_checksum = flg & 0x10 != 0;
        let content_size = flg & 0x08 != 0;
        let content_checksum = flg & 0x04 != 0;
        let dict_id = flg & 0x01 != 0;
        let max_block = match (bd >> 4) & 7 {
            4 => 64 << 10,
            5 => 256 << 10,
            6 => 1 << 20,
            7 => 4 << 20,
            v => return Err(format!("bad LZ4 block size code {v}")),
        };
        pos += 6 + if content_size { 8 } else { 0 } + if dict_id { 4 } else { 0 } + 1;
        let frame_start = n;
        loop {
            let word = u32_at(input, pos).ok_or("LZ4 block header cut short")?;
            pos += 4;
            if word == 0 {
                break; // end mark
            }
            let stored = word & 0x8000_0000 != 0;
            let len = (word & 0x7FFF_FFFF) as usize;
            let block = input
                .get(pos..pos + len)
                .ok_or("LZ4 block runs past the packet")?;
            pos += len + if block_checksum { 4 } else { 0 };
            if n + max_block > MAX_OUTPUT {
                return Err("LZ4 output exceeds 1 GiB".into());
            }
            if out.len() < n + max_block {
                out.resize((n + max_block).max(out.len() * 2), 0);
            }
            if stored {
                if len > max_block {
                    return Err("stored LZ4 block larger than the block size".into());
                }
                out[n..n + len].copy_from_slice(block);
                n += len;
            } else if independent || n == frame_start {
                // no history to refer to: liblz4's bounds-checked LZ4_decompress_safe, about
                // 1.3x lz4_flex's checked decoder on event packets
                let k = lz4::block::decompress_to_buffer(
                    block,
                    Some(max_block as i32),
                    &mut out[n..n + max_block],
                )
                .map_err(|e| format!("LZ4 decompression failed: {e}"))?;
                n += k;
            } else {
                // linked blocks (dv-processing's default) refer back into the blocks before
                let (before, after) = out.split_at_mut(n);
                let dict_from = n.saturating_sub(WINDOW).max(frame_start);
                let k = lz4_flex::block::decompress_into_with_dict(
                    block,
                    &mut after[..max_block],
                    &before[dict_from..],
                )
                .map_err(|e| format!("LZ4 decompression failed: {e}"))?;
                n += k;
            }
        }
        if content_checksum {
            pos += 4;
        }
        if pos > input.len() {
            return Err("LZ4 frame checksum cut short".into());
        }
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;
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
}
