#!/usr/bin/env python3
"""The page in a real browser (Debian's chromium, headless, driven by selenium).

Cuts 5 minutes from 1234 s of ../shared/enf-reference/2022_08_17_Wed_17_00_00.wav, saves it
as 8 kHz audio with noise, builds a store from the six shared hours (--tz Asia/Shanghai),
starts `eenf serve --store S --port 0`, uploads the clip on the page and checks:
- #verdict names the 50 Hz grid and the number of estimates; #trace holds a figure;
- #match lists 2022-08-17T09:20:34Z (within 1 s) first;
- the report downloaded from a#report holds the clip's SHA-256 and the trace that
  `eenf reference --json` gives for the same file;
- a real event recording (jaer_MovingDarkBox.aedat) shows its grid and flicker map, and its
  report's trace is the one `eenf extract --json` gives;
- a garbage upload shows its error on the page, and the next upload works;
- requests without the token get 401, with a wrong one 403; two uploads at once both finish;
- every file of fixtures/hostile, uploaded, gives a result or a one-line error, and the server
  goes on serving under 400 MB;
- Ctrl-C stops the server, and its upload folder is gone.
Screenshots of each state go to OUT (default target/page-check).

usage: page_check.py EENF SHARED [--out DIR]
"""

import argparse
import hashlib
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request
import wave
from datetime import datetime, timezone

import numpy as np
from selenium import webdriver
from selenium.webdriver.chrome.options import Options
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait

EXPECTED = datetime(2022, 8, 17, 9, 20, 34, tzinfo=timezone.utc)


def clip_wav(src, dst, start_s=1234, seconds=300, fs_out=8000, seed=1):
    """The clip, resampled exactly (band-limited, by FFT) to fs_out, with white noise."""
    with wave.open(src) as w:
        fs = w.getframerate()
        assert w.getsampwidth() == 2, "16-bit source expected"
        w.setpos(start_s * fs)
        x = np.frombuffer(w.readframes(seconds * fs), dtype="<i2").astype(np.float64)
        if w.getnchannels() > 1:
            x = x.reshape(-1, w.getnchannels())[:, 0]
    n_out = seconds * fs_out
    spec = np.fft.rfft(x)
    y = np.fft.irfft(spec, n_out) * (n_out / len(x))
    rng = np.random.default_rng(seed)
    y = y + rng.normal(0.0, 0.5 * y.std(), len(y))
    y = y / np.abs(y).max() * 0.8 * 32767
    with wave.open(dst, "wb") as w:
        w.setnchannels(1)
        w.setsampwidth(2)
        w.setframerate(fs_out)
        w.writeframes(y.astype("<i2").tobytes())


def status(url, headers=None, data=None):
    req = urllib.request.Request(url, data=data, headers=headers or {})
    try:
        with urllib.request.urlopen(req, timeout=30) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def multipart(path, name):
    boundary = "pagecheckboundary"
    body = (
        f"--{boundary}\r\nContent-Disposition: form-data; name=\"file\"; filename=\"{name}\"\r\n"
        "Content-Type: application/octet-stream\r\n\r\n"
    ).encode() + open(path, "rb").read() + f"\r\n--{boundary}--\r\n".encode()
    return body, {"Content-Type": f"multipart/form-data; boundary={boundary}"}


def downloaded_report(downloads):
    """The report's HTML once the browser has saved it (None after 10 s)."""
    for _ in range(100):
        done = [n for n in os.listdir(downloads) if n.endswith(".html")]
        if done:
            return open(os.path.join(downloads, done[0]), encoding="utf-8").read()
        time.sleep(0.1)
    return None


def same_trace(report, reference):
    """Whether the report's trace (its `trace-json` script) holds `reference`'s values; and
    the two lengths."""
    start = report.index('id="trace-json" type="application/json">')
    body = report[report.index(">", start) + 1:report.index("</script>", start)]
    page, ref = json.loads(body)["enf_hz"], reference["enf_hz"]
    same = len(page) == len(ref) and all(
        (p is None and r is None) or (p is not None and r is not None and abs(p - r) < 1e-9)
        for p, r in zip(page, ref))
    return same, len(page), len(ref)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("eenf")
    ap.add_argument("shared")
    ap.add_argument("--out", default="target/page-check")
    a = ap.parse_args()
    # chromedriver takes only canonical paths for uploads (no `..`)
    a.shared = os.path.realpath(a.shared)
    eenf = os.path.abspath(a.eenf)
    out = os.path.abspath(a.out)
    os.makedirs(out, exist_ok=True)
    failures = []

    def check(ok, what):
        print(f"{'ok' if ok else 'FAILED'}: {what}")
        if not ok:
            failures.append(what)

    work = tempfile.mkdtemp(prefix="page-check-")
    clip = os.path.join(work, "clip_1234s_8k.wav")
    clip_wav(os.path.join(a.shared, "enf-reference", "2022_08_17_Wed_17_00_00.wav"), clip)
    digest = hashlib.sha256(open(clip, "rb").read()).hexdigest()
    garbage = os.path.join(work, "garbage.wav")
    with open(garbage, "wb") as f:
        f.write(np.random.default_rng(2).integers(0, 256, 200_000, dtype=np.uint8).tobytes())
    store = os.path.join(work, "store")
    hours = sorted(
        os.path.join(a.shared, "enf-reference", n)
        for n in os.listdir(os.path.join(a.shared, "enf-reference"))
        if n.endswith(".wav")
    )
    subprocess.run([eenf, "-q", "refdb", "build", store, *hours, "--tz", "Asia/Shanghai"],
                   check=True, stdout=subprocess.DEVNULL)
    cli = json.loads(subprocess.run([eenf, "-q", "reference", clip, "--json"], check=True,
                                    capture_output=True, text=True).stdout)

    uploads = os.path.join(work, "tmp")
    os.makedirs(uploads)
    server = subprocess.Popen(
        [eenf, "serve", "--store", store, "--port", "0"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env=dict(os.environ, TMPDIR=uploads),
    )
    url = server.stdout.readline().strip()
    check(url.startswith("http://127.0.0.1:") and "?token=" in url, f"first line is the URL: {url}")
    base, token = url.split("/?token=")

    code, _ = status(base + "/api/config")
    check(code == 401, f"no token: {code}")
    code, _ = status(base + "/api/config?token=" + "0" * 32)
    check(code == 403, f"wrong token: {code}")

    opts = Options()
    for o in ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--window-size=1280,2400"]:
        opts.add_argument(o)
    downloads = os.path.join(work, "downloads")
    os.makedirs(downloads)
    opts.add_experimental_option("prefs", {"download.default_directory": downloads,
                                           "download.prompt_for_download": False})
    driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=opts)
    try:
        driver.get(url)
        driver.save_screenshot(os.path.join(out, "1-ready.png"))
        visible = lambda i: driver.find_element(By.ID, i).is_displayed()  # noqa: E731

        driver.find_element(By.CSS_SELECTOR, "input[type=file]").send_keys(clip)
        t0 = time.time()
        shot = False
        while not (visible("results") or visible("error")) and time.time() - t0 < 300:
            if not shot and visible("progress"):
                driver.save_screenshot(os.path.join(out, "2-analysing.png"))
                shot = True
            time.sleep(0.2)
        took = time.time() - t0
        driver.save_screenshot(os.path.join(out, "3-result.png"))
        check(visible("results"), f"the clip's results shown after {took:.1f} s"
              + ("" if visible("results") else ": " + driver.find_element(By.ID, "error").text))
        verdict = driver.find_element(By.ID, "verdict").text
        check("50 Hz grid" in verdict and "estimates" in verdict, f"#verdict: {verdict}")
        figs = driver.find_elements(By.CSS_SELECTOR, "#trace svg, #trace img")
        check(len(figs) == 1, f"#trace holds a figure ({len(figs)})")
        times = driver.find_elements(By.CSS_SELECTOR, "#match time")
        first = times[0].get_attribute("datetime") if times else ""
        when = datetime.fromisoformat(first.replace("Z", "+00:00")) if first else None
        off = abs((when - EXPECTED).total_seconds()) if when else float("inf")
        check(off <= 1.0, f"#match first: {first} ({off:.2f} s from {EXPECTED.isoformat()})")
        edits = driver.find_element(By.ID, "edits").text
        check(len(edits) > 10, f"#edits: {edits.splitlines()[0] if edits else ''}")

        driver.find_element(By.CSS_SELECTOR, "a#report").click()
        report = downloaded_report(downloads)
        check(report is not None, "the report downloaded")
        if report:
            check(digest in report, f"the report holds the clip's SHA-256 {digest[:16]}…")
            same, n_page, n_ref = same_trace(report, cli)
            check(same, f"the report's trace = `eenf reference --json` ({n_page} vs {n_ref} values)")

        # the report as a reader sees it (no script in it runs: it is looked at, then left)
        html = [n for n in os.listdir(downloads) if n.endswith(".html")]
        if html:
            driver.get("file://" + os.path.join(downloads, html[0]))
            driver.save_screenshot(os.path.join(out, "3-report.png"))
            driver.get(url)

        # an event recording: its trace, its flicker map, and the report's trace against
        # `eenf extract --json` on the same file
        events = os.path.join(a.shared, "fixtures", "real-flicker", "jaer_MovingDarkBox.aedat")
        extracted = json.loads(subprocess.run([eenf, "-q", "extract", events, "--json"], check=True,
                                              capture_output=True, text=True).stdout)
        for n in os.listdir(downloads):
            os.remove(os.path.join(downloads, n))
        driver.find_element(By.CSS_SELECTOR, "input[type=file]").send_keys(events)
        WebDriverWait(driver, 300).until(
            lambda d: (visible("results") and "jaer_MovingDarkBox" in
                       d.find_element(By.ID, "trace").get_attribute("innerHTML")) or visible("error"))
        driver.save_screenshot(os.path.join(out, "4-events.png"))
        verdict = driver.find_element(By.ID, "verdict").text
        check(visible("results") and "Hz grid" in verdict, f"events #verdict: {verdict}")
        check(visible("flicker"), "events: the flicker map is shown")
        driver.find_element(By.CSS_SELECTOR, "a#report").click()
        report = downloaded_report(downloads)
        check(report is not None, "events: the report downloaded")
        if report:
            same, n_page, n_ref = same_trace(report, extracted)
            check(same, f"events: the report's trace = `eenf extract --json` ({n_page} vs {n_ref} values)")

        driver.find_element(By.CSS_SELECTOR, "input[type=file]").send_keys(garbage)
        WebDriverWait(driver, 60).until(lambda d: visible("error"))
        error = driver.find_element(By.ID, "error").text
        driver.save_screenshot(os.path.join(out, "5-garbage.png"))
        check("garbage.wav" in error and "\n" not in error.strip(), f"garbage: {error}")

        driver.find_element(By.CSS_SELECTOR, "input[type=file]").send_keys(clip)
        WebDriverWait(driver, 300).until(lambda d: visible("results") or visible("error"))
        driver.save_screenshot(os.path.join(out, "6-after-garbage.png"))
        check(visible("results"), "the next upload works")
    finally:
        driver.quit()

    # two uploads at once through the API
    ids = []

    def post():
        body, headers = multipart(clip, "clip.wav")
        headers["X-Eenf-Token"] = token
        code, r = status(base + "/api/analyses", headers, body)
        ids.append((code, json.loads(r)))

    threads = [threading.Thread(target=post) for _ in range(2)]
    [t.start() for t in threads]
    [t.join() for t in threads]
    states = []
    for code, r in ids:
        for _ in range(1500):
            _, s = status(f"{base}/api/analyses/{r['id']}", {"X-Eenf-Token": token})
            s = json.loads(s)
            if s["state"] in ("done", "failed"):
                break
            time.sleep(0.2)
        states.append(s["state"])
    check(states == ["done", "done"], f"two uploads at once: {states}")

    # every hostile fixture uploaded: each gives a result or a one-line error, and the server
    # goes on, within its memory
    hostile = os.path.join(a.shared, "fixtures", "hostile")
    for n in sorted(os.listdir(hostile)):
        path = os.path.join(hostile, n)
        if n == "README.md" or not os.path.isfile(path):
            continue
        body, headers = multipart(path, n)
        headers["X-Eenf-Token"] = token
        code, r = status(base + "/api/analyses", headers, body)
        if code != 202:
            check(code in (400, 413), f"hostile {n}: refused at upload ({code})")
            continue
        t0, s = time.time(), {}
        while time.time() - t0 < 120:
            _, s = status(f"{base}/api/analyses/{json.loads(r)['id']}", {"X-Eenf-Token": token})
            s = json.loads(s)
            if s["state"] in ("done", "failed"):
                break
            time.sleep(0.2)
        line = s.get("error") or (s.get("result") or {}).get("verdict", "")
        check(s.get("state") in ("done", "failed") and "\n" not in line,
              f"hostile {n}: {s.get('state')} in {time.time() - t0:.1f} s: {line[:100]}")
    peak = next((int(x.split()[1]) // 1024 for x in open(f"/proc/{server.pid}/status")
                 if x.startswith("VmHWM")), 0)
    check(peak < 400, f"the server's peak memory over every upload: {peak} MB (< 400)")
    code, _ = status(base + "/api/config", {"X-Eenf-Token": token})
    check(code == 200, "the server still serves")

    server.send_signal(signal.SIGINT)
    try:
        rc = server.wait(10)
    except subprocess.TimeoutExpired:
        server.kill()
        rc = "hung"
    left = [os.path.join(d, f) for d, _, fs in os.walk(uploads) for f in fs] + [
        d for d in os.listdir(uploads)]
    check(rc == 0 and not left, f"Ctrl-C: exit {rc}, left in the upload folder: {left}")
    print(f"screenshots in {out}")
    if failures:
        print(f"page check: {len(failures)} FAILED")
        sys.exit(1)
    print("page check: ok")


if __name__ == "__main__":
    main()
