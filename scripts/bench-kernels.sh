#!/usr/bin/env bash
# Every kernel set this CPU can run against the C floor (../shared/bench/floors.c), on the same
# frames and table, in the same runs: `eotn bench` interleaves the sets and the floor in each
# round; this runs it RUNS times per frame size and prints the medians over the runs.
#   scripts/bench-kernels.sh [RUNS] [ROUNDS]      (default 3 runs of 5 rounds)
# Frames and the 7-bit table come from peer_pipeline.py --make-sample (needs .venv: numpy, OpenCV).
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-3}
ROUNDS=${2:-5}
SHARED=${EOTN_SHARED:-../shared}
WORK=${TMPDIR:-/tmp}/eotn-bench-kernels
PYTHON=${PYTHON:-.venv/bin/python}
mkdir -p "$WORK"
[ -f "$WORK/sample_b7.lut" ] || "$PYTHON" "$SHARED/bench/peer_pipeline.py" --make-sample "$WORK" --sample-frames 4 >/dev/null
cargo build --release --no-default-features --quiet
EOTN="${CARGO_TARGET_DIR:-target}/release/eotn"
gcc -O3 -march=native -o "$WORK/floors" "$SHARED/bench/floors.c"
lscpu | grep 'Model name' || true
for size in 640x480 208x160; do
  : > "$WORK/$size.jsonl"
  for _ in $(seq "$RUNS"); do
    "$EOTN" bench "$WORK/$size"/*.uyvy --lut "$WORK/sample_b7.lut" --rounds "$ROUNDS" --reps 100 \
      --floor "$WORK/floors" --json | tail -1 >> "$WORK/$size.jsonl"
  done
  "$PYTHON" - "$WORK/$size.jsonl" "$size" <<'PY'
import json, statistics, sys
runs = [json.loads(l) for l in open(sys.argv[1])]
print(f"{sys.argv[2]}: {runs[0]['cpu']}; chosen: {runs[0]['kernels']}; {len(runs)} runs x {runs[0]['rounds']} rounds x {runs[0]['frames']} frames")
floor = statistics.median(r["floor_ns_per_px"] for r in runs)
print(f"  {'kernels':14s} {'classify':>9s} {'blobs':>7s} {'total':>7s}  vs floor (per run)")
for i, s in enumerate(runs[0]["sets"]):
    med = lambda k: statistics.median(r["sets"][i][k] for r in runs)
    per_run = " ".join(f"{r['sets'][i]['vs_floor']:.2f}" for r in runs)
    print(f"  {s['kernels']:14s} {med('classify_ns_per_px'):9.3f} {med('blobs_ns_per_px'):7.3f} {med('total_ns_per_px'):7.3f}  {med('total_ns_per_px') / floor:.2f}x ({per_run})")
print(f"  {'C floor':14s} {'':9s} {'':7s} {floor:7.3f}  ns/pixel, median of the runs")
PY
done
