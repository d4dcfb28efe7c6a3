#!/usr/bin/env python3
"""Every file of ../shared/fixtures/hostile through the commands its README names, under the
limits of the issue that collected them (`ulimit -v 4000000`, 20 s, 200 MB peak): an error
or a warning is fine; a panic, abort, signal, hang or overrun is not. Every file also goes to
`refdb build` (which sniffs grid archives), with damaged archives written here: truncated and
bombed zips, a truncated gzip, a line without end, wild and far-apart dates.

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
