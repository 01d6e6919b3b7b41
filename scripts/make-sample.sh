#!/usr/bin/env bash
# Builds the bundled sample: streams/sample.mcap and lookup_tables/sample.lut.
#   scripts/make-sample.sh [FRAMES]        (default 48 robot-camera frames, 208×160, 30 fps)
# Frames and the 7-bit table come from ../shared/bench/peer_pipeline.py --make-sample (synthetic
# field scenes, the ball moving from frame to frame). The sensor readings are generated here and
# are plausible, not measured: a slow head pan (±0.6 rad, 4 s period) with the matching pan PWM,
# a steady head tilt, IR distances, gravity on the accelerometers with a little noise, a slowly
# draining battery. They do not match the scene's geometry.
set -euo pipefail
cd "$(dirname "$0")/.."
FRAMES=${1:-48}
SHARED=${EOTN_SHARED:-../shared}
scripts/deps.sh --test   # numpy and OpenCV for peer_pipeline.py, in .venv/
PYTHON=${PYTHON:-.venv/bin/python}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

"$PYTHON" "$SHARED/bench/peer_pipeline.py" --make-sample "$WORK" --width 208 --height 160 \
  --sample-frames "$FRAMES" --sample-bits 7 >/dev/null

"$PYTHON" - "$WORK/sensors.csv" "$FRAMES" <<'PY'
import csv, math, random, sys
path, n = sys.argv[1], int(sys.argv[2])
rng = random.Random(2009)
fields = ["frame", "time_s", "head_pan_rad", "head_tilt_rad", "neck_tilt_rad", "pan_pwm",
          "ir_near_cm", "ir_far_cm", "ir_chest_cm", "accel_x_mps2", "accel_y_mps2",
          "accel_z_mps2", "body_pitch_rad", "body_roll_rad", "body_height_cm",
          "battery_percent", "temperature_c"]
with open(path, "w", newline="") as f:
    w = csv.writer(f)
    w.writerow(fields)
    for i in range(n):
        t = i / 30.0
        phase = 2 * math.pi * t / 4.0
        pan = 0.6 * math.sin(phase)
        pwm = max(-1.0, min(1.0, 0.35 * math.cos(phase) + rng.gauss(0, 0.02)))
        far = 60 + 25 * math.cos(phase) + rng.gauss(0, 1.5)
        near = "" if far > 50 else round(far, 1)      # the near sensor sees up to 50 cm
        w.writerow([i, f"{t:.6f}", f"{pan:.5f}", f"{-0.22 + 0.01 * math.sin(3 * phase):.5f}", "0.0",
                    f"{pwm:.3f}", near, f"{far:.1f}", f"{95 + rng.gauss(0, 2):.1f}",
                    f"{rng.gauss(0.05, 0.08):.3f}", f"{rng.gauss(0, 0.08):.3f}",
                    f"{9.81 + rng.gauss(0, 0.1):.3f}", "0.087", "0.0", "18.5",
                    f"{87 - 0.01 * i:.2f}", f"{41.0 + 0.002 * i:.3f}"])
PY

mkdir -p streams lookup_tables
cargo run --quiet --no-default-features -- import "$WORK/208x160" \
  --sensors "$WORK/sensors.csv" --fps 30 --source robot \
  --description "Bundled sample: ${FRAMES} synthetic 208×160 robot-camera frames (peer_pipeline.py --make-sample) with generated, plausible sensor readings (slow head pan)" \
  -o streams/sample.mcap
cp "$WORK/sample_b7.lut" lookup_tables/sample.lut
ls -l streams/sample.mcap lookup_tables/sample.lut
