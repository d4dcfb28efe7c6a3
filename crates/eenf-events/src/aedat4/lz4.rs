//! The LZ4 frame format, decoded block by block straight into a reused output buffer
//! (streaming decoders copy every byte once more through their own buffer). Every block goes
//! through liblz4's bounds-checked `LZ4_decompress_safe_usingDict` (the `lz4-sys` crate): linked
//! blocks (dv-processing writes 64 KiB linked blocks) with the blocks before them in the same
//! buffer as their history, which is liblz4's fast path; independent blocks with none.

/// The LZ4 frame magic number.
const MAGIC: u32 = 0x184D_2204;
/// Largest decompressed packet accepted.
const MAX_OUTPUT: usize = super::MAX_PACKET as usize;
/// Linked blocks may refer back this far.
const WINDOW: usize = 64 * 1024;

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    b.get(at..at + 4)
        .map(|s| u32::from_le_bytes(s.try_into().unwrap()))
}

/// The largest block of a frame, from its BD byte (LZ4 frame format: codes 4-7).
fn block_max(bd: u8) -> Option<usize> {
    match (bd >> 4) & 7 {
        4 => Some(64 << 10),
        5 => Some(256 << 10),
        6 => Some(1 << 20),
        7 => Some(4 << 20),
        _ => None,
    }
}

/// Decodes all LZ4 frames in `input` into `out` (grown as needed, never shrunk) and returns the
/// number of bytes produced.
pub fn decode_frames(input: &[u8], out: &mut Vec<u8>) -> Result<usize, String> {
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
        let max_block =
            block_max(bd).ok_or_else(|| format!("bad LZ4 block size code {}", (bd >> 4) & 7))?;
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
                return Err(super::over_limit((n + max_block) as u64));
            }
            if out.len() < n + max_block {
                out.resize((n + max_block).max(out.len() * 2).min(MAX_OUTPUT), 0);
            }
            if stored {
                if len > max_block {
                    return Err("stored LZ4 block larger than the block size".into());
                }
                out[n..n + len].copy_from_slice(block);
                n += len;
            } else {
                // linked blocks (dv-processing's default) may refer back up to 64 KiB into the
                // blocks of their frame before them; independent ones to nothing
                let dict_from = if independent {
                    n
                } else {
                    n.saturating_sub(WINDOW).max(frame_start)
                };
                let k = liblz4::decompress_block(block, out, dict_from, n, max_block)
                    .ok_or("LZ4 decompression failed: corrupt block")?;
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

/// An upper bound of what the LZ4 frames in `input` decompress to (a block at most its
/// frame's block size), read from the block headers alone; saturates on damage, which the
/// decoder reports.
pub(crate) fn decoded_bound(input: &[u8]) -> u64 {
    let mut pos = 0usize;
    let mut total = 0u64;
    while pos < input.len() && total < MAX_OUTPUT as u64 {
        let (Some(magic), Some(&flg), Some(&bd)) =
            (u32_at(input, pos), input.get(pos + 4), input.get(pos + 5))
        else {
            return MAX_OUTPUT as u64;
        };
        if magic & 0xFFFF_FFF0 == 0x184D_2A50 {
            let Some(len) = u32_at(input, pos + 4) else {
                return MAX_OUTPUT as u64;
            };
            pos = pos.saturating_add(8).saturating_add(len as usize);
            continue;
        }
        let Some(max_block) = block_max(bd).map(|b| b as u64) else {
            return MAX_OUTPUT as u64;
        };
        pos += 6 + if flg & 0x08 != 0 { 8 } else { 0 } + if flg & 0x01 != 0 { 4 } else { 0 } + 1;
        loop {
            let Some(word) = u32_at(input, pos) else {
                return MAX_OUTPUT as u64;
            };
            pos += 4;
            if word == 0 {
                break;
            }
            total += max_block;
            pos = pos.saturating_add((word & 0x7FFF_FFFF) as usize + 4 * ((flg >> 4) & 1) as usize);
        }
        pos += 4 * ((flg >> 2) & 1) as usize;
    }
    total.min(MAX_OUTPUT as u64)
}

/// The one call into liblz4. Its `_safe` decoders are written to be safe on any input: they
/// never read outside `src` or the dictionary and never write past `dst + dstCapacity`
/// (lz4.h, "LZ4_decompress_safe"); a corrupt block returns a negative number.
#[allow(unsafe_code)]
mod liblz4 {
    use std::os::raw::{c_char, c_int};

    // liblz4 is built and linked by lz4-sys; this function of its stable API (lz4.h,
    // LZ4LIB_API since 1.7) is not among the ones lz4-sys declares
    use lz4_sys as _;
    unsafe extern "C" {
        fn LZ4_decompress_safe_usingDict(
            src: *const c_char,
            dst: *mut c_char,
            src_size: c_int,
            dst_capacity: c_int,
            dict_start: *const c_char,
            dict_size: c_int,
        ) -> c_int;
    }

    /// Decodes the LZ4 block `src` into `buf[at..at + cap]`, with `buf[dict_from..at]` as the
    /// history its matches may refer to; returns the bytes written, `None` on a corrupt block.
    pub(super) fn decompress_block(
        src: &[u8],
        buf: &mut [u8],
        dict_from: usize,
        at: usize,
        cap: usize,
    ) -> Option<usize> {
        if dict_from > at || at.checked_add(cap)? > buf.len() {
            return None;
        }
        let src_size = c_int::try_from(src.len()).ok()?;
        let dst_capacity = c_int::try_from(cap).ok()?;
        let dict_size = c_int::try_from(at - dict_from).ok()?;
        let base = buf.as_mut_ptr();
        // SAFETY: `src` is readable for `src_size` bytes; `base + at` is writable for
        // `dst_capacity` bytes and `base + dict_from` readable for `dict_size` bytes, all inside
        // `buf` (checked above), which nothing else touches during the call; the dictionary
        // ends where the output starts, so they do not overlap. The `_safe` decoder stays
        // inside these ranges whatever `src` holds.
        let k = unsafe {
            LZ4_decompress_safe_usingDict(
                src.as_ptr().cast(),
                base.add(at).cast(),
                src_size,
                dst_capacity,
                base.add(dict_from).cast(),
                dict_size,
            )
        };
        usize::try_from(k).ok()
    }
}
