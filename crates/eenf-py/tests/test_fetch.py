"""`eenf.refdb_fetch` and `eenf.refdb_update` against a replay of Svenska kraftnät's
control-room answers served from 127.0.0.1 (nothing here reaches the internet): the same store
as the command line builds from the same files, the provenance in the manifest, and a failure
that leaves the store as it was."""

import hashlib
import json
import math
import threading
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from urllib.parse import parse_qs, urlparse

import pytest

import eenf


def truth(u):
    return 50.0 + 0.03 * math.sin(u / 700.0) + 0.01 * math.cos(u / 97.0)


class Svk(BaseHTTPRequestHandler):
    """Answers `…/freq?fromDateTime=MS&toDateTime=MS` with `{"Data": [{"x": ms, "y": hz}]}`;
    any other path with 404."""

    requests = []

    def do_GET(self):
        url = urlparse(self.path)
        Svk.requests.append(self.path)
        if not url.path.endswith("/freq"):
            self.send_response(404)
            self.send_header("Content-Length", "0")
            self.end_headers()
            return
        q = parse_qs(url.query)
        a, b = int(q["fromDateTime"][0]) // 1000, int(q["toDateTime"][0]) // 1000
        data = [{"x": s * 1000, "y": round(truth(s), 3)} for s in range(a, b)]
        body = json.dumps({"Data": data}).encode()
        self.send_response(200)
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args):
        pass


@pytest.fixture()
def svk():
    server = ThreadingHTTPServer(("127.0.0.1", 0), Svk)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    Svk.requests = []
    yield f"http://127.0.0.1:{server.server_address[1]}/services/controlroom/v2/freq"
    server.shutdown()


def digest(folder):
    h = hashlib.sha256()
    for p in sorted(folder.iterdir()):
        if not p.name.startswith(".eenf-store.lock"):
            h.update(p.name.encode() + p.read_bytes())
    return h.hexdigest()


def test_refdb_fetch_fills_the_store_the_command_line_builds_from_the_same_files(tmp_path, svk, cli):
    r = eenf.refdb_fetch(
        "se", tmp_path / "py", "2023-05-01T10:00:00Z", "2023-05-01T12:00:00Z",
        endpoint=svk, cache=tmp_path / "cache",
    )
    assert r["grids"] == [{"grid": "se", "values": 7200}]
    assert len(Svk.requests) == 2 and all(not f["cached"] for f in r["files"])
    meta = json.loads((tmp_path / "py" / "se.json").read_text())
    fetched = meta["fetched"][0]
    assert fetched["source"] == "se" and fetched["endpoint"] == svk
    for f, entry in zip(r["files"], fetched["files"]):
        data = open(f["path"], "rb").read()
        assert entry["sha256"] == hashlib.sha256(data).hexdigest()
        assert entry["bytes"] == len(data) and entry["url"] == f["url"]
    # the command line builds the very same values from the cached files
    cli("refdb", "build", tmp_path / "cli", *[f["path"] for f in r["files"]], "--grid", "se")
    other = json.loads((tmp_path / "cli" / "se.json").read_text())
    assert [p["crc32"] for p in other["parts"]] == [p["crc32"] for p in meta["parts"]]
    assert other["start_unix_s"] == meta["start_unix_s"]
    # a source that does not exist, a 404: errors that leave the store as it was
    before = digest(tmp_path / "py")
    with pytest.raises(ValueError, match="not a source"):
        eenf.refdb_fetch("xx", tmp_path / "py", "2023-05-01")
    with pytest.raises(ValueError, match=r"se: .*404"):
        eenf.refdb_fetch(
            "se", tmp_path / "py", "2023-05-01T12:00:00Z", "2023-05-01T13:00:00Z",
            endpoint=svk.replace("/freq", "/gone"), cache=tmp_path / "cache", retries=0,
        )
    assert digest(tmp_path / "py") == before


def test_refdb_update_needs_a_fetched_grid(tmp_path):
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match="no grid here was fetched"):
        eenf.refdb_update(tmp_path / "empty", cache=tmp_path / "cache")
