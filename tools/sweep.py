#!/usr/bin/env python3
"""Hostile-input sweep: every fixture cut at every 1/200th of its length and copied with random
bit flips, each copy run through `info`, `extract` and a fine `extract` under a 2 GB
address-space limit (as `ulimit -v 2000000`). Bad input may give an error, never a panic, an
abort, a hang (20 s) or more than 200 MB of memory.

    tools/sweep.py EENF_BINARY FIXTURES_DIR [--flips 300] [--cuts 200] [--jobs 2]
    tools/sweep.py EENF_BINARY --audio [--flips 200] [--cuts 100]
    tools/sweep.py EENF_BINARY --traces [--flips 200] [--cuts 100]

With --audio, the seeds are 20 s of mains hum with noise encoded by ffmpeg in seven containers
(WAV, FLAC, MP3, M4A/AAC, OGG/Vorbis, MKV, WebM/Opus), and each copy goes through `audio`.
With --traces, the seeds are a trace CSV, an eenf JSON trace and the two files of a reference
store (its manifest and its values): damaged traces go through `match` (as the trace and as the
reference) and `compare`, damaged stores through `refdb info` and `match`.

Prints the counts and exits non-zero on any panic, abort, timeout or memory overrun. Each
child's peak memory is its own (wait4), not the sweep's.
"""
import argparse
import json
import os
import shutil
import random
import resource
import signal
import subprocess
import sys
import tempfile
import threading
import time
from concurrent.futures import ThreadPoolExecutor

LIMIT_AS = 2_000_000 * 1024  # ulimit -v 2000000 (KiB)
TIMEOUT_S = 20
MAX_RSS_MB = 200
EVENT_COMMANDS = {
    "info": ["info"],
    "extract": ["extract"],
    "extract-fine": ["extract", "--window", "0.02", "--step", "0.01", "--dt-us", "100"],
}
AUDIO_COMMANDS = {"audio": ["audio"]}
COMMANDS = EVENT_COMMANDS
# container: ffmpeg's encoding arguments
AUDIO_SEEDS = {
    "wav": ["-c:a", "pcm_s16le"],
    "flac": ["-c:a", "flac"],
    "mp3": ["-c:a", "libmp3lame", "-b:a", "64k"],
    "m4a": ["-c:a", "aac", "-b:a", "64k"],
    "ogg": ["-c:a", "libvorbis"],
    "mkv": ["-c:a", "flac"],
    "webm": ["-c:a", "libopus", "-b:a", "48k"],
}


def trace_seeds(binary, work):
    """A trace CSV, an eenf JSON trace, and a store built from the CSV: (path, commands)."""
    import shutil
    clip = os.path.join(work, "clip.csv")
    seed_csv = os.path.join(work, "seed.csv")
    rng = random.Random(5)
    v, rows = 50.0, []
    for i in range(900):
        v += rng.gauss(0, 0.0008) - 0.002 * (v - 50.0)
        rows.append(f"{i},{v:.6f}\n")
    with open(seed_csv, "w") as f:
        f.write("time_s,enf_hz\n" + "".join(rows))
    with open(clip, "w") as f:
        f.write("time_s,enf_hz\n" + "".join(f"{i},{r.split(',')[1]}" for i, r in enumerate(rows[300:600])))
    seed_json = os.path.join(work, "seed.json")
    out = subprocess.run([binary, "-q", "compare", seed_csv, seed_csv], capture_output=True)
    trace = json.dumps({"time_s": list(range(900)), "enf_hz": [float(r.split(",")[1]) for r in rows],
                        "step_s": 1.0, "nominal_hz": 50.0})
    with open(seed_json, "w") as f:
        f.write(trace)
    store = os.path.join(work, "store")
    r = subprocess.run([binary, "-q", "refdb", "build", store, seed_csv, "--start",
                        "2022-08-17T08:00:00Z"], capture_output=True, text=True)
    if r.returncode != 0 or out.returncode != 0:
        sys.exit(f"could not make the trace seeds: {r.stderr.strip()}")
    manifest = os.path.join(store, "grid50.json")
    values = os.path.join(store, json.load(open(manifest))["parts"][0]["file"])
    as_trace = {"match-trace": ["match", "{}", seed_csv], "match-reference": ["match", clip, "{}"],
                "compare": ["compare", "{}", clip]}
    as_store = {"refdb-info": ["refdb", "info", "{}"], "match-store": ["match", clip, "{}"]}

    def in_store(part):
        def place(name, body, dest):
            copy = os.path.join(dest, name)
            shutil.copytree(store, copy)
            with open(os.path.join(copy, os.path.basename(part)), "wb") as f:
                f.write(body)
            return copy
        return place

    return [(seed_csv, as_trace, None), (seed_json, as_trace, None),
            (manifest, as_store, in_store(manifest)), (values, as_store, in_store(values))]


def audio_seeds(work):
    """20 s of a 50 Hz hum and its harmonics in noise, in each container of AUDIO_SEEDS."""
    hum = "0.2*sin(2*PI*50*t)+0.05*sin(2*PI*100*t)+0.03*sin(2*PI*150*t)"
    paths = []
    for ext, codec in AUDIO_SEEDS.items():
        out = os.path.join(work, f"seed.{ext}")
        src = f"aevalsrc={hum}:s=8000:d=20"
        cmd = ["ffmpeg", "-v", "error", "-y", "-f", "lavfi", "-i", src, "-f", "lavfi", "-i",
               "anoisesrc=a=0.02:d=20:r=8000", "-filter_complex", "amix=inputs=2", "-ar",
               "48000" if ext == "webm" else "8000", *codec, out]
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.exit(f"ffmpeg could not make the {ext} seed: {r.stderr.strip()}")
        paths.append(out)
    return paths


def limit():
    resource.setrlimit(resource.RLIMIT_AS, (LIMIT_AS, LIMIT_AS))


def run(binary, cmd, path, errdir):
    """Runs one command; returns (outcome, peak_mb, detail)."""
    with tempfile.TemporaryFile(dir=errdir) as err:
        p = subprocess.Popen(
            # the file goes where the command has "{}", else last
            [binary, "--quiet", *([a.replace("{}", path) for a in COMMANDS[cmd]]
                                  if "{}" in COMMANDS[cmd] else [*COMMANDS[cmd], path])],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=err,
            preexec_fn=limit,
        )
        timer = threading.Timer(TIMEOUT_S, p.kill)
        timer.start()
        t0 = time.monotonic()
        _, status, usage = os.wait4(p.pid, 0)
        took = time.monotonic() - t0
        timer.cancel()
        p.returncode = 0  # reaped here, not by Popen
        err.seek(0)
        text = err.read().decode("utf-8", "replace")
    peak_mb = usage.ru_maxrss / 1024
    if os.WIFSIGNALED(status):
        sig = os.WTERMSIG(status)
        if sig == signal.SIGKILL and took >= TIMEOUT_S - 0.5:
            return "timeout", peak_mb, f"{took:.1f} s"
        kind = "abort" if sig == signal.SIGABRT else "crash"
        return kind, peak_mb, f"signal {sig}: {text.strip()[-300:]}"
    code = os.WEXITSTATUS(status)
    if code == 101 or "panicked" in text:
        return "panic", peak_mb, text.strip()[-300:]
    if code not in (0, 1):
        return "crash", peak_mb, f"exit {code}: {text.strip()[-300:]}"
    lines = [l for l in text.splitlines() if l.strip()]
    # an error is one line (warnings and notes may come before it)
    if code == 1 and not (lines and lines[-1].startswith("eenf: error: ")):
        return "bad-error", peak_mb, text.strip()[-300:]
    return ("error" if code else "ok"), peak_mb, ""


def variants(data, rng, cuts, flips):
    for k in range(cuts):
        yield f"cut{k:03d}", data[: len(data) * k // cuts]
    for k in range(flips):
        b = bytearray(data)
        for _ in range(rng.randint(1, 4)):
            i = rng.randrange(len(b))
            b[i] ^= 1 << rng.randrange(8)
        yield f"flip{k:03d}", bytes(b)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("fixtures", nargs="?")
    ap.add_argument("--audio", action="store_true", help="sweep sound files through `audio`")
    ap.add_argument("--traces", action="store_true", help="sweep traces and stores through match")
    ap.add_argument("--cuts", type=int, default=200)
    ap.add_argument("--flips", type=int, default=300)
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--seed", type=int, default=2026)
    a = ap.parse_args()
    global COMMANDS
    seeds = tempfile.TemporaryDirectory()
    if a.audio:
        COMMANDS = AUDIO_COMMANDS
        files = [(f, AUDIO_COMMANDS, None) for f in audio_seeds(seeds.name)]
    elif a.traces:
        files = trace_seeds(a.binary, seeds.name)
        COMMANDS = {k: v for _, cmds, _ in files for k, v in cmds.items()}
    else:
        files = [
            (os.path.join(d, f), EVENT_COMMANDS, None)
            for d, _, fs in sorted(os.walk(a.fixtures))
            for f in sorted(fs)
            if not f.endswith((".md", ".json", ".npy")) and f != "LICENSE"
        ]
    counts = {}
    worst = {}
    bad = []
    peak = 0.0
    started = time.monotonic()
    with tempfile.TemporaryDirectory() as work, ThreadPoolExecutor(a.jobs) as pool:
        for f, commands, place in files:
            data = open(f, "rb").read()
            rng = random.Random(f"{a.seed}:{os.path.basename(f)}")
            ext = os.path.splitext(f)[1]
            jobs = []
            for name, body in variants(data, rng, a.cuts, a.flips):
                if place:
                    path = place(name, body, work)
                else:
                    path = os.path.join(work, f"{name}{ext}")
                    with open(path, "wb") as out:
                        out.write(body)
                for cmd in commands:
                    jobs.append((name, cmd, pool.submit(run, a.binary, cmd, path, work)))
            for name, cmd, fut in jobs:
                outcome, mb, detail = fut.result()
                counts[outcome] = counts.get(outcome, 0) + 1
                peak = max(peak, mb)
                worst[cmd] = max(worst.get(cmd, 0.0), mb)
                if outcome not in ("ok", "error") or mb > MAX_RSS_MB:
                    bad.append(f"{os.path.basename(f)} {name} {cmd}: {outcome}, {mb:.0f} MB {detail}")
            for name in os.listdir(work):
                p = os.path.join(work, name)
                shutil.rmtree(p) if os.path.isdir(p) else os.remove(p)
            print(f"  {os.path.basename(f)}: {len(jobs)} runs", flush=True)
    runs = sum(counts.values())
    summary = ", ".join(f"{v} {k}" for k, v in sorted(counts.items()))
    print(f"sweep: {len(files)} fixtures, {runs} runs in {time.monotonic() - started:.0f} s: {summary}")
    print("peak memory (MB): " + ", ".join(f"{k} {v:.0f}" for k, v in worst.items()) + f"; limit {MAX_RSS_MB}")
    for b in bad[:40]:
        print("  " + b)
    print(f"sweep: {len(bad)} panics/aborts/crashes/timeouts/overruns/bad errors")
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
