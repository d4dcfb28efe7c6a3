// Shared by the fuzz targets: each input, behind a valid header for the format under test,
// is fed to the readers as bytes in memory and read to the end. Any error is fine; a panic, a
// hang or a huge allocation is a bug.

pub fn read_with_header(header: &[u8], data: &[u8], _ext: &str) {
    let mut bytes = header.to_vec();
    bytes.extend_from_slice(data);
    let len = bytes.len();
    let src = Box::new(std::io::Cursor::new(bytes));
    if let Ok(mut r) = eenf_events::open_source(src, std::path::Path::new("fuzz-input")) {
        let _ = r.info();
        let mut total = 0usize;
        while let Ok(Some(b)) = r.next_batch() {
            total += b.len();
            assert!(total <= len * 64, "more events than the bytes can hold");
        }
        let _ = r.skipped();
    }
}
