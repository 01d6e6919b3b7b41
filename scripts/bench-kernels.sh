#!/usr/bin/env bash
# Classification + blobs: every kernel set this CPU can run against the C floors and the
# numpy + OpenCV peer of ../shared/bench/, on the same frames and table, in the same runs.
# Each run: `eotn bench` (every set and the AVX2 C floor interleaved in each round), then the
# plain C pipeline of floors.c and the peer on the same frames. Prints, per frame size, one table
# of medians over the runs (markdown, as docs/speed.md quotes it).
#   scripts/bench-kernels.sh [RUNS] [ROUNDS]      (default 3 runs of 5 rounds)
# Frames and the 7-bit table come from peer_pipeline.py --make-sample (numpy, OpenCV in .venv/).
set -euo pipefail
cd "$(dirname "$0")/.."
RUNS=${1:-3}
ROUNDS=${2:-5}
SHARED=${EOTN_SHARED:-../shared}
WORK=${TMPDIR:-/tmp}/eotn-bench-kernels
scripts/deps.sh --test >/dev/null   # numpy and OpenCV for the peer, in .venv/
PYTHON=${PYTHON:-.venv/bin/python}
mkdir -p "$WORK"
[ -f "$WORK/sample_b7.lut" ] || "$PYTHON" "$SHARED/bench/peer_pipeline.py" --make-sample "$WORK" --sample-frames 4 >/dev/null
cargo build --release --no-default-features --quiet
EOTN="${CARGO_TARGET_DIR:-target}/release/eotn"
gcc -O3 -march=native -o "$WORK/floors" "$SHARED/bench/floors.c"
lscpu | grep 'Model name' || true
echo "load average: $(cut -d' ' -f1-3 /proc/loadavg); $(date -u '+%Y-%m-%d %H:%M UTC')"
for size in 640x480 208x160; do
  w=${size%x*}; h=${size#*x}
  : > "$WORK/$size.jsonl"; : > "$WORK/$size.plain"; : > "$WORK/$size.peer"
  for _ in $(seq "$RUNS"); do
    "$EOTN" bench "$WORK/$size"/*.uyvy --lut "$WORK/sample_b7.lut" --rounds "$ROUNDS" --reps 100 \
      --floor "$WORK/floors" --json | tail -1 >> "$WORK/$size.jsonl"
    for frame in "$WORK/$size"/*.uyvy; do
      "$WORK/floors" "$frame" "$w" "$h" "$WORK/sample_b7.lut" \
        | awk '/^classify\+cc8 \(pipeline\)/{print $(NF-1)}' >> "$WORK/$size.plain"
      "$PYTHON" "$SHARED/bench/peer_pipeline.py" "$frame" --lut "$WORK/sample_b7.lut" \
        --width "$w" --height "$h" --bench 30 | awk '/^total/{print $(NF-1)}' >> "$WORK/$size.peer"
    done
  done
  "$PYTHON" - "$WORK" "$size" <<'PY'
import json, statistics, sys
work, size = sys.argv[1], sys.argv[2]
runs = [json.loads(l) for l in open(f"{work}/{size}.jsonl")]
med = statistics.median
floor = med(r["floor_ns_per_px"] for r in runs)
plain = med(float(x) for x in open(f"{work}/{size}.plain"))
peer = med(float(x) for x in open(f"{work}/{size}.peer"))
print(f"\n{size}: {runs[0]['cpu']}; chosen: {runs[0]['kernels']}; {len(runs)} runs x {runs[0]['rounds']} rounds x {runs[0]['frames']} frames")
print("| set | classify | blobs | total ns/pixel | vs AVX2 C floor (per run) | vs plain C | peer ÷ set |")
print("|---|---|---|---|---|---|---|")
for i, s in enumerate(runs[0]["sets"]):
    m = lambda k: med(r["sets"][i][k] for r in runs)
    total = m("total_ns_per_px")
    per_run = " ".join(f"{r['sets'][i]['vs_floor']:.2f}" for r in runs)
    name = f"**`{s['kernels']}`** (chosen)" if s["kernels"] == runs[0]["kernels"] else f"`{s['kernels']}`"
    print(f"| {name} | {m('classify_ns_per_px'):.3f} | {m('blobs_ns_per_px'):.3f} | {total:.3f} | {total / floor:.2f}× ({per_run}) | {total / plain:.2f}× | {peer / total:.0f}× |")
print(f"| C floor, AVX2 runs (`classify+cc8 simd-rle`) | | | {floor:.3f} | 1 | | |")
print(f"| C floor, plain (`classify+cc8 (pipeline)`) | | | {plain:.3f} | | 1 | |")
print(f"| peer, numpy + OpenCV (`peer_pipeline.py`) | | | {peer:.1f} | | | 1 |")
PY
done
