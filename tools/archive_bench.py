"""Grid archives into the reference store: eenf beside libhum on the same files.

Writes DAYS of 1 s grid frequency (a random walk with a slow swing around 50 Hz, rounded to
1 mHz like the operators' files) to target/archive-bench/ in two layouts:
  - the UK National Grid ESO's `dtm,f` CSV (what `eenf refdb build` reads, UTC), and
  - the OSF/WETI `year;month;day;hour;minute;second;value` rows that libhum's `read_weti` reads;
and a Fingrid-style month: the same days at 0.1 s as day files `Time,Value` in a zip.
Then times `eenf refdb build` on each (a fresh store each run) and libhum's `read_weti` on the
WETI file, RUNS times each, and prints wall time and peak memory (GNU time). libhum is run on
LIBHUM_DAYS days only (its resampler interpolates every second separately) and its time is
also given per day.

Usage: python tools/archive_bench.py [DAYS] [RUNS] [LIBHUM_DAYS]   (defaults 31, 3, 1)
Needs: numpy; /usr/bin/time; `pip install libhum==1.1.5` for the peer (skipped when missing);
a release build of eenf (cargo build --release)."""
import os
import shutil
import subprocess
import sys
import zipfile

import numpy as np

days = int(sys.argv[1]) if len(sys.argv) > 1 else 31
runs = int(sys.argv[2]) if len(sys.argv) > 2 else 3
libhum_days = int(sys.argv[3]) if len(sys.argv) > 3 else 1
root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
out = os.path.join(root, "target", "archive-bench")
os.makedirs(out, exist_ok=True)
eenf = os.path.join(root, "target", "release", "eenf")
start = np.datetime64("2023-01-01T00:00:00")


def values(n, seed):
    rng = np.random.default_rng(seed)
    walk = np.cumsum(rng.normal(0, 0.0015, n))
    return 50 + 0.03 * np.sin(2 * np.pi * np.arange(n) / 1800) + walk - walk.mean()


def write_eso(path, n):
    if os.path.exists(path):
        return
    t = start + np.arange(n).astype("timedelta64[s]")
    f = values(n, 1)
    with open(path, "w") as out_f:
        out_f.write("dtm,f\n")
        for k in range(0, n, 86_400):
            stamps = np.datetime_as_string(t[k:k + 86_400], unit="s")
            out_f.writelines(f"{s.replace('T', ' ')},{v:.3f}\n" for s, v in zip(stamps, f[k:k + 86_400]))


def write_weti(path, n):
    if os.path.exists(path):
        return
    t = start + np.arange(n).astype("timedelta64[s]")
    f = values(n, 1)
    with open(path, "w") as out_f:
        for s, v in zip(np.datetime_as_string(t, unit="s"), f):
            d, c = s.split("T")
            y, mo, dd = d.split("-")
            h, mi, se = c.split(":")
            out_f.write(f"{int(y)};{int(mo)};{int(dd)};{int(h)};{int(mi)};{float(se):.1f};{v:.3f}\n")


def write_fingrid(path, d):
    if os.path.exists(path):
        return
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        for day in range(d):
            n = 864_000
            t = start + np.timedelta64(day, "D") + (np.arange(n) * 100).astype("timedelta64[ms]")
            f = values(n, 10 + day)
            stamps = np.datetime_as_string(t, unit="ms")
            body = "Time,Value\n" + "".join(
                f"{s.replace('T', ' ')},{v:.3f}\n" for s, v in zip(stamps, f)
            )
            z.writestr(f"{str(start + np.timedelta64(day, 'D'))[:10]}.csv", body)


def timed(cmd):
    r = subprocess.run(["/usr/bin/time", "-f", "%e %M"] + cmd, capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{cmd[:3]} failed: {r.stderr.strip().splitlines()[-3:]}")
    wall, kb = r.stderr.strip().splitlines()[-1].split()
    return float(wall), int(kb) / 1024


def median_run(cmd, before=None):
    results = []
    for _ in range(runs):
        if before:
            before()
        results.append(timed(cmd))
    walls = sorted(r[0] for r in results)
    return walls[len(walls) // 2], max(r[1] for r in results)


eso = os.path.join(out, f"eso-{days}d.csv")
weti = os.path.join(out, f"weti-{libhum_days}d.csv")
weti_all = os.path.join(out, f"weti-{days}d.csv")
fingrid = os.path.join(out, f"fingrid-{min(days, 7)}d.zip")
write_eso(eso, days * 86_400)
write_weti(weti, libhum_days * 86_400)
write_weti(weti_all, days * 86_400)
write_fingrid(fingrid, min(days, 7))
store = os.path.join(out, "store")


def fresh():
    shutil.rmtree(store, ignore_errors=True)


rows = []
for name, path, extra in [
    (f"ESO dtm,f, {days} days of 1 s", eso, []),
    (f"OSF/WETI rows, {days} days of 1 s", weti_all, []),
    (f"Fingrid zip, {min(days, 7)} days of 0.1 s", fingrid, ["--tz", "Z", "--format", "fingrid"]),
]:
    wall, mb = median_run([eenf, "-q", "refdb", "build", store, path] + extra, fresh)
    size = os.path.getsize(path) / 1e6
    rows.append((f"eenf refdb build: {name}", wall, mb, size))

try:
    import libhum  # noqa: F401

    code = f"import libhum.io as io; s = io.read_weti({weti!r}); print(len(s.signal))"
    wall, mb = median_run([sys.executable, "-c", code])
    rows.append((f"libhum read_weti: {libhum_days} day(s) of 1 s", wall, mb, os.path.getsize(weti) / 1e6))
except ImportError:
    print("libhum not installed: the peer is skipped")

print(f"{'what':<52} {'wall s':>8} {'peak MB':>8} {'file MB':>8}")
for what, wall, mb, size in rows:
    print(f"{what:<52} {wall:8.2f} {mb:8.0f} {size:8.1f}")
