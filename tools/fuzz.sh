#!/usr/bin/env bash
# Fuzzes the event readers with cargo-fuzz (libFuzzer; stable toolchain, no sanitizer: the
# readers' own code is safe Rust, so a crash is a panic, an abort, a hang or an allocation
# past the limit; the C inside — liblz4, zstd, SQLite, c-blosc — is reached through it).
#
#   tools/fuzz.sh SECONDS [TARGET...]      (default: every target, one after another)
#
# Each target's corpus is seeded with the shared fixtures of its format, cut to 64 KiB and
# stripped of the header the target puts in front (fuzz/fuzz_targets/*.rs). Logs go to
# fuzz/logs/TARGET.log; the last "#N DONE" line holds the executions and the coverage.
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
secs=${1:?seconds per target}
shift
targets=("$@")
((${#targets[@]})) || targets=(aedat4 evt2 evt21 evt3 dat aedat2 aedat31 text eventstream atis rosbag mcap rosbag2_sqlite hdf5 ecf probe)
shared=${EENF_SHARED:-$PWD/../../shared}
command -v cargo-fuzz >/dev/null || cargo install --locked cargo-fuzz
cargo fuzz build -s none -O >/dev/null
mkdir -p logs
python3 - "$shared/fixtures" "${targets[@]}" <<'PY'
import os, sys, glob
fixtures, targets = sys.argv[1], sys.argv[2:]
files = sorted(glob.glob(f"{fixtures}/**/*.*", recursive=True))
files = [f for f in files if os.path.isfile(f)]
def text_header_end(b, prefix):
    pos = 0
    while b.startswith(prefix, pos):
        pos = b.index(b"\n", pos) + 1
    return pos
def seed(target, b, f=""):
    if target == "probe":
        return b
    if target == "aedat4":
        return b[14:] if b.startswith(b"#!AER-DAT4.0") else None
    if target in ("evt2", "evt21", "evt3"):
        if not b.startswith(b"%"):
            return None
        head = b[:text_header_end(b, b"%")].lower()
        want = {"evt2": b"evt 2.0", "evt21": b"evt 2.1", "evt3": b"evt 3.0"}[target]
        alt = {"evt2": b"evt2", "evt21": b"evt21", "evt3": b"evt3"}[target]
        return b[len(head):] if (want in head or alt in head) else None
    if target == "dat":
        end = text_header_end(b, b"%")
        return b[end + 2:] if b.startswith(b"%") and b"evt" not in b[:end].lower() else None
    if target == "aedat2":
        return b[text_header_end(b, b"#"):] if b.startswith(b"#!AER-DAT2.0") else None
    if target == "aedat31":
        return b[b.index(b"#!END-HEADER\r\n") + 14:] if b.startswith(b"#!AER-DAT3") else None
    if target == "eventstream":
        return b[20:] if b.startswith(b"Event Stream") else None
    if target == "rosbag":
        return b[13:] if b.startswith(b"#ROSBAG V2.0") else None
    if target == "mcap":
        return b[8:] if b.startswith(b"\x89MCAP0\r\n") else None
    if target == "rosbag2_sqlite":
        return b[16:] if b.startswith(b"SQLite format 3\0") else None
    if target == "hdf5":
        return b[8:] if b.startswith(b"\x89HDF\r\n\x1a\n") else None
    if target == "atis":
        return b if f.endswith(".bin") else None
    if target == "text":
        return b if b[:1].isdigit() or b[:1] == b"#" or b[:2] == b"t," else None
for t in targets:
    os.makedirs(f"corpus/{t}", exist_ok=True)
    n = 0
    for f in files:
        s = seed(t, open(f, "rb").read(), f)
        if s:
            open(f"corpus/{t}/seed_{os.path.basename(f)}", "wb").write(s[:65536])
            n += 1
    print(f"{t}: {n} seeds")
PY
for t in "${targets[@]}"; do
  echo "== $t for $secs s"
  # -rss_limit_mb: a reader that allocates from a size field is caught as a crash
  cargo fuzz run -s none -O "$t" -- -max_total_time="$secs" -rss_limit_mb=1024 \
    -max_len=262144 -timeout=20 -print_final_stats=1 >"logs/$t.log" 2>&1 || {
    echo "$t: crashed, see fuzz/logs/$t.log and fuzz/artifacts/$t"; tail -30 "logs/$t.log"; exit 1; }
  grep -E "DONE|stat::number_of_executed_units|stat::peak_rss_mb" "logs/$t.log" | tr '\n' ' '
  echo
done
