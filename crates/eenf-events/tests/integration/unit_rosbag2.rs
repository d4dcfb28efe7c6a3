//! Tests of eenf-events's `rosbag2` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use crate::read_all;
use eenf_events::rosbag2::*;

use eenf_events::{open, open_with, EventBatch, OpenOptions, Result, StreamInfo};
use std::path::Path;

/// A ROS 2 `event_array_msgs/EventArray` in CDR of `mono` events `(t ns, x, y, p)`.
fn mono_packet(time_base: u64, events: &[(u32, u16, u16, bool)]) -> Vec<u8> {
    let mut m = vec![0, 1, 0, 0];
    m.extend([0u8; 8]); // stamp
    m.extend(1u32.to_le_bytes()); // frame_id ""
    m.extend([0u8, 0, 0, 0]); // its NUL, padded to 4
    m.extend(480u32.to_le_bytes());
    m.extend(640u32.to_le_bytes());
    m.extend(7u64.to_le_bytes()); // seq
    m.extend(time_base.to_le_bytes());
    m.extend(5u32.to_le_bytes());
    m.extend(b"mono\0");
    m.push(0); // is_bigendian
    m.extend([0u8; 2]); // pad to 4
    m.extend(((events.len() * 8) as u32).to_le_bytes());
    for &(t, x, y, p) in events {
        let w = ((p as u64) << 63) | ((y as u64) << 48) | ((x as u64) << 32) | t as u64;
        m.extend(w.to_le_bytes());
    }
    m
}

/// A rosbag2 SQLite file at `path`: an IMU topic, then events in two messages.
fn write_db3(path: &Path, compress: bool) {
    let db = rusqlite::Connection::open(path).unwrap();
    db.execute_batch(
        "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);
         CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, data BLOB NOT NULL);
         INSERT INTO topics VALUES (1, '/imu', 'sensor_msgs/msg/Imu', 'cdr', '');
         INSERT INTO topics VALUES (2, '/events', 'event_array_msgs/msg/EventArray', 'cdr', '');",
    )
    .unwrap();
    let msgs = [
        (1, vec![0u8, 1, 0, 0, 9]),
        (
            2,
            mono_packet(1_000_000, &[(1000, 1, 2, true), (3000, 3, 4, false)]),
        ),
        (1, vec![0u8, 1, 0, 0, 9]),
        (2, mono_packet(2_000_000, &[(0, 5, 6, true)])),
    ];
    for (i, (topic, data)) in msgs.into_iter().enumerate() {
        let data = if compress {
            zstd::encode_all(&data[..], 1).unwrap()
        } else {
            data
        };
        db.execute(
            "INSERT INTO messages VALUES (?1, ?2, ?3, ?4)",
            rusqlite::params![i as i64 + 1, topic, i as i64, data],
        )
        .unwrap();
    }
}

fn read(path: &Path, topic: Option<&str>) -> Result<(StreamInfo, EventBatch)> {
    read_all(open_with(
        path,
        &OpenOptions {
            topic: topic.map(str::to_string),
            ..Default::default()
        },
    )?)
}

#[test]
fn sqlite_folders_and_files_compressed_or_not() {
    let dir = tempfile::tempdir().unwrap();
    for compress in [false, true] {
        let bag = dir.path().join(format!("bag{compress}"));
        std::fs::create_dir(&bag).unwrap();
        write_db3(&bag.join("bag_0.db3"), compress);
        for path in [bag.clone(), bag.join("bag_0.db3")] {
            let (info, b) = read(&path, None).unwrap();
            assert_eq!(info.format, "rosbag2 (SQLite)");
            assert_eq!(b.t, vec![1_001, 1_003, 2_000]);
            assert_eq!((b.x, b.y), (vec![1, 3, 5], vec![2, 4, 6]));
            assert_eq!(b.p, vec![true, false, true]);
            assert_eq!((info.width, info.height), (Some(640), Some(480)));
            let counts: Vec<_> = info.streams.iter().map(|s| s.messages).collect();
            assert_eq!(counts, vec![Some(2), Some(2)]);
        }
    }
    // a split bag: its files in the order metadata.yaml lists them
    let split = dir.path().join("split");
    std::fs::create_dir(&split).unwrap();
    write_db3(&split.join("b_1.db3"), false);
    write_db3(&split.join("b_0.db3"), true);
    std::fs::write(
        split.join("metadata.yaml"),
        "rosbag2_bagfile_information:\n  relative_file_paths:\n    - b_0.db3\n    - b_1.db3\n  files: []\n",
    )
    .unwrap();
    assert_eq!(read(&split, None).unwrap().1.len(), 6);
    // a bag compressed file by file (rosbag2's zstd file mode)
    let zbag = dir.path().join("zstd");
    std::fs::create_dir(&zbag).unwrap();
    let db = std::fs::read(split.join("b_1.db3")).unwrap();
    std::fs::write(
        zbag.join("b_0.db3.zstd"),
        zstd::encode_all(&db[..], 3).unwrap(),
    )
    .unwrap();
    assert_eq!(read(&zbag, None).unwrap().1.t, vec![1_001, 1_003, 2_000]);
    // topics asked for by name; ones that are not there or carry no events are refused
    let bag = dir.path().join("bagfalse");
    let e = read(&bag, Some("/imu")).unwrap_err().to_string();
    assert!(e.contains("sensor_msgs/msg/Imu"), "{e}");
    let e = read(&bag, Some("/nope")).unwrap_err().to_string();
    assert!(
        e.contains("/events (event_array_msgs/msg/EventArray)"),
        "{e}"
    );
    // a folder that is no bag, and an SQLite database that is no bag
    let e = read(dir.path(), None).unwrap_err().to_string();
    assert!(e.contains("not a rosbag2"), "{e}");
    let other = dir.path().join("other.db3");
    rusqlite::Connection::open(&other)
        .unwrap()
        .execute_batch("CREATE TABLE t(a)")
        .unwrap();
    let e = read(&other, None).unwrap_err().to_string();
    assert!(e.contains("without the tables of a rosbag2"), "{e}");
}

fn write_mcap(summary: bool) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    let opts = mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        .use_chunks(true)
        .emit_summary_records(summary)
        .emit_summary_offsets(summary)
        .emit_statistics(summary)
        .emit_chunk_indexes(summary)
        .emit_message_indexes(summary);
    let mut w = opts.create(&mut out).unwrap();
    let imu = w.add_schema("sensor_msgs/msg/Imu", "ros2msg", b"").unwrap();
    let ev = w
        .add_schema("event_array_msgs/msg/EventArray", "ros2msg", b"")
        .unwrap();
    let imu = w
        .add_channel(imu, "/imu", "cdr", &Default::default())
        .unwrap();
    let ev = w
        .add_channel(ev, "/events", "cdr", &Default::default())
        .unwrap();
    for (i, (ch, data)) in [
        (imu, vec![0u8, 1, 0, 0]),
        (ev, mono_packet(0, &[(5000, 1, 1, true)])),
        (ev, mono_packet(0, &[(9000, 2, 2, false)])),
    ]
    .into_iter()
    .enumerate()
    {
        let header = mcap::records::MessageHeader {
            channel_id: ch,
            sequence: i as u32,
            log_time: i as u64,
            publish_time: i as u64,
        };
        w.write_to_known_channel(&header, &data).unwrap();
    }
    w.finish().unwrap();
    drop(w);
    out.into_inner()
}

#[test]
fn mcap_with_and_without_its_summary() {
    for summary in [true, false] {
        let bytes = write_mcap(summary);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.mcap");
        std::fs::write(&path, &bytes).unwrap();
        let (info, b) = read(&path, None).unwrap();
        assert_eq!(info.format, "rosbag2 (MCAP)");
        assert_eq!(b.t, vec![5, 9]);
        let counts: Vec<_> = info.streams.iter().map(|s| s.messages).collect();
        let want = if summary {
            vec![Some(1), Some(2)]
        } else {
            vec![None, None]
        };
        assert_eq!(counts, want, "summary {summary}");
        // cut anywhere: an error or the events before the cut, never a panic
        for cut in 0..bytes.len() {
            std::fs::write(&path, &bytes[..cut]).unwrap();
            if let Ok(mut r) = open(&path) {
                let mut n = 0;
                while let Ok(Some(b)) = r.next_batch() {
                    n += b.len();
                }
                assert!(n <= 2);
            }
        }
    }
}

#[test]
fn files_compressed_whole_are_read_as_they_expand_and_bombs_refused() {
    // an MCAP compressed whole: read from the stream, no copy
    let dir = tempfile::tempdir().unwrap();
    let bag = dir.path().join("z");
    std::fs::create_dir(&bag).unwrap();
    let mcap = zstd::encode_all(&write_mcap(true)[..], 3).unwrap();
    std::fs::write(bag.join("b.mcap.zstd"), mcap).unwrap();
    let (info, b) = read(&bag, None).unwrap();
    assert_eq!((info.format, b.t), ("rosbag2 (MCAP)", vec![5, 9]));
    // zeros, an SQLite header stating two pages then zeros: refused at once
    let zeros = vec![0u8; 256 << 20];
    let mut sqlite = SQLITE_MAGIC.to_vec();
    sqlite.resize(100, 0);
    sqlite[16..18].copy_from_slice(&4096u16.to_be_bytes());
    sqlite[24..28].copy_from_slice(&7u32.to_be_bytes());
    sqlite[28..32].copy_from_slice(&2u32.to_be_bytes());
    sqlite[92..96].copy_from_slice(&7u32.to_be_bytes());
    sqlite.extend(&zeros[..64 << 10]);
    for (name, content, why) in [
        ("b.mcap.zstd", &zeros[..], "neither an SQLite nor an MCAP"),
        ("b.db3.zstd", &sqlite[..], "the size its header states"),
    ] {
        std::fs::remove_dir_all(&bag).unwrap();
        std::fs::create_dir(&bag).unwrap();
        std::fs::write(bag.join(name), zstd::encode_all(content, 19).unwrap()).unwrap();
        let e = read(&bag, None).unwrap_err().to_string();
        assert!(e.contains(why), "{e}");
    }
    // an MCAP that goes on as zeros, a thousand times its compressed size
    let mut bomb = MCAP_MAGIC.to_vec();
    bomb.extend(&zeros);
    std::fs::remove_dir_all(&bag).unwrap();
    std::fs::create_dir(&bag).unwrap();
    std::fs::write(
        bag.join("b.mcap.zstd"),
        zstd::encode_all(&bomb[..], 19).unwrap(),
    )
    .unwrap();
    assert!(read(&bag, None).is_err());
}
