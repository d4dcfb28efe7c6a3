#!/usr/bin/env bash
# E-ENF on every recording of a simulated dataset (eenf simulate-dataset), compared with its
# hourly references: one line per recording, then the mean CC and MAE per class.
# Usage: tools/eval_dataset.sh DATASET_DIR [EENF_BINARY] [extract options...]
set -euo pipefail
dir=$1; shift
eenf=${1:-target/release/eenf}; shift || true
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
printf "%-9s %-46s %8s %10s %s\n" class recording CC MAE_mHz scene
tail -n +2 "$dir/manifest.csv" | while IFS=, read -r rec class ref off videos scene rest; do
    stem=$(basename "$rec" .aedat4)
    "$eenf" -q extract "$dir/$rec" -o "$out/$stem.csv" "$@" >/dev/null 2>&1 || { echo "$class $rec extract failed"; continue; }
    "$eenf" -q compare "$out/$stem.csv" "$dir/ENF_Reference" --json > "$out/$stem.json"
    python3 - "$out/$stem.json" "$class" "$rec" "$scene" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
a = m.get("agreement", m)
print(f"{sys.argv[2]:<9} {sys.argv[3]:<46} {a['cc']:8.4f} {a['mae_hz']*1e3:10.3f} {sys.argv[4]}")
PY
done | tee "$out/rows.txt"
echo
python3 - "$out/rows.txt" <<'PY'
import sys, collections
rows = collections.defaultdict(list)
for line in open(sys.argv[1]):
    f = line.split()
    if len(f) >= 4 and f[2] != "extract":
        rows[f[0]].append((float(f[2]), float(f[3])))
print(f"{'class':<9} {'n':>3} {'mean CC':>8} {'mean MAE (mHz)':>15}")
for c in ("static", "dynamic", "extreme"):
    if rows[c]:
        cc = sum(r[0] for r in rows[c]) / len(rows[c])
        mae = sum(r[1] for r in rows[c]) / len(rows[c])
        print(f"{c:<9} {len(rows[c]):>3} {cc:8.4f} {mae:15.3f}")
PY
