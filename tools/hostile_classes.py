#!/usr/bin/env python3
"""New members of every class of hostile container that a structure-aware campaign found
(issue 45; ../shared/hostile-new), written here from the fixtures with a seeded generator and
run under the campaign's limits (`ulimit -v 4000000`, 20 s, 200 MB): an error of one line
naming the input, or a warning and the readable part; never a panic, abort, hang, overrun or
a file opened outside a bag. The files of ../shared/hostile-new run first, with the commands
its README names. A SIGTERM during each decompression must leave nothing in TMPDIR.

    tools/hostile_classes.py EENF_BINARY SHARED_DIR [--seed 1] [--per-class 6] [--big]

`--big` adds the members that write hundreds of MB of input (a 300 MB SQLite message, 4 GiB
gzip streams); CI runs without it. Prints a table of runs per class; exits non-zero on any
failure.
"""
import argparse
import bz2
import os
import random
import re
import shutil
import signal
import sqlite3
import struct
import subprocess
import sys
import tempfile
import time
import zlib

sys.path.insert(0, os.path.dirname(__file__))
import sweep  # noqa: E402

sweep.LIMIT_AS = 4_000_000 * 1024
MAX_S = 10.0  # "a few seconds": the campaign's hangs ran past 20 s

ZSTD_MAGIC = b"\x28\xb5\x2f\xfd"
MCAP_MAGIC = b"\x89MCAP0\r\n"


def block_header(size, kind, last):
    """A zstd block header (RFC 8878 §3.1.1.2): size, type (0 raw, 1 RLE), last-block bit."""
    return struct.pack("<I", (size << 3) | (kind << 1) | last)[:3]


def zstd_frame(first, zeros):
    """A zstd frame holding `first` (a raw block), then `zeros` bytes of zeros in RLE blocks of
    128 KiB (RFC 8878 §3.1.1): four bytes of frame per 128 KiB, so GiBs fit in KBs."""
    out = bytearray(ZSTD_MAGIC + bytes([0x00, 0x58]))  # no content size; window 8 MiB
    block = 128 << 10
    header = block_header
    if first:
        out += header(len(first), 0, 0) + first
    n = zeros // block
    rle = header(block, 1, 0) + b"\0"
    out += rle * (n - 1) + header(block, 1, 1) + b"\0"
    return bytes(out)


def zstd_slow(path, gib=2):
    """A `.db3.zstd` whose SQLite header states `gib` GiB, and which expands to that (85 times
    its size, under the bound): seconds of honest expansion to kill in the middle."""
    out = bytearray(ZSTD_MAGIC + bytes([0x00, 0x58]))
    rng = random.Random(0)
    header = block_header
    first = sqlite_header(pages=(gib << 30) // 4096)
    out += header(len(first), 0, 0) + first
    units = (gib << 30) // (128 << 10)
    for u in range(units):
        raw = rng.randbytes(1536)
        out += header(len(raw), 0, 0) + raw
        out += header((128 << 10) - 1536 - (len(first) if u == 0 else 0), 1, u == units - 1) + b"\0"
    with open(path, "wb") as f:
        f.write(out)


def sqlite_header(page=4096, pages=2, valid=True):
    h = bytearray(b"SQLite format 3\0" + bytes(84))
    struct.pack_into(">H", h, 16, page if page < 65536 else 1)
    h[18] = h[19] = 1
    struct.pack_into(">I", h, 24, 7)
    struct.pack_into(">I", h, 28, pages)
    struct.pack_into(">I", h, 92, 7 if valid else 6)
    return bytes(h)


def flac_members(shared, rng, d):
    src = open(os.path.join(shared, "hostile-new/flac_picture_mime_len_4GiB_abort.flac"), "rb").read()
    # walk to the PICTURE block: fLaC, then 4-byte headers
    at, blocks = 4, []
    while at + 4 <= len(src):
        kind, n = src[at] & 0x7F, int.from_bytes(src[at + 1:at + 4], "big")
        blocks.append((at, kind, n))
        if src[at] & 0x80:
            break
        at += 4 + n
    pic = next(b for b in blocks if b[1] == 6)
    out = []
    for i in range(rng.randint(2, 4)):
        b = bytearray(src)
        kind = rng.choice([2, 4, 5, 6])
        b[pic[0]] = (b[pic[0]] & 0x80) | kind
        # an inner length (MIME, description, vendor, data) that lies, at a random place
        for _ in range(rng.randint(1, 3)):
            off = pic[0] + 4 + 4 * rng.randint(0, 7)
            struct.pack_into(">I", b, off, rng.choice([0xFFFFFFFF, 0x80000000, rng.randint(1 << 24, 1 << 32)]))
        p = os.path.join(d, f"flac_{kind}_{i}.flac")
        open(p, "wb").write(b)
        out += [("audio", ["audio", "{}", "-o", os.path.join(d, "x.csv")], p), ("edits", ["edits"], p)]
    return out


def hdf5_members(shared, rng, d):
    out = []
    for i in range(rng.randint(2, 3)):
        name = rng.choice(["dsec_layout_gzip.h5", "dsec_layout_blosc_zstd.h5", "mvsec_layout.h5",
                           "m3ed_layout_blosc.h5"])
        b = bytearray(open(os.path.join(shared, "fixtures/containers/hdf5", name), "rb").read())
        claimed = rng.choice([1 << 40, 1 << 60, (1 << 63) - 1, (1 << 64) - 1, rng.randint(1 << 30, 1 << 50)])
        # the rows: the dataspaces' dims (and max dims) of 38478
        for m in re.finditer(re.escape(struct.pack("<Q", 38478)), bytes(b)):
            if rng.random() < 0.8:
                struct.pack_into("<Q", b, m.start(), claimed)
        p = os.path.join(d, f"hdf5_rows_{i}_{name}")
        open(p, "wb").write(b)
        out += [("info", ["info"], p), ("extract", ["extract"], p)]
        # chunks that claim gigabytes (the layout's chunk dims)
        b = bytearray(open(os.path.join(shared, "fixtures/containers/hdf5", name), "rb").read())
        for dim in (4810, 2405, 9620, 1203):
            for m in re.finditer(re.escape(struct.pack("<I", dim)), bytes(b)):
                struct.pack_into("<I", b, m.start(), rng.choice([1 << 26, 1 << 28, 0x7FFFFFFF]))
        p = os.path.join(d, f"hdf5_chunks_{i}_{name}")
        open(p, "wb").write(b)
        out += [("info", ["info"], p)]
    return out


def hdf5_bomb_members(shared, rng, d):
    """zstd chunks (filter 32015) rewritten in place, same length, to expand to tens of MiB."""
    src = open(os.path.join(shared, "fixtures/containers/hdf5/dsec_layout_zstd32015.h5"), "rb").read()

    def frame_len(at):
        """A zstd frame's length, from its header and block headers (RFC 8878 §3.1.1)."""
        fhd = src[at + 4]
        single, fcs, dict_id, checksum = fhd & 0x20, fhd >> 6, fhd & 3, fhd & 4
        n = 5 + (0 if single else 1) + [0, 1, 2, 4][dict_id]
        n += (1 if single else 0) if fcs == 0 else [0, 2, 4, 8][fcs]
        while True:
            v = int.from_bytes(src[at + n:at + n + 3], "little")
            n += 3 + (1 if (v >> 1) & 3 == 1 else v >> 3)
            if v & 1:
                return n + (4 if checksum else 0)

    frames = [m.start() for m in re.finditer(re.escape(ZSTD_MAGIC), src)]
    out = []
    for k in range(rng.randint(1, 2)):
        b = bytearray(src)
        for at in rng.sample(frames, rng.randint(1, len(frames))):
            size = frame_len(at)
            if size < 16:
                continue
            body = bytearray(ZSTD_MAGIC + bytes([0x00, 0x58]))
            n = (size - 6 - 4) // 4
            body += (block_header(128 << 10, 1, 0) + b"\0") * n
            rest = size - len(body) - 3
            body += block_header(rest, 0, 1) + bytes(rest)
            b[at:at + size] = body
        p = os.path.join(d, f"hdf5_zstd_bomb_{k}.h5")
        open(p, "wb").write(b)
        out += [("info", ["info"], p), ("extract", ["extract"], p)]
    return out


def bag_path_members(shared, rng, d):
    db3 = os.path.join(shared, "fixtures/containers/ros2/ros2_dvs_msgs_sqlite3/ros2_dvs_msgs_sqlite3.db3")
    yaml = open(os.path.join(shared, "fixtures/containers/ros2/ros2_dvs_msgs_sqlite3/metadata.yaml")).read()
    out = []
    kinds = ["absolute", "dev", "proc", "dotdot", "symlink", "fifo", "repeated", "huge-yaml", "nested"]
    rng.shuffle(kinds)
    for i, kind in enumerate(kinds[: rng.randint(4, len(kinds))]):
        bag = os.path.join(d, f"bag_{kind}_{i}")
        os.makedirs(bag)
        shutil.copy(db3, os.path.join(bag, "b.db3"))
        listed = ["b.db3"]
        if kind == "absolute":
            listed = [rng.choice(["/etc/passwd", "/etc/hostname", "/etc/os-release"])]
        elif kind == "dev":
            listed = [rng.choice(["/dev/zero", "/dev/urandom", "/dev/stdin"])]
        elif kind == "proc":
            listed = [rng.choice(["/proc/self/environ", "/proc/self/mem", "/proc/kcore"])]
        elif kind == "dotdot":
            listed = ["../" * rng.randint(1, 12) + "etc/passwd"]
        elif kind == "symlink":
            os.symlink(rng.choice(["/etc/passwd", "/dev/zero", "../../.."]), os.path.join(bag, "s.db3"))
            listed = ["s.db3"]
        elif kind == "fifo":
            os.mkfifo(os.path.join(bag, "f.db3"))
            listed = ["f.db3"]
        elif kind == "repeated":
            listed = ["b.db3"] * rng.randint(2, 10000)
        body = "\n".join(f"  - {f}" for f in listed)
        text = re.sub(r"relative_file_paths:\n(\s*- .*\n)+", lambda _: f"relative_file_paths:\n{body}\n", yaml)
        if kind == "huge-yaml":
            text += "# " + "x" * (rng.randint(2, 8) << 20) + "\n"
        elif kind == "nested":
            depth = rng.randint(1000, 20000)
            text += "".join(" " * k + "a:\n" for k in range(0, depth))[: 3 << 20]
        open(os.path.join(bag, "metadata.yaml"), "w").write(text)
        out.append(("info", ["info"], bag))
    return out


def zstd_members(shared, rng, d):
    """Storage files compressed whole that expand to GiBs: their content is checked as it
    arrives, an SQLite copy is bounded by what its header states."""
    out = []
    for i in range(rng.randint(2, 4)):
        kind = rng.choice(["zeros", "mcap", "sqlite-stated", "sqlite-unstated"])
        first = {"zeros": b"", "mcap": MCAP_MAGIC,
                 "sqlite-stated": sqlite_header(pages=rng.choice([rng.randint(1, 4096), 1 << 31])),
                 "sqlite-unstated": sqlite_header(valid=False)}[kind]
        ext = ".mcap.zstd" if kind in ("zeros", "mcap") else ".db3.zstd"
        bag = os.path.join(d, f"zstd_{kind}_{i}")
        os.makedirs(bag)
        open(os.path.join(bag, "x" + ext), "wb").write(zstd_frame(first, rng.choice([1, 4, 10]) << 30))
        out.append(("info", ["info"], bag))
    return out


def mcap_members(shared, rng, d):
    """Record lengths inside an uncompressed MCAP chunk that lie."""
    src = open(os.path.join(shared, "fixtures/containers/ros2/ros2_dvs_msgs_mcap/ros2_dvs_msgs_mcap.mcap"), "rb").read()
    i = 8
    while i < len(src) - 9:
        op, n = src[i], struct.unpack_from("<Q", src, i + 1)[0]
        if op == 6:
            break
        i += 9 + n
    body = i + 9
    start_records = body + 8 + 8 + 8 + 4
    clen = struct.unpack_from("<I", src, start_records)[0]
    records = start_records + 4 + clen + 8
    inner = []
    j = records
    while j < body + n - 9:
        inner.append(j)
        j += 9 + struct.unpack_from("<Q", src, j + 1)[0]
    out = []
    for k in range(rng.randint(2, 4)):
        b = bytearray(src)
        at = rng.choice(inner)
        struct.pack_into("<Q", b, at + 1, rng.choice([1008 << 20, 1 << 30, 1 << 40, rng.randint(1 << 20, 1 << 32)]))
        p = os.path.join(d, f"mcap_inner_{k}.mcap")
        open(p, "wb").write(b)
        out.append(("info", ["info"], p))
    return out


def ros1_members(shared, rng, d, big):
    """A ROS 1 bag whose last chunk honestly expands (bz2) to tens or hundreds of MiB; the bag
    header's index position is moved past it, so the bag stays whole."""
    src = open(os.path.join(shared, "fixtures/containers/ros1/ros1_dvs_msgs.bag"), "rb").read()
    at = len(b"#ROSBAG V2.0\n")
    chunks = []
    while at < len(src):
        hlen = struct.unpack_from("<I", src, at)[0]
        header = src[at + 4:at + 4 + hlen]
        dlen = struct.unpack_from("<I", src, at + 4 + hlen)[0]
        if b"op=\x05" in header:
            chunks.append((at, 8 + hlen + dlen))
        at += 8 + hlen + dlen
    at, old = chunks[-1]
    out = []
    for k in range(rng.randint(1, 2)):
        mib = rng.choice([48, 64, 160, 300] if big else [48, 64, 80])
        data = bz2.compress(bytes(mib << 20), 1)
        fields = [b"compression=bz2", b"size=" + struct.pack("<I", mib << 20)]
        h = b"".join(struct.pack("<I", len(f)) + f for f in fields + [b"op=\x05"])
        rec = struct.pack("<I", len(h)) + h + struct.pack("<I", len(data)) + data
        b = bytearray(src[:at] + rec + src[at + old:])
        m = re.search(rb"index_pos=", bytes(b[:4096]))
        pos = struct.unpack_from("<Q", b, m.end())[0]
        struct.pack_into("<Q", b, m.end(), pos + len(rec) - old)
        p = os.path.join(d, f"ros1_bz2_{mib}MiB_{k}.bag")
        open(p, "wb").write(b)
        out.append(("info", ["info"], p))
        out.append(("extract", ["extract"], p))
    return out


def sqlite_members(shared, rng, d, big):
    """A bag message larger than a camera sends, and a damaged schema."""
    out = []
    mb = rng.choice([100, 300] if big else [20, 40])
    p = os.path.join(d, f"db3_message_{mb}MB.db3")
    db = sqlite3.connect(p)
    db.executescript(
        "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL,"
        " serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
        "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL,"
        " timestamp INTEGER NOT NULL, data BLOB NOT NULL);")
    db.execute("INSERT INTO topics VALUES (1, '/events', 'dvs_msgs/msg/EventArray', 'cdr', '')")
    db.execute("INSERT INTO messages VALUES (1, 1, 0, zeroblob(?))", (mb << 20,))
    db.commit()
    db.close()
    out.append(("info", ["info"], p))
    src = open(os.path.join(shared, "fixtures/containers/ros2/ros2_dvs_msgs_sqlite3/ros2_dvs_msgs_sqlite3.db3"), "rb").read()
    for k in range(rng.randint(1, 3)):
        b = bytearray(src)
        # the schema's text on page 1: a flip inside a CREATE statement
        m = [x.start() for x in re.finditer(rb"CREATE", src[:4096])]
        at = rng.choice(m) + rng.randint(0, 60)
        b[at] ^= rng.choice([0x01, 0x20, 0x0A ^ ord("x")])
        b[rng.choice(m) + rng.randint(6, 30)] = 0x0A
        p = os.path.join(d, f"db3_schema_{k}.db3")
        open(p, "wb").write(b)
        out.append(("info", ["info"], p))
    return out


def archive_members(shared, rng, d, big):
    out = []
    hour = "".join(f"2023-01-01 00:{i // 60:02}:{i % 60:02},50.0{i % 9}\n" for i in range(3600))
    for k in range(rng.randint(1, 3)):
        far = "".join(f"2023-01-01 00:00:00,50.0\n".replace("2023-01-01", time.strftime(
            "%Y-%m-%d", time.gmtime(1672531200 + 86400 * rng.randint(1, 399)))) for _ in range(rng.randint(1, 5)))
        p = os.path.join(d, f"archive_far_{k}.csv")
        open(p, "w").write("time,frequency\n" + hour + far)
        out.append(("refdb-archive", ["refdb", "build", os.path.join(d, f"store_far_{k}"), "--tz", "Z", "{}"], p))
    # a gzip stream of one repeated row (whole-flushed deflate blocks repeat byte for byte)
    for k in range(rng.randint(1, 2)):
        row = rng.choice(["2023-06-03 00:00:00.000,50.000\n", "2023-06-03 00:00:00,50.0\n",
                          "garbage row\n"])
        total = (rng.choice([1, 4]) << 30) if big else (256 << 20)
        block = (row * ((1 << 20) // len(row))).encode()
        c = zlib.compressobj(9, zlib.DEFLATED, 31)
        head = c.compress(b"time,frequency\n" + block) + c.flush(zlib.Z_FULL_FLUSH)
        unit = c.compress(block) + c.flush(zlib.Z_FULL_FLUSH)
        n = total // len(block)
        tail = c.flush(zlib.Z_FINISH)
        p = os.path.join(d, f"archive_repeated_{k}.csv.gz")
        with open(p, "wb") as f:
            f.write(head)
            for _ in range(n):
                f.write(unit)
            f.write(tail)
        out.append(("refdb-archive", ["refdb", "build", os.path.join(d, f"store_rep_{k}"), "--tz", "Z", "{}"], p))
    return out


def readme_members(shared, d):
    """The files of ../shared/hostile-new with the commands its README names."""
    h = os.path.join(shared, "hostile-new")
    if not os.path.isdir(h):
        return []
    out = []
    for line in open(os.path.join(h, "README.md")):
        m = re.match(r"\| `([^`]+)` \| (.+?) \|", line)
        if not m or m.group(1) == "file":
            continue
        path = os.path.join(h, m.group(1).rstrip("/"))
        for cmd in re.findall(r"`eenf (\w+) (?:FILE|DIR)`", m.group(2)) or ["info"]:
            argv = [cmd] if cmd != "audio" else ["audio", "{}", "-o", os.path.join(d, "x.csv")]
            out.append((cmd, argv, path))
        if m.group(1).endswith(".h5"):
            out.append(("extract", ["extract"], path))
    return out


def sigterm_leaves_nothing(binary, bag, work):
    """`eenf info BAG` killed by SIGTERM while it expands: nothing left in its TMPDIR."""
    tmp = os.path.join(work, "tmpdir")
    shutil.rmtree(tmp, ignore_errors=True)
    os.makedirs(tmp)
    env = dict(os.environ, TMPDIR=tmp)
    p = subprocess.Popen([binary, "--quiet", "info", bag], env=env,
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(0.5)
    running = p.poll() is None
    p.send_signal(signal.SIGTERM)
    p.wait(timeout=20)
    left = os.listdir(tmp)
    return running, left


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("shared")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--per-class", type=int, default=3)
    ap.add_argument("--big", action="store_true")
    ap.add_argument("--keep", help="write the members into this folder and keep them")
    a = ap.parse_args()
    rng = random.Random(a.seed)
    work = a.keep or tempfile.mkdtemp(prefix="eenf-classes-")
    os.makedirs(work, exist_ok=True)
    runs = [("hostile-new", r) for r in readme_members(a.shared, work)]
    gens = [
        ("flac metadata lengths", lambda d: flac_members(a.shared, rng, d)),
        ("hdf5 rows and chunks claimed", lambda d: hdf5_members(a.shared, rng, d)),
        ("hdf5 zstd chunk bombs", lambda d: hdf5_bomb_members(a.shared, rng, d)),
        ("rosbag2 paths in metadata", lambda d: bag_path_members(a.shared, rng, d)),
        ("rosbag2 zstd expansion", lambda d: zstd_members(a.shared, rng, d)),
        ("mcap inner record lengths", lambda d: mcap_members(a.shared, rng, d)),
        ("ros1 honest chunk bombs", lambda d: ros1_members(a.shared, rng, d, a.big)),
        ("sqlite messages and schema", lambda d: sqlite_members(a.shared, rng, d, a.big)),
        ("archive spans and repeats", lambda d: archive_members(a.shared, rng, d, a.big)),
    ]
    for k in range(a.per_class):
        for name, gen in gens:
            d = os.path.join(work, f"{k}-{name.split()[0]}")
            os.makedirs(d, exist_ok=True)
            runs += [(name, r) for r in gen(d)]
    commands = {}
    for i, (_, (key, argv, _)) in enumerate(runs):
        commands[f"{key}:{i}"] = argv
    sweep.COMMANDS = commands
    table, bad = {}, []
    for i, (cls, (key, argv, path)) in enumerate(runs):
        t0 = time.monotonic()
        outcome, mb, detail = sweep.run(a.binary, f"{key}:{i}", path, work)
        took = time.monotonic() - t0
        row = table.setdefault(cls, [0, 0, 0, 0.0, 0.0, 0])
        row[0] += 1
        row[1 if outcome == "ok" else 2] += outcome in ("ok", "error")
        row[3] = max(row[3], mb)
        row[4] = max(row[4], took)
        if outcome not in ("ok", "error") or mb > sweep.MAX_RSS_MB or took > MAX_S:
            row[5] += 1
            bad.append(f"{cls}: {key} {os.path.relpath(path, work) if path.startswith(work) else path}: "
                       f"{outcome}, {mb:.0f} MB, {took:.1f} s {detail}")
    # a SIGTERM during each expansion leaves nothing behind
    zbags = [path for cls, (_, _, path) in runs if cls == "rosbag2 zstd expansion"]
    zbags.append(os.path.join(a.shared, "hostile-new/rosbag2_mcap_zstd_10GiB_tmpfile"))
    slow = os.path.join(work, "slow")
    os.makedirs(slow, exist_ok=True)
    zstd_slow(os.path.join(slow, "x.db3.zstd"))
    row = table.setdefault("SIGTERM while expanding", [0, 0, 0, 0.0, 0.0, 0])
    for bag in zbags + [slow]:
        if not os.path.isdir(bag):
            continue
        running, left = sigterm_leaves_nothing(a.binary, bag, work)
        row[0] += 1
        if left or (bag == slow and not running):
            row[5] += 1
            bad.append(f"SIGTERM: {bag} {'left ' + str(left) if left else 'had ended before the signal'}")
        else:
            row[1] += 1
    print(f"{'class':<30} {'runs':>5} {'ok':>4} {'error':>6} {'max MB':>7} {'max s':>6} {'failed':>7}")
    for cls, (n, ok, err, mb, s, failed) in table.items():
        print(f"{cls:<30} {n:>5} {ok:>4} {err:>6} {mb:>7.0f} {s:>6.1f} {failed:>7}")
    for b in bad:
        print("  " + b)
    print(f"hostile classes (seed {a.seed}): {sum(r[0] for r in table.values())} runs, {len(bad)} failed")
    if not a.keep:
        shutil.rmtree(work, ignore_errors=True)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
