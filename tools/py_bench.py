"""Speed and memory of the Python package, for the README (a benchmark, not a test).

Usage: python tools/py_bench.py [FILE] [--runs N]
FILE defaults to target/tmp/bench-60s-LZ4.aedat4 (`cargo bench -p eenf-bench --bench pipeline`
writes it); the venv needs eenf (pip install ./crates/eenf-py) and dv-processing.

Each measure runs in a fresh interpreter, alternating between the two sides (paired runs),
and reports the median wall time and the peak resident memory:
1. the file's events into one numpy array: `eenf.read_events` against dv-processing's own
   numpy path (MonoCameraRecording, getNextEventBatch().numpy(), concatenated);
2. `eenf.extract(FILE)` from Python against the `eenf extract FILE` command;
3. `eenf.iter_events` over the first 20 s and over the whole file: peak memory must not grow.
"""

import json
import os
import statistics
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)

READ_EENF = """
import eenf, sys
ev = eenf.read_events(sys.argv[1])
n = len(ev)
"""
READ_DV = """
import dv_processing as dv, numpy as np, sys
rec = dv.io.MonoCameraRecording(sys.argv[1])
parts = []
while rec.isRunning():
    b = rec.getNextEventBatch()
    if b is not None and b.size() > 0:
        parts.append(b.numpy())
ev = np.concatenate(parts)
n = len(ev)
"""
EXTRACT_PY = """
import eenf, sys
t = eenf.extract(sys.argv[1])
n = len(t)
"""
ITER = """
import eenf, sys
end = float(sys.argv[2]) * 1e6 if len(sys.argv) > 2 else None
n, first = 0, None
for b in eenf.iter_events(sys.argv[1]):
    first = b["t"][0] if first is None else first
    n += len(b)
    if end is not None and b["t"][-1] - first >= end:
        break
"""

# the timed part starts after the imports: the interpreter's start is the same for both sides
TIMER = """
import time, resource, json
t0 = time.perf_counter()
{body}
dt = time.perf_counter() - t0
print(json.dumps({{"s": dt, "n": n, "rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}}))
"""


def run_py(body, *args):
    # imports outside the timer
    head, _, rest = body.strip().partition("\n")
    code = head + "\n" + TIMER.format(body=rest)
    out = subprocess.run([sys.executable, "-c", code, *args], capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(out.stderr.strip().splitlines()[-1])
    return json.loads(out.stdout.strip().splitlines()[-1])


def run_cli(*args):
    """The command, whole process; and the time it reports for its own extraction."""
    exe = os.environ.get("EENF_BIN", os.path.join(REPO, "target", "release", "eenf"))
    code = f"""
import subprocess, time, resource, json, re
t0 = time.perf_counter()
r = subprocess.run({[exe, *args, "-o", "/dev/null"]!r}, check=True, capture_output=True, text=True)
dt = time.perf_counter() - t0
own = float(re.search(r" in ([0-9.]+) s \\(", r.stderr).group(1))
print(json.dumps({{"s": dt, "own": own, "n": 0,
                  "rss_mb": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024}}))
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def paired(name_a, fa, name_b, fb, runs):
    a, b = [], []
    for _ in range(runs):
        a.append(fa())
        b.append(fb())
    ma = statistics.median(r["s"] for r in a)
    mb = statistics.median(r["s"] for r in b)
    for name, rs, m in [(name_a, a, ma), (name_b, b, mb)]:
        times = ", ".join("%.3f" % r["s"] for r in rs)
        peak = max(r["rss_mb"] for r in rs)
        print(f"  {name:44s} median {m:7.3f} s  (runs {times})  peak {peak:7.0f} MB")
    print(f"  ratio {mb / ma:.2f} ({name_b} / {name_a})")
    if "own" in b[0]:
        own = statistics.median(r["own"] for r in b)
        print(f"  the command's own extraction time (as it reports it): median {own:.3f} s;"
              f" Python / command {ma / own:.3f}")


def main():
    argv = sys.argv[1:]
    if "--runs" in argv:
        i = argv.index("--runs")
        argv = argv[:i] + argv[i + 2 :]
    args = argv
    runs = 5
    if "--runs" in sys.argv:
        runs = int(sys.argv[sys.argv.index("--runs") + 1])
    path = args[0] if args else os.path.join(REPO, "target", "tmp", "bench-60s-LZ4.aedat4")
    if not os.path.exists(path):
        raise SystemExit(f"{path}: missing (cargo bench -p eenf-bench --bench pipeline writes it)")
    print(f"{path}: {os.path.getsize(path) / 1e6:.0f} MB")
    print("1. events into numpy")
    paired("eenf.read_events", lambda: run_py(READ_EENF, path),
           "dv-processing batches .numpy(), concatenated", lambda: run_py(READ_DV, path), runs)
    print("2. E-ENF from Python and from the command")
    paired("eenf.extract (Python)", lambda: run_py(EXTRACT_PY, path),
           "eenf extract (command, whole process)", lambda: run_cli("extract", path), runs)
    print("3. iter_events peak memory, 20 s against the whole file")
    short = run_py(ITER, path, "20")
    whole = run_py(ITER, path)
    print(f"  first 20 s: {short['n']} events, peak {short['rss_mb']:.0f} MB; "
          f"whole file: {whole['n']} events, peak {whole['rss_mb']:.0f} MB")


if __name__ == "__main__":
    main()
