// Shared by the fuzz targets: the readers take paths, so each input is written to a file
// (behind a valid header for the format under test) and read to the end. Any error is fine;
// a panic, a hang or a huge allocation is a bug.

pub fn read_with_header(header: &[u8], data: &[u8], ext: &str) {
    let path = std::env::temp_dir().join(format!("eenf-fuzz-{}.{ext}", std::process::id()));
    let mut bytes = header.to_vec();
    bytes.extend_from_slice(data);
    std::fs::write(&path, &bytes).unwrap();
    if let Ok(mut r) = eenf_events::open(&path) {
        let _ = r.info();
        let mut total = 0usize;
        while let Ok(Some(b)) = r.next_batch() {
            total += b.len();
            assert!(total <= bytes.len() * 64, "more events than the bytes can hold");
        }
        let _ = r.skipped();
    }
}
