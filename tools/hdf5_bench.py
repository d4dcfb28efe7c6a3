"""DSEC-layout HDF5 decode speed: eenf beside h5py + hdf5plugin (the peer every DSEC user
has), on the same file.

    python tools/hdf5_bench.py write [MILLION_EVENTS]   # target/tmp/dsec-bench.h5 (default 100)
    python tools/hdf5_bench.py peer                     # h5py reads x, y, p, t into numpy
    cargo bench -p eenf-bench --bench containers -- dsec   # eenf's EventReader on the same file

The file is laid out as DSEC's `events_left/events.h5`: `events/{x u16, y u16, p u8, t u32}`,
`ms_to_idx`, `t_offset`, every dataset compressed with blosc + zstd (hdf5plugin's Blosc,
shuffle) in h5py's automatic chunks. Events are random pixels at 2 M events/s.

Needs: pip install h5py hdf5plugin numpy (best in a venv)."""
import os
import sys
import time

here = os.path.dirname(os.path.abspath(__file__))
path = os.path.join(here, "..", "target", "tmp", "dsec-bench.h5")


def write(million):
    import h5py
    import hdf5plugin
    import numpy as np

    n = int(million * 1_000_000)
    rng = np.random.default_rng(7)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    blosc = hdf5plugin.Blosc(cname="zstd", clevel=5, shuffle=hdf5plugin.Blosc.SHUFFLE)
    t = (np.arange(n, dtype=np.uint64) // 2).astype(np.uint32)  # 2 events a µs
    with h5py.File(path + ".part", "w") as f:
        g = f.create_group("events")
        g.create_dataset("x", data=rng.integers(0, 640, n, dtype=np.uint16), chunks=True, **blosc)
        g.create_dataset("y", data=rng.integers(0, 480, n, dtype=np.uint16), chunks=True, **blosc)
        g.create_dataset("p", data=rng.integers(0, 2, n, dtype=np.uint8), chunks=True, **blosc)
        g.create_dataset("t", data=t, chunks=True, **blosc)
        ms = np.searchsorted(t, np.arange(0, int(t[-1]) // 1000 + 1) * 1000).astype(np.uint64)
        f.create_dataset("ms_to_idx", data=ms, chunks=True, **blosc)
        f.create_dataset("t_offset", data=np.int64(1_600_000_000_000_000))
    os.replace(path + ".part", path)
    print(f"wrote {n} events to {path} ({os.path.getsize(path) / 1e6:.1f} MB)")


def peer():
    import h5py
    import hdf5plugin  # noqa: F401  (registers the blosc filter)

    best = None
    for _ in range(3):
        t0 = time.perf_counter()
        with h5py.File(path, "r") as f:
            e = f["events"]
            x, y, p, t = e["x"][:], e["y"][:], e["p"][:], e["t"][:]
            n = len(t)
        dt = time.perf_counter() - t0
        best = dt if best is None else min(best, dt)
        del x, y, p, t
    print(f"h5py + hdf5plugin: {n} events in {best:.3f} s = {n / best / 1e6:.1f} M events/s")


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "peer"
    if what == "write":
        write(float(sys.argv[2]) if len(sys.argv) > 2 else 100)
    else:
        peer()
