"""ENF from real and realistic audio: eenf beside libhum on the same files, for docs/audio.md.

    python tools/audio_side_by_side.py EENF_BINARY SHARED_DIR

Files: the four of SHARED/fixtures/real-audio (three with hum on a 60 Hz grid, one without),
and recordings made like the ENF-WHU case: the real room noise of enfwhu_H0_01_no_enf_1kHz.wav
with a hum at 4 f0 that follows a real 50 Hz mains hour of SHARED/enf-reference (13.5 dB over
its local floor in 16 s Welch segments; 2 f0 at 4.5 dB, f0 at 1.3 dB), the mains recording's own
trace (`eenf audio --harmonics 1`) being the truth; and the same hum cut to 10 s.

eenf runs with its defaults (grid detected). libhum 1.1.5 (`pip install libhum==1.1.5`) is
given the right grid (it cannot detect one) and its own defaults otherwise; its ENF is relative
to the grid and masked where it rejects the signal. Prints a Markdown table.
"""
import csv
import os
import subprocess
import sys
import tempfile

import numpy as np
import scipy.io.wavfile as wavfile
import scipy.signal as ss

eenf, shared = sys.argv[1], sys.argv[2]
work = tempfile.mkdtemp(prefix="eenf-side-by-side-")


def read(path):
    fs, x = wavfile.read(path)
    x = x.astype(float)
    return fs, (x.mean(axis=1) if x.ndim > 1 else x)


def eenf_trace(path, extra=()):
    out = os.path.join(work, os.path.basename(path) + ".csv")
    r = subprocess.run([eenf, "-q", "audio", path, "-o", out, *extra], capture_output=True, text=True)
    if r.returncode != 0:
        return None, r.stderr.strip().splitlines()[-1].split(".wav: ", 1)[-1]
    rows = list(csv.DictReader(open(out)))
    return np.array([float(r["enf_hz"]) for r in rows]), None


def libhum_trace(path, grid):
    import libhum.analysis
    fs, x = read(path)
    r = libhum.analysis.compute_enf(x, float(fs), network_frequency=grid)
    if r is None:
        return None, "no ENF found"
    v = np.ma.filled(r.enf.signal.astype(float), np.nan) + grid
    return v, None


def agree(v, truth):
    n = min(len(v), len(truth))
    v, t = v[:n], truth[:n]
    ok = np.isfinite(v) & np.isfinite(t)
    if ok.sum() < 3:
        return "—"
    cc = np.corrcoef(v[ok], t[ok])[0, 1]
    return f"CC {cc:.3f}, MAE {np.mean(np.abs(v[ok] - t[ok])) * 1e3:.2f} mHz over {ok.sum()} of {n} s"


def describe(v, err, truth=None):
    if v is None:
        return f"refused ({err[:90]})" if err else "refused"
    ok = np.isfinite(v)
    s = f"{ok.sum()} of {len(v)} s, mean {np.nanmean(v):.4f} Hz"
    return s + (f"; {agree(v, truth)}" if truth is not None else "")


def whu_like(hour, offset, seconds=None):
    """Real room noise plus a hum at 4 f0 (and weak 2 f0, f0) following a real mains hour."""
    fsn, noise = read(os.path.join(shared, "fixtures/real-audio/enfwhu_H0_01_no_enf_1kHz.wav"))
    ref_wav = sorted(f for f in os.listdir(os.path.join(shared, "enf-reference")) if f.endswith(".wav"))[hour]
    fsm, mains = read(os.path.join(shared, "enf-reference", ref_wav))
    secs = len(noise) / fsn
    seg = mains[offset * fsm: int((offset + secs + 2) * fsm)]
    ref_path = os.path.join(work, f"mains_{hour}_{offset}_{len(noise)}.wav")
    wavfile.write(ref_path, fsm, seg[: int(secs * fsm)].astype(np.int16))
    sos = ss.butter(4, [45, 55], "bandpass", fs=fsm, output="sos")
    phi = np.unwrap(np.angle(ss.hilbert(ss.sosfiltfilt(sos, seg))))
    ph = np.interp(np.arange(len(noise)) / fsn, np.arange(len(seg)) / fsm, phi)

    def line_db(x, f):
        # the detector's measure: 16 s Hann segments, peak within ±0.2 k Hz over the floor beside it
        fr, p = ss.welch(x, fsn, window="hann", nperseg=min(16 * fsn, len(x) // 2), noverlap=None)
        w = 0.2 * f / 50
        s = np.abs(fr - f) <= w
        ring = (np.abs(fr - f) >= w + 1) & (np.abs(fr - f) <= w + 6)
        return 10 * np.log10(p[s].max() / np.median(p[ring]))

    amp = [1.0, 1.0, 1.0]
    for _ in range(12):
        x = noise + amp[0] * np.cos(ph) + amp[1] * np.cos(2 * ph + 0.4) + amp[2] * np.cos(4 * ph + 1.1)
        got = [line_db(x, 50), line_db(x, 100), line_db(x, 200)]
        amp = [a * 10 ** ((t - g) / 20 * 0.8) for a, t, g in zip(amp, [1.3, 4.5, 13.5], got)]
    if seconds:
        # a clip of the first seconds; the truth is the whole stretch's (16 s windows)
        x = x[: int(seconds * fsn)]
    path = os.path.join(work, f"whu_like_{hour}_{offset}_{len(x)}.wav")
    wavfile.write(path, fsn, np.clip(x, -32767, 32767).astype(np.int16))
    truth, _ = eenf_trace(ref_path, ["--harmonics", "1"])
    return path, truth


rows = []
real = os.path.join(shared, "fixtures/real-audio")
for name, grid in [("pyenf_new_record.wav", 60), ("pyenf_room_34s.wav", 60), ("pyenf_room_16s.wav", 60),
                   ("enfwhu_H0_01_no_enf_1kHz.wav", 50)]:
    p = os.path.join(real, name)
    rows.append((name, describe(*eenf_trace(p)), describe(*libhum_trace(p, grid))))
for hour, offset in [(0, 0), (2, 1800), (5, 1800)]:
    p, truth = whu_like(hour, offset)
    rows.append((f"WHU-like, 4 f0, hour {hour} from {offset} s (480 s)",
                 describe(*eenf_trace(p), truth), describe(*libhum_trace(p, 50), truth)))
p, truth = whu_like(0, 0, seconds=10)
rows.append(("the same hum cut to 10 s", describe(*eenf_trace(p), truth), describe(*libhum_trace(p, 50), truth)))

print("| recording | eenf (defaults) | libhum 1.1.5 (grid given) |")
print("|---|---|---|")
for r in rows:
    print("| " + " | ".join(r) + " |")
