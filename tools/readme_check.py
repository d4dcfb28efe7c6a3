#!/usr/bin/env python3
"""Runs the README's examples in order, as a user would, and checks they print what it shows.

    python3 tools/readme_check.py [--eenf target/release/eenf] [--keep] [--only N]

Every `$ command` line of the README's ```text blocks (and the set-up block's
`cargo run -- …`) is run with bash in a fresh folder that has the shared data beside
it (`--shared`, default the clone's `../shared`), so that `../shared/…` means what it means from
the clone's root; `eenf` is the binary given (the
release build by default, as `cargo install --path crates/eenf-cli` would put on the PATH).
The lines after a command, up to the next one, are what it must print (stdout and stderr
together). Times and speeds vary from run to run: `in 0.17 s`, `(105.9 M events/s)`,
`0.02 s` after `in`, are compared as `in <time> s`; every other character must be the same.

Exit status 1 when an example fails, with a diff of what it printed.
"""

import argparse
import difflib
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# what varies between runs on the same input: durations and rates
VOLATILE = [
    (re.compile(r"\bin \d+(\.\d+)? s\b"), "in <time> s"),
    (re.compile(r"\d+(\.\d+)? M events/s"), "<rate> M events/s"),
    (re.compile(r"\bsearched in \d+(\.\d+)? s"), "searched in <time> s"),
    (re.compile(r"\d+(\.\d+)? s wall"), "<time> s wall"),
]


def normalise(line):
    line = line.rstrip()
    for pattern, replacement in VOLATILE:
        line = pattern.sub(replacement, line)
    return line


def examples(readme):
    """(line number, command, expected lines, (first, end) of those lines' indices) of every
    example, in order."""
    out = []
    lines = readme.splitlines()
    in_block = False
    fence = None
    current = None
    pending_demo = None
    for i, line in enumerate(lines):
        no = i + 1
        if line.startswith("```"):
            if not in_block:
                in_block, fence = True, line[3:].strip()
            else:
                if current:
                    out.append(current)
                current, in_block = None, False
            continue
        if not in_block:
            continue
        if fence == "sh" and re.match(r"cargo run (--release )?-- ", line):
            # the set-up block: the demo, whose output the next text block shows
            cmd = "eenf " + line.split("-- ", 1)[1].split("#")[0].strip()
            pending_demo = (no, cmd)
            continue
        if fence != "text":
            continue
        if line.startswith("$ "):
            if current:
                out.append(current)
            current = [no, line[2:], [], (i + 1, i + 1)]
            pending_demo = None
        elif current:
            current[2].append(line)
            current[3] = (current[3][0], i + 1)
        elif pending_demo:
            current = [pending_demo[0], pending_demo[1], [line], (i, i + 1)]
            pending_demo = None
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--eenf", default=os.path.join(ROOT, "target", "release", "eenf"))
    ap.add_argument("--readme", default=os.path.join(ROOT, "README.md"))
    ap.add_argument("--shared", default=os.path.join(os.path.dirname(ROOT), "shared"))
    ap.add_argument("--keep", action="store_true", help="keep the scratch folder")
    ap.add_argument(
        "--update",
        action="store_true",
        help="write what each failing example printed into the README (then read the diff)",
    )
    args = ap.parse_args()
    eenf = os.path.abspath(args.eenf)
    if not os.access(eenf, os.X_OK):
        sys.exit(f"readme_check: {eenf}: no eenf binary (cargo build --release)")
    with open(args.readme, encoding="utf-8") as f:
        text = f.read()
    cases = examples(text)
    updates = []
    shared = os.path.abspath(args.shared)
    if not os.path.isdir(os.path.join(shared, "fixtures")):
        sys.exit(f"readme_check: {shared}: no shared data (--shared)")
    # a scratch folder with the shared data beside it, as the clone's root has
    top = tempfile.mkdtemp(prefix="eenf-readme-check-")
    os.symlink(shared, os.path.join(top, "shared"))
    work = os.path.join(top, "clone")
    os.mkdir(work)
    bindir = os.path.join(work, ".bin")
    os.mkdir(bindir)
    os.symlink(eenf, os.path.join(bindir, "eenf"))
    env = dict(os.environ, PATH=bindir + os.pathsep + os.environ.get("PATH", ""))
    env.pop("CI", None)
    failed = 0
    started = time.time()
    for no, cmd, expected, span in cases:
        t0 = time.time()
        p = subprocess.run(
            ["bash", "-c", cmd],
            cwd=work,
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            stdin=subprocess.DEVNULL,
            timeout=1800,
        )
        raw = p.stdout.decode("utf-8", "replace").splitlines()
        got = [normalise(l) for l in raw]
        want = [normalise(l) for l in (expected or [])]
        took = time.time() - t0
        if got == want:
            print(f"ok    README.md:{no}  {cmd}  ({took:.1f} s)")
            continue
        failed += 1
        updates.append((span, raw))
        print(f"FAIL  README.md:{no}  {cmd}  ({took:.1f} s)")
        for d in difflib.unified_diff(want, got, "README", "printed", lineterm="", n=1):
            print("      " + d)
    print(
        f"readme_check: {len(cases)} examples, {failed} failed, in {time.time() - started:.0f} s"
        + (f"; scratch folder {work}" if args.keep else "")
    )
    if not args.keep:
        shutil.rmtree(top, ignore_errors=True)
    if args.update and updates:
        lines = text.splitlines()
        for (first, end), raw in sorted(updates, reverse=True):
            lines[first:end] = [l.replace(work + "/", "") for l in raw]
        with open(args.readme, "w", encoding="utf-8") as f:
            f.write("\n".join(lines) + "\n")
        print(f"readme_check: {len(updates)} examples rewritten in {args.readme}")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
