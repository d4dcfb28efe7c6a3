"""Type stubs of eenf: every keyword parameter, with the command line's defaults."""

import os
from typing import Any, Dict, Iterator, List, Literal, NamedTuple, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
EVENT_DTYPE: np.dtype[np.void]

PathLike = Union[str, os.PathLike[str]]
#: Events in memory: a structured array (t x y p, or timestamp x y polarity), a mapping of
#: those columns, a dv-processing EventStore, or a tuple (t, x, y, p).
Events = Union[np.ndarray, Dict[str, npt.ArrayLike], Tuple[npt.ArrayLike, npt.ArrayLike, npt.ArrayLike, npt.ArrayLike], Any]
Nominal = Union[Literal["auto", "50", "60"], int]
Peak = Literal["exact", "paper"]
Sampling = Literal["paper", "authors", "block", "sum", "auto"]
Selection = Literal["smoothest", "consensus", "journal"]
Format = Literal["aedat4", "evt2", "evt3", "dat", "text"]
Compression = Literal["none", "lz4", "lz4_high", "zstd", "zstd_high"]

class EenfWarning(UserWarning): ...

class Trace:
    @classmethod
    def read(cls, path: PathLike, index_step: Optional[float] = None) -> Trace: ...
    @classmethod
    def from_values(cls, enf_hz: npt.ArrayLike, step_s: float = 1.0) -> Trace: ...
    @property
    def time_s(self) -> npt.NDArray[np.float64]: ...
    @property
    def enf_hz(self) -> npt.NDArray[np.float64]: ...
    @property
    def confidence(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def harmonics(self) -> Dict[int, npt.NDArray[np.float64]]: ...
    @property
    def harmonic_confidence(self) -> Dict[int, npt.NDArray[np.float64]]: ...
    @property
    def meta(self) -> Dict[str, Any]: ...
    @property
    def step_s(self) -> float: ...
    @property
    def nominal_hz(self) -> Optional[float]: ...
    @property
    def mean_hz(self) -> float: ...
    def __len__(self) -> int: ...
    def to_csv(self, path: Optional[PathLike] = None) -> Optional[str]: ...
    def to_json(self, path: Optional[PathLike] = None) -> Optional[str]: ...
    def save_figure(self, path: PathLike, title: Optional[str] = None) -> None: ...
    def plot(self, ax: Any = None, *, label: str = "ENF", harmonics: bool = True, **style: Any) -> Any: ...

class Comparison(NamedTuple):
    cc: float
    mae_hz: float
    rmse_hz: float
    max_err_hz: float
    seconds: int
    time_s: npt.NDArray[np.float64]
    estimate: npt.NDArray[np.float64]
    reference: npt.NDArray[np.float64]

class Simulation(NamedTuple):
    recording: str
    truth: Trace
    truth_file: str
    events: int
    width: int
    height: int
    videos: List[str]
    references: List[str]

def read_events(
    path: PathLike,
    *,
    start: Optional[float] = None,
    end: Optional[float] = None,
    chip: Optional[str] = None,
    camera: Optional[int] = None,
    strict: bool = False,
    max_gap: float = 5.0,
    topic: Optional[str] = None,
) -> np.ndarray: ...
def iter_events(
    path: PathLike,
    batch: int = 1_000_000,
    *,
    chip: Optional[str] = None,
    camera: Optional[int] = None,
    strict: bool = False,
    max_gap: float = 5.0,
    topic: Optional[str] = None,
) -> Iterator[np.ndarray]: ...
def info(
    path: PathLike,
    *,
    chip: Optional[str] = None,
    camera: Optional[int] = None,
    strict: bool = False,
    max_gap: float = 5.0,
    topic: Optional[str] = None,
) -> Dict[str, Any]: ...
def write_events(
    path: PathLike,
    events: Events,
    *,
    width: Optional[int] = None,
    height: Optional[int] = None,
    format: Optional[Format] = None,
    compression: Compression = "lz4",
) -> int: ...
def extract(
    source: Union[PathLike, Events],
    *,
    width: Optional[int] = None,
    height: Optional[int] = None,
    name: str = "<events>",
    nominal: Nominal = "auto",
    peak: Peak = "exact",
    window: Optional[float] = None,
    step: float = 1.0,
    half_band: float = 2.0,
    sampling: Sampling = "auto",
    dt_us: Optional[int] = None,
    harmonics: int = 4,
    filter_order: int = 4,
    median_len: int = 21,
    median_threshold: float = 0.02,
    segment: int = 10,
    selection: Selection = "consensus",
    jump_hz: float = 0.005,
    agree_hz: float = 0.005,
    all_pixels: bool = False,
    chip: Optional[str] = None,
    camera: Optional[int] = None,
    strict: bool = False,
    max_gap: float = 5.0,
    topic: Optional[str] = None,
) -> Trace: ...
def reference(
    source: Union[PathLike, npt.ArrayLike],
    fs: Optional[float] = None,
    *,
    name: str = "<samples>",
    channel: Union[Literal["mix"], int] = "mix",
    harmonics: Union[Literal["auto"], int] = "auto",
    nominal: Nominal = "auto",
    peak: Peak = "exact",
    window: Optional[float] = None,
    step: float = 1.0,
    half_band: float = 2.0,
) -> Trace: ...
def edits(
    source: Union[PathLike, npt.ArrayLike],
    fs: Optional[float] = None,
    *,
    name: str = "<samples>",
    nominal: Nominal = "auto",
    side: float = 10.0,
    min_gap: float = 1.0,
    false_alarms: float = 0.05,
    weak_jump: float = 90.0,
    step_z: float = 10.0,
    channel: Union[Literal["mix"], int] = "mix",
    index_step: Optional[float] = None,
    kind: Literal["auto", "audio", "events", "trace"] = "auto",
    chip: Optional[str] = None,
    camera: Optional[int] = None,
    strict: bool = False,
    max_gap: float = 5.0,
    topic: Optional[str] = None,
) -> Dict[str, Any]: ...
def video(
    path: PathLike,
    *,
    nominal: Nominal = "auto",
    readout_ms: Optional[float] = None,
    idle: Optional[Literal["auto"]] = None,
    virtual_rows: Optional[float] = None,
    sampling: Literal["auto", "zero-pad", "naive", "global"] = "auto",
    scene_removal: Literal["paper", "row-mean", "none"] = "paper",
    peak: Peak = "exact",
    window: float = 16.0,
) -> Trace: ...
def compare(
    estimate: Union[Trace, PathLike],
    reference: Union[Trace, PathLike],
    *,
    offset_s: float = 0.0,
    index_step: float = 2.0,
    nominal: str = "auto",
    peak: Optional[Peak] = None,
) -> Comparison: ...
def match(
    trace: Union[Trace, PathLike],
    reference: PathLike,
    top: int = 5,
    *,
    verify: Optional[str] = None,
    score: Literal["combined", "cc"] = "combined",
    alpha: float = 0.001,
    tz: Optional[str] = None,
) -> Dict[str, Any]: ...
def refdb_build(
    store: PathLike,
    *inputs: PathLike,
    grid: Optional[str] = None,
    tz: Optional[str] = None,
    format: Literal["auto", "ngeso", "fingrid", "transnetbw", "osf"] = "auto",
    value_unit: Literal["auto", "hz", "mhz-deviation", "hz-deviation"] = "auto",
    date_order: Literal["auto", "dmy", "mdy"] = "auto",
    nominal: Nominal = "auto",
    start: Optional[str] = None,
    no_wait: bool = False,
    index_step: Optional[float] = None,
) -> Dict[str, Any]: ...
def refdb_fetch(
    source: Literal["gb", "se", "ch", "osf", "fi"],
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
) -> Dict[str, Any]: ...
def refdb_update(
    store: PathLike,
    *,
    cache: Optional[PathLike] = None,
    retries: int = 3,
    wait: bool = True,
    api_key: Optional[str] = None,
) -> List[Dict[str, Any]]: ...
def simulate(
    output: Optional[PathLike] = None,
    *,
    scene: str = "static",
    lamp: str = "led",
    duration: float = 60.0,
    enf: str = "synthetic",
    index_step: float = 2.0,
    grid: int = 50,
    resolution: str = "64x48",
    seed: int = 1,
    readout: Literal["dvxplorer", "prophesee", "dvs128"] = "dvxplorer",
    illumination: Optional[float] = None,
    ambient: Optional[float] = None,
    spot_gain: Optional[float] = None,
    noise_hz: Optional[float] = None,
    start: str = "2022-08-17T16:10:00+08:00",
    reference_dir: Optional[PathLike] = None,
    format: Optional[Format] = None,
    compression: Compression = "lz4",
    video: Optional[str] = None,
    video_scale: float = 1.0,
    mp4: bool = False,
) -> Simulation: ...
def simulate_dataset(
    out_dir: PathLike,
    *,
    preset: Literal["ev-enfd", "small", "lamp-spot"] = "ev-enfd",
    enf_dir: Optional[PathLike] = None,
    grid: int = 50,
    start: str = "2022-08-17T16",
    tz: str = "+08:00",
    resolution: Optional[str] = None,
    duration: Optional[float] = None,
    readout: Literal["dvxplorer", "prophesee", "dvs128"] = "dvxplorer",
    compression: Compression = "lz4",
    seed: int = 2023,
    video: Optional[str] = None,
    video_scale: float = 1.0,
    mp4: bool = False,
) -> Dict[str, Any]: ...
