#!/usr/bin/env python3
"""Fails when the top-level modules of a crate import each other in a circle, or when the
library crate `eenf` depends on the command line's crates (clap, indicatif, plotters,
signal-hook), on `anyhow` (its errors are typed: `eenf::Error`) or on the server's (axum, tokio),
`eenf-figures` on `anyhow` or the server's, the Python package `eenf-py` or the page `eenf-serve`
on the command line (`eenf-cli`, clap, indicatif, signal-hook), or `eenf-dsp` on `eenf-events`.

A module's imports are its `crate::NAME` paths, names re-exported by `lib.rs` resolved to the
module that defines them. Usage: python3 tools/module_cycles.py [ROOT]"""

import os
import re
import subprocess
import sys


def reexports(src):
    """Name → module for what `lib.rs` re-exports or defines."""
    names = {}
    path = os.path.join(src, "lib.rs")
    if not os.path.exists(path):
        return names
    text = open(path, encoding="utf-8").read()
    for mod, body in re.findall(r"pub use ([a-z_0-9]+)::\{([^}]*)\}", text):
        for n in re.findall(r"[A-Za-z_0-9]+", body):
            names[n] = mod
    for mod, n in re.findall(r"pub use ([a-z_0-9]+)::([A-Za-z_0-9]+);", text):
        names[n] = mod
    for n in re.findall(r"pub (?:struct|enum|trait|fn|type|const) ([A-Za-z_0-9]+)", text):
        names.setdefault(n, "lib")
    return names


def module_graph(src):
    """Top-level module → the top-level modules it imports."""
    rx = reexports(src)
    graph = {}
    for root, _, files in os.walk(src):
        for f in files:
            if not f.endswith(".rs"):
                continue
            path = os.path.join(root, f)
            top = os.path.relpath(path, src).split(os.sep)[0].removesuffix(".rs")
            if top in ("lib", "main"):
                continue
            text = open(path, encoding="utf-8").read()
            deps = set()
            for body in re.findall(r"crate::\{([^}]*)\}", text):
                deps.update(rx.get(n, n) for n in re.findall(r"[A-Za-z_0-9]+", body))
            deps.update(rx.get(n, n) for n in re.findall(r"crate::([A-Za-z_0-9]+)", text))
            graph.setdefault(top, set()).update(d for d in deps if d not in (top, "lib"))
    return graph


def cycles(graph):
    """Each circle found by a depth-first walk, as a list of modules."""
    state, stack, found = {}, [], []

    def walk(u):
        state[u] = 1
        stack.append(u)
        for v in sorted(graph.get(u, ())):
            if v not in graph:
                continue
            if state.get(v) == 1:
                found.append(stack[stack.index(v):] + [v])
            elif not state.get(v):
                walk(v)
        stack.pop()
        state[u] = 2

    for u in sorted(graph):
        if not state.get(u):
            walk(u)
    return found


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else "."
    bad = 0
    crates = os.path.join(root, "crates")
    for crate in sorted(os.listdir(crates)):
        for c in cycles(module_graph(os.path.join(crates, crate, "src"))):
            print(f"{crate}: modules in a circle: {' -> '.join(c)}")
            bad += 1
    for package, banned in [
        # the library's errors are typed (`eenf::Error`): each front end words them
        ("eenf", ["clap", "indicatif", "plotters", "signal-hook", "anyhow", "axum", "tokio"]),
        ("eenf-figures", ["anyhow"]),
        ("eenf-dsp", ["eenf-events"]),
        # the Python package is a front end over the library, not over the command line
        ("eenf-py", ["clap", "indicatif", "signal-hook", "eenf-cli", "eenf-serve"]),
        # so is the page; and the library serves nothing itself
        ("eenf-serve", ["clap", "indicatif", "signal-hook", "eenf-cli", "anyhow"]),
        ("eenf-figures", ["axum", "tokio"]),
    ]:
        tree = subprocess.run(
            ["cargo", "tree", "-p", package, "-e", "normal", "--prefix", "none"],
            cwd=root, capture_output=True, text=True, check=True).stdout
        names = {line.split()[0] for line in tree.splitlines() if line.strip()}
        for b in banned:
            if b in names:
                print(f"{package} depends on {b}")
                bad += 1
    print(f"module cycles and forbidden dependencies: {bad}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
