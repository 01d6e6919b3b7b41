#!/usr/bin/env bash
# The real window's speed without a GPU: each renderer (OpenGL on llvmpipe, wgpu on lavapipe)
# plays the 208×160 sample and a 640×480 stream, every overlay on, in a 1280×800 window under Xvfb,
# once at the recorded rate (counting dropped frames) and once frame by frame as fast as it can
# (median UI frame time). Prints the app's own EOTN_STATS lines and a table.
#   scripts/bench-window.sh [SECONDS]      (default 18 s a run: 15 s of stream, start-up)
# EOTN_PROFILE=dev measures the debug build instead of the release build.
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_PER_RUN=${1:-18}
scripts/deps.sh
if [ "${EOTN_PROFILE:-release}" = dev ]; then
  cargo build --quiet; EOTN=${CARGO_TARGET_DIR:-target}/debug/eotn
else
  cargo build --release --quiet; EOTN=${CARGO_TARGET_DIR:-target}/release/eotn
fi
WORK=$(mktemp -d)
n=120
while [ -e "/tmp/.X11-unix/X$n" ] || [ -e "/tmp/.X$n-lock" ]; do n=$((n + 1)); done
Xvfb ":$n" -screen 0 1280x800x24 -nolisten tcp >/dev/null 2>&1 &
XVFB=$!
trap 'kill $XVFB 2>/dev/null || true; rm -rf "$WORK"' EXIT
for _ in $(seq 50); do [ -e "/tmp/.X11-unix/X$n" ] && break; sleep 0.1; done

# Streams of 15 s at 30 fps: a robot camera's 208×160 and the overhead camera's 640×480; and the
# bundled 48-frame sample.
"$EOTN" sim --scenario walk-and-pan --frames 450 --seed 5 -o "$WORK/208x160.mcap" 2>/dev/null
"$EOTN" sim --scenario overhead-game --frames 450 --seed 5 -o "$WORK/640x480.mcap" 2>/dev/null
declare -A STREAM=([sample]="streams/sample.mcap lookup_tables/sample.lut"
                   [208x160]="$WORK/208x160.mcap lookup_tables/sim.lut"
                   [640x480]="$WORK/640x480.mcap lookup_tables/sim.lut")
printf '%-8s %-8s %-6s %10s %8s %8s %6s\n' renderer size speed "median ms" played dropped late
for renderer in gl wgpu; do
  for size in sample 208x160 640x480; do
    for speed in 1x every; do
      # shellcheck disable=SC2086
      out=$(DISPLAY=":$n" HOME="$WORK/home" EOTN_STATS=1 "$EOTN" open ${STREAM[$size]} \
              --renderer "$renderer" --play --speed "$speed" --all-overlays \
              --quit-after "$SECONDS_PER_RUN" 2>&1 >/dev/null | grep 'eotn stats' | tail -1 || true)
      echo "$out" >> "$WORK/stats.txt"
      median=$(echo "$out" | sed -n 's/.*playing frames [0-9]* median \([0-9.]*\) ms.*/\1/p')
      played=$(echo "$out" | sed -n 's/.*played \([0-9]*\) dropped.*/\1/p')
      dropped=$(echo "$out" | sed -n 's/.*dropped \([0-9]*\) late.*/\1/p')
      late=$(echo "$out" | sed -n 's/.*late \([0-9]*\);.*/\1/p')
      printf '%-8s %-8s %-6s %10s %8s %8s %6s\n' "$renderer" "$size" "$speed" "${median:-?}" "${played:-?}" "${dropped:-?}" "${late:-?}"
    done
  done
done
echo
cat "$WORK/stats.txt"
