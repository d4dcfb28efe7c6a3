"""`eenf.refdb_build`: a site's archive in Berlin wall-clock time, across the autumn change of
summer time, becomes the same store as the command line builds, with every UTC second once."""

import json
from datetime import datetime, timedelta, timezone
from zoneinfo import ZoneInfo

import numpy as np
import pytest

import eenf


def truth(u):
    return 50.0 + 0.02 * np.sin(u / 300.0)


def berlin_csv(path, start, seconds):
    berlin = ZoneInfo("Europe/Berlin")
    with open(path, "w") as f:
        f.write("time,frequency\n")
        for k in range(seconds):
            u = start + timedelta(seconds=k)
            local = u.astimezone(berlin).strftime("%Y-%m-%d %H:%M:%S")
            f.write(f"{local},{truth(u.timestamp()):.6f}\n")


def test_refdb_build_reads_an_archive_across_summer_time(tmp_path, cli):
    start = datetime(2024, 10, 26, 23, 0, tzinfo=timezone.utc)  # 01:00 CEST
    csv = tmp_path / "site.csv"
    berlin_csv(csv, start, 4 * 3600)  # to 04:00 CET: 02:00-03:00 local twice
    r = eenf.refdb_build(tmp_path / "py", csv, tz="Europe/Berlin", grid="DE")
    assert r["grids"] == [{"grid": "DE", "values": 4 * 3600}]
    report = r["archives"][0]["report"]
    assert report["rows"] == 4 * 3600 and report["second_passage"] == 3600
    assert "passed twice" in r["archives"][0]["summary"]
    meta = json.loads((tmp_path / "py" / "DE.json").read_text())
    assert meta["start_unix_s"] == start.timestamp()
    # the command line builds the very same values
    cli("refdb", "build", tmp_path / "cli", csv, "--tz", "Europe/Berlin", "--grid", "DE")
    other = json.loads((tmp_path / "cli" / "DE.json").read_text())
    assert [p["crc32"] for p in other["parts"]] == [p["crc32"] for p in meta["parts"]]
    # no zone, no store: the error names the file and the keyword
    with pytest.raises(Exception, match="site.csv.*tz"):
        eenf.refdb_build(tmp_path / "none", csv)
