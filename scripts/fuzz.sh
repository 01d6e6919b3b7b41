#!/usr/bin/env bash
# Fuzzes every parser of outside data (fuzz/fuzz_targets/: the live protocol as the client takes
# it, viewers' and the server's messages as `eotn serve`'s gate takes them, lookup tables in all
# seven formats, B-Human logs, parameter/label/sensor text files, MCAP streams, frame files,
# field/points/calibration files, the edit journal and the settings file, ROS 2 CDR messages,
# image encodings, rosbag2 metadata.yaml and .db3 files, YOLO/COCO/VOC label sets, SSL-Vision
# packets and the league's SSL game logs)
# with libFuzzer through cargo-fuzz, each for SECONDS (default 60), starting from the bundled
# files as seeds. Prints executions and coverage per target; a crash stops the run, leaving its
# input in fuzz/artifacts/TARGET/ (add it to fuzz/regressions/TARGET/ once fixed: CI replays
# those). Works on the stable toolchain (no sanitizer: `-s none`; Rust's own checks still panic).
#   scripts/fuzz.sh [SECONDS] [TARGET…]
set -euo pipefail
cd "$(dirname "$0")/.."
SECONDS_PER_TARGET=${1:-60}
shift || true
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz --locked --version 0.13.2
TARGETS=("$@")
[ ${#TARGETS[@]} -gt 0 ] || TARGETS=(live_protocol serve_viewer_messages lookup_tables bhuman_log text_files mcap_stream frame_files field_files app_files ros2_messages image_encodings rosbag2 label_sets ssl_vision_packets ssl_vision_logs wmd_inputs)

# Seeds: a real input or two of each kind, copied into a temporary corpus so fuzz/ stays clean
# (inputs up to 1 MiB: -max_len below).
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
seed() { mkdir -p "$WORK/$1"; cp "${@:2}" "$WORK/$1/" 2>/dev/null || true; }
seed lookup_tables lookup_tables/bhuman2009.lut
seed live_protocol fuzz/seeds/live_protocol/*
seed serve_viewer_messages fuzz/seeds/serve_viewer_messages/*
seed mcap_stream streams/sim-goalkeeper.mcap \
  tests/data/mcap-conformance/TenMessages/TenMessages-ch-chx-mx-pad-rch-rsh-st-sum.mcap \
  tests/data/mcap-conformance/TenMessages/TenMessages-pad-rch-rsh-st-sum.mcap \
  tests/data/mcap-conformance/OneMetadata/OneMetadata-mdx-pad-st-sum.mcap \
  tests/data/mcap-conformance/OneAttachment/OneAttachment-ax-pad-st-sum.mcap
seed frame_files assets/screenshot.png
seed text_files params/*.json streams/bhuman2009.labels.json
seed field_files params/fields/*.json params/overhead/*.points.json
seed app_files tests/data/journal-seed.jsonl tests/data/settings-seed.json
seed rosbag2 fuzz/seeds/rosbag2/*
seed ros2_messages fuzz/seeds/ros2_messages/*
seed image_encodings fuzz/seeds/image_encodings/*
seed wmd_inputs fuzz/seeds/wmd_inputs/*
seed label_sets fuzz/seeds/label_sets/*
seed ssl_vision_packets fuzz/seeds/ssl_vision_packets/*
seed ssl_vision_logs fuzz/seeds/ssl_vision_logs/*
for t in "${TARGETS[@]}"; do
  mkdir -p "$WORK/$t"
  [ -d "fuzz/regressions/$t" ] && cp fuzz/regressions/"$t"/* "$WORK/$t/" 2>/dev/null || true
done

cd fuzz
cargo fuzz build -s none
for t in "${TARGETS[@]}"; do
  echo "== $t: ${SECONDS_PER_TARGET} s"
  log="$WORK/$t.log"
  if ! cargo fuzz run -s none "$t" "$WORK/$t" -- -max_total_time="$SECONDS_PER_TARGET" \
      -max_len=1048576 -rss_limit_mb=2048 -timeout=10 >"$log" 2>&1; then
    grep -v "^\s*\[" "$log" | tail -40 | cut -c1-300
    echo "fuzz: $t failed (its input is in fuzz/artifacts/$t/)" >&2
    exit 1
  fi
  grep -E '^#[0-9]+\s+(DONE|pulse)' "$log" | tail -1 | sed "s/^/$t: /"
done
