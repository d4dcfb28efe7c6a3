#!/usr/bin/env python3
"""Runs two eenf binaries on the same inputs and reports every difference in what they give:
exit code, stdout, stderr and each file written (bytes). For refactors that must not change
behaviour. Usage: same_outputs.py OLD_EENF NEW_EENF [SHARED_DIR]

Each binary runs the same commands, in order, in its own temporary folder (paths in the
output are replaced by a placeholder). The first commands simulate the inputs the later ones
read, so simulated files are compared too."""

import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

S = "{shared}"
COMMANDS = [
    # inputs, simulated
    "simulate -o sim.aedat4 --duration 30 --video lr --video-scale 0.25 --reference-dir refs",
    "simulate -o sim60.raw --duration 20 --grid 60 --lamp fluorescent --seed 3",
    "simulate -o spot.aedat4 --duration 20 --scene lamp-spot --readout prophesee --spot-gain 4",
    # events
    "info sim.aedat4", "info --json sim.aedat4", "info --json sim60.raw",
    "extract sim.aedat4 -o t.csv --json --plot t.svg",
    "extract sim.aedat4 --sampling block --dt-us 100 --selection journal --jump-hz 0.05 -o tb.json",
    "extract sim60.raw --nominal 60 --harmonics 2 --median-len 5 --segment 4",
    "extract spot.aedat4 --all-pixels --json",
    "convert sim.aedat4 sim.dat", "convert sim.aedat4 sim.txt --format text",
    "convert sim60.raw sim60.aedat4 --compression zstd",
    "flicker-map sim.aedat4 -o map.svg", "flicker-map spot.aedat4 --json",
    "compare t.csv sim.truth.csv --json --plot c.svg", "compare t.csv sim.truth.csv --offset-s 1",
    "video sim_lr.y4m --json", "video sim_lr.y4m --sampling global --nominal 50 -o v.csv",
    "match t.csv refs --tz +08:00 --json --top 3",
    "match t.csv refs --tz +08:00 --verify 2022-08-17T16:10:00+08:00",
    "edits tb.json --json",
    "simulate-dataset ds --preset small --duration 20 --resolution 32x24 --video lr --video-scale 0.25",
    "simulate-dataset ds2 --preset small --grid 55", "simulate-dataset ds3 --start tomorrow",
    # sound and references
    f"reference {S}/fixtures/real-audio/pyenf_room_16s.wav --json",
    f"audio {S}/fixtures/real-audio/pyenf_room_34s.wav --harmonics 2 -o a.csv --plot a.svg",
    f"edits {S}/fixtures/real-discontinuities/enfwhu_H1_ref_077.wav --json",
    f"edits {S}/fixtures/real-audio/pyenf_room_34s.wav --false-alarms 0.5 --side 5",
    f"refdb build store {S}/fixtures/grid-archives/ngeso_2022-08-17T08Z.csv",
    "refdb info store",
    f"refdb build store2 {S}/fixtures/grid-archives/netzfrequenzmessung_2024-08-19T15-26-02.csv",
    f"refdb build store3 {S}/fixtures/grid-archives/netzfrequenzmessung_2024-08-19T15-26-02.csv --tz Europe/Berlin --grid DE",
    f"info {S}/fixtures/real-flicker/jaer_MovingDarkBox.aedat",
    f"extract {S}/fixtures/real-flicker/fhaust_Tmpdiff128StereoPair-vertical-arm.aedat --json",
    f"info --json {S}/fixtures/real/tonic_sample.aedat4",
    # refusals: each option's range, rules between options, advice naming flags
    "extract sim.aedat4 --window -1", "extract sim.aedat4 --window nan",
    "extract sim.aedat4 --harmonics 40", "extract sim.aedat4 --dt-us 5",
    "simulate -o x.aedat4 --resolution big", "simulate -o x.aedat4 --spot-gain 2",
    "simulate -o x.aedat4 --lamp neon", "simulate -o x.aedat4 --scene beach",
    "simulate -o x.aedat4 --readout kodak", "simulate -o x.aedat4 --video vhs",
    "simulate -o x.unknown", "simulate -o x.aedat4 --duration 0",
    "video sim_lr.y4m --readout-ms 10 --idle auto", "video sim_lr.y4m --readout-ms 0",
    "convert sim.aedat4 x.unknown", "info missing.aedat4",
    "match t.csv refs --verify yesterday", "match t.csv refs --top 0",
    "edits sim.truth.csv --min-gap 0.1",
    "refdb build store4 t.csv", "compare t.csv missing.csv",
]


# what differs from run to run: times taken, rates, the store's file names (time and process)
VOLATILE = [
    (rb"in \d+(\.\d+)? (s|ms)\b", b"in T s"),
    (rb"\d+(\.\d+)? M events/s", b"R M events/s"),
    (rb'"(elapsed_s|seconds|wall_s)": [0-9.e-]+', rb'"\1": T'),
    (rb"\.[0-9a-f]{16,}\.\d+\.i32", b".ID.i32"),
]


def clean(data, work, exe):
    data = data.replace(str(work).encode(), b"WORK").replace(exe.encode(), b"EENF")
    for pattern, repl in VOLATILE:
        data = re.sub(pattern, repl, data)
    return data


def run(exe, shared, work):
    out = []
    for cmd in COMMANDS:
        parts = cmd.format(shared=shared).split()
        head = 2 if parts[0] == "refdb" else 1
        args = [exe] + parts[:head] + ["-q"] + parts[head:]
        p = subprocess.run(args, cwd=work, capture_output=True, timeout=900)
        out.append((cmd, p.returncode, clean(p.stdout, work, exe), clean(p.stderr, work, exe)))
    files = {}
    for f in sorted(Path(work).rglob("*")):
        if f.is_file():
            name = clean(str(f.relative_to(work)).encode(), work, exe).decode()
            files[name] = clean(f.read_bytes(), work, exe)
    return out, files


def first_difference(a, b):
    i = next((k for k, (x, y) in enumerate(zip(a, b)) if x != y), min(len(a), len(b)))
    return f"at byte {i}: old {a[max(0, i - 60):i + 100]!r}\n    new {b[max(0, i - 60):i + 100]!r}"


def main():
    # each binary runs under the name eenf, which its usage lines print
    bins = tempfile.mkdtemp()
    old, new = (os.path.join(bins, k, "eenf") for k in ("old", "new"))
    for src, dst in zip(sys.argv[1:3], (old, new)):
        os.makedirs(os.path.dirname(dst))
        os.symlink(os.path.abspath(src), dst)
    shared = os.path.abspath(sys.argv[3] if len(sys.argv) > 3 else "../shared")
    with tempfile.TemporaryDirectory() as a, tempfile.TemporaryDirectory() as b:
        ra, fa = run(old, shared, a)
        rb, fb = run(new, shared, b)
    differ = 0
    for (cmd, ca, oa, ea), (_, cb, ob, eb) in zip(ra, rb):
        if (ca, oa, ea) != (cb, ob, eb):
            differ += 1
            print(f"DIFF {cmd}: exit {ca}/{cb}")
            if oa != ob:
                print(f"  stdout {first_difference(oa, ob)}")
            if ea != eb:
                print(f"  stderr {first_difference(ea, eb)}")
    for name in sorted(set(fa) | set(fb)):
        if fa.get(name) != fb.get(name):
            differ += 1
            print(f"DIFF file {name}: {first_difference(fa.get(name, b''), fb.get(name, b''))}")
    codes = sum(1 for r in ra if r[1] != 0)
    print(f"{len(COMMANDS)} commands ({codes} refusals), {len(fa)} files: {differ} differences")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
