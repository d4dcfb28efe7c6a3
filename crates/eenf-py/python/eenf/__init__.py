"""eenf: the Electric Network Frequency (ENF) from event cameras, videos and sound.

A thin layer over the eenf Rust library (the same code as the ``eenf`` command), with numpy
arrays in and out:

- events: :func:`read_events`, :func:`iter_events`, :func:`info`, :func:`write_events`
- traces: :func:`extract` (E-ENF, from a file or from arrays), :func:`reference` (any sound,
  from a file or from samples), :func:`video` (V-ENF); each returns a :class:`Trace`
- evaluation: :func:`compare` (CC, MAE, RMSE against a reference), :func:`match` (when was
  it recorded), and :func:`simulate` (a recording of a flickering scene with its truth)

Keyword parameters have the command line's names and defaults (``window=16`` is
``--window 16``); ``help(eenf.extract)`` lists them. Errors are ``OSError`` (a file that
cannot be read or written) or ``ValueError`` (bad data or parameters); their messages name
keyword arguments (``window``), not the command line's flags. A recording read only in part (damage, a wild timestamp) gives an
:class:`EenfWarning` and the readable part. The work runs with the GIL released.
"""

from __future__ import annotations

import json
import math
import os
import warnings
from typing import Any, Dict, Iterator, List, NamedTuple, Optional, Tuple, Union

import numpy as np

from . import _eenf

__version__ = _eenf.VERSION

#: The events' structured dtype: ``t`` (int64 µs), ``x``, ``y`` (uint16), ``p`` (int8, 1 = ON),
#: packed into 13 bytes per event. Field names follow tonic's and Metavision's.
EVENT_DTYPE = np.dtype(
    {
        "names": ["t", "x", "y", "p"],
        "formats": ["<i8", "<u2", "<u2", "i1"],
        "offsets": [0, 8, 10, 12],
        "itemsize": _eenf.RECORD_BYTES,
    }
)

__all__ = [
    "EVENT_DTYPE",
    "EenfWarning",
    "Trace",
    "Comparison",
    "Simulation",
    "read_events",
    "iter_events",
    "info",
    "write_events",
    "extract",
    "reference",
    "video",
    "compare",
    "match",
    "simulate",
    "simulate_dataset",
    "edits",
    "refdb_build",
    "refdb_fetch",
    "refdb_update",
]

PathLike = Union[str, "os.PathLike[str]"]


class EenfWarning(UserWarning):
    """A recording read only in part (damage, a cut-short file, a wild timestamp)."""


def _is_path(x: Any) -> bool:
    return isinstance(x, (str, bytes, os.PathLike))


def _options(params: Dict[str, Any]) -> str:
    """Keyword arguments as the JSON object the library's option sets take: ``None`` leaves
    the default; a list becomes comma-separated text (``video=["lr", "hr"]``); a path its
    text; a non-finite float its name, for the range check to refuse by name."""
    out: Dict[str, Any] = {}
    for k, v in params.items():
        if v is None:
            continue
        if isinstance(v, (list, tuple)):
            v = ",".join(str(e) for e in v)
        elif isinstance(v, os.PathLike):
            v = os.fspath(v)
        elif isinstance(v, np.generic):
            v = v.item()
        if isinstance(v, float) and not math.isfinite(v):
            v = repr(v)
        out[k] = v
    return json.dumps(out)


def _warn(message: Optional[str]) -> None:
    if message:
        warnings.warn(message, EenfWarning, stacklevel=3)


# ---------------------------------------------------------------------------------------------
# events


def read_events(
    path: PathLike,
    *,
    start: Optional[float] = None,
    end: Optional[float] = None,
    **params: Any,
) -> np.ndarray:
    """Reads the events of an event file (any format eenf reads) into a structured array of
    :data:`EVENT_DTYPE` (fields ``t``, ``x``, ``y``, ``p``).

    ``start`` and ``end`` keep the events from ``start`` to before ``end`` seconds after the
    first event. Reading options (``camera``, ``chip``, ``strict``, ``max_gap``) are those of
    ``eenf info``; see below.
    """
    records, warning = _eenf.read_events(os.fspath(path), start, end, _options(params))
    _warn(warning)
    return records.view(EVENT_DTYPE)


def iter_events(path: PathLike, batch: int = 1_000_000, **params: Any) -> Iterator[np.ndarray]:
    """Streams the events of a file as structured arrays of at most ``batch`` events each, in
    memory that does not grow with the file. Reading options as for :func:`read_events`."""
    it = _eenf.EventIterator(os.fspath(path), int(batch), _options(params))
    while True:
        try:
            records, warning = it.next()
        except StopIteration:
            return
        _warn(warning)
        if len(records):
            yield records.view(EVENT_DTYPE)


def info(path: PathLike, **params: Any) -> Dict[str, Any]:
    """What an event file holds, as ``eenf info --json`` reports it: format, codec, size,
    streams, events, span, the sampling E-ENF would use, the flicker line per camera, damage."""
    return json.loads(_eenf.info(os.fspath(path), _options(params)))


def _field(events: Any, *names: str) -> Optional[np.ndarray]:
    for n in names:
        try:
            return np.asarray(events[n])
        except (KeyError, ValueError, IndexError, TypeError):
            continue
    return None


def _columns(events: Any) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``t, x, y, p`` columns of events given as a structured array (eenf, tonic, Metavision:
    ``t x y p``; dv-processing: ``timestamp x y polarity``), a mapping of such columns, a
    dv-processing ``EventStore`` (its ``.numpy()``), or a tuple ``(t, x, y, p)``; checked
    and converted to int64 µs, uint16 addresses and bool polarities."""
    if hasattr(events, "numpy") and not isinstance(events, np.ndarray):
        events = events.numpy()
    if isinstance(events, (tuple, list)):
        if len(events) != 4:
            raise ValueError("events as a tuple must be (t, x, y, p)")
        t, x, y, p = (np.asarray(c) for c in events)
    else:
        if isinstance(events, np.ndarray) and events.dtype.names is None:
            raise TypeError(
                "events must be a structured array with fields t, x, y, p (or timestamp, x, y, "
                f"polarity), a mapping of those columns or a tuple (t, x, y, p); got an array of {events.dtype}"
            )
        t = _field(events, "t", "timestamp", "ts")
        x = _field(events, "x")
        y = _field(events, "y")
        p = _field(events, "p", "polarity", "pol")
        missing = [n for n, c in zip("txyp", (t, x, y, p)) if c is None]
        if missing:
            raise TypeError(f"events: no field for {', '.join(missing)} (expected t, x, y, p)")
    cols = {"t": t, "x": x, "y": y, "p": p}
    for n, c in cols.items():
        if c.ndim != 1:
            raise ValueError(f"events: {n} must be one-dimensional, not of shape {c.shape}")
        if len(c) != len(t):
            raise ValueError(f"events: t has {len(t)} values but {n} has {len(c)}")
    if len(t) == 0:
        raise ValueError("events: the array is empty")
    for n in ("t", "x", "y"):
        if cols[n].dtype.kind not in "iu":
            raise TypeError(
                f"events: {n} must hold integers ({'microseconds' if n == 't' else 'pixels'}), not {cols[n].dtype}"
            )
    if p.dtype.kind not in "biu":
        raise TypeError(f"events: p must be bool or integer (ON > 0), not {p.dtype}")
    for n in ("x", "y"):
        c = cols[n]
        lo, hi = int(c.min()), int(c.max())
        if lo < 0 or hi > 65535:
            raise ValueError(f"events: {n} must lie in 0..65535, found {lo}..{hi}")
    if t.dtype == np.uint64 and int(t.max()) > np.iinfo(np.int64).max:
        raise ValueError("events: t exceeds the int64 range")
    return (
        np.ascontiguousarray(t, dtype=np.int64),
        np.ascontiguousarray(x, dtype=np.uint16),
        np.ascontiguousarray(y, dtype=np.uint16),
        np.ascontiguousarray(p > 0 if p.dtype.kind != "b" else p, dtype=np.bool_),
    )


def _size(x: np.ndarray, y: np.ndarray, width: Optional[int], height: Optional[int]):
    w = int(x.max()) + 1 if width is None else int(width)
    h = int(y.max()) + 1 if height is None else int(height)
    if not (0 < w <= 65535 and 0 < h <= 65535):
        raise ValueError(f"events: the sensor size {w} x {h} must be 1..65535 each way")
    return w, h


def write_events(
    path: PathLike,
    events: Any,
    *,
    width: Optional[int] = None,
    height: Optional[int] = None,
    **params: Any,
) -> int:
    """Writes events (as :func:`extract` takes them) to an event file, whole or not at all:
    AEDAT4, EVT 2.0, EVT 3.0, DAT or text, from ``format`` or the file's extension; AEDAT4
    packets compressed as ``compression`` says. The sensor size defaults to the largest
    address + 1. Returns the number of events written."""
    t, x, y, p = _columns(events)
    w, h = _size(x, y, width, height)
    return _eenf.write_events(os.fspath(path), t, x, y, p, w, h, _options(params))


# ---------------------------------------------------------------------------------------------
# traces


class Trace:
    """An ENF trace: one estimate every ``step_s`` seconds from the recording's start, with how
    it was made (``meta``). Made by :func:`extract`, :func:`reference`, :func:`video`, or read
    from a file with :meth:`Trace.read`."""

    __slots__ = ("_native", "_meta")

    def __init__(self, native: Any):
        self._native = native
        self._meta: Optional[Dict[str, Any]] = None

    @classmethod
    def read(cls, path: PathLike, index_step: Optional[float] = None) -> "Trace":
        """Reads a trace file: eenf JSON, a ``time_s,enf_hz`` CSV, or an ``index,value`` CSV
        with a value every ``index_step`` seconds."""
        return cls(_eenf.NativeTrace.read(os.fspath(path), index_step))

    @classmethod
    def from_values(cls, enf_hz: Any, step_s: float = 1.0) -> "Trace":
        """A trace of the values ``enf_hz`` (Hz), one every ``step_s`` seconds from 0."""
        v = np.ascontiguousarray(enf_hz, dtype=np.float64)
        if v.ndim != 1:
            raise ValueError("enf_hz must be one-dimensional")
        return cls(_eenf.NativeTrace.from_values(float(step_s), v))

    @property
    def time_s(self) -> np.ndarray:
        """Seconds from the recording's start of each estimate."""
        return self._native.time_s

    @property
    def enf_hz(self) -> np.ndarray:
        """The ENF, Hz (NaN where there is no estimate)."""
        return self._native.enf_hz

    @property
    def confidence(self) -> Optional[np.ndarray]:
        """Each estimate's line strength over its noise, dB (``None`` when not measured)."""
        v = self._native.snr_db
        return v if len(v) else None

    @property
    def harmonics(self) -> Dict[int, np.ndarray]:
        """Per-harmonic ENF estimates, Hz, by harmonic number m (E-ENF: the band at 2m·f0;
        audio: m·f0)."""
        return {m: enf for m, _, enf, _ in self._native.harmonic_parts()}

    @property
    def harmonic_confidence(self) -> Dict[int, np.ndarray]:
        """Per-harmonic line strengths, dB, by harmonic number."""
        return {m: snr for m, _, _, snr in self._native.harmonic_parts()}

    @property
    def meta(self) -> Dict[str, Any]:
        """How the trace was made: the JSON metadata of ``eenf extract --json`` without the
        value arrays (file, nominal_hz, step_s, selected harmonics, provenance)."""
        if self._meta is None:
            full = json.loads(self._native.to_json())
            for k in ("time_s", "enf_hz", "snr_db", "harmonics"):
                full.pop(k, None)
            self._meta = full
        return self._meta

    @property
    def step_s(self) -> float:
        """Seconds between estimates."""
        return float(self.meta.get("step_s") or 0.0)

    @property
    def nominal_hz(self) -> Optional[float]:
        """The grid, Hz, when known."""
        return self.meta.get("nominal_hz")

    @property
    def mean_hz(self) -> float:
        """The mean of the estimates, Hz."""
        return float(np.nanmean(self.enf_hz)) if len(self) else float("nan")

    def __len__(self) -> int:
        return len(self._native.enf_hz)

    def __repr__(self) -> str:
        return (
            f"Trace({len(self)} estimates every {self.step_s:g} s, mean {self.mean_hz:.4f} Hz, "
            f"file={self.meta.get('file')!r})"
        )

    def to_csv(self, path: Optional[PathLike] = None) -> Optional[str]:
        """The CSV form (``time_s,enf_hz`` first): written to ``path`` whole or not at all, or
        returned as text."""
        if path is None:
            return self._native.to_csv()
        p = os.fspath(path)
        if p.endswith(".json"):
            raise ValueError(f"{p}: a CSV trace file must not end in .json (use to_json)")
        self._native.save(p)
        return None

    def to_json(self, path: Optional[PathLike] = None) -> Optional[str]:
        """The JSON form of ``eenf extract --json``: written to ``path`` (which should end in
        ``.json``) whole or not at all, or returned as text."""
        if path is None:
            return self._native.to_json()
        p = os.fspath(path)
        if not p.endswith(".json"):
            raise ValueError(f"{p}: a JSON trace file must end in .json")
        self._native.save(p)
        return None

    def save_figure(self, path: PathLike, title: Optional[str] = None) -> None:
        """Draws the trace into ``path`` (``.png`` or ``.svg``, by its extension) as
        ``eenf extract --plot`` does: the ENF, each harmonic's estimates and the harmonic chosen
        in each segment, on axes that fit the ENF. The figure is written whole or not at all;
        ``title`` defaults to the traced file's name."""
        if title is None:
            f = self.meta.get("file")
            title = os.path.basename(f) if f else "ENF trace"
        _eenf.plot_trace(self._native, os.fspath(path), title)

    def plot(
        self, ax: Any = None, *, label: str = "ENF", harmonics: bool = True, **style: Any
    ) -> Any:
        """Plots the trace as ``label`` (and, with ``harmonics``, its per-harmonic estimates,
        faintly) on ``ax`` (a new figure's axes when ``None``); ``style`` goes to matplotlib's
        ``plot``. Returns the axes. Needs matplotlib (``pip install 'eenf[plot]'``)."""
        try:
            import matplotlib.pyplot as plt
        except ImportError as e:  # pragma: no cover - depends on the environment
            raise ImportError("Trace.plot needs matplotlib: pip install 'eenf[plot]'") from e
        if ax is None:
            fig, ax = plt.subplots(figsize=(8, 3), layout="constrained")
        if harmonics:
            for m, v in sorted(self.harmonics.items()):
                ax.plot(self.time_s[: len(v)], v, lw=0.6, alpha=0.35, label=f"harmonic {m}")
        ax.plot(self.time_s, self.enf_hz, lw=1.4, label=label, **style)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("frequency (Hz)")
        ax.legend(loc="best", fontsize="small")
        return ax


def _trace(native: Any) -> Trace:
    t = Trace(native)
    damage = t.meta.get("damage")
    if damage:
        _warn(damage)
    return t


def extract(
    source: Any,
    *,
    width: Optional[int] = None,
    height: Optional[int] = None,
    name: str = "<events>",
    **params: Any,
) -> Trace:
    """The E-ENF trace of an event recording: a file path, or events in memory (a structured
    array from :func:`read_events`, tonic, dv-processing or Metavision, a mapping of columns,
    or a tuple ``(t, x, y, p)``; the sensor is ``width`` × ``height``, by default the largest
    address + 1). Events in memory take the same path as a file's, so they give the same trace.
    """
    if _is_path(source):
        return _trace(_eenf.extract(os.fspath(source), _options(params)))
    t, x, y, p = _columns(source)
    w, h = _size(x, y, width, height)
    return _trace(_eenf.extract_events(t, x, y, p, w, h, name, _options(params)))


def _frames(source: Any, what: str) -> np.ndarray:
    """Samples in memory as float32 frames × channels (integers scaled to ±1)."""
    a = np.asarray(source)
    if a.ndim == 1:
        a = a[:, None]
    if a.ndim != 2 or a.size == 0:
        raise ValueError(f"{what}: samples must be (frames,) or (frames, channels), not {a.shape}")
    if a.dtype.kind in "iu":
        bits = a.dtype.itemsize * 8
        a = a.astype(np.float32) / np.float32(2 ** (bits - 1))
    elif a.dtype.kind != "f":
        raise TypeError(f"{what}: samples must be numbers, not {a.dtype}")
    return np.ascontiguousarray(a, dtype=np.float32)


def reference(
    source: Any, fs: Optional[float] = None, *, name: str = "<samples>", **params: Any
) -> Trace:
    """The ENF of a recording's sound: a file (a mains WAV, WAV/FLAC/MP3/M4A/OGG, a video's
    soundtrack through ffmpeg), or samples in memory at ``fs`` Hz (one-dimensional, or frames
    × channels; integer samples are scaled to ±1). NaN or infinite samples are refused."""
    if _is_path(source):
        if fs is not None:
            raise ValueError("fs is for samples in memory; a file gives its own rate")
        return _trace(_eenf.trace_sound(os.fspath(source), _options(params)))
    if fs is None:
        raise TypeError("reference: samples in memory need their rate: fs=...")
    frames = _frames(source, "reference")
    return _trace(
        _eenf.trace_samples(frames.reshape(-1), frames.shape[1], float(fs), name, _options(params))
    )


def edits(
    source: Any, fs: Optional[float] = None, *, name: str = "<samples>", **params: Any
) -> Dict[str, Any]:
    """Was a recording edited? Cuts and insertions from the mains hum's phase and frequency
    (``eenf edits``): a file (sound in any container ``reference`` reads, an event file, or an
    ENF trace for frequency steps alone), or sound samples in memory at ``fs`` Hz.

    Returns the report ``eenf edits --json`` prints, as a dict (``edits``: each break with
    ``time_s``, ``kind``, ``phase_jump_deg``, ``strength``, ``false_alarms_per_hour`` and
    ``p_value`` from the null model calibrated on real mains, ``reading``: what the break is
    consistent with, …; ``undecided``: stretches too weak to tell; ``tested_side_s``;
    ``verdict``), with
    ``series``: numpy arrays ``time_s``, ``phase_deg``, ``strength`` and ``enf_hz`` (the
    figure's data)."""
    if _is_path(source):
        if fs is not None:
            raise ValueError("fs is for samples in memory; a file gives its own rate")
        out = _eenf.edits(os.fspath(source), _options(params))
    else:
        if fs is None:
            raise TypeError("edits: samples in memory need their rate: fs=...")
        frames = _frames(source, "edits")
        out = _eenf.edits_samples(
            frames.reshape(-1), frames.shape[1], float(fs), name, _options(params)
        )
    report = json.loads(out[0])
    report["series"] = dict(zip(("time_s", "phase_deg", "strength", "enf_hz"), out[1:]))
    return report


def video(path: PathLike, **params: Any) -> Trace:
    """The V-ENF trace of a conventional video's rolling-shutter flicker (Y4M natively, other
    containers through ffmpeg)."""
    return _trace(_eenf.video(os.fspath(path), _options(params)))


class Comparison(NamedTuple):
    """How an estimate agrees with its reference over the seconds both hold."""

    cc: float
    mae_hz: float
    rmse_hz: float
    max_err_hz: float
    seconds: int
    time_s: np.ndarray
    estimate: np.ndarray
    reference: np.ndarray


def _as_trace(x: Any, index_step: Optional[float] = None) -> Tuple[Any, str]:
    if isinstance(x, Trace):
        return x._native, str(x.meta.get("file") or "<trace>")
    if _is_path(x):
        return _eenf.NativeTrace.read(os.fspath(x), index_step), os.fspath(x)
    raise TypeError(f"expected a Trace or a trace file's path, not {type(x).__name__}")


def compare(
    estimate: Any,
    reference: Any,
    *,
    offset_s: float = 0.0,
    index_step: float = 2.0,
    nominal: str = "auto",
    peak: Optional[str] = None,
) -> Comparison:
    """``eenf compare``: the agreement (CC, MAE, RMSE, max error) of an estimate (a
    :class:`Trace` or a trace file) with a reference (a :class:`Trace`, a trace file, a mains
    WAV, or a folder of hourly WAVs, where the recording's ``dvSave-…`` name places it).
    ``offset_s`` is added to the estimate's times; ``index_step`` is the spacing of an
    ``index,value`` CSV; ``nominal`` and ``peak`` are for a WAV reference."""
    est, name = _as_trace(estimate, index_step)
    ref = reference._native if isinstance(reference, Trace) else os.fspath(reference)
    r = json.loads(
        _eenf.compare(est, name, ref, float(offset_s), float(index_step), str(nominal), peak)
    )
    return Comparison(
        cc=r["cc"],
        mae_hz=r["mae_hz"],
        rmse_hz=r["rmse_hz"],
        max_err_hz=r["max_err_hz"],
        seconds=r["seconds"],
        time_s=np.asarray(r["time_s"], dtype=np.float64),
        estimate=np.asarray([np.nan if v is None else v for v in r["estimate"]], dtype=np.float64),
        reference=np.asarray([np.nan if v is None else v for v in r["reference"]], dtype=np.float64),
    )


def match(trace: Any, reference: PathLike, top: int = 5, **params: Any) -> Dict[str, Any]:
    """``eenf match``: where a trace (a :class:`Trace` or a trace file) fits in a long
    reference (a store from ``eenf refdb build``, a folder of hourly WAVs, a WAV, a trace),
    as ``eenf match --json`` reports it: the ``candidates``, best first (start, offset, CC,
    MAE, p-value), and with ``verify=TIME`` how the claimed time fits."""
    native, name = _as_trace(trace)
    return json.loads(
        _eenf.locate(native, name, os.fspath(reference), _options({"top": top, **params}))
    )


def refdb_build(store: PathLike, *inputs: PathLike, **params: Any) -> Dict[str, Any]:
    """``eenf refdb build``: adds grid archives (operators' and measurement sites' frequency
    CSVs, plain or in zip, 7z or gzip files), hourly mains WAVs or trace files to the store
    ``store`` (created when missing). Local times need ``tz`` (``"Europe/Berlin"``,
    ``"+08:00"``, ``"Z"``): none is assumed. Returns the ``grids`` changed (name, values) and,
    for each archive, its ``summary`` and ``report`` (layout, zone, rows read and dropped)."""
    return json.loads(
        _eenf.refdb_build(os.fspath(store), [os.fspath(i) for i in inputs], _options(params))
    )


def refdb_fetch(
    source: str,
    store: PathLike,
    start: str,
    end: Optional[str] = None,
    *,
    endpoint: Optional[str] = None,
    grid: Optional[str] = None,
    cache: Optional[PathLike] = None,
    retries: int = 3,
    wait: bool = True,
    api_key: Optional[str] = None,
) -> Dict[str, Any]:
    """``eenf refdb fetch``: fetches ``start`` to ``end`` (a day such as ``"2023-01-01"``, or a
    time with its zone; ``end`` defaults to now) of a grid operator's frequency data into the
    store ``store``: ``"gb"`` (National Grid ESO / NESO monthly files), ``"se"`` (Svenska
    kraftnät's control room), ``"ch"`` (Swissgrid, its last minutes only), ``"osf"`` (an OSF
    database file at ``endpoint``) or ``"fi"`` (Fingrid's open data API: ``api_key``, else the
    environment variable ``FINGRID_API_KEY``). ``endpoint`` asks a mirror instead of the operator.
    Downloads are kept in ``cache`` (default ``~/.cache/eenf/fetch``) and resumed when cut;
    the store changes only when all are in, with each file's address, time of retrieval and
    SHA-256 in its manifest. Returns the ``files`` (``url``, ``path``, ``cached``), the
    ``grids`` changed and the ``notes``."""
    return json.loads(
        _eenf.refdb_fetch(
            source,
            os.fspath(store),
            start,
            end,
            endpoint,
            grid,
            None if cache is None else os.fspath(cache),
            retries,
            wait,
            api_key,
        )
    )


def refdb_update(
    store: PathLike,
    *,
    cache: Optional[PathLike] = None,
    retries: int = 3,
    wait: bool = True,
    api_key: Optional[str] = None,
) -> List[Dict[str, Any]]:
    """``eenf refdb update``: brings every fetched grid of ``store`` up to now, asking each
    source its manifest records for what lies after the grid's last value. Returns what each
    source gave, as :func:`refdb_fetch` does."""
    return json.loads(
        _eenf.refdb_update(
            os.fspath(store), None if cache is None else os.fspath(cache), retries, wait, api_key
        )
    )


class Simulation(NamedTuple):
    """What :func:`simulate` wrote."""

    recording: str
    truth: Trace
    truth_file: str
    events: int
    width: int
    height: int
    videos: List[str]
    references: List[str]


def simulate(output: Optional[PathLike] = None, **params: Any) -> Simulation:
    """``eenf simulate``: writes an event recording of a flickering scene to ``output``
    (default ``simulated.aedat4``) and its ground-truth ENF beside it; returns the paths and
    the truth as a :class:`Trace`."""
    if output is not None:
        params = {"output": os.fspath(output), **params}
    r = json.loads(_eenf.simulate(_options(params)))
    return Simulation(
        recording=r["recording"],
        truth=Trace.read(r["truth"]),
        truth_file=r["truth"],
        events=r["events"],
        width=r["width"],
        height=r["height"],
        videos=r["videos"],
        references=r["references"],
    )


def simulate_dataset(out_dir: PathLike, **params: Any) -> Dict[str, Any]:
    """``eenf simulate-dataset``: builds a simulated dataset laid out like EV-ENFD in
    ``out_dir`` (``static/``, ``dynamic/``, ``extreme/`` recordings with their truth,
    ``ENF_Reference/`` hourly WAVs, ``manifest.csv``, ``dataset.json``); a folder made here is
    removed again if the build fails. Returns the ``manifest`` path, the number of
    ``recordings`` and ``events``, the ``references`` written and any ``notes``."""
    return json.loads(_eenf.simulate_dataset(os.fspath(out_dir), _options(params)))


# ---------------------------------------------------------------------------------------------
# docstrings: every keyword parameter with the command line's default and help


def _document(fn: Any, *sets: str) -> None:
    lines = ["", "Keyword parameters (the command line's flags, with their defaults):", ""]
    for s in sets:
        for o in json.loads(_eenf.options(s)):
            head = o["name"]
            if o["switch"]:
                head += " (True or False, default False)"
            else:
                if o["default"] is not None:
                    head += f" (default {o['default']})"
                if o["choices"]:
                    head += f"; one of {', '.join(o['choices'])}"
            body = " ".join(o["help"].split())
            lines.append(f"    {head}")
            lines.append(f"        {body}")
    fn.__doc__ = (fn.__doc__ or "") + "\n".join(lines) + "\n"


_document(read_events, "input")
_document(iter_events, "input")
_document(info, "input")
_document(extract, "extract")
_document(reference, "reference")
_document(video, "video")
_document(match, "match")
_document(simulate, "simulate")
_document(simulate_dataset, "simulate_dataset")
_document(refdb_build, "refdb_build")
_document(write_events, "write")
_document(edits, "edits")
