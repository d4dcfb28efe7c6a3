//! Tests of eenf-events's `rosbag` (kept out of the library so that `cargo test` does not
//! compile the library a second time).

use crate::read_all;
use eenf_events::rosbag::*;

use eenf_events::{EventBatch, Result, StreamInfo};
use std::path::Path;

fn field(name: &str, value: &[u8]) -> Vec<u8> {
    let mut f = ((name.len() + 1 + value.len()) as u32)
        .to_le_bytes()
        .to_vec();
    f.extend_from_slice(name.as_bytes());
    f.push(b'=');
    f.extend_from_slice(value);
    f
}

fn record(header: &[Vec<u8>], data: &[u8]) -> Vec<u8> {
    let h: Vec<u8> = header.concat();
    let mut r = (h.len() as u32).to_le_bytes().to_vec();
    r.extend_from_slice(&h);
    r.extend_from_slice(&(data.len() as u32).to_le_bytes());
    r.extend_from_slice(data);
    r
}

fn connection(conn: u32, topic: &str, msg_type: &str) -> Vec<u8> {
    record(
        &[
            field("op", &[OP_CONNECTION]),
            field("conn", &conn.to_le_bytes()),
            field("topic", topic.as_bytes()),
        ],
        &[
            field("topic", topic.as_bytes()),
            field("type", msg_type.as_bytes()),
        ]
        .concat(),
    )
}

/// A `dvs_msgs/EventArray` of events `(s, ns, x, y, p)`.
fn event_array(events: &[(u32, u32, u16, u16, bool)]) -> Vec<u8> {
    let mut m = vec![0u8; 12];
    m.extend_from_slice(&0u32.to_le_bytes()); // frame_id ""
    m.extend_from_slice(&480u32.to_le_bytes());
    m.extend_from_slice(&640u32.to_le_bytes());
    m.extend_from_slice(&(events.len() as u32).to_le_bytes());
    for &(s, ns, x, y, p) in events {
        m.extend_from_slice(&x.to_le_bytes());
        m.extend_from_slice(&y.to_le_bytes());
        m.extend_from_slice(&s.to_le_bytes());
        m.extend_from_slice(&ns.to_le_bytes());
        m.push(p as u8);
    }
    m
}

fn message(conn: u32, data: &[u8]) -> Vec<u8> {
    record(
        &[
            field("op", &[OP_MSG_DATA]),
            field("conn", &conn.to_le_bytes()),
            field("time", &0u64.to_le_bytes()),
        ],
        data,
    )
}

/// A bag of two topics (an IMU first), its messages in one chunk compressed as asked.
fn bag(compression: &str) -> Vec<u8> {
    let mut inner = connection(0, "/imu", "sensor_msgs/Imu");
    inner.extend(connection(1, "/dvs/events", "dvs_msgs/EventArray"));
    inner.extend(message(0, &[1, 2, 3]));
    inner.extend(message(
        1,
        &event_array(&[(10, 1000, 1, 2, true), (10, 3000, 3, 4, false)]),
    ));
    inner.extend(message(1, &event_array(&[(11, 0, 5, 6, true)])));
    let packed = match compression {
        "none" => inner.clone(),
        "lz4" => {
            let mut w = lz4_flex::frame::FrameEncoder::new(Vec::new());
            std::io::Write::write_all(&mut w, &inner).unwrap();
            w.finish().unwrap()
        }
        _ => {
            let mut w = bzip2::write::BzEncoder::new(Vec::new(), bzip2::Compression::fast());
            std::io::Write::write_all(&mut w, &inner).unwrap();
            w.finish().unwrap()
        }
    };
    let chunk = record(
        &[
            field("op", &[OP_CHUNK]),
            field("compression", compression.as_bytes()),
            field("size", &(inner.len() as u32).to_le_bytes()),
        ],
        &packed,
    );
    let index = [
        connection(0, "/imu", "sensor_msgs/Imu"),
        connection(1, "/dvs/events", "dvs_msgs/EventArray"),
    ]
    .concat();
    let head_len =
        MAGIC.len() + record(&[field("op", &[3]), field("index_pos", &[0; 8])], &[0; 16]).len();
    let index_pos = (head_len + chunk.len()) as u64;
    let mut b = MAGIC.to_vec();
    b.extend(record(
        &[
            field("op", &[OP_BAG_HEADER]),
            field("index_pos", &index_pos.to_le_bytes()),
        ],
        &[0; 16],
    ));
    b.extend(chunk);
    b.extend(index);
    b
}

fn read(bytes: Vec<u8>, topic: Option<&str>) -> Result<(StreamInfo, EventBatch)> {
    read_all(reader(
        Box::new(std::io::Cursor::new(bytes)),
        Path::new("t.bag"),
        topic,
    )?)
}

#[test]
fn event_arrays_in_every_chunk_compression() {
    // the sensor's size is known on opening (flicker maps lay their tiles with it)
    let r = reader(
        Box::new(std::io::Cursor::new(bag("none"))),
        Path::new("t.bag"),
        None,
    );
    assert_eq!(r.unwrap().info().width, Some(640));
    for c in ["none", "bz2", "lz4"] {
        let (info, b) = read(bag(c), None).unwrap();
        assert_eq!(b.t, vec![10_000_001, 10_000_003, 11_000_000], "{c}");
        assert_eq!(
            (b.x, b.y, b.p),
            (vec![1, 3, 5], vec![2, 4, 6], vec![true, false, true])
        );
        assert_eq!((info.width, info.height), (Some(640), Some(480)));
        assert_eq!(info.streams.len(), 2);
    }
}

#[test]
fn topics_that_are_not_there_or_not_events_are_named() {
    let e = read(bag("none"), Some("/nope")).unwrap_err().to_string();
    assert!(
        e.contains("/nope") && e.contains("/dvs/events (dvs_msgs/EventArray)"),
        "{e}"
    );
    let e = read(bag("none"), Some("/imu")).unwrap_err().to_string();
    assert!(e.contains("sensor_msgs/Imu"), "{e}");
    // cut anywhere: an error or the events before the cut, never a panic
    let whole = bag("lz4");
    for cut in 0..whole.len() {
        let r = reader(
            Box::new(std::io::Cursor::new(whole[..cut].to_vec())),
            Path::new("t.bag"),
            None,
        );
        if let Ok(mut r) = r {
            while let Ok(Some(_)) = r.next_batch() {}
        }
    }
}
