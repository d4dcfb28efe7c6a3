"""Any length, any span: wall time and peak memory of eenf on long inputs (issue 49).

Three parts, each run on inputs written here into target/scale-bench/ (kept between runs):
  audio  MINUTES,...   `eenf audio` on 44.1 kHz 16-bit mono hum of each length (default 10,60,240;
                       1440 writes a 7.6 GB WAV), with its agreement with the truth;
  match  YEARS,...     `eenf match` of a 5 min and a 1 h trace cut from a store of one grid over
                       each span at 1 s (default 1,10), and with --grids 3 over three grids;
                       says whether the right second came first;
  month                `eenf refdb build` adding a month (an ESO `dtm,f` CSV) to a copy of the
                       ten-year store;
  libhum DAYS,...      libhum 1.1.5's `match_signals` (numpy backend, its only one without a GPU)
                       and `eenf match` on the same 5 min trace over the first DAYS of the same
                       store (default 1,7), each with a time limit of 900 s.
Stores are written directly in the store's format (refdb: parts of i32 µHz with their CRC-32):
a random walk held near 50 Hz, 2 mHz a step, like a grid's one-second means.

Usage: python tools/scale_bench.py audio [MINUTES] | match [YEARS] [--grids N] | month | libhum [DAYS]
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
PART = 1 << 22  # values per part (refdb's PART_VALUES)


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


def part_entry(file, first, b):
    """A part's entry in the manifest, from its bytes: its CRC-32, values that are not gaps
    and their sum (what refdb writes)."""
    v = np.frombuffer(b, dtype="<i4").astype(np.int64)
    v = v[v != -2**31]
    return {"file": file, "first": first, "count": len(b) // 4, "crc32": zlib.crc32(b),
            "finite": int(len(v)), "sum_uhz": int(v.sum())}


def with_sums(d, manifest):
    """Gives the parts of a store written before parts carried their sums those sums."""
    meta = json.load(open(manifest))
    if all("sum_uhz" in p for p in meta["parts"]):
        return
    meta["parts"] = [part_entry(p["file"], p["first"], open(os.path.join(d, p["file"]), "rb").read())
                     for p in meta["parts"]]
    with open(manifest + ".part", "w") as f:
        json.dump(meta, f)
    os.replace(manifest + ".part", manifest)


def store(name, years, seed):
    """A store folder holding one grid `name` over `years` at 1 s; its folder. Written in the
    store's layout: parts of 2^22 values counted from the Unix epoch, each with its CRC-32 and
    sums."""
    d = os.path.join(out, f"store-{name}-{years:g}y")
    manifest = os.path.join(d, f"{name}.json")
    if os.path.exists(manifest):
        with_sums(d, manifest)
        return d
    os.makedirs(d, exist_ok=True)
    count = int(years * 365.25 * 86400)
    rng = np.random.default_rng(seed)
    x, parts = 0.0, []
    lo = 0
    while lo < count:
        n = min(PART - (START + lo) % PART, count - lo)
        steps = rng.normal(0, 2e-3, n)
        walk = np.empty(n)
        for i0 in range(0, n, 100_000):  # held near nominal: x ← 0.999 x + step
            seg = steps[i0:i0 + 100_000]
            k = np.arange(len(seg))
            w = 0.999 ** k
            walk[i0:i0 + len(seg)] = w * (x * 0.999 + np.cumsum(seg / w))
            x = walk[i0 + len(seg) - 1]
        b = np.round(walk * 1e6).astype("<i4").tobytes()
        file = f"{name}.bench{len(parts):05d}.0.i32"
        with open(os.path.join(d, file), "wb") as f:
            f.write(b)
        parts.append(part_entry(file, lo, b))
        lo += n
    meta = {"grid": name, "nominal_hz": 50.0, "step_s": 1.0, "start_unix_s": float(START),
            "count": count, "encoding": "i32 little-endian, µHz deviation from nominal_hz, "
            "-2147483648 = gap", "parts": parts}
    with open(manifest, "w") as f:
        json.dump(meta, f)
    return d


def stored(d, name, at, n):
    """Values at..at+n of the grid `name` in the store at d, µHz."""
    meta = json.load(open(os.path.join(d, f"{name}.json")))
    out = []
    for p in meta["parts"]:
        a, b = max(at, p["first"]), min(at + n, p["first"] + p["count"])
        if a < b:
            v = np.memmap(os.path.join(d, p["file"]), dtype="<i4", mode="r")
            out.append(np.asarray(v[a - p["first"]:b - p["first"]]))
    return np.concatenate(out)


def cut(d, name, at, seconds, path):
    """A trace of `seconds` from the store's grid at second `at`, with 1 mHz of noise."""
    hz = 50 + stored(d, name, at, seconds).astype(float) / 1e6
    hz += np.random.default_rng(at).normal(0, 1e-3, seconds)
    np.savetxt(path, np.c_[np.arange(seconds), hz], delimiter=",", header="time_s,enf_hz",
               comments="", fmt="%.6f")


def match(years_list, grids):
    print("| match | store | wall s | peak MB | right second and grid first |\n"
          "|---|---|---|---|---|")
    for years in years_list:
        names = ["DE", "FR", "PL"][:grids]
        dirs = [store(n, years, seed) for seed, n in enumerate(names)]
        d = dirs[0]
        if grids > 1:  # one folder holding every grid
            d = os.path.join(out, f"store-{grids}grids-{years:g}y")
            os.makedirs(d, exist_ok=True)
            for n, src in zip(names, dirs):
                for f in os.listdir(src):
                    to = os.path.join(d, f)
                    if f == n + ".json" and os.path.exists(to):
                        os.remove(to)  # the manifest may have been given its sums since
                    if f.startswith(n + ".") and not os.path.exists(to):
                        os.link(os.path.join(src, f), to)
        at = int(years * 365.25 * 86400 * 0.73)
        for seconds in (300, 3600):
            trace = os.path.join(out, f"cut-{years:g}y-{seconds}.csv")
            cut(dirs[-1], names[-1], at, seconds, trace)
            wall, mb, text = timed([eenf, "-q", "match", trace, d, "--json"])
            found = json.loads(text)
            best = found["candidates"][0]
            right = abs(best["start_s"] - (START + at)) < 1 and best["grid"] == names[-1]
            print(f"| {seconds // 60} min | {grids} grid(s) × {years:g} y | {wall:.1f} | {mb:.0f} "
                  f"| {'yes' if right else 'no'} ({best['grid']}, p {best['p_value']:.1e}) |",
                  flush=True)


def month():
    """A month added at the end of a store of ten years less that month (a store may span ten
    years): the build reads and rewrites only the parts the month touches."""
    src = store("DE", 10, 0)
    d = os.path.join(out, "store-month")
    shutil.rmtree(d, ignore_errors=True)
    shutil.copytree(src, d)
    manifest = os.path.join(d, "DE.json")
    meta = json.load(open(manifest))
    keep = meta["count"] - 31 * 86400
    parts = []
    for p in meta["parts"]:
        path = os.path.join(d, p["file"])
        if p["first"] >= keep:
            os.remove(path)
            continue
        if p["first"] + p["count"] > keep:
            p["count"] = keep - p["first"]
            with open(path, "r+b") as f:
                f.truncate(p["count"] * 4)
            p = part_entry(p["file"], p["first"], open(path, "rb").read())
        parts.append(p)
    meta.update(count=keep, parts=parts)
    json.dump(meta, open(manifest, "w"))
    t0 = START + keep
    rng = np.random.default_rng(9)
    hz = 50 + rng.normal(0, 0.02, 31 * 86400)
    path = os.path.join(out, "month.csv")
    with open(path, "w") as f:
        f.write("dtm,f\n")
        for i, v in enumerate(hz):
            t = np.datetime64(int(t0 + i), "s")
            f.write(f"{str(t).replace('T', ' ')},{v:.3f}\n")
    before = set(os.listdir(d))
    wall, mb, _ = timed([eenf, "-q", "refdb", "build", d, path, "--grid", "DE"])
    after = set(os.listdir(d))
    print(f"| a month added to 10 y less a month | {wall:.1f} s | {mb:.0f} MB | "
          f"{len(after - before)} part files written, {len(before - after)} removed, "
          f"{len(before & after) - 2} untouched |")


LIBHUM = """
import sys, time, numpy as np
from libhum.types import Signal
from libhum.match import match_signals
ref = np.fromfile(sys.argv[1], dtype="<i4").astype(np.float32) / 1e6
clip = np.loadtxt(sys.argv[2], delimiter=",", skiprows=1)[:, 1] - 50
sig = lambda x: Signal(50.0, 1.0, np.ma.masked_invalid(x.astype(np.float32)))
t = time.time()
m = match_signals(sig(ref), sig(clip), max_matches=1)
print(time.time() - t, m[0].offset.total_seconds() if m else "none")
"""


def libhum(days_list):
    """libhum and eenf on the same trace and the same span of the store's values."""
    src = store("DE", 1, 0)
    at = 3 * 3600 + 1234  # inside the first day
    trace = os.path.join(out, "cut-libhum-300.csv")
    cut(src, "DE", at, 300, trace)
    print("| span | libhum 1.1.5 (numpy) | eenf match |\n|---|---|---|")
    for days in days_list:
        n = int(days * 86400)
        raw = os.path.join(out, f"libhum-{days:g}d.i32")
        stored(src, "DE", 0, n).astype("<i4").tofile(raw)
        d = os.path.join(out, f"store-DE-{days:g}d")
        shutil.rmtree(d, ignore_errors=True)
        os.makedirs(d)
        csv_path = os.path.join(out, f"libhum-{days:g}d.csv")
        with open(csv_path, "w") as f:
            f.write("time_s,enf_hz\n")
            np.savetxt(f, np.c_[np.arange(n), 50 + np.fromfile(raw, "<i4") / 1e6], delimiter=",",
                       fmt=["%d", "%.6f"])
        subprocess.run([eenf, "-q", "refdb", "build", d, f"{csv_path}@2016-01-01T00:00:00Z",
                        "--grid", "DE"], check=True, capture_output=True)
        try:
            r = subprocess.run(["/usr/bin/time", "-f", "%e %M", sys.executable, "-c", LIBHUM, raw,
                                trace], capture_output=True, text=True, timeout=900)
            secs, where = r.stdout.split()[:2]
            peak = int(r.stderr.strip().splitlines()[-1].split()[1]) / 1024
            theirs = f"{float(secs):.1f} s, {peak:.0f} MB, {'right' if where != 'none' and abs(float(where) - at) < 1 else 'wrong'} second"
        except subprocess.TimeoutExpired:
            theirs = "no answer in 900 s"
        wall, mb, text = timed([eenf, "-q", "match", trace, d, "--json"])
        best = json.loads(text)["candidates"][0]
        ok = abs(best["start_s"] - (START + at)) < 1
        print(f"| {days:g} d | {theirs} | {wall:.2f} s, {mb:.0f} MB, "
              f"{'right' if ok else 'wrong'} second |", flush=True)


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
    elif what == "libhum":
        libhum([float(d) for d in (arg or "1,7").split(",")])
    else:
        sys.exit(__doc__)
