"""The README's worked example (simulate → extract → compare → plot), as it is written there,
and the equality with the command line on the README's examples."""

import json

import numpy as np
import pytest

import eenf
from conftest import REPO


def readme_example():
    """The code block after `<!-- python-example -->` in the repository's README."""
    text = (REPO / "README.md").read_text()
    block = text.split("<!-- python-example -->", 1)[1]
    return block.split("```python", 1)[1].split("```", 1)[0]


def test_readme_worked_example(tmp_path, monkeypatch, capsys):
    pytest.importorskip("matplotlib").use("Agg")
    monkeypatch.chdir(tmp_path)
    scope = {}
    exec(compile(readme_example(), "README.md", "exec"), scope)
    printed = capsys.readouterr().out.strip()
    c, trace = scope["c"], scope["trace"]
    assert printed == f"CC {c.cc:.4f}, MAE {c.mae_hz * 1e3:.3f} mHz over {c.seconds} s"
    # the README quotes what it prints
    assert f"It prints `{printed}`" in (REPO / "README.md").read_text()
    assert len(trace) == 61 and trace.nominal_hz == 50.0
    assert c.cc >= 0.95 and c.mae_hz <= 0.002, c
    assert (tmp_path / "enf.png").stat().st_size > 1000


def cli_json(cli, *args):
    return json.loads(cli(*args))


def same(a, b):
    """Equal to the last bit, NaN where the other is NaN (JSON null)."""
    a = np.asarray([np.nan if v is None else v for v in a], dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a, b, equal_nan=True)


def test_extract_equals_the_command_line(cli, sim):
    for params, flags in [({}, []), ({"window": 8.0, "all_pixels": True}, ["--window", "8", "--all-pixels"]),
                          ({"sampling": "sum", "harmonics": 2}, ["--sampling", "sum", "--harmonics", "2"])]:
        want = cli_json(cli, "extract", sim.recording, "--json", *flags)
        got = eenf.extract(sim.recording, **params)
        assert same(want["enf_hz"], got.enf_hz), params
        assert same(want["time_s"], got.time_s)
        assert same(want["snr_db"], got.confidence)
        for h in want["harmonics"]:
            assert same(h["enf_hz"], got.harmonics[h["harmonic"]])
        assert want["selected"] == got.meta["selected"]


def test_compare_and_reference_equal_the_command_line(cli, sim, tmp_path):
    trace = eenf.extract(sim.recording)
    path = tmp_path / "dvSave-2022_08_17_16_10_00.enf.json"
    trace.to_json(path)
    # against the truth, and against the hourly mains WAVs (placed by the recording's name)
    for ref in [sim.truth_file, str(sim.references[0]).rsplit("/", 1)[0]]:
        want = cli_json(cli, "compare", path, ref, "--json")
        got = eenf.compare(path, ref)
        assert (got.cc, got.mae_hz, got.rmse_hz, got.max_err_hz, got.seconds) == (
            want["cc"], want["mae_hz"], want["rmse_hz"], want["max_err_hz"], want["seconds"])
    wav = sim.references[0]
    want = cli_json(cli, "reference", wav, "--json")
    got = eenf.reference(wav)
    assert same(want["enf_hz"], got.enf_hz)


def test_match_equals_the_command_line(cli, sim, tmp_path):
    refs = str(sim.references[0]).rsplit("/", 1)[0]
    trace = eenf.extract(sim.recording)
    path = tmp_path / "clip.enf.csv"
    trace.to_csv(path)
    want = cli_json(cli, "match", path, refs, "--json", "--top", "3", "--tz", "+08:00",
                    "--verify", "2022-08-17T16:10:00+08:00")
    got = eenf.match(path, refs, top=3, tz="+08:00", verify="2022-08-17T16:10:00+08:00")
    strip = lambda r: {k: v for k, v in r.items() if k != "seconds"}
    assert strip(got) == strip(want)
    assert got["candidates"][0]["start"] == want["candidates"][0]["start"]
    assert got["verify"]["rank"] == 1
    # a Trace at hand gives the same places as its file
    again = eenf.match(eenf.Trace.read(path), refs, top=3, tz="+08:00")
    assert [c["offset_steps"] for c in again["candidates"]] == [
        c["offset_steps"] for c in want["candidates"]]
    # local file names without their zone: the library's refusal names the keyword, not the flag
    with pytest.raises(ValueError, match="tz") as e:
        eenf.match(path, refs, top=3)
    assert "--" not in str(e.value)


def test_trace_files_round_trip(sim, tmp_path):
    t = eenf.extract(sim.recording)
    t.to_csv(tmp_path / "t.csv")
    t.to_json(tmp_path / "t.json")
    assert (tmp_path / "t.csv").read_text().startswith("time_s,enf_hz")
    for p in ["t.csv", "t.json"]:
        back = eenf.Trace.read(tmp_path / p)
        assert np.array_equal(back.enf_hz, t.enf_hz, equal_nan=True)
    assert eenf.Trace.read(tmp_path / "t.json").meta["sampling"] == t.meta["sampling"]
    with pytest.raises(ValueError):
        t.to_json(tmp_path / "t.csv")


def test_help_lists_the_parameters_with_their_defaults():
    doc = eenf.extract.__doc__
    for needle in ["step (default 1)", "window", "sampling (default auto)", "all_pixels", "max_gap"]:
        assert needle in doc, needle
    assert "channel (default mix)" in eenf.reference.__doc__
    assert "duration (default 60)" in eenf.simulate.__doc__
    assert "preset (default ev-enfd)" in eenf.simulate_dataset.__doc__
    # the help names keyword arguments, never the command line's flags
    for fn in [eenf.extract, eenf.reference, eenf.simulate, eenf.edits, eenf.match]:
        params = fn.__doc__.split("Keyword parameters", 1)[1]
        assert "--" not in params, fn.__name__


def test_video_equals_the_command_line(cli, tmp_path):
    sim = eenf.simulate(tmp_path / "v.aedat4", duration=20, video="lr", video_scale=0.25)
    assert len(sim.videos) == 1
    want = cli_json(cli, "video", sim.videos[0], "--json")
    got = eenf.video(sim.videos[0])
    assert same(want["enf_hz"], got.enf_hz)
    c = eenf.compare(got, sim.truth)
    assert c.seconds > 10


def test_real_recordings_equal_the_command_line(cli, shared):
    for name in ["jaer_MovingDarkBox.aedat", "fhaust_Tmpdiff128StereoPair-vertical-arm.aedat"]:
        path = shared / "fixtures" / "real-flicker" / name
        want = cli_json(cli, "extract", path, "--json")
        got = eenf.extract(path)
        assert same(want["enf_hz"], got.enf_hz), name
        assert got.meta.get("camera") == want.get("camera")


def test_simulate_dataset_equals_the_command_line(cli, tmp_path):
    """The dataset Python builds is the command's, file for file (the same seed, the same
    bytes), and a refused option leaves no folder behind."""
    args = dict(preset="small", duration=20, resolution="24x18", seed=7)
    got = eenf.simulate_dataset(tmp_path / "py", **args)
    cli("simulate-dataset", tmp_path / "cli", "--preset", "small", "--duration", "20",
        "--resolution", "24x18", "--seed", "7")
    assert got["recordings"] == 9 and got["events"] > 0 and got["references"]
    files = lambda root: sorted(p.relative_to(root) for p in root.rglob("*") if p.is_file())
    py_files, cli_files = files(tmp_path / "py"), files(tmp_path / "cli")
    assert py_files == cli_files and len(py_files) > 9 * 2
    for f in py_files:
        if f.suffix in (".aedat4", ".wav", ".csv"):
            assert (tmp_path / "py" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes(), f
    with pytest.raises(ValueError, match="preset"):
        eenf.simulate_dataset(tmp_path / "bad", preset="huge")
    assert not (tmp_path / "bad").exists()
