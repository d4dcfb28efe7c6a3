"""E-ENF extraction against dv-processing's decode alone, in paired runs on the same AEDAT4 file
(issue 17's measure). Each round runs every `eenf` binary (whole process, `eenf -q extract FILE
-o /dev/null`) and then dv-processing's decode in a fresh interpreter (timed inside Python from
opening the recording to its last batch, so its interpreter start is not counted against it).

Usage: python tools/dv_pair_bench.py [FILE] [--runs N] [--bin PATH ...] [--dv-written]

FILE defaults to target/tmp/bench-60s-LZ4.aedat4 (made by `cargo bench -p eenf-bench`, 120 M events).
`--dv-written` benchmarks a copy of FILE re-written by dv-processing (its own LZ4 settings:
64 KiB linked blocks, the layout of files recorded with DV), made once beside FILE.

Needs: pip install dv-processing (best in a venv)."""
import argparse
import os
import resource
import statistics
import subprocess
import sys
import time

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")

DV_DECODE = """
import sys, time, dv_processing as dv
t0 = time.perf_counter()
rec = dv.io.MonoCameraRecording(sys.argv[1])
n = 0
while rec.isRunning():
    b = rec.getNextEventBatch()
    if b is not None:
        n += b.size()
print(time.perf_counter() - t0, n)
"""

DV_WRITE = """
import sys, dv_processing as dv
rec = dv.io.MonoCameraRecording(sys.argv[1])
cfg = dv.io.MonoCameraWriter.Config("DVXplorer")
cfg.compression = dv.CompressionType.LZ4
cfg.addEventStream(rec.getEventResolution())
w = dv.io.MonoCameraWriter(sys.argv[2], cfg)
while rec.isRunning():
    b = rec.getNextEventBatch()
    if b is not None:
        w.writeEvents(b)
del w
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file", nargs="?", default=os.path.join(ROOT, "target/tmp/bench-60s-LZ4.aedat4"))
    ap.add_argument("--runs", type=int, default=15)
    ap.add_argument("--bin", action="append", help="eenf binaries (default: target/release/eenf)")
    ap.add_argument("--dv-written", action="store_true")
    a = ap.parse_args()
    bins = a.bin or [os.path.join(ROOT, "target/release/eenf")]
    path = a.file
    if not os.path.exists(path):
        sys.exit(f"{path}: missing (cargo bench -p eenf-bench makes it)")
    if a.dv_written:
        dv_path = path.replace(".aedat4", "-dv.aedat4")
        if not os.path.exists(dv_path):
            tmp = dv_path.replace(".aedat4", ".part.aedat4")
            subprocess.run([sys.executable, "-c", DV_WRITE, path, tmp], check=True)
            os.replace(tmp, dv_path)
        path = dv_path
    wall = {b: [] for b in bins}
    cpu = {b: [] for b in bins}
    dv = []
    # one round more than counted: the first warms the page cache
    for i in range(a.runs + 1):
        for b in bins:
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            subprocess.run([b, "-q", "extract", path, "-o", "/dev/null"], check=True,
                           stderr=subprocess.DEVNULL)
            w = time.perf_counter() - t0
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            if i:
                wall[b].append(w)
                cpu[b].append(r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime)
        out = subprocess.run([sys.executable, "-c", DV_DECODE, path], capture_output=True,
                             text=True, check=True).stdout.split()
        if i:
            dv.append(float(out[0]))
    mb = os.path.getsize(path) / 1e6
    print(f"{path} ({mb:.0f} MB, {out[1]} events), {a.runs} paired runs, medians (quartiles)")
    q = lambda v: statistics.quantiles(v, n=4) if len(v) > 1 else [v[0]] * 3
    dv_med = statistics.median(dv)
    for b in bins:
        lo, med, hi = q(wall[b])
        print(f"{b}: {med:.3f} s ({lo:.3f}-{hi:.3f}), CPU {statistics.median(cpu[b]):.3f} s, "
              f"{dv_med / med:.2f}x dv-processing")
    lo, med, hi = q(dv)
    print(f"dv-processing decode alone: {med:.3f} s ({lo:.3f}-{hi:.3f})")


if __name__ == "__main__":
    main()
