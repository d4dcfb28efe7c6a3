#![no_main]
//! Fuzz target: the ATIS `.bin` reader (no header: the reader is called directly).

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let len = data.len();
    let src = Box::new(std::io::Cursor::new(data.to_vec()));
    if let Ok(mut r) = eenf_events::atis::reader(src, std::path::Path::new("fuzz-input")) {
        let mut total = 0usize;
        while let Ok(Some(b)) = r.next_batch() {
            total += b.len();
            assert!(total <= len / 5, "more events than words");
        }
    }
});
