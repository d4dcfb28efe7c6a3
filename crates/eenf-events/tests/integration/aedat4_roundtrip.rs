//! Writer → reader round trips and damaged files, on data made here (no shared files needed).

use eenf_events::{
    open, open_with, Aedat4Writer, Compression, DamageKind, EventBatch, EventError, OpenOptions,
    StreamStats,
};
use std::io::Write;

fn sample(n: usize) -> EventBatch {
    let mut b = EventBatch::default();
    let mut state = 12345u64;
    let mut t = 1_700_000_000_000_000i64;
    for i in 0..n {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        if i % 3 == 0 {
            t += (state >> 60) as i64; // several events share a timestamp
        }
        b.push(
            t,
            (state >> 20) as u16 % 640,
            (state >> 40) as u16 % 480,
            state >> 63 == 1,
        );
    }
    b
}

fn read_all(path: &std::path::Path) -> EventBatch {
    let mut r = open(path).unwrap();
    let mut all = EventBatch::default();
    while let Some(b) = r.next_batch().unwrap() {
        all.extend_from(&b);
    }
    all
}

fn write(path: &std::path::Path, codec: Compression, events: &EventBatch) {
    let mut w = Aedat4Writer::create(path, codec, 640, 480)
        .unwrap()
        .with_packet_events(1000);
    // uneven slices, to exercise packet assembly across writes
    let mut start = 0;
    for len in [1usize, 999, 7_000, 13_337, 100_000] {
        let end = (start + len).min(events.len());
        let mut part = EventBatch::default();
        part.t.extend_from_slice(&events.t[start..end]);
        part.x.extend_from_slice(&events.x[start..end]);
        part.y.extend_from_slice(&events.y[start..end]);
        part.p.extend_from_slice(&events.p[start..end]);
        w.write(&part).unwrap();
        start = end;
    }
    assert_eq!(w.finish().unwrap(), events.len() as u64);
}

#[test]
fn every_codec_round_trips_exactly_with_index() {
    let dir = tempfile::tempdir().unwrap();
    let events = sample(25_000);
    for code in 0..5 {
        let codec = Compression::from_code(code).unwrap();
        let path = dir.path().join(format!("rt_{code}.aedat4"));
        write(&path, codec, &events);
        let r = open(&path).unwrap();
        let info = r.info().clone();
        assert_eq!(info.format, "AEDAT 4.0");
        assert_eq!(info.codec.as_deref(), Some(codec.name()));
        assert_eq!((info.width, info.height), (Some(640), Some(480)));
        assert!(info.indexed, "FileDataTable read back");
        assert_eq!(info.event_count, Some(25_000));
        assert_eq!(info.first_t, Some(events.t[0]));
        assert_eq!(info.last_t, Some(*events.t.last().unwrap()));
        assert_eq!(read_all(&path), events, "codec {}", codec.name());
    }
    // nothing but the finished files is left behind
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 5);
}

/// The error `--strict` reading gives.
fn expect_err(path: &std::path::Path) -> EventError {
    let strict = OpenOptions {
        strict: true,
        ..OpenOptions::default()
    };
    let mut r = match open_with(path, &strict) {
        Ok(r) => r,
        Err(e) => return e,
    };
    loop {
        match r.next_batch() {
            Ok(Some(_)) => {}
            Ok(None) => panic!("{} read without error", path.display()),
            Err(e) => return e,
        }
    }
}

#[test]
fn truncated_and_corrupt_files_are_errors_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let events = sample(20_000);
    let good = dir.path().join("good.aedat4");
    write(&good, Compression::Lz4, &events);
    let bytes = std::fs::read(&good).unwrap();

    // cut in the middle of the third packet
    let cut = dir.path().join("cut.aedat4");
    let mut pos = 18 + u32::from_le_bytes(bytes[14..18].try_into().unwrap()) as usize;
    for _ in 0..2 {
        pos += 8 + i32::from_le_bytes(bytes[pos + 4..pos + 8].try_into().unwrap()) as usize;
    }
    std::fs::write(&cut, &bytes[..pos + 30]).unwrap();
    let e = expect_err(&cut);
    assert!(matches!(e, EventError::Truncated { .. }), "{e}");
    assert!(e.to_string().contains("cut.aedat4"), "{e}");
    // by default the events before the damage are read, and the damage is reported
    let mut r = open(&cut).unwrap();
    let mut salvaged = EventBatch::default();
    while let Some(b) = r.next_batch().unwrap() {
        salvaged.extend_from(&b);
    }
    assert_eq!(salvaged.len(), 2000, "two whole packets before the cut");
    let n = salvaged.len();
    assert_eq!(salvaged.t[..], events.t[..n]);
    assert_eq!(salvaged.x[..], events.x[..n]);
    assert_eq!(salvaged.y[..], events.y[..n]);
    assert_eq!(salvaged.p[..], events.p[..n]);
    let d = r.damage().expect("the cut is reported");
    assert_eq!(d.kind, DamageKind::Truncated);
    assert_eq!(d.offset, pos as u64);
    assert_eq!(d.events_before, 2000);
    assert!(d.to_string().contains("the 2000 events before it"), "{d}");

    // flip bytes inside the compressed body of the second packet
    let bad = dir.path().join("bad.aedat4");
    let mut b2 = bytes.clone();
    let p0 = 18 + u32::from_le_bytes(bytes[14..18].try_into().unwrap()) as usize;
    let p1 = p0 + 8 + i32::from_le_bytes(bytes[p0 + 4..p0 + 8].try_into().unwrap()) as usize;
    for k in 0..64 {
        b2[p1 + 20 + k] ^= 0x5a;
    }
    std::fs::write(&bad, &b2).unwrap();
    let e = expect_err(&bad);
    assert!(matches!(e, EventError::Corrupt { .. }), "{e}");
    assert!(e.to_string().contains("bad.aedat4"), "{e}");

    // header only, cut inside the IOHeader, and a non-event file
    let short = dir.path().join("short.aedat4");
    std::fs::write(&short, &bytes[..40]).unwrap();
    assert!(matches!(expect_err(&short), EventError::Truncated { .. }));
    let junk = dir.path().join("junk.bin");
    std::fs::File::create(&junk)
        .unwrap()
        .write_all(&[0u8, 1, 2, 3, 200, 100])
        .unwrap();
    let e = expect_err(&junk);
    assert!(matches!(e, EventError::UnknownFormat { .. }), "{e}");
    let empty = dir.path().join("empty.aedat4");
    std::fs::write(&empty, b"").unwrap();
    assert!(expect_err(&empty).to_string().contains("empty"));
    let missing = dir.path().join("missing.aedat4");
    assert!(matches!(expect_err(&missing), EventError::Io { .. }));
}

#[test]
fn a_file_without_data_table_reads_to_the_end() {
    let dir = tempfile::tempdir().unwrap();
    let events = sample(5_000);
    let path = dir.path().join("t.aedat4");
    write(&path, Compression::Zstd, &events);
    // Drop the table and set the header's dataTablePosition to -1, as an interrupted recording
    // leaves the file.
    assert!(open(&path).unwrap().info().indexed);
    let bytes = without_table(&path);
    std::fs::write(&path, &bytes).unwrap();
    let r = open(&path).unwrap();
    assert!(!r.info().indexed);
    assert_eq!(r.info().event_count, None);
    assert_eq!(read_all(&path), events);
    let mut r = open(&path).unwrap();
    let stats = StreamStats::scan(r.as_mut()).unwrap();
    assert_eq!(stats.events, 5_000);
}

fn find_table_pos(bytes: &[u8], hlen: usize) -> i64 {
    // walk packets until the remaining bytes are not a packet of the event stream
    let mut pos = 18 + hlen;
    loop {
        let size = i32::from_le_bytes(bytes[pos + 4..pos + 8].try_into().unwrap()) as usize;
        let next = pos + 8 + size;
        if next >= bytes.len() || i32::from_le_bytes(bytes[pos..pos + 4].try_into().unwrap()) != 0 {
            return pos as i64;
        }
        pos = next;
    }
}

#[test]
fn text_files_read_both_time_spellings() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.txt");
    std::fs::write(&a, "# t x y p\n0.000001 1 2 1\n0.0000026 3 4 0\n").unwrap();
    let e = read_all(&a);
    assert_eq!(e.t, vec![1, 3]); // 2.6 us rounds to 3, not truncated to 2
    assert_eq!(e.p, vec![true, false]);
    let b = dir.path().join("b.csv");
    std::fs::write(&b, "t_us,x,y,p\n10,1,2,-1\n11,3,4,1\n").unwrap();
    let e = read_all(&b);
    assert_eq!(e.t, vec![10, 11]);
    assert_eq!(e.p, vec![false, true]);
    let c = dir.path().join("c.txt");
    std::fs::write(&c, "1 2 3 1\n2 2 3 1\nbroken line here\n").unwrap();
    let err = expect_err(&c);
    assert!(err.to_string().contains("line 3"), "{err}");
}

#[test]
fn a_wild_timestamp_ends_the_stream_where_it_is() {
    let dir = tempfile::tempdir().unwrap();
    // one second of events, then one 48 h later, then more of the first second
    let mut text = String::new();
    for i in 0..1000 {
        text += &format!("{} 1 2 1\n", i * 1000);
    }
    let jump_at = text.len();
    text += &format!("{} 1 2 1\n", 48i64 * 3600 * 1_000_000);
    text += "1000000 1 2 0\n";
    let path = dir.path().join("jump.txt");
    std::fs::write(&path, &text).unwrap();
    let mut r = open(&path).unwrap();
    let stats = StreamStats::scan(r.as_mut()).unwrap();
    assert_eq!((stats.events, stats.last_t), (1000, Some(999_000)));
    let d = r.damage().unwrap();
    assert_eq!((d.kind, d.events_before), (DamageKind::TimeJump, 1000));
    assert!(d.message.contains("172800.000000 s"), "{d}");
    assert!(d.offset <= jump_at as u64, "{} > {jump_at}", d.offset);
    // a wider limit reads on; --strict refuses
    let wide = OpenOptions {
        max_gap_us: Some(49 * 3600 * 1_000_000),
        ..OpenOptions::default()
    };
    let mut r = open_with(&path, &wide).unwrap();
    assert_eq!(StreamStats::scan(r.as_mut()).unwrap().events, 1002);
    let e = expect_err(&path);
    assert!(e.to_string().contains("timestamp jumps"), "{e}");
    // the limit is exact: 4.9 s and 5 s steps pass, 5.000001 s does not (forwards or back)
    std::fs::write(
        &path,
        "0 1 2 1\n4900000 1 2 1\n9900000 1 2 1\n14900001 1 2 1\n",
    )
    .unwrap();
    let mut r = open(&path).unwrap();
    assert_eq!(StreamStats::scan(r.as_mut()).unwrap().events, 3);
    std::fs::write(&path, "20000000 1 2 1\n15000000 1 2 1\n9999999 1 2 1\n").unwrap();
    let mut r = open(&path).unwrap();
    assert_eq!(StreamStats::scan(r.as_mut()).unwrap().events, 2);
    // backwards by more than the limit ends it too
    std::fs::write(&path, "10000000 1 2 1\n10000010 1 2 1\n10 1 2 1\n").unwrap();
    let mut r = open(&path).unwrap();
    assert_eq!(StreamStats::scan(r.as_mut()).unwrap().events, 2);
    assert_eq!(r.damage().unwrap().kind, DamageKind::TimeJump);
}

/// The bytes of the AEDAT4 file at `path` without its FileDataTable, the header's
/// dataTablePosition set to -1.
fn without_table(path: &std::path::Path) -> Vec<u8> {
    let mut bytes = std::fs::read(path).unwrap();
    let hlen = u32::from_le_bytes(bytes[14..18].try_into().unwrap()) as usize;
    let table_pos = find_table_pos(&bytes, hlen);
    bytes.truncate(table_pos as usize);
    let needle = table_pos.to_le_bytes();
    let at = bytes[18..18 + hlen]
        .windows(8)
        .position(|w| w == needle)
        .unwrap();
    bytes[18 + at..18 + at + 8].copy_from_slice(&(-1i64).to_le_bytes());
    bytes
}

/// `events` written without an index, then `packet` (a compressed body) appended as a further
/// packet of the event stream.
fn with_extra_packet(
    path: &std::path::Path,
    codec: Compression,
    events: &EventBatch,
    packet: &[u8],
) {
    write(path, codec, events);
    let mut bytes = without_table(path);
    bytes.extend_from_slice(&0i32.to_le_bytes());
    bytes.extend_from_slice(&(packet.len() as i32).to_le_bytes());
    bytes.extend_from_slice(packet);
    std::fs::write(path, &bytes).unwrap();
}

#[test]
fn a_packet_that_expands_past_the_limit_is_damage_after_the_events_before_it() {
    let dir = tempfile::tempdir().unwrap();
    let events = sample(3_000);
    let zeros = vec![0u8; (64 << 20) + 4096];
    // zstd with the size in its frame header, zstd streamed without it, and LZ4
    let zstd_sized = zstd::bulk::compress(&zeros, 1).unwrap();
    let mut zstd_streamed = Vec::new();
    {
        let mut enc = zstd::stream::write::Encoder::new(&mut zstd_streamed, 1).unwrap();
        enc.include_contentsize(false).unwrap();
        enc.write_all(&zeros).unwrap();
        enc.finish().unwrap();
    }
    let mut lz4 = lz4_flex::frame::FrameEncoder::new(Vec::new());
    lz4.write_all(&zeros).unwrap();
    let lz4 = lz4.finish().unwrap();
    for (name, codec, packet) in [
        ("zstd_sized", Compression::Zstd, zstd_sized),
        ("zstd_streamed", Compression::Zstd, zstd_streamed),
        ("lz4", Compression::Lz4, lz4),
    ] {
        let path = dir.path().join(format!("{name}.aedat4"));
        with_extra_packet(&path, codec, &events, &packet);
        let mut r = open(&path).unwrap();
        let mut all = EventBatch::default();
        while let Some(b) = r.next_batch().unwrap() {
            all.extend_from(&b);
        }
        assert_eq!(all, events, "{name}: the events before the packet");
        let err = r
            .damage()
            .expect("the outsized packet is damage")
            .to_string();
        assert!(err.contains("64 MiB limit"), "{name}: {err}");
        assert!(err.contains(&path.display().to_string()), "{name}: {err}");
    }
}

#[test]
fn a_large_honest_packet_is_read_whole_in_bounded_batches() {
    let dir = tempfile::tempdir().unwrap();
    let events = sample(1_500_000);
    let path = dir.path().join("big.aedat4");
    let mut w = Aedat4Writer::create(&path, Compression::Lz4, 640, 480)
        .unwrap()
        .with_packet_events(1_500_000);
    w.write(&events).unwrap();
    w.finish().unwrap();
    let mut r = open(&path).unwrap();
    let mut all = EventBatch::default();
    while let Some(b) = r.next_batch().unwrap() {
        assert!(b.len() <= 1 << 18, "a batch of {} events", b.len());
        all.extend_from(&b);
    }
    assert_eq!(all, events);
}
