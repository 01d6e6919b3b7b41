#!/usr/bin/env bash
# Long runs with memory sampled (hardening): a synthetic stream of MINUTES minutes at 30 frames a
# second (default 20: 36,000 frames, about 1.7 GB in a temporary folder, removed afterwards) read
# end to end by `eotn detect` (the CLI) and stepped end to end through the app's state
# (examples/long_run.rs: the headless Workspace the window draws). Prints resident memory at the
# start, after the first tenth and at its peak for each; fails when either grows by more than
# 16 MiB after the first tenth (the frame cache and the pipeline's buffers are bounded). Then
# `eotn serve` with 40 viewers that never read beside a good one for SERVE_SECONDS (default 20).
# Last, every fuzz target for FUZZ_SECONDS each (default 600).
#   scripts/long-run.sh [MINUTES]
set -euo pipefail
cd "$(dirname "$0")/.."
MINUTES=${1:-20}
FRAMES=$((MINUTES * 60 * 30))
cargo build --release --quiet
cargo build --release --quiet --no-default-features --example long_run
EOTN="${CARGO_TARGET_DIR:-target}/release/eotn"
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
STREAM="$WORK/long.mcap"
echo "long-run: making $FRAMES frames ($MINUTES min at 30 fps)"
"$EOTN" sim --scenario walk-and-pan --frames "$FRAMES" --seed 11 -o "$STREAM" >/dev/null
ls -l "$STREAM" | awk '{printf "long-run: stream of %.1f GB\n", $5 / 1e9}'

# The CLI: resident memory of `eotn detect` sampled five times a second from /proc.
"$EOTN" detect "$STREAM" --lut lookup_tables/sim.lut --json >/dev/null &
PID=$!
: >"$WORK/cli-rss.txt"
while kill -0 "$PID" 2>/dev/null; do
  awk '/^VmRSS:/ {print $2 / 1024}' "/proc/$PID/status" 2>/dev/null >>"$WORK/cli-rss.txt" || true
  sleep 0.2
done
wait "$PID"
awk -v frames="$FRAMES" '
  { rss[NR] = $1 }
  END {
    if (NR == 0) { print "long-run: detect ended before a sample"; exit 0 }
    warm = int(NR / 10) + 1; base = rss[warm]; peak = 0
    for (i = warm; i <= NR; i++) if (rss[i] > peak) peak = rss[i]
    printf "long-run: detect, %d frames in about %.0f s: resident %.1f MiB at start, %.1f after the first tenth, peak %.1f (growth %.1f MiB)\n", frames, NR / 5, rss[1], base, peak, peak - base
    if (peak - base > 16) { print "long-run: detect grew by more than 16 MiB"; exit 1 }
  }' "$WORK/cli-rss.txt"

# The app's state.
"${CARGO_TARGET_DIR:-target}/release/examples/long_run" "$STREAM" lookup_tables/sim.lut 16 >"$WORK/app-rss.txt"
tail -1 "$WORK/app-rss.txt"

# `eotn serve` with 40 viewers that never read beside a good one for SERVE_SECONDS (default 20):
# its resident memory stays bounded and the good viewer keeps its rate (the test in
# tests/it/serve_load.rs, which runs 5 s in the suite).
EOTN_SERVE_LOAD_STALLED=40 EOTN_SERVE_LOAD_SECONDS=${SERVE_SECONDS:-20} cargo test --quiet --no-default-features --test it \
  -- --nocapture serve_load::viewers_that_never_read 2>&1 | grep -E "^serve with|test result"

# The portable path compiles for aarch64 (issue 31: no aarch64 machine here; the kernels' run-time
# rule picks `portable` there). A type check of the library without the app, no linking; the C
# parts of the dependencies (SQLite, zstd, lz4) need a cross C compiler (Debian:
# gcc-aarch64-linux-gnu) and the target (`rustup target add aarch64-unknown-linux-gnu`). Skipped,
# said so, when either is missing. Cold: 9.5 CPU-minutes, 23 minutes on 2 busy cores (2026-12-07),
# too long for .ci/run.
if rustup target list --installed 2>/dev/null | grep -qx aarch64-unknown-linux-gnu &&
  command -v aarch64-linux-gnu-gcc >/dev/null; then
  CC_aarch64_unknown_linux_gnu=aarch64-linux-gnu-gcc cargo check --quiet --lib \
    --no-default-features --target aarch64-unknown-linux-gnu
  echo "long-run: the library type-checks for aarch64-unknown-linux-gnu"
else
  echo "long-run: aarch64 check skipped (needs the aarch64-unknown-linux-gnu target and aarch64-linux-gnu-gcc)"
fi

# Deep fuzzing: every fuzz target for FUZZ_SECONDS (default 600, ten minutes a target; CI's
# fuzz-smoke gives each 5 s). A crash or hang stops the run with its input in fuzz/artifacts/.
scripts/fuzz.sh "${FUZZ_SECONDS:-600}"
