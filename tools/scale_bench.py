"""Any length, any span: wall time and peak memory of eenf on long inputs (issue 49).

Three parts, each run on inputs written here into target/scale-bench/ (kept between runs):
  audio  MINUTES,...   `eenf audio` on 44.1 kHz 16-bit mono hum of each length (default 10,60,240;
                       1440 writes a 7.6 GB WAV), with its agreement with the truth;
  match  YEARS,...     `eenf match` of a 5 min and a 1 h trace cut from a store of one grid over
                       each span at 1 s (default 1,10), and with --grids 3 over three grids;
                       says whether the right second came first;
  month                `eenf refdb build` adding a month (an ESO `dtm,f` CSV) to a copy of the
                       ten-year store.
Stores are written directly in the store's format (refdb.rs: i32 µHz, CRC-32 in the manifest):
a random walk held near 50 Hz, 2 mHz a step, like a grid's one-second means.

Usage: python tools/scale_bench.py audio [MINUTES] | match [YEARS] [--grids N] | month
Needs: numpy; /usr/bin/time; a release build of eenf (cargo build --release)."""
import csv
import json
import os
import shutil
import subprocess
import sys
import wave
import zlib

import numpy as np

root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
out = os.path.join(root, "target", "scale-bench")
eenf = os.path.join(root, "target", "release", "eenf")
START = 1451606400  # 2016-01-01T00:00:00Z
CHUNK = 10_000_000


def timed(cmd):
    """Runs cmd under GNU time: (wall s, peak MB, stdout)."""
    r = subprocess.run(["/usr/bin/time", "-f", "%e %M"] + cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed: {r.stderr.strip().splitlines()[-2:]}")
    wall, kb = r.stderr.strip().splitlines()[-1].split()
    return float(wall), int(kb) / 1024, r.stdout


def hum_wav(minutes):
    """44.1 kHz hum with a known ENF (as tools/audio_bench.py writes it), a minute at a time."""
    wav = os.path.join(out, f"hum-{minutes:g}min.wav")
    if os.path.exists(wav):
        return wav
    fs, secs = 44100, int(minutes * 60)
    rng = np.random.default_rng(7)
    k = secs + 2
    walk = np.cumsum(rng.normal(0, 0.002, k))
    enf_s = 50 + 0.02 * np.sin(2 * np.pi * np.arange(k) / 97) + walk - walk.mean()
    np.savetxt(wav + ".truth.csv", np.c_[np.arange(k), enf_s], delimiter=",",
               header="time_s,enf_hz", comments="", fmt="%.9f")
    with wave.open(wav + ".part", "wb") as f:
        f.setnchannels(1)
        f.setsampwidth(2)
        f.setframerate(fs)
        phase = 0.0
        for start in range(0, secs, 60):
            n = fs * min(60, secs - start)
            t = start + np.arange(n) / fs
            phi = phase + 2 * np.pi * np.cumsum(np.interp(t, np.arange(k), enf_s)) / fs
            phase = phi[-1]
            x = 0.02 * np.sin(phi + 0.3) + 0.008 * np.sin(2 * phi + 0.6) + 0.005 * np.sin(3 * phi)
            x += rng.normal(0, 0.05, n)
            f.writeframes((np.clip(x, -1, 1) * 32767).astype("<i2").tobytes())
    os.replace(wav + ".part", wav)
    return wav


def agreement(trace_csv, truth_csv):
    a = {round(float(r["time_s"])): float(r["enf_hz"]) for r in csv.DictReader(open(trace_csv))}
    b = {round(float(r["time_s"])): float(r["enf_hz"]) for r in csv.DictReader(open(truth_csv))}
    ks = [k for k in a if k in b and np.isfinite(a[k])]
    x, y = np.array([a[k] for k in ks]), np.array([b[k] for k in ks])
    return np.corrcoef(x, y)[0, 1], np.mean(np.abs(x - y)) * 1e3


def audio(minutes_list):
    print("| audio (44.1 kHz mono) | wall s | peak MB | CC | MAE mHz |\n|---|---|---|---|---|")
    for minutes in minutes_list:
        wav = hum_wav(minutes)
        trace = os.path.join(out, f"hum-{minutes:g}min.enf.csv")
        wall, mb, _ = timed([eenf, "-q", "audio", wav, "-o", trace])
        cc, mae = agreement(trace, wav + ".truth.csv")
        print(f"| {minutes:g} min | {wall:.1f} | {mb:.0f} | {cc:.4f} | {mae:.2f} |", flush=True)


def store(name, years, seed):
    """A store folder holding one grid `name` over `years` at 1 s; its folder."""
    d = os.path.join(out, f"store-{name}-{years:g}y")
    manifest = os.path.join(d, f"{name}.json")
    if os.path.exists(manifest):
        return d
    os.makedirs(d, exist_ok=True)
    count = int(years * 365.25 * 86400)
    values = f"{name}.bench.i32"
    rng = np.random.default_rng(seed)
    x, crc = 0.0, 0
    with open(os.path.join(d, values), "wb") as f:
        for lo in range(0, count, CHUNK):
            n = min(CHUNK, count - lo)
            steps = rng.normal(0, 2e-3, n)
            walk = np.empty(n)
            for i0 in range(0, n, 100_000):  # held near nominal: x ← 0.999 x + step
                seg = steps[i0:i0 + 100_000]
                k = np.arange(len(seg))
                w = 0.999 ** k
                walk[i0:i0 + len(seg)] = w * (x * 0.999 + np.cumsum(seg / w))
                x = walk[i0 + len(seg) - 1]
            b = np.round(walk * 1e6).astype("<i4").tobytes()
            crc = zlib.crc32(b, crc)
            f.write(b)
    meta = {"grid": name, "nominal_hz": 50.0, "step_s": 1.0, "start_unix_s": float(START),
            "count": count, "encoding": "i32 little-endian, µHz deviation from nominal_hz, "
            "-2147483648 = gap", "values_file": values, "values_crc32": crc}
    with open(manifest, "w") as f:
        json.dump(meta, f)
    return d


def cut(d, name, at, seconds, path):
    """A trace of `seconds` from the store's grid at second `at`, with 1 mHz of noise."""
    v = np.memmap(os.path.join(d, f"{name}.bench.i32"), dtype="<i4", mode="r")
    hz = 50 + v[at:at + seconds].astype(float) / 1e6
    hz += np.random.default_rng(at).normal(0, 1e-3, seconds)
    np.savetxt(path, np.c_[np.arange(seconds), hz], delimiter=",", header="time_s,enf_hz",
               comments="", fmt="%.6f")


def match(years_list, grids):
    print("| match | store | wall s | peak MB | right second first |\n|---|---|---|---|---|")
    for years in years_list:
        names = ["DE", "FR", "PL"][:grids]
        dirs = [store(n, years, seed) for seed, n in enumerate(names)]
        d = dirs[0]
        if grids > 1:  # one folder holding every grid
            d = os.path.join(out, f"store-{grids}grids-{years:g}y")
            os.makedirs(d, exist_ok=True)
            for n, src in zip(names, dirs):
                for f in (f"{n}.json", f"{n}.bench.i32"):
                    if not os.path.exists(os.path.join(d, f)):
                        os.link(os.path.join(src, f), os.path.join(d, f))
        at = int(years * 365.25 * 86400 * 0.73)
        for seconds in (300, 3600):
            trace = os.path.join(out, f"cut-{years:g}y-{seconds}.csv")
            cut(dirs[-1], names[-1], at, seconds, trace)
            wall, mb, text = timed([eenf, "-q", "match", trace, d, "--json"])
            found = json.loads(text)
            best = found["candidates"][0] if "candidates" in found else found
            right = abs(best.get("start_unix_s", START + best.get("offset_s", -1)) - (START + at))
            print(f"| {seconds // 60} min | {grids} grid(s) × {years:g} y | {wall:.1f} | {mb:.0f} "
                  f"| {'yes' if right < 1 else 'no (' + str(best)[:80] + ')'} |", flush=True)


def month():
    src = store("DE", 10, 0)
    d = os.path.join(out, "store-month")
    shutil.rmtree(d, ignore_errors=True)
    shutil.copytree(src, d)
    meta = json.load(open(os.path.join(d, "DE.json")))
    t0 = START + meta["count"] - 31 * 86400 // 2  # half inside, half past the end
    rng = np.random.default_rng(9)
    hz = 50 + rng.normal(0, 0.02, 31 * 86400)
    path = os.path.join(out, "month.csv")
    with open(path, "w") as f:
        f.write("dtm,f\n")
        for i, v in enumerate(hz):
            t = np.datetime64(int(t0 + i), "s")
            f.write(f"{str(t).replace('T', ' ')},{v:.3f}\n")
    wall, mb, _ = timed([eenf, "-q", "refdb", "build", d, path, "--grid", "DE"])
    print(f"| a month added to 10 y | {wall:.1f} s | {mb:.0f} MB |")


if __name__ == "__main__":
    os.makedirs(out, exist_ok=True)
    what = sys.argv[1] if len(sys.argv) > 1 else "audio"
    arg = sys.argv[2] if len(sys.argv) > 2 and not sys.argv[2].startswith("--") else None
    grids = int(sys.argv[sys.argv.index("--grids") + 1]) if "--grids" in sys.argv else 1
    if what == "audio":
        audio([float(m) for m in (arg or "10,60,240").split(",")])
    elif what == "match":
        match([float(y) for y in (arg or "1,10").split(",")], grids)
    elif what == "month":
        month()
    else:
        sys.exit(__doc__)
