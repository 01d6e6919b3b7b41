#!/usr/bin/env bash
# Classification + blobs: eotn against the two references in ../shared/bench/, on the same frames
# and table, in the same run, rounds interleaved so that machine load hits all three alike.
#   scripts/bench-compare.sh [ROUNDS]        (default 5)
# Frames and the 7-bit table come from peer_pipeline.py --make-sample; floors.c is compiled with
# gcc -O3 -march=native. Prints per-round figures, then medians (ns/pixel) and the ratios.
set -euo pipefail
cd "$(dirname "$0")/.."
ROUNDS=${1:-5}
SHARED=${EOTN_SHARED:-../shared}
WORK=${TMPDIR:-/tmp}/eotn-bench-compare
scripts/deps.sh --test   # numpy and OpenCV for the peer, in .venv/
PYTHON=${PYTHON:-.venv/bin/python}
mkdir -p "$WORK"
[ -f "$WORK/sample_b7.lut" ] || "$PYTHON" "$SHARED/bench/peer_pipeline.py" --make-sample "$WORK" --sample-frames 4 >/dev/null
gcc -O3 -march=native -o "$WORK/floors" "$SHARED/bench/floors.c"
cargo build --release --no-default-features --quiet
EOTN="${CARGO_TARGET_DIR:-target}/release/eotn"

for size in 208x160 640x480; do
  w=${size%x*}; h=${size#*x}
  frame="$WORK/$size/sample_${size}_00.uyvy"
  : > "$WORK/$size.eotn"; : > "$WORK/$size.plain"; : > "$WORK/$size.avx2"; : > "$WORK/$size.peer"
  for _ in $(seq "$ROUNDS"); do
    "$EOTN" bench "$frame" --lut "$WORK/sample_b7.lut" --reps 400 --rounds 1 --chosen-only --no-floor --json | tail -1 \
      | "$PYTHON" -c 'import json,sys; print(json.load(sys.stdin)["total_ns_per_px"])' >> "$WORK/$size.eotn"
    out=$("$WORK/floors" "$frame" "$w" "$h" "$WORK/sample_b7.lut")
    echo "$out" | awk '/^classify\+cc8 \(pipeline\)/{print $(NF-1)}' >> "$WORK/$size.plain"
    echo "$out" | awk '/^classify\+cc8 simd-rle/{print $(NF-1)}' >> "$WORK/$size.avx2"
    "$PYTHON" "$SHARED/bench/peer_pipeline.py" "$frame" --lut "$WORK/sample_b7.lut" --width "$w" --height "$h" --bench 30 \
      | awk '/^total/{print $(NF-1)}' >> "$WORK/$size.peer"
  done
  "$PYTHON" - "$WORK" "$size" <<'PY'
import statistics, sys
work, size = sys.argv[1], sys.argv[2]
med = {k: statistics.median(float(x) for x in open(f"{work}/{size}.{k}")) for k in ("eotn", "plain", "avx2", "peer")}
print(f"{size}: median ns/pixel (classify + blobs, 8-connectivity, 7-bit table)")
for k, label in (("eotn", "eotn"), ("plain", "floors.c plain"), ("avx2", "floors.c AVX2 runs"), ("peer", "peer numpy+OpenCV")):
    print(f"  {label:20s} {med[k]:7.3f}")
print(f"  eotn vs peer:       {med['peer'] / med['eotn']:6.1f}x faster (target >= 50x)")
print(f"  eotn vs plain C:    {med['plain'] / med['eotn']:6.2f}x (target >= 1.0)")
print(f"  eotn vs AVX2 C:     {med['avx2'] / med['eotn']:6.2f}x (aim >= 1.0)")
PY
done
