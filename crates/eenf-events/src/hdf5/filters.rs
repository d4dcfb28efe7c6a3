//! The HDF5 filters of event data sets that the HDF5 reader does not build in. Each bounds
//! what it allocates: by the chunk size the filter's parameters state (blosc), by the format's
//! own limit (ECF), or by [`MAX_CHUNK`] (zstd).

use hdf5_reader::messages::filter_pipeline::FilterDescription;
use hdf5_reader::FilterRegistry;

/// zstd (HDF5 registered filter 32015: one zstd frame a chunk; VECtor, MPL data sets).
pub const ZSTD: u16 = 32015;
/// blosc 1 (registered filter 32001; DSEC, M3ED; hdf5plugin's default).
pub const BLOSC: u16 = 32001;
/// Prophesee's ECF (0x8ECF).
pub const ECF: u16 = 0x8ECF;
/// The largest chunk eenf decodes: 16 times the 1 MiB h5py chunks at most, and small enough
/// that the chunks of a slice, decoded on all cores, keep the process well under 200 MB.
pub const MAX_CHUNK: usize = 16 << 20;

fn err(what: &str, reason: impl std::fmt::Display) -> hdf5_reader::error::Error {
    hdf5_reader::error::Error::InvalidData(format!("a {what} chunk that does not expand: {reason}"))
}

/// The filter registry eenf opens HDF5 files with: the built-in ones and these.
pub fn registry() -> FilterRegistry {
    let mut r = FilterRegistry::new();
    r.register(ZSTD, Box::new(|_, data, _| zstd_chunk(data)));
    r.register(BLOSC, Box::new(|f, data, _| blosc_chunk(f, data)));
    r.register(
        ECF,
        Box::new(|_, data, _| super::ecf::decode(data).map_err(|e| err("ECF", e))),
    );
    r
}

fn zstd_chunk(data: &[u8]) -> hdf5_reader::error::Result<Vec<u8>> {
    use std::io::Read;
    let mut out = Vec::new();
    zstd::stream::read::Decoder::new(data)
        .and_then(|d| d.take(MAX_CHUNK as u64 + 1).read_to_end(&mut out))
        .map_err(|e| err("zstd", e))?;
    if out.len() > MAX_CHUNK {
        return Err(err(
            "zstd",
            format!("it expands past {} MiB", MAX_CHUNK >> 20),
        ));
    }
    Ok(out)
}

/// A blosc 1 chunk (c-blosc's own decoder): its header states the size, checked against the
/// chunk size in the filter's parameters (`cd_values[3]`) before anything is allocated.
fn blosc_chunk(f: &FilterDescription, data: &[u8]) -> hdf5_reader::error::Result<Vec<u8>> {
    let bound = f
        .client_data
        .get(3)
        .map(|&b| b as usize)
        .filter(|&b| b > 0)
        .unwrap_or(MAX_CHUNK)
        .min(MAX_CHUNK);
    let n = blosc::expanded_size(data).ok_or_else(|| err("blosc", "a damaged header"))?;
    if n > bound {
        return Err(err(
            "blosc",
            format!("its header states {n} bytes, more than the chunk's {bound}"),
        ));
    }
    blosc::decompress(data, n).ok_or_else(|| err("blosc", "damaged data"))
}

/// The two calls into c-blosc (built from source by `blosc-src`), the only `unsafe` of the
/// HDF5 reader.
#[allow(unsafe_code)]
mod blosc {
    /// The size `data` expands to, when its header is sound and states its own length.
    pub fn expanded_size(data: &[u8]) -> Option<usize> {
        // blosc 1's header is 16 bytes; the validation reads no more than `data.len()`
        if data.len() < 16 {
            return None;
        }
        let mut n = 0usize;
        // SAFETY: `data` is valid for `data.len()` bytes and `n` is a valid out-pointer;
        // blosc_cbuffer_validate reads only within the given length.
        let rc =
            unsafe { blosc_src::blosc_cbuffer_validate(data.as_ptr().cast(), data.len(), &mut n) };
        (rc == 0).then_some(n)
    }

    /// `data` expanded into `n` bytes (as validated by [`expanded_size`]).
    pub fn decompress(data: &[u8], n: usize) -> Option<Vec<u8>> {
        // not zeroed first: c-blosc writes every byte of a chunk it expands whole
        let mut out: Vec<u8> = Vec::with_capacity(n);
        // SAFETY: the header was validated against `data.len()`; `out` has room for `n`
        // bytes, the size passed; one internal thread, no global state.
        let rc = unsafe {
            blosc_src::blosc_decompress_ctx(data.as_ptr().cast(), out.as_mut_ptr().cast(), n, 1)
        };
        if rc < 0 || rc as usize != n {
            return None;
        }
        // SAFETY: blosc_decompress_ctx returned `n`: it wrote all `n` bytes
        unsafe { out.set_len(n) };
        Some(out)
    }
}
