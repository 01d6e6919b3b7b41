#!/usr/bin/env bash
# Installs what eotn needs beyond Rust: Mesa's software Vulkan (lavapipe) and X libraries so the
# app and its snapshot tests run without a GPU, Xvfb for a virtual display, and Python's numpy and
# OpenCV for the peer cross-check. Quick when everything is already there.
set -euo pipefail

APT_PACKAGES=(
  xvfb xauth mesa-vulkan-drivers libvulkan1 libegl1 libgl1-mesa-dri libegl-mesa0
  libxkbcommon-x11-0 libx11-xcb1 libxcursor1 libxrandr2 libxi6 libfontconfig1
  x11-apps imagemagick xdotool
)

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

PYTHON=${PYTHON:-python3}
if ! "$PYTHON" -c "import numpy, cv2, mcap, mcap_protobuf" 2>/dev/null; then
  echo "deps: installing numpy, opencv-python-headless, mcap readers for $PYTHON" >&2
  "$PYTHON" -m pip install -q numpy opencv-python-headless mcap mcap-protobuf-support
fi
