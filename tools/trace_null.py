#!/usr/bin/env python3
"""How often real continuous ENF traces show a frequency step: the tail behind `edits`' false
alarms per hour on a trace (`TRACE_STEP_TAIL` in crates/eenf/src/edits.rs).

Traces the 24 hours of one day of real mains (`enf-reference` and `mains-day`) with `eenf audio`,
takes the three 60 Hz days of `enf-traces-60hz` as they are (2 s steps), runs `eenf edits --kind
trace --step-z 2` on each, and fits the rate per hour at which |z| passes x: an exponential over
the rates between 0.1 and 10 per hour, raised to bound every rate resting on two peaks or more.

    python3 tools/trace_null.py target/release/eenf ../shared
"""
import glob
import json
import math
import os
import subprocess
import sys
import tempfile


def main():
    eenf, shared = sys.argv[1], sys.argv[2]
    zs, hours = [], 0.0
    with tempfile.TemporaryDirectory() as tmp:
        jobs = []
        for wav in sorted(glob.glob(f"{shared}/enf-reference/*.wav") + glob.glob(f"{shared}/mains-day/*.wav")):
            csv = os.path.join(tmp, os.path.basename(wav) + ".csv")
            subprocess.run([eenf, "-q", "audio", wav, "-o", csv], check=True, stderr=subprocess.DEVNULL)
            jobs.append([eenf, "-q", "edits", csv, "--kind", "trace", "--step-z", "2", "--json"])
        for day in sorted(glob.glob(f"{shared}/enf-traces-60hz/*.csv")):
            jobs.append([eenf, "-q", "edits", day, "--kind", "trace", "--index-step", "2", "--step-z", "2", "--json"])
        for cmd in jobs:
            r = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
            zs += [abs(e["frequency_step_z"]) for e in r["edits"]]
            hours += r["duration_s"] / 3600
    xs = [i * 0.05 for i in range(1, 400)]
    rates = [(x, sum(v > x for v in zs) / hours, sum(v > x for v in zs)) for x in xs]
    pts = [(x, math.log(r)) for x, r, _ in rates if 0.1 <= r <= 10]
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    slope = sum((p[0] - mx) * (p[1] - my) for p in pts) / sum((p[0] - mx) ** 2 for p in pts)
    b = -1 / slope
    a = max(r * math.exp(x / b) for x, r, c in rates if c >= 2)
    print(f"{hours:.1f} hours of real traces, {len(zs)} steps past z 2")
    for x in (3, 4, 5, 6, 7, 8, 10):
        print(f"  |z| > {x}: {sum(v > x for v in zs) / hours:.3f} per hour (model {a * math.exp(-x / b):.3f})")
    print(f"tail: A = {a:.0f} per hour, b = {b:.3f}; z at 0.05 per hour {b * math.log(a / 0.05):.2f}")


if __name__ == "__main__":
    main()
