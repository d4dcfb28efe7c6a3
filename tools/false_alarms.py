#!/usr/bin/env python3
"""False alarms: recordings that hold no mains line must not yield a trace.

    false_alarms.py EENF_BINARY [--each 5] [--seed 7]

Audio (16-bit WAV at 8 kHz and 44.1 kHz, 40 s): white noise, brown noise, music-like chords
with vibrato, speech-like noise bursts, steady tones 0.3-3 Hz away from 50/60 Hz and their
harmonics, and a 7 Hz square wave (odd harmonics at 49 and 63 Hz). Events (text files, 64x48,
30 s): background noise, a bar sweeping the view, and a lamp flickering at a frequency no grid
has (37, 83, 140 Hz). Each goes through `audio` or `extract`; a trace written is a false alarm.
Prints a table of traced / tried per kind and exits 1 on any false alarm.
"""
import argparse
import math
import os
import random
import struct
import subprocess
import sys
import tempfile
import wave


def write_wav(path, fs, samples):
    with wave.open(path, "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(fs)
        w.writeframes(b"".join(struct.pack("<h", int(max(-1, min(1, v)) * 32000)) for v in samples))


def audio_kinds(rng):
    tau = 2 * math.pi

    def white(fs, n):
        return [rng.gauss(0, 0.2) for _ in range(n)]

    def brown(fs, n):
        v, out = 0.0, []
        for _ in range(n):
            v = 0.999 * v + rng.gauss(0, 0.02)
            out.append(v)
        return out

    def music(fs, n):
        notes = [220 * 2 ** (rng.randrange(24) / 12) for _ in range(3)]
        out = []
        for i in range(n):
            t = i / fs
            if i % (fs // 2) == 0:
                notes = [220 * 2 ** (rng.randrange(24) / 12) for _ in range(3)]
            vib = 1 + 0.003 * math.sin(tau * 5 * t)
            out.append(sum(0.15 * math.sin(tau * f * vib * t) for f in notes) + rng.gauss(0, 0.01))
        return out

    def speech(fs, n):
        out, env = [], 0.0
        for i in range(n):
            t = i / fs
            env = 0.5 * (1 + math.sin(tau * 4 * t + 3 * math.sin(tau * 0.3 * t)))
            out.append(env * rng.gauss(0, 0.3))
        return out

    def near_tone(fs, n):
        grid = rng.choice([50.0, 60.0])
        k = rng.choice([1, 1, 2, 3])
        off = rng.choice([-1, 1]) * rng.uniform(0.3, 3.0)
        f = k * (grid + off)
        return [0.3 * math.sin(tau * f * i / fs) + rng.gauss(0, 0.02) for i in range(n)]

    def square7(fs, n):
        return [0.5 * (1 if math.sin(tau * 7 * i / fs) >= 0 else -1) + rng.gauss(0, 0.01)
                for i in range(n)]

    return {"white noise": white, "brown noise": brown, "music": music,
            "speech-like": speech, "tone near mains": near_tone, "7 Hz square": square7}


def event_kinds(rng):
    w, h, seconds = 64, 48, 30

    def noise(path):
        with open(path, "w") as f:
            t = 0.0
            while t < seconds:
                t += rng.expovariate(20_000)
                f.write(f"{int(t * 1e6)} {rng.randrange(w)} {rng.randrange(h)} {rng.randrange(2)}\n")

    def sweep(path):
        with open(path, "w") as f:
            t = 0.0
            while t < seconds:
                t += rng.expovariate(30_000)
                x = int((t * 17) % w)
                xx = min(w - 1, max(0, x + rng.choice([-1, 0, 1])))
                f.write(f"{int(t * 1e6)} {xx} {rng.randrange(h)} {int(rng.random() < 0.5)}\n")

    def odd_lamp(path):
        f_lamp = rng.choice([37.0, 83.0, 140.0])
        with open(path, "w") as f:
            t = 0.0
            while t < seconds:
                t += rng.expovariate(40_000)
                s = math.sin(2 * math.pi * f_lamp * t)
                if rng.random() < abs(s):
                    f.write(f"{int(t * 1e6)} {rng.randrange(w)} {rng.randrange(h)} {int(s > 0)}\n")

    return {"event noise": noise, "moving bar": sweep, "lamp off any grid": odd_lamp}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("eenf")
    ap.add_argument("--each", type=int, default=5)
    ap.add_argument("--seed", type=int, default=7)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    work = tempfile.mkdtemp(prefix="eenf-false-alarms-")
    rows, alarms = [], []

    def try_kind(kind, command, ext, write):
        """`each` negatives of one kind, written by write(path, i), through `command`."""
        traced = 0
        for i in range(a.each):
            path = os.path.join(work, f"{kind.replace(' ', '_')}_{i}.{ext}")
            write(path, i)
            out = path + ".csv"
            r = subprocess.run([a.eenf, "-q", command, path, "-o", out], capture_output=True, text=True)
            if r.returncode == 0 or os.path.exists(out):
                traced += 1
                alarms.append(f"{kind} #{i}: {r.stderr.strip()}")
            os.remove(path)
        rows.append((kind, traced, a.each))

    def wav_of(make):
        def write(path, i):
            fs = [8000, 44100][i % 2]
            write_wav(path, fs, make(fs, fs * 40))
        return write

    for kind, make in audio_kinds(rng).items():
        try_kind(kind, "audio", "wav", wav_of(make))
    for kind, make in event_kinds(rng).items():
        try_kind(kind, "extract", "txt", lambda path, i, make=make: make(path))
    print(f"{'negative':<20} traced / tried")
    for kind, traced, tried in rows:
        print(f"{kind:<20} {traced} / {tried}")
    for x in alarms:
        print("  false alarm: " + x)
    print(f"false alarms: {len(alarms)} of {sum(r[2] for r in rows)}")
    sys.exit(1 if alarms else 0)


if __name__ == "__main__":
    main()
