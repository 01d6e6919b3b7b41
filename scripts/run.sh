#!/usr/bin/env bash
# The README's first command: installs what the app needs, builds it (release) and opens it on the
# bundled sample stream and table:
#   scripts/run.sh [FILE…]        (default: streams/sample.mcap lookup_tables/sample.lut)
# With no display ($DISPLAY and $WAYLAND_DISPLAY unset, e.g. over ssh or in CI) it starts a
# virtual X server (Xvfb) itself, lets the app draw, saves a screenshot to
# assets/screenshot-latest.png, says so, and closes both again.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/deps.sh
cargo build --release
EOTN="${CARGO_TARGET_DIR:-target}/release/eotn"

if [ $# -gt 0 ]; then
  FILES=("$@")
else
  FILES=(streams/sample.mcap lookup_tables/sample.lut)
fi
for f in "${FILES[@]}"; do
  [ -e "$f" ] || { echo "run.sh: $f does not exist" >&2; exit 1; }
done

if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ]; then
  exec "$EOTN" open "${FILES[@]}"
fi

# No display: a virtual one, a screenshot, then clean up what we started (by PID).
n=99
while [ -e "/tmp/.X11-unix/X$n" ] || [ -e "/tmp/.X$n-lock" ]; do n=$((n + 1)); done
Xvfb ":$n" -screen 0 1280x800x24 -nolisten tcp >/dev/null 2>&1 &
XVFB=$!
APP=""
cleanup() {
  [ -n "$APP" ] && kill "$APP" 2>/dev/null || true
  kill "$XVFB" 2>/dev/null || true
}
trap cleanup EXIT
export DISPLAY=":$n"
for _ in $(seq 50); do [ -e "/tmp/.X11-unix/X$n" ] && break; sleep 0.1; done
"$EOTN" open "${FILES[@]}" &
APP=$!
# Wait for the window, then give the software renderer a moment to draw.
for _ in $(seq 120); do
  xdotool search --name '^eotn' >/dev/null 2>&1 && break
  kill -0 "$APP" 2>/dev/null || { echo "run.sh: the app exited early" >&2; exit 1; }
  sleep 0.5
done
sleep 4
mkdir -p assets
xwd -root -silent | convert xwd:- png:assets/screenshot-latest.png
echo "No display here, so the app ran under Xvfb ($DISPLAY); screenshot: assets/screenshot-latest.png"
