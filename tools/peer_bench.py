"""Decode speed of the peer libraries on the files `cargo bench -p eenf-bench` generates (in
target/tmp), for the table in the README. Usage: python tools/peer_bench.py [SECONDS]

Needs: pip install dv-processing aedat expelliarmus evlib numpy (best in a venv)."""
import os
import sys
import time

seconds = sys.argv[1] if len(sys.argv) > 1 else "20"
d = os.path.join(os.path.dirname(__file__), "..", "target", "tmp")


def best(fn, runs=3):
    out = None
    times = []
    for _ in range(runs):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return out, min(times)


def report(name, path, fn):
    if not os.path.exists(path):
        print(f"{name:40s} missing {path}")
        return
    try:
        n, dt = best(fn)
    except Exception as e:  # a peer that cannot read the file is reported, not fatal
        print(f"{name:40s} failed: {type(e).__name__}: {e}")
        return
    mb = os.path.getsize(path) / 1e6
    print(f"{name:40s} {n:>11d} events {dt:7.3f} s {n / dt / 1e6:8.1f} M events/s {mb / dt:8.1f} MB/s")


def dv_read(path):
    import dv_processing as dv

    rec = dv.io.MonoCameraRecording(path)
    n = 0
    while rec.isRunning():
        b = rec.getNextEventBatch()
        if b is not None:
            n += b.size()
    return n


def aedat_read(path):
    import aedat

    n = 0
    for packet in aedat.Decoder(path):
        if "events" in packet:
            n += len(packet["events"])
    return n


def expelliarmus_read(path, enc):
    import expelliarmus

    return len(expelliarmus.Wizard(encoding=enc, fpath=path).read())


def evlib_read(path):
    import evlib

    df = evlib.load_events(path, sort=False)
    df = df.collect() if hasattr(df, "collect") else df
    return len(df)


f = lambda name: os.path.join(d, f"bench-{seconds}s-{name}")
for codec in ["LZ4", "ZSTD"]:
    p = f(f"{codec}.aedat4")
    report(f"dv-processing AEDAT4 {codec}", p, lambda: dv_read(p))
    report(f"aedat AEDAT4 {codec}", p, lambda: aedat_read(p))
p2 = f("evt2.raw")
report("expelliarmus EVT 2.0", p2, lambda: expelliarmus_read(p2, "evt2"))
report("evlib EVT 2.0", p2, lambda: evlib_read(p2))
p3 = f("evt3.raw")
report("evlib EVT 3.0", p3, lambda: evlib_read(p3))
pd = os.path.join(d, f"bench-{seconds}s.dat")
report("expelliarmus DAT", pd, lambda: expelliarmus_read(pd, "dat"))
