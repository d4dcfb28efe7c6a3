//! Decoding speed of the same EVT 3.0 events as a Prophesee `.raw` and inside rosbag2 files
//! (SQLite and MCAP) as `event_camera_msgs/EventPacket` messages of 5,000 bytes, about what
//! metavision_driver publishes each millisecond at 2 M events/s.
//!
//! The files are written once into the target folder (`EENF_BENCH_SECONDS`, default 10 s =
//! 20 M events); `cargo bench -p eenf-bench --bench containers` prints events/s.
//!
//! `dsec`: a DSEC-layout HDF5 file (blosc + zstd), when `tools/hdf5_bench.py write` has made
//! one (`target/tmp/dsec-bench.h5`); `tools/hdf5_bench.py peer` times h5py on the same file.
#![allow(missing_docs)] // criterion_group! makes undocumented public functions

use std::path::{Path, PathBuf};

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use eenf_events::writers::{create, OutputFormat};
use eenf_events::EventBatch;

const RATE: u64 = 2_000_000;
const PACKET: usize = 5_000;

/// An EVT 3.0 recording of `seconds` of random events at 2 M events/s.
fn raw(dir: &Path, seconds: u64) -> PathBuf {
    let path = dir.join(format!("containers-{seconds}s.raw"));
    if path.exists() {
        return path;
    }
    let mut w = create(&path, OutputFormat::Evt3, 640, 480).unwrap();
    let mut state = 0x2545f4914f6cdd1du64;
    let mut batch = EventBatch::default();
    for i in 0..seconds * RATE {
        state ^= state >> 12;
        state ^= state << 25;
        state ^= state >> 27;
        let r = state.wrapping_mul(0x2545f4914f6cdd1d);
        batch.push(
            (i * 1_000_000 / RATE) as i64,
            (r % 640) as u16,
            ((r >> 16) % 480) as u16,
            r >> 63 == 1,
        );
        if batch.len() == 1 << 20 {
            w.write(&batch).unwrap();
            batch.clear();
        }
    }
    w.write(&batch).unwrap();
    w.finish().unwrap();
    path
}

/// An `event_camera_msgs/EventPacket` in CDR carrying `bytes` of EVT 3.0.
fn packet(seq: u64, bytes: &[u8]) -> Vec<u8> {
    let mut m = vec![0, 1, 0, 0];
    m.extend([0u8; 8]); // stamp
    m.extend(4u32.to_le_bytes());
    m.extend(b"cam\0");
    m.extend(480u32.to_le_bytes());
    m.extend(640u32.to_le_bytes());
    m.extend(seq.to_le_bytes());
    m.extend(0u64.to_le_bytes()); // time base
    m.extend(5u32.to_le_bytes());
    m.extend(b"evt3\0");
    m.push(0); // is_bigendian
    m.extend([0u8; 2]);
    m.extend((bytes.len() as u32).to_le_bytes());
    m.extend(bytes);
    m
}

/// The EVT 3.0 words of `raw` (after its `%` header), cut into packets.
fn packets(raw: &Path) -> Vec<Vec<u8>> {
    let bytes = std::fs::read(raw).unwrap();
    let mut start = 0;
    while bytes[start..].starts_with(b"%") {
        start += bytes[start..].iter().position(|&b| b == b'\n').unwrap() + 1;
    }
    bytes[start..]
        .chunks(PACKET)
        .enumerate()
        .map(|(i, c)| packet(i as u64, c))
        .collect()
}

fn sqlite(dir: &Path, raw: &Path) -> PathBuf {
    let bag = dir.join(format!(
        "{}-bag-sqlite",
        raw.file_stem().unwrap().to_string_lossy()
    ));
    if bag.exists() {
        return bag;
    }
    std::fs::create_dir_all(&bag).unwrap();
    let mut db = rusqlite::Connection::open(bag.join("bag_0.db3")).unwrap();
    db.execute_batch(
        "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);
         CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, data BLOB NOT NULL);
         INSERT INTO topics VALUES (1, '/event_camera/events', 'event_camera_msgs/msg/EventPacket', 'cdr', '');",
    )
    .unwrap();
    let tx = db.transaction().unwrap();
    for (i, p) in packets(raw).iter().enumerate() {
        tx.execute(
            "INSERT INTO messages (topic_id, timestamp, data) VALUES (1, ?1, ?2)",
            rusqlite::params![i as i64, p],
        )
        .unwrap();
    }
    tx.commit().unwrap();
    bag
}

fn mcap(dir: &Path, raw: &Path) -> PathBuf {
    let path = dir.join(format!(
        "{}.mcap",
        raw.file_stem().unwrap().to_string_lossy()
    ));
    if path.exists() {
        return path;
    }
    let f = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    // rosbag2's MCAP writer compresses chunks with zstd by default
    let mut w = mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Zstd))
        .create(f)
        .unwrap();
    let schema = w
        .add_schema("event_camera_msgs/msg/EventPacket", "ros2msg", b"")
        .unwrap();
    let ch = w
        .add_channel(schema, "/event_camera/events", "cdr", &Default::default())
        .unwrap();
    for (i, p) in packets(raw).iter().enumerate() {
        let header = mcap::records::MessageHeader {
            channel_id: ch,
            sequence: i as u32,
            log_time: i as u64,
            publish_time: i as u64,
        };
        w.write_to_known_channel(&header, p).unwrap();
    }
    w.finish().unwrap();
    path
}

fn benches(c: &mut Criterion) {
    let seconds: u64 = std::env::var("EENF_BENCH_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(10);
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let raw = raw(&dir, seconds);
    let inputs = [
        ("evt3_raw", raw.clone()),
        ("rosbag2_sqlite_evt3", sqlite(&dir, &raw)),
        ("rosbag2_mcap_zstd_evt3", mcap(&dir, &raw)),
    ];
    let n = seconds * RATE;
    let mut g = c.benchmark_group("containers");
    g.sample_size(10);
    g.throughput(Throughput::Elements(n));
    for (name, path) in inputs {
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut r = eenf_events::open(&path).unwrap();
                let mut count = 0u64;
                while let Some(batch) = r.next_batch().unwrap() {
                    count += batch.len() as u64;
                }
                assert_eq!(count, n, "{name}");
            })
        });
    }
    g.finish();
    let dsec = dir.join("dsec-bench.h5");
    if !dsec.exists() {
        eprintln!(
            "dsec: skipped ({} missing: run tools/hdf5_bench.py write)",
            dsec.display()
        );
        return;
    }
    let n = eenf_events::open(&dsec)
        .unwrap()
        .info()
        .event_count
        .unwrap();
    let mut g = c.benchmark_group("dsec");
    g.sample_size(10);
    g.throughput(Throughput::Elements(n));
    g.bench_function("hdf5_blosc_zstd", |b| {
        b.iter(|| {
            let mut r = eenf_events::open(&dsec).unwrap();
            let mut count = 0u64;
            while let Some(batch) = r.next_batch().unwrap() {
                count += batch.len() as u64;
            }
            assert_eq!(count, n);
        })
    });
    g.finish();
}

criterion_group!(containers, benches);
criterion_main!(containers);
