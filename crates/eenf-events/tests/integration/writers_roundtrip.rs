//! Every writer → eenf's reader is lossless, including absolute (epoch) timestamps in formats
//! whose clocks are narrow; and damaged files give errors or the events before the damage.

use eenf_events::writers::{create, OutputFormat};
use eenf_events::{open_with, Compression, EventBatch, OpenOptions};

/// The samples hold a 40 s gap (to loop narrow clocks): read past it.
fn open(path: &std::path::Path) -> eenf_events::Result<Box<dyn eenf_events::EventReader>> {
    let wide = OpenOptions {
        max_gap_us: Some(60_000_000),
        ..OpenOptions::default()
    };
    open_with(path, &wide)
}

fn sample(n: usize, t0: i64) -> EventBatch {
    let mut b = EventBatch::default();
    let mut s = 0x853c49e6748fea9bu64;
    let mut t = t0;
    for i in 0..n {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        if i % 5 == 0 {
            t += (s >> 58) as i64; // groups of events share timestamps, with gaps up to 63 µs
        }
        if i == n / 2 {
            t += 40_000_000; // a 40 s gap: loops of the 24-bit EVT 3.0 clock
        }
        // runs along a row, so EVT 3.0 vectors are exercised
        let x = if i % 7 < 4 {
            100 + (i % 7) as u16
        } else {
            (s % 640) as u16
        };
        b.push(t, x, ((s >> 20) % 480) as u16, (s >> 40) & 1 == 1);
    }
    b
}

fn read_all(path: &std::path::Path) -> EventBatch {
    let mut r = open(path).unwrap_or_else(|e| panic!("{e}"));
    let mut all = EventBatch::default();
    while let Some(b) = r.next_batch().unwrap_or_else(|e| panic!("{e}")) {
        all.extend_from(&b);
    }
    all
}

fn canonical(b: &EventBatch) -> Vec<(i64, u16, u16, bool)> {
    let mut v: Vec<_> = (0..b.len())
        .map(|i| (b.t[i], b.x[i], b.y[i], b.p[i]))
        .collect();
    v.sort();
    v
}

fn formats() -> Vec<(OutputFormat, &'static str)> {
    vec![
        (OutputFormat::Aedat4(Compression::Lz4), "aedat4"),
        (OutputFormat::Aedat4(Compression::ZstdHigh), "aedat4"),
        (OutputFormat::Evt2, "raw"),
        (OutputFormat::Evt3, "raw"),
        (OutputFormat::Dat, "dat"),
        (OutputFormat::Text, "txt"),
    ]
}

#[test]
fn every_writer_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    for t0 in [0i64, 1_700_000_000_123_456] {
        let events = sample(30_000, t0);
        for (k, (format, ext)) in formats().into_iter().enumerate() {
            let path = dir.path().join(format!("rt{k}_{t0}.{ext}"));
            let mut w = create(&path, format, 640, 480).unwrap();
            for chunk in [0..1usize, 1..9_999, 9_999..30_000] {
                let mut part = EventBatch::default();
                part.t.extend_from_slice(&events.t[chunk.clone()]);
                part.x.extend_from_slice(&events.x[chunk.clone()]);
                part.y.extend_from_slice(&events.y[chunk.clone()]);
                part.p.extend_from_slice(&events.p[chunk]);
                w.write(&part).unwrap();
            }
            assert_eq!(w.finish().unwrap(), 30_000);
            let back = read_all(&path);
            let r = open(&path).unwrap();
            if format != OutputFormat::Text {
                assert_eq!(
                    (r.info().width, r.info().height),
                    (Some(640), Some(480)),
                    "{format:?}"
                );
            }
            if format == OutputFormat::Evt3 {
                // events sharing a timestamp may come back in another order
                assert_eq!(canonical(&back), canonical(&events), "{format:?} t0 {t0}");
            } else {
                assert_eq!(back, events, "{format:?} t0 {t0}");
            }
        }
    }
}

/// Reads a file to the end; returns the events and whether it ended in an error.
fn read_lenient(path: &std::path::Path) -> (EventBatch, bool) {
    let mut all = EventBatch::default();
    let mut r = match open(path) {
        Ok(r) => r,
        Err(_) => return (all, true),
    };
    loop {
        match r.next_batch() {
            Ok(Some(b)) => all.extend_from(&b),
            Ok(None) => return (all, false),
            Err(_) => return (all, true),
        }
    }
}

#[test]
fn truncated_and_flipped_files_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    let events = sample(5_000, 1_000);
    for (k, (format, ext)) in formats().into_iter().enumerate() {
        let path = dir.path().join(format!("src{k}.{ext}"));
        let mut w = create(&path, format, 640, 480).unwrap();
        w.write(&events).unwrap();
        w.finish().unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let damaged = dir.path().join(format!("bad{k}.{ext}"));
        // cuts everywhere in the first 300 bytes (headers, mid-word), then spread out
        let cuts: Vec<usize> = (0..300.min(bytes.len()))
            .chain((300..bytes.len()).step_by(bytes.len() / 97 + 1))
            .collect();
        for cut in cuts {
            std::fs::write(&damaged, &bytes[..cut]).unwrap();
            let (got, _) = read_lenient(&damaged);
            // what comes back is a prefix of the stream (EVT 3.0 may reorder within a timestamp)
            assert!(got.len() <= events.len(), "{format:?} cut {cut}");
            if format != OutputFormat::Evt3 && format != OutputFormat::Text {
                assert_eq!(got.t[..], events.t[..got.len()], "{format:?} cut {cut}");
            }
        }
        let mut state = 99u64 + k as u64;
        for _ in 0..200 {
            let mut b = bytes.clone();
            for _ in 0..4 {
                state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
                let at = (state >> 33) as usize % b.len();
                b[at] ^= 1 << ((state >> 29) & 7);
            }
            std::fs::write(&damaged, &b).unwrap();
            let _ = read_lenient(&damaged); // must not panic or allocate wildly
        }
    }
}

/// A writer into any seekable sink, and the readers over any byte source, give what the file
/// paths give: bytes in memory decode to the same events as the file.
#[test]
fn writers_and_readers_work_over_bytes_in_memory() {
    use std::io::{Cursor, Read, Seek, SeekFrom};
    let dir = tempfile::tempdir().unwrap();
    let events = sample(12_000, 1_700_000_000_123_456);
    for (k, (format, ext)) in formats().into_iter().enumerate() {
        let path = dir.path().join(format!("mem{k}.{ext}"));
        // the same events through a temporary file handed over as a sink
        let mut file = tempfile::tempfile().unwrap();
        let sink = Box::new(file.try_clone().unwrap());
        let name = std::path::Path::new("in-memory");
        let mut w = eenf_events::writers::writer(sink, name, format, 640, 480).unwrap();
        w.write(&events).unwrap();
        w.finish().unwrap();
        let mut bytes = Vec::new();
        file.seek(SeekFrom::Start(0)).unwrap();
        file.read_to_end(&mut bytes).unwrap();
        std::fs::write(&path, &bytes).unwrap();
        let from_file = read_all(&path);
        let wide = OpenOptions {
            max_gap_us: Some(60_000_000),
            ..OpenOptions::default()
        };
        let mut r =
            eenf_events::open_source_with(Box::new(Cursor::new(bytes)), name, &wide).unwrap();
        let mut from_bytes = EventBatch::default();
        while let Some(b) = r.next_batch().unwrap() {
            from_bytes.extend_from(&b);
        }
        assert_eq!(from_bytes, from_file, "{format}");
        assert_eq!(canonical(&from_file), canonical(&events), "{format}");
    }
}
