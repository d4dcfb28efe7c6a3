"""Files written by eenf, read back by other tools: dv-processing (AEDAT4), expelliarmus (EVT 2.0,
DAT) and evlib (EVT 3.0). Usage: peers.py TRUTH_CSV DIR (DIR holds eenf's conversions of TRUTH)."""
import sys

import numpy as np


def canonical(a):
    """Rows (t, x, y, p) sorted, for formats that may reorder events sharing a timestamp."""
    return a[np.lexsort((a[:, 3], a[:, 2], a[:, 1], a[:, 0]))]


def check(name, got, truth, reorders=False):
    if reorders:
        got, truth = canonical(got), canonical(truth)
    if got.shape != truth.shape or not np.array_equal(got, truth):
        n = min(len(got), len(truth))
        bad = np.nonzero(np.any(got[:n] != truth[:n], axis=1))[0]
        print(f"peer check {name}: FAILED ({len(got)} events vs {len(truth)}; first difference at {bad[:1]})")
        return False
    print(f"peer check {name}: ok ({len(got)} events identical)")
    return True


def main():
    truth_csv, d = sys.argv[1], sys.argv[2]
    truth = np.loadtxt(truth_csv, delimiter=",", skiprows=1, dtype=np.int64)
    ok = True

    import dv_processing as dv

    for f in ["out_lz4.aedat4", "out_zstd.aedat4", "out_none.aedat4"]:
        rec = dv.io.MonoCameraRecording(f"{d}/{f}")
        parts = []
        while rec.isRunning():
            b = rec.getNextEventBatch()
            if b is not None and b.size() > 0:
                n = b.numpy()
                parts.append(np.stack([n["timestamp"], n["x"], n["y"], n["polarity"]], 1).astype(np.int64))
        ok &= check(f"dv-processing {f}", np.concatenate(parts), truth)

    import expelliarmus

    for enc, f in [("evt2", "out_evt2.raw"), ("dat", "out.dat")]:
        a = expelliarmus.Wizard(encoding=enc, fpath=f"{d}/{f}").read()
        got = np.stack([a["t"], a["x"], a["y"], a["p"]], 1).astype(np.int64)
        ok &= check(f"expelliarmus {f}", got, truth)

    import evlib

    df = evlib.load_events(f"{d}/out_evt3.raw")
    df = df.collect() if hasattr(df, "collect") else df
    t = df["t"].dt.total_microseconds().to_numpy()
    p = (df["polarity"].to_numpy() > 0).astype(np.int64)
    got = np.stack([t, df["x"].to_numpy(), df["y"].to_numpy(), p], 1).astype(np.int64)
    ok &= check("evlib out_evt3.raw", got, truth, reorders=True)
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
