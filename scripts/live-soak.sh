#!/usr/bin/env bash
# Four stand-in robots at 30 fps for a full minute (the suite runs the same test for 2 s):
# every frame must arrive, in order, with its sensors, none a second late.
set -euo pipefail
cd "$(dirname "$0")/.."
EOTN_LIVE_SECONDS=${EOTN_LIVE_SECONDS:-60} cargo test --no-default-features --test it \
  live::four_robots_at_30_fps_lose_no_frame_and_keep_up -- --exact --nocapture
