#!/usr/bin/env bash
# Installs what eotn needs beyond Rust, on a plain Debian/Ubuntu (only the system Python, which
# refuses pip: PEP 668). Quick when everything is already there.
#   scripts/deps.sh           the app: Mesa's software renderers (OpenGL llvmpipe and Vulkan
#                             lavapipe) and X libraries so it runs without a GPU, Xvfb for a
#                             virtual display, screenshot tools
#   scripts/deps.sh --test    also what the tests use: python3-venv, and the project's own
#                             virtual environment .venv/ (made from /usr/bin/python3) with the
#                             pinned packages of scripts/requirements-test.txt
set -euo pipefail
cd "$(dirname "$0")/.."

WITH_TESTS=0
[ "${1:-}" = "--test" ] && WITH_TESTS=1

# Building needs only Rust and a C compiler (for zstd and lz4): these are the app's run-time
# libraries (loaded when the window opens) and the tools for running it without a display.
APT_PACKAGES=(
  xvfb xauth mesa-vulkan-drivers libvulkan1 libegl1 libgl1 libgl1-mesa-dri libegl-mesa0
  libxkbcommon-x11-0 libx11-xcb1 libxcursor1 libxrandr2 libxi6 libfontconfig1
  x11-apps imagemagick xdotool
)
if [ "$WITH_TESTS" = 1 ]; then
  APT_PACKAGES+=(python3 python3-venv)
fi

missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "deps: installing ${missing[*]}" >&2
  SUDO=""
  if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

[ "$WITH_TESTS" = 1 ] || exit 0

# The tests' Python: a virtual environment of the system interpreter, inside the project's ignored
# files, re-made whenever the pinned requirements change.
VENV=.venv
REQ=scripts/requirements-test.txt
STAMP="$VENV/.requirements.sha256"
want=$(sha256sum "$REQ" | cut -d' ' -f1)
if [ ! -x "$VENV/bin/python" ] || [ "$(cat "$STAMP" 2>/dev/null)" != "$want" ]; then
  echo "deps: making $VENV from /usr/bin/python3 with $REQ" >&2
  rm -rf "$VENV"
  /usr/bin/python3 -m venv "$VENV"
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check -r "$REQ"
  echo "$want" > "$STAMP"
fi
