"""`eenf.edits`: the report `eenf edits --json` prints, from samples in memory and from a file,
with the figure's series as numpy arrays."""

import wave

import numpy as np
import pytest

import eenf


def hum(seconds, cut=None, fs=8000, seed=3):
    """Hum at f0, 2f0, 3f0 of a grid that swings slowly, in white noise; `cut` = (at, length)
    removes that stretch, the hum's phase running on through it."""
    rng = np.random.default_rng(seed)
    total = seconds + (cut[1] if cut else 0)
    t = np.arange(int(total * fs)) / fs
    f = 50 + 0.02 * np.sin(2 * np.pi * t / 97)
    phi = 2 * np.pi * np.cumsum(f) / fs
    x = 0.01 * np.cos(phi) + 0.004 * np.cos(2 * phi + 0.4) + 0.003 * np.cos(3 * phi + 1.3)
    x = x + rng.normal(0, 0.05, x.size)
    if cut:
        a, b = int(cut[0] * fs), int((cut[0] + cut[1]) * fs)
        x = np.concatenate([x[:a], x[b:]])
    return np.round(np.clip(x, -1, 1) * 32767).astype(np.int16)


def test_a_cut_in_samples_is_found_and_the_whole_clip_is_clean(tmp_path):
    r = eenf.edits(hum(150, cut=(70.3, 0.737)), fs=8000)
    assert [round(e["time_s"]) for e in r["edits"]] == [70]
    e = r["edits"][0]
    assert e["kind"].startswith("phase_jump") and abs(e["time_s"] - 70.3) <= 0.5
    assert r["grid_hz"] == 50.0 and r["lines_hz"] == [50.0, 100.0, 150.0]
    s = r["series"]
    assert s["time_s"].dtype == np.float64 and len(s["time_s"]) == len(s["enf_hz"]) == len(s["strength"])
    assert np.nanmax(s["strength"]) >= 1.0
    # the same from a file, and a whole clip is not flagged
    path = tmp_path / "whole.wav"
    with wave.open(str(path), "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(8000)
        w.writeframes(hum(150).tobytes())
    r = eenf.edits(path)
    assert r["edits"] == [] and r["verdict"].startswith("no edit found")


def test_bad_calls_are_errors_in_python_words():
    with pytest.raises(TypeError):
        eenf.edits(np.zeros(100))
    with pytest.raises(ValueError, match="side"):
        eenf.edits(hum(30), fs=8000, side=0.1)
    with pytest.raises(ValueError):
        eenf.edits(np.random.default_rng(1).normal(0, 0.05, 8000 * 60), fs=8000)
