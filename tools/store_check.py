#!/usr/bin/env python3
"""The reference store cannot lose data: concurrent builds and builds killed at random moments.

    store_check.py EENF_BINARY ENF_REFERENCE_DIR [--rounds 20] [--kills 50] [--seed 1]

Rounds of two `refdb build` runs started together (the second 0-150 ms later) into one store,
each adding different hourly WAVs; then builds killed (SIGKILL) at random moments. After each
round and each kill, every hour committed so far must still be found at its own time by
`match --verify` (rank 1, significant), and `refdb info` must read the store. A store whose
manifest names a path outside the store must make `build` write nothing outside it. Prints
a table and exits 1 on any loss.
"""
import argparse
import csv
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

TZ = "+08:00"


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("eenf")
    ap.add_argument("refs")
    ap.add_argument("--rounds", type=int, default=20)
    ap.add_argument("--kills", type=int, default=50)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    eenf = os.path.abspath(a.eenf)
    wavs = sorted(Path(a.refs).glob("*.wav"))
    assert len(wavs) >= 4, "need the hourly WAVs"
    work = Path(tempfile.mkdtemp(prefix="eenf-store-check-"))
    # a 5-minute clip of each hour, from 16:10 local (values 600..900 of the hour's trace)
    clips = {}
    for w in wavs:
        out = work / (w.stem + ".csv")
        r = run([eenf, "-q", "reference", str(w), "-o", str(out)])
        assert r.returncode == 0, r.stderr
        rows = list(csv.reader(open(out)))[1:]
        clip = work / (w.stem + ".clip.csv")
        with open(clip, "w") as f:
            f.write("time_s,enf_hz\n")
            for i, row in enumerate(rows[600:900]):
                f.write(f"{i},{row[1]}\n")
        y, mo, d, _, h = w.stem.split("_")[:5]
        clips[w] = (clip, f"{y}-{mo}-{d}T{h}:10:00{TZ}")

    def committed_ok(store, hours):
        """Every hour in `hours` is found at its own time; returns the ones lost."""
        lost = []
        for w in hours:
            clip, when = clips[w]
            r = run([eenf, "-q", "match", str(clip), str(store), "--verify", when, "--top", "1"])
            # found: the best fit at the claimed time (with one hour stored, it cannot be
            # significant against the others, so significance is not asked)
            if r.returncode != 0 or ", rank 1," not in r.stdout or "CC 1.0000" not in r.stdout:
                lost.append((w.name, (r.stdout + r.stderr).strip().splitlines()[-1:]))
        return lost

    def readable(store, any_committed):
        r = run([eenf, "refdb", "info", str(store)])
        return r.returncode == 0 or (not any_committed and "no reference series" in r.stderr)

    losses, unreadable = 0, 0
    # 1. concurrent builds
    for k in range(a.rounds):
        store = work / f"round{k}"
        first, second = rng.sample(wavs, 2)
        cmd = lambda w: [eenf, "-q", "refdb", "build", str(store), str(w), "--tz", TZ]
        p1 = subprocess.Popen(cmd(first), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        time.sleep(rng.uniform(0, 0.15))
        p2 = subprocess.Popen(cmd(second), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
        rc = (p1.wait(), p2.wait())
        lost = committed_ok(store, [first, second]) if rc == (0, 0) else [("exit", rc)]
        losses += len(lost)
        unreadable += not readable(store, True)
        if lost:
            print(f"round {k}: lost {lost}")
    print(f"concurrent builds: {a.rounds} rounds of two, {losses} hours lost, {unreadable} unreadable stores")
    total_losses, total_unreadable = losses, unreadable
    # 2. kills at random moments: over the whole length of a build (timed on this machine), so
    # that some are killed early, some mid-commit and some finish
    t0 = time.monotonic()
    run([eenf, "-q", "refdb", "build", str(work / "timing"), str(wavs[0]), "--tz", TZ])
    per_hour = time.monotonic() - t0
    store = work / "killed"
    committed = []
    losses = unreadable = killed = 0
    for k in range(a.kills):
        hours = rng.sample(wavs, rng.randint(1, 3))
        p = subprocess.Popen(
            [eenf, "-q", "refdb", "build", str(store), *map(str, hours), "--tz", TZ],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(rng.uniform(0, 1.3 * per_hour * len(hours)))
        finished = p.poll() is not None
        if not finished:
            p.send_signal(signal.SIGKILL)
            killed += 1
        rc = p.wait()
        if rc == 0:
            committed = sorted(set(committed) | set(hours))
        lost = committed_ok(store, committed)
        losses += len(lost)
        ok = readable(store, bool(committed))
        unreadable += not ok
        if lost or not ok:
            print(f"kill {k}: lost {lost}, readable {ok}")
    print(f"killed builds: {a.kills} builds, {killed} killed mid-build, {len(committed)} hours "
          f"committed, {losses} losses, {unreadable} unreadable stores")
    total_losses += losses
    total_unreadable += unreadable
    # 3. a manifest that names a path
    outside = work / "outside"
    escaped = 0
    for i, name in enumerate(("../outside/x", str(outside / "y"))):
        st = work / f"evil{i}"
        st.mkdir()
        (st / "grid50.json").write_text(
            '{"grid": "%s", "nominal_hz": 50.0, "step_s": 1.0, "start_unix_s": 1660723200.0, '
            '"count": 0, "encoding": "i32"}' % name)
        (st / "grid50.i32").write_bytes(b"")
        run([eenf, "-q", "refdb", "build", str(st), str(wavs[0]), "--tz", TZ])
        escaped += outside.exists()
    print(f"manifests naming paths: 2, written outside the store: {int(escaped)}")
    bad = total_losses + total_unreadable + escaped
    print("store check: " + ("ok" if bad == 0 else "FAILED"))
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
