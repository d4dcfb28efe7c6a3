#!/usr/bin/env python3
"""Every file of ../shared/fixtures/hostile through the commands its README names, under the
limits of the issue that collected them (`ulimit -v 4000000`, 20 s, 200 MB peak): an error
or a warning is fine; a panic, abort, signal, hang or overrun is not. Every file also goes to
`refdb build` (which sniffs grid archives), with damaged archives written here: truncated and
bombed zips, a truncated gzip, a line without end, wild and far-apart dates. Containers whose
size fields lie are written here too (from the files of ../shared/fixtures/containers): an
MCAP chunk, a ROS 1 bag chunk and blosc chunks announcing gigabytes, CDR messages announcing
billions of events, an SQLite bag whose messages are not CDR.

    tools/hostile.py EENF_BINARY HOSTILE_DIR ENF_REFERENCE_DIR
"""
import gzip
import io
import os
import shutil
import sys
import tempfile
import zipfile

sys.path.insert(0, os.path.dirname(__file__))
import sweep  # noqa: E402

sweep.LIMIT_AS = 4_000_000 * 1024


def damaged_archives(work):
    """Grid archives with the faults a download or a disk gives them."""
    d = os.path.join(work, "archives")
    os.makedirs(d)
    day = "Time,Value\n" + "".join(
        f"2023-06-01 00:{m:02}:{s:02}.{t}00,{50 + 0.001 * (s % 9):.3f}\n"
        for m in range(60) for s in range(60) for t in range(0, 10, 5))
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("2023-06-01.csv", day)
        z.writestr("2023-06-02.csv", day.replace("2023-06-01", "2023-06-02"))
    whole = buf.getvalue()
    files = {
        "zip_truncated.zip": whole[: len(whole) // 2],
        "zip_flipped.zip": whole[:200] + bytes(b ^ 0x5A for b in whole[200:400]) + whole[400:],
        "gzip_truncated.csv.gz": gzip.compress(day.encode())[:5000],
        "line_without_end.csv": b"dtm,f\n2022-08-17 08:00:00," + b"9" * 5_000_000,
        "wild_dates.csv": ("dtm,f\n2022-08-17 08:00:00,50.01\n2099-12-31 23:59:59,50.0\n"
                           "1971-01-01 00:00:00,50.0\n2031-01-01 00:00:00,50.02\n"
                           "2022-08-17 08:00:01,0\n").encode(),
    }
    bomb = io.BytesIO()
    with zipfile.ZipFile(bomb, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("2023-06-03.csv", "Time,Value\n" + "2023-06-03 00:00:00.000,50.000\n" * 3_000_000)
    files["zip_bomb_repeated_rows.zip"] = bomb.getvalue()
    for name, data in files.items():
        with open(os.path.join(d, name), "wb") as f:
            f.write(data)
    return d


def damaged_containers(work, containers):
    """Bags and HDF5 files whose size fields lie, from the fixtures of `containers`."""
    import re
    import sqlite3
    import struct

    d = os.path.join(work, "containers")
    os.makedirs(d)
    files = {}
    mcap = open(os.path.join(containers, "ros2/ros2_dvs_msgs_mcap/ros2_dvs_msgs_mcap.mcap"), "rb").read()
    i = 8
    while i < len(mcap) - 9:
        op, n = mcap[i], struct.unpack_from("<Q", mcap, i + 1)[0]
        if op == 6:  # a chunk: start, end, uncompressed size, crc, compression, records
            b = bytearray(mcap)
            struct.pack_into("<Q", b, i + 9 + 16, 1 << 40)
            files["mcap_chunk_says_1_TiB.mcap"] = bytes(b)
            b = bytearray(mcap)
            struct.pack_into("<Q", b, i + 1, 1 << 60)
            files["mcap_record_says_2^60_bytes.mcap"] = bytes(b)
            break
        i += 9 + n
    bag = open(os.path.join(containers, "ros1/event_camera_py_test_events_1.bag"), "rb").read()
    m = re.search(rb"size=(....)", bag, re.S)
    if m:
        b = bytearray(bag)
        b[m.start(1):m.end(1)] = struct.pack("<I", 0xFFFFFFFF)
        files["bag_chunk_says_4_GiB.bag"] = bytes(b)
    h5 = open(os.path.join(containers, "hdf5/dsec_layout_blosc_zstd.h5"), "rb").read()
    b = bytearray(h5)
    # blosc 1 headers (version 2, lz version 1, flags, type size 4) of the t chunks (9,620 B)
    for m in re.finditer(re.escape(bytes([2, 1])) + b".." + struct.pack("<I", 9620), h5, re.S):
        struct.pack_into("<I", b, m.start() + 4, 0x7FFFFFFF)
    files["hdf5_blosc_chunks_say_2_GiB.h5"] = bytes(b)
    # CDR messages that announce more than they hold
    def packet(n_bytes, encoding=b"evt3\0"):
        m = b"\0\1\0\0" + bytes(8) + struct.pack("<I", 1) + b"\0\0\0\0"
        m += struct.pack("<II", 480, 640) + struct.pack("<QQ", 0, 0)
        m += struct.pack("<I", len(encoding)) + encoding + b"\0"
        m += bytes((-len(m)) % 4) + struct.pack("<I", n_bytes) + bytes(64)
        return m
    dvs = b"\0\1\0\0" + bytes(8) + struct.pack("<I", 1) + b"\0\0\0\0" + struct.pack("<III", 480, 640, 0x7FFFFFFF) + bytes(64)
    for name, topic_type, msgs in [
        ("db3_packet_says_4_GiB.db3", "event_camera_msgs/msg/EventPacket", [packet(0xFFFFFFF0)]),
        ("db3_dvs_says_2^31_events.db3", "dvs_msgs/msg/EventArray", [dvs]),
        ("db3_unknown_encoding.db3", "event_camera_msgs/msg/EventPacket", [packet(64, b"trigger_evt\0")]),
        ("db3_not_cdr.db3", "event_camera_msgs/msg/EventPacket", [b"\xff" * 100, b""]),
    ]:
        path = os.path.join(d, name)
        db = sqlite3.connect(path)
        db.executescript(
            "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
            " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
            "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL,"
            " timestamp INTEGER NOT NULL, data BLOB NOT NULL);")
        db.execute("INSERT INTO topics VALUES (1, '/events', ?, 'cdr', '')", (topic_type,))
        for k, msg in enumerate(msgs):
            db.execute("INSERT INTO messages VALUES (?, 1, ?, ?)", (k + 1, k, msg))
        db.commit()
        db.close()
    for name, data in files.items():
        with open(os.path.join(d, name), "wb") as f:
            f.write(data)
    return d


def main():
    binary, hostile, refs = sys.argv[1:4]
    hour = os.path.join(refs, "2022_08_17_Wed_16_00_00.wav")
    work = tempfile.mkdtemp(prefix="eenf-hostile-")
    clip = os.path.join(work, "clip.csv")
    with open(clip, "w") as f:
        f.write("time_s,enf_hz\n" + "".join(f"{i},{50 + 0.01 * (i % 7)}\n" for i in range(300)))
    out = os.path.join(work, "out.raw")
    commands = {}
    runs = []
    for name in sorted(os.listdir(hostile)):
        path = os.path.join(hostile, name)
        ext = os.path.splitext(name)[1]
        if ext in (".mkv", ".webm", ".m4a", ".wav"):
            cmds = {"audio": ["audio"]}
        elif ext == ".aedat4":
            cmds = {"info": ["info"], "extract": ["extract"],
                    "convert": ["convert", "{}", out, "--format", "evt3"]}
        elif ext == ".csv":
            cmds = {"match": ["match", clip]}
        elif os.path.isdir(path):
            store = os.path.join(work, name)
            shutil.copytree(path, store)
            for d, _, fs in os.walk(store):
                os.chmod(d, 0o755)
                for f in fs:
                    os.chmod(os.path.join(d, f), 0o644)
            cmds = {"refdb-build": ["refdb", "build", "--tz", "+08:00", hour, "--"]}
            path = store
        else:
            continue
        if not os.path.isdir(path):
            # anything may be handed to refdb build as an archive
            cmds["refdb-archive"] = ["refdb", "build", os.path.join(work, "archive-store"),
                                     "--tz", "Z", "{}"]
        for key, argv in cmds.items():
            commands[f"{key}:{name}"] = argv
            runs.append((name, f"{key}:{name}", path))
    archives = damaged_archives(work)
    for name in sorted(os.listdir(archives)):
        key = f"refdb-archive:{name}"
        commands[key] = ["refdb", "build", os.path.join(work, "archive-store"), "--tz", "Z", "{}"]
        runs.append((name, key, os.path.join(archives, name)))
    containers = os.path.join(os.path.dirname(os.path.abspath(hostile)), "containers")
    if os.path.isdir(containers):
        lying = damaged_containers(work, containers)
        for name in sorted(os.listdir(lying)):
            for key, argv in {"info": ["info"], "extract": ["extract"]}.items():
                commands[f"{key}:{name}"] = argv
                runs.append((name, f"{key}:{name}", os.path.join(lying, name)))
    sweep.COMMANDS = commands
    bad = []
    for name, key, path in runs:
        outcome, mb, detail = sweep.run(binary, key, path, work)
        print(f"  {key.split(':')[0]:<12} {name:<52} {outcome:<8} {mb:5.0f} MB")
        if outcome not in ("ok", "error") or mb > sweep.MAX_RSS_MB:
            bad.append(f"{key}: {outcome}, {mb:.0f} MB {detail}")
    # a store whose manifest names a path must not make a build write outside it
    escaped = [p for p in (os.path.join(work, "escaped"), "/var/tmp/eenf-escape") if os.path.exists(p)]
    bad += [f"written outside the store: {p}" for p in escaped]
    for b in bad:
        print("  " + b)
    print(f"hostile: {len(runs)} runs, {len(bad)} panics/aborts/crashes/timeouts/overruns")
    shutil.rmtree(work, ignore_errors=True)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
