"""Bad input raises a Python exception with the command line's message, and never brings the
interpreter down."""

import numpy as np
import pytest

import eenf


def test_a_missing_file_is_an_os_error(tmp_path):
    missing = tmp_path / "nope.aedat4"
    for call in [eenf.read_events, eenf.info, eenf.extract, eenf.reference, eenf.Trace.read]:
        with pytest.raises(OSError, match="nope"):
            call(missing)
    with pytest.raises(FileNotFoundError):
        list(eenf.iter_events(missing))


def test_an_unknown_or_empty_file_is_a_value_error(tmp_path):
    (tmp_path / "empty.aedat4").write_bytes(b"")
    (tmp_path / "junk.bin").write_bytes(b"\x00\x01garbage" * 100)
    for name in ["empty.aedat4", "junk.bin"]:
        with pytest.raises(ValueError, match=name):
            eenf.read_events(tmp_path / name)


def test_a_truncated_file_warns_and_gives_what_is_readable(sim, tmp_path):
    data = open(sim.recording, "rb").read()
    cut = tmp_path / "cut.aedat4"
    cut.write_bytes(data[: len(data) * 6 // 10])
    whole = eenf.read_events(sim.recording)
    with pytest.warns(eenf.EenfWarning, match="truncated"):
        part = eenf.read_events(cut)
    assert 0 < len(part) < len(whole) and np.array_equal(part, whole[: len(part)])
    with pytest.raises(ValueError, match="truncated"):
        eenf.read_events(cut, strict=True)
    with pytest.warns(eenf.EenfWarning):
        assert len(np.concatenate(list(eenf.iter_events(cut)))) == len(part)
    # cut inside the header: nothing to read
    head = tmp_path / "head.aedat4"
    head.write_bytes(data[:20])
    with pytest.raises(ValueError, match="head.aedat4"):
        eenf.read_events(head)


def events(n=1000):
    t = np.arange(n, dtype=np.int64) * 10
    return t, (np.arange(n) % 32).astype(np.uint16), (np.arange(n) % 24).astype(np.uint16), np.ones(n, bool)


def test_bad_event_arrays():
    t, x, y, p = events()
    with pytest.raises(TypeError, match="t must hold integers"):
        eenf.extract((t.astype(float), x, y, p))
    with pytest.raises(TypeError, match="structured array"):
        eenf.extract(np.zeros((10, 4)))
    with pytest.raises(TypeError, match="no field"):
        eenf.extract(np.zeros(10, dtype=[("a", "i8"), ("x", "u2")]))
    with pytest.raises(ValueError, match="empty"):
        eenf.extract((t[:0], x[:0], y[:0], p[:0]))
    with pytest.raises(ValueError, match="t has 1000 values but x has 999"):
        eenf.extract((t, x[:-1], y, p))
    with pytest.raises(ValueError, match="0..65535"):
        eenf.extract((t, x.astype(np.int32) - 1, y, p))
    unsorted = t.copy()
    unsorted[500] = 3
    with pytest.raises(ValueError, match="must not decrease"):
        eenf.extract((unsorted, x, y, p))
    with pytest.raises(ValueError, match="outside"):
        eenf.extract((t, x, y, p), width=8)
    with pytest.raises(ValueError, match="must not decrease"):
        eenf.write_events("never-written.aedat4", (unsorted, x, y, p))


def test_bad_samples_and_parameters(sim, tmp_path):
    x = np.sin(np.arange(20000) * 0.3)
    x[1234] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        eenf.reference(x, fs=1000)
    with pytest.raises(TypeError, match="fs"):
        eenf.reference(x)
    with pytest.raises(ValueError, match="unexpected keyword argument 'windoww'") as e:
        eenf.extract(sim.recording, windoww=8)
    assert "--" not in str(e.value)
    with pytest.raises(ValueError, match=r"'window'.*outside 0.01..=3600") as e:
        eenf.extract(sim.recording, window=-1.0)
    assert "--" not in str(e.value) and "<WINDOW>" not in str(e.value)
    with pytest.raises(ValueError, match="invalid value 'nope'"):
        eenf.extract(sim.recording, sampling="nope")
    with pytest.raises(ValueError, match="camera 3"):
        eenf.read_events(sim.recording, camera=3)
    with pytest.raises(ValueError):
        eenf.write_events(tmp_path / "a.unknown", events())
    assert not (tmp_path / "a.unknown").exists()


def test_absurd_numbers_raise_value_errors(sim, tmp_path):
    """Numbers that once killed the interpreter or never returned (fs=1e12, fs=1e300) or
    raised PanicException (top=2**64-1) are ValueErrors naming the range."""
    hum = np.sin(2 * np.pi * 50 * np.arange(4000) / 400.0)
    for fs in [1e12, 1e300, 0.0, -5.0, float("nan"), float("inf")]:
        with pytest.raises(ValueError, match="sample rate"):
            eenf.reference(hum, fs=fs)
    trace = tmp_path / "t.csv"
    trace.write_text("time_s,enf_hz\n" + "".join(f"{i},{50 + 0.001 * (i % 5)}\n" for i in range(60)))
    for top in [2**64 - 1, 10**9, 0]:
        with pytest.raises(ValueError, match="top"):
            eenf.match(trace, trace, top=top)
    with pytest.raises(ValueError, match="median"):
        eenf.extract(sim.recording, median_len=10**9)
    bad = tmp_path / "ns.csv"
    bad.write_text("time_s,enf_hz\n" + "".join(f"{i}e-9,50.0\n" for i in range(60)))
    with pytest.raises(ValueError, match="s apart"):
        eenf.Trace.read(bad)


def test_options_are_checked_by_the_library_and_named_as_keywords(sim, tmp_path):
    """Keyword arguments fill the library's option sets (no command-line parser in the
    wheel): each kind of refusal is a ValueError naming the keyword, never a flag."""
    cases = [
        (lambda: eenf.extract(sim.recording, harmonics="many"), r"'harmonics': not a whole number"),
        (lambda: eenf.extract(sim.recording, window="wide"), r"'window': not a number"),
        (lambda: eenf.extract(sim.recording, window=float("nan")), r"'window': NaN is outside"),
        (lambda: eenf.extract(sim.recording, strict="yes"), r"'strict': expected true or false"),
        (lambda: eenf.video(sim.recording, readout_ms=10.0, idle="auto"), r"readout_ms cannot be used with idle"),
        (lambda: eenf.video(sim.recording, idle="some"), r"'idle': expected auto"),
        (lambda: eenf.simulate(output=tmp_path / "s.aedat4", resolution="big"), r"resolution \"big\": expected WxH"),
        (lambda: eenf.simulate(output=tmp_path / "s.aedat4", scene="static", spot_gain=2.0), r"spot_gain needs a scene"),
        (lambda: eenf.edits(sim.recording, side=0.5), r"'side': 0.5 is outside 1..=600"),
        (lambda: eenf.write_events(tmp_path / "x.unknown", events()), r"pass format aedat4"),
    ]
    for call, message in cases:
        with pytest.raises(ValueError, match=message) as e:
            call()
        assert "--" not in str(e.value), str(e.value)
    assert not list(tmp_path.iterdir())


def test_library_messages_name_keywords(sim, tmp_path):
    """Advice in the library's messages names the keyword argument, as the command line's
    names its flag: `strict=True`, `tz=...`."""
    data = open(sim.recording, "rb").read()
    cut = tmp_path / "cut.aedat4"
    cut.write_bytes(data[: len(data) * 6 // 10])
    with pytest.warns(eenf.EenfWarning, match=r"strict=True refuses the file"):
        eenf.read_events(cut)
    local = tmp_path / "local.csv"
    local.write_text("time,frequency\n" + "".join(f"2022-08-17 16:00:{s:02d},50.01\n" for s in range(60)))
    with pytest.raises(ValueError, match=r"give it with tz \(") as e:
        eenf.refdb_build(tmp_path / "store", local)
    assert "--" not in str(e.value)


def test_os_errors_keep_their_kind(sim, tmp_path):
    """A file that cannot be written is the OSError subclass of its cause."""
    t = eenf.Trace.from_values(np.full(60, 50.0))
    (tmp_path / "file").write_text("x")
    with pytest.raises(NotADirectoryError):
        t.to_csv(tmp_path / "file" / "t.csv")
    with pytest.raises(IsADirectoryError):
        t.to_csv(tmp_path)
