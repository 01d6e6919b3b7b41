#!/usr/bin/env bash
# Four stand-in robots at 30 fps for a full minute into the app's workspace (the suite runs the
# same test for 2 s): the UI's loop ticking, every robot recorded; every frame must arrive, in
# order, with its sensors, none a second late, the shown robot followed to its last frame, and
# each recording bit-exact. CI runs this (.ci/run).
set -euo pipefail
cd "$(dirname "$0")/.."
EOTN_LIVE_SECONDS=${EOTN_LIVE_SECONDS:-60} cargo test --no-default-features --test it \
  robots::four_robots_at_30_fps_into_the_workspace_lose_no_frame_and_keep_up -- --exact --nocapture
