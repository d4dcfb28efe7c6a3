"""ENF from audio: eenf beside libhum on the same synthetic hum, for the table in the README.

Writes MINUTES of 44.1 kHz 16-bit mono hum with a known ENF (a slow swing and a random walk
around 50 Hz, lines at f0, 2f0 and 3f0, in broadband noise) to target/audio-bench/, then runs
`eenf reference`, `eenf edits` and `libhum compute_enf` on it, paired, RUNS times each, and prints wall time
and peak memory (GNU time), and eenf's agreement with the truth.

Usage: python tools/audio_bench.py [MINUTES] [RUNS]   (defaults 60 and 3)
Needs: numpy; /usr/bin/time; `pip install libhum==1.1.5` for the peer (skipped when missing);
a release build of eenf (cargo build --release)."""
import os
import shutil
import subprocess
import sys
import wave

import numpy as np

minutes = float(sys.argv[1]) if len(sys.argv) > 1 else 60.0
runs = int(sys.argv[2]) if len(sys.argv) > 2 else 3
root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
out = os.path.join(root, "target", "audio-bench")
os.makedirs(out, exist_ok=True)
eenf = os.path.join(root, "target", "release", "eenf")
wav = os.path.join(out, f"hum-{minutes:g}min.wav")
truth = wav + ".truth.csv"

if not os.path.exists(wav):
    fs, secs = 44100, minutes * 60
    rng = np.random.default_rng(7)
    k = int(secs) + 2
    walk = np.cumsum(rng.normal(0, 0.002, k))
    enf_s = 50 + 0.02 * np.sin(2 * np.pi * np.arange(k) / 97) + walk - walk.mean()
    np.savetxt(truth, np.c_[np.arange(k), enf_s], delimiter=",", header="time_s,enf_hz",
               comments="", fmt="%.9f")
    with wave.open(wav, "wb") as f:
        f.setnchannels(1)
        f.setsampwidth(2)
        f.setframerate(fs)
        phase = 0.0
        for start in range(0, int(secs), 60):  # a minute at a time: memory stays small
            n = fs * min(60, int(secs) - start)
            t = start + np.arange(n) / fs
            enf = np.interp(t, np.arange(k), enf_s)
            phi = phase + 2 * np.pi * np.cumsum(enf) / fs
            phase = phi[-1]
            x = 0.02 * np.sin(phi + 0.3) + 0.008 * np.sin(2 * phi + 0.6) + 0.005 * np.sin(3 * phi)
            x += rng.normal(0, 0.05, n)
            f.writeframes((np.clip(x, -1, 1) * 32767).astype("<i2").tobytes())


def timed(cmd):
    r = subprocess.run(["/usr/bin/time", "-f", "%e %M"] + cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{cmd[0]} failed: {r.stderr.strip().splitlines()[-1:]}")
    wall, kb = r.stderr.strip().splitlines()[-1].split()
    return float(wall), int(kb) / 1024


libhum = shutil.which("libhum")
rows = {"eenf": [], "edits": [], "libhum": []}
for _ in range(runs):
    rows["eenf"].append(timed([eenf, "-q", "reference", wav, "-o", os.path.join(out, "eenf.csv")]))
    # `eenf edits` reads the same hour and tests every boundary of it
    rows["edits"].append(timed([eenf, "-q", "edits", wav, "-o", os.path.join(out, "edits.json")]))
    if libhum:
        rows["libhum"].append(timed([libhum, "compute_enf", wav, os.path.join(out, "libhum.enf")]))

print(f"{minutes:g} min of 44.1 kHz 16-bit mono ({os.path.getsize(wav) / 1e6:.0f} MB), {runs} paired runs")
for name, r in rows.items():
    if r:
        walls = sorted(w for w, _ in r)
        print(f"{name:7s} wall median {walls[len(walls) // 2]:.2f} s (min {walls[0]:.2f}, max {walls[-1]:.2f}),"
              f" peak memory {max(m for _, m in r):.0f} MB")
cmp = subprocess.run([eenf, "compare", os.path.join(out, "eenf.csv"), truth], capture_output=True, text=True)
print("eenf against the truth:", " ".join(l.split()[0] + " " + l.split()[1] for l in cmp.stdout.splitlines()
                                         if l.split()[:1] in (["CC"], ["MAE"])))
