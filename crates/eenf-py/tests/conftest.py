"""Shared fixtures: a simulated recording with its truth (no data needed), the eenf command to
compare against, and the shared data and peers when CI provides them.

CI (.ci/run) sets EENF_PY_REQUIRE=1: then a missing command, missing peers or missing shared
data fail the tests instead of skipping them."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

import eenf

REPO = Path(__file__).resolve().parents[3]
REQUIRED = os.environ.get("EENF_PY_REQUIRE") == "1"


def need(what: str):
    """Skips a test for lack of `what`, or fails it when CI requires everything."""
    if REQUIRED:
        pytest.fail(f"{what} is missing, and EENF_PY_REQUIRE=1")
    pytest.skip(f"{what} is missing")


@pytest.fixture(scope="session")
def cli():
    """Runs the eenf command (EENF_BIN, else the workspace's release build) and returns stdout."""
    exe = os.environ.get("EENF_BIN") or str(REPO / "target" / "release" / "eenf")
    if not (os.path.isfile(exe) or shutil.which(exe)):
        need(f"the eenf command ({exe})")

    def run(*args):
        r = subprocess.run([exe, "--quiet", *map(str, args)], capture_output=True, text=True)
        if r.returncode != 0:
            raise AssertionError(f"eenf {' '.join(map(str, args))}: {r.stderr.strip()}")
        return r.stdout

    return run


@pytest.fixture(scope="session")
def sim(tmp_path_factory):
    """A 30 s simulated recording on a 50 Hz grid with hourly mains references beside it."""
    d = tmp_path_factory.mktemp("sim")
    return eenf.simulate(
        d / "dvSave-2022_08_17_16_10_00.aedat4", duration=30, reference_dir=d / "refs"
    )


@pytest.fixture(scope="session")
def shared():
    """The shared data folder (EENF_SHARED), holding fixtures/ and enf-reference/."""
    p = os.environ.get("EENF_SHARED")
    if not p or not os.path.isdir(os.path.join(p, "fixtures")):
        need("the shared data (EENF_SHARED)")
    return Path(p)


def peer(module: str):
    """Imports a peer library (dv_processing, tonic, expelliarmus)."""
    try:
        return __import__(module)
    except ImportError:
        need(f"the peer library {module}")
