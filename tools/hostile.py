#!/usr/bin/env python3
"""Every file of ../shared/fixtures/hostile through the commands its README names, under the
limits of the issue that collected them (`ulimit -v 4000000`, 20 s, 200 MB peak): an error
or a warning is fine; a panic, abort, signal, hang or overrun is not.

    tools/hostile.py EENF_BINARY HOSTILE_DIR ENF_REFERENCE_DIR
"""
import os
import shutil
import sys
import tempfile

sys.path.insert(0, os.path.dirname(__file__))
import sweep  # noqa: E402

sweep.LIMIT_AS = 4_000_000 * 1024


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
        for key, argv in cmds.items():
            commands[f"{key}:{name}"] = argv
            runs.append((name, f"{key}:{name}", path))
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
