#!/usr/bin/env bash
# The real window's speed without a GPU: each renderer (OpenGL on llvmpipe, wgpu on lavapipe)
# plays the 208×160 sample and a 640×480 stream, every overlay on, in a 1280×800 window under Xvfb,
# once at the recorded rate (counting dropped frames) and once frame by frame as fast as it can
# (median UI frame time). Then a 1920×1200 overhead stream on OpenGL: played frame by frame, and
# zoomed, panned and typed into by xdotool (the slowest frame that answered input, and the time
# from launch to the first frame). Prints the app's own EOTN_STATS lines and tables.
# ONLY_BIG=1 runs only the 1920×1200 ones, SKIP_BIG=1 all but those; BIG_FRAMES=N sets that stream's length (default 150,
# 2 s at 75 fps).
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

# ONLY_BIG=1 skips these runs (the 1920×1200 overhead runs below only).
if [ -z "${ONLY_BIG:-}" ]; then
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
              --quit-after "$SECONDS_PER_RUN" 2>&1 >/dev/null | grep 'eotn stats: steps' | tail -1 || true)
      echo "$out" >> "$WORK/stats.txt"
      median=$(echo "$out" | sed -n 's/.*playing frames [0-9]* median \([0-9.]*\) ms.*/\1/p')
      played=$(echo "$out" | sed -n 's/.*played \([0-9]*\) dropped.*/\1/p')
      dropped=$(echo "$out" | sed -n 's/.*dropped \([0-9]*\) late.*/\1/p')
      late=$(echo "$out" | sed -n 's/.*late \([0-9]*\);.*/\1/p')
      printf '%-8s %-8s %-6s %10s %8s %8s %6s\n' "$renderer" "$size" "$speed" "${median:-?}" "${played:-?}" "${dropped:-?}" "${late:-?}"
    done
  done
done
fi

[ -n "${SKIP_BIG:-}" ] && { cat "$WORK/stats.txt"; exit 0; }
# The big overhead stream and the window's answers to the user (issue 33): a 1920×1200 overhead
# camera (one camera of `eotn overhead sim-field`, 150 frames at 75 fps, its own table) played
# frame by frame with every overlay; then, not playing, zooming (the wheel over the image),
# panning (a middle-button drag) and typing (the Parameters window's Find field) driven by
# xdotool. GL on llvmpipe only: the renderer this machine draws with. Each run prints the time
# from launch to the first frame, and for the interaction runs the median and slowest interval
# of the frames that answered input.
"$EOTN" overhead sim-field --cameras 1 --size 1920x1200 --frames "${BIG_FRAMES:-150}" \
  -o "$WORK/field1920" >/dev/null 2>&1
BIG="$WORK/field1920/cam0.mcap"; BIG_LUT="$WORK/field1920/cam0.lut"
mkdir -p "$WORK/home/.local/share/eotn"
run_big() { # NAME SETTINGS_JSON SECONDS [open args…] ; the interaction is read from stdin
  local name=$1 settings=$2 seconds=$3; shift 3
  echo "$settings" > "$WORK/home/.local/share/eotn/settings.json"
  DISPLAY=":$n" HOME="$WORK/home" EOTN_STATS=1 "$EOTN" open "$BIG" "$BIG_LUT" --renderer gl \
    --all-overlays --quit-after "$seconds" "$@" 2> "$WORK/$name.err" >/dev/null &
  local app=$!
  sleep 4
  # No window manager gives the window the keyboard: xdotool does, as a user's click would.
  DISPLAY=":$n" xdotool search --onlyvisible --name eotn windowfocus --sync >/dev/null 2>&1 || true
  DISPLAY=":$n" bash -s
  wait "$app" || true
  local first input play
  first=$(sed -n 's/.*first frame \([0-9]*\) ms after launch.*/\1/p' "$WORK/$name.err" | tail -1)
  input=$(sed -n 's/.*input frames \([0-9]*\) median \([0-9.]*\) ms max \([0-9.]*\) ms.*/\1 \2 \3/p' "$WORK/$name.err" | tail -1)
  play=$(sed -n 's/.*playing frames \([0-9]*\) median \([0-9.]*\) ms max \([0-9.]*\) ms.*/\1 \2 \3/p' "$WORK/$name.err" | tail -1)
  printf '%-8s first frame %6s ms | input frames (n median max) %-22s | playing frames (n median max) %s\n' \
    "$name" "${first:-?}" "${input:-?}" "${play:-?}"
  grep 'eotn stats' "$WORK/$name.err" >> "$WORK/stats.txt" || true
}
echo
echo "1920x1200 overhead stream, GL on llvmpipe, Xvfb 1280x800"
# Played frame by frame as fast as it can (`--speed every`): at the recorded 75 fps nearly every
# frame would be dropped and the median would rest on a handful of frames.
run_big play '{}' 10 --play --speed every <<<'sleep 3'
# The image's centre at the default layout (Classify panel left, thumbnails below).
run_big zoom '{}' 12 <<'XDO'
xdotool mousemove 700 330
for _ in 1 2 3; do
  xdotool click --repeat 12 --delay 40 4
  xdotool click --repeat 12 --delay 40 5
done
XDO
run_big pan '{"transform": {"zoom": 2.0, "centre": [960.0, 600.0]}}' 12 <<'XDO'
xdotool mousemove 700 330
for _ in 1 2 3 4; do
  xdotool mousedown 2
  for _ in $(seq 20); do xdotool mousemove_relative -- 8 4; sleep 0.03; done
  for _ in $(seq 20); do xdotool mousemove_relative -- -8 -4; sleep 0.03; done
  xdotool mouseup 2
done
XDO
# The Parameters window docked at the right; its Find field at the top of the dock.
run_big typing '{"show_params": true}' 12 <<'XDO'
xdotool mousemove "${FIND_X:-985}" "${FIND_Y:-129}" click 1
sleep 0.3
for word in height weight diameter ball overhead; do
  xdotool type --delay 60 "$word"
  xdotool key --delay 60 BackSpace BackSpace BackSpace BackSpace BackSpace BackSpace BackSpace BackSpace
done
XDO
echo
cat "$WORK/stats.txt"
