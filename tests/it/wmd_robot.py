"""A robot written with the official Foxglove SDK (not eotn) that sends its world model on
/world_model (JSON, docs/formats.md) with known errors, for the live `eotn wmd` test.

It does not see the field: the test feeds it, one line on standard input per overhead frame, the
overhead truth (`/ground_truth` of the frame `eotn serve` is sending), and it answers each with
the world model of the scene robot `--robot`: the truth plus `--error dx,dy,dheading_deg`, its
ball, its distance to the ball times `--distance-scale`, stamped with its own clock
(`time_ns` = this machine's clock + `--clock-offset` seconds). After `--stop-after` world models it
stays connected but sends nothing more; `--exit-after` seconds after that it ends abruptly (its
connection drops without a close), as a robot that crashes would. It ends when its input does.
Nothing is sent (or counted) before a viewer subscribes. With `--image` it also sends a 64x48
UYVY camera frame (foxglove.RawImage on /camera/image) with each world model, byte k of the
n-th (k + 3 n) mod 256.
"""

import argparse
import json
import math
import os
import sys
import threading
import time

import foxglove
from foxglove.channels import RawImageChannel
from foxglove.messages import RawImage, Timestamp


class Viewer(foxglove.ServerListener):
    """Sets `subscribed` once a viewer has subscribed to /world_model: before that nothing is
    sent (or counted)."""

    def __init__(self):
        self.subscribed = threading.Event()

    def on_subscribe(self, client, channel):
        if channel.topic == "/world_model":
            self.subscribed.set()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--port", type=int, required=True)
    ap.add_argument("--robot", type=int, required=True, help="the scene robot's number (truth id)")
    ap.add_argument("--error", default="0,0,0", help="dx_cm,dy_cm,dheading_deg")
    ap.add_argument("--distance-scale", type=float, default=1.0)
    ap.add_argument("--clock-offset", type=float, default=0.0, help="seconds its clock is ahead")
    ap.add_argument("--stop-after", type=int, default=0, help="world models, then silence (0: never)")
    ap.add_argument("--exit-after", type=float, default=0.0, help="seconds of silence, then exit")
    ap.add_argument("--image", action="store_true", help="a camera frame with each world model")
    args = ap.parse_args()
    dx, dy, dh = (float(v) for v in args.error.split(","))
    viewer = Viewer()
    server = foxglove.start_server(name=f"python-robot-{args.robot}", host="127.0.0.1",
                                   port=args.port, server_listener=viewer)
    channel = foxglove.Channel("/world_model", message_encoding="json")
    images = RawImageChannel(topic="/camera/image") if args.image else None
    print("ready", flush=True)
    sent = 0
    for line in sys.stdin:
        if not viewer.subscribed.is_set() or (args.stop_after and sent >= args.stop_after):
            continue  # silent, but still reading: the test's pipe never fills
        truth = json.loads(line)
        me = next((r for r in truth.get("robots", []) if r.get("id") == args.robot), None)
        if me is None or me.get("marker") is None:
            continue
        x, y = me["field_cm"]
        heading = me["heading_rad"]
        ball = truth.get("ball")
        model = {
            "team": me["marker"]["team"],
            "robot_id": me["marker"]["identity"],
            "self": {"x_cm": x + dx, "y_cm": y + dy, "heading_rad": heading + math.radians(dh)},
            "ball": None if ball is None else {"x_cm": ball["field_cm"][0], "y_cm": ball["field_cm"][1]},
            "time_ns": time.time_ns() + int(args.clock_offset * 1e9),
        }
        if ball is not None:
            bx, by = ball["field_cm"][0] - x, ball["field_cm"][1] - y
            bearing = math.atan2(by, bx) - heading
            bearing = math.atan2(math.sin(bearing), math.cos(bearing))
            model["seen"] = [{"object": "ball", "distance_cm": math.hypot(bx, by) * args.distance_scale,
                              "bearing_rad": bearing}]
        channel.log(json.dumps(model).encode())
        if images is not None:
            now = time.time_ns()
            data = bytes((k + 3 * sent) % 256 for k in range(64 * 48 * 2))
            images.log(RawImage(timestamp=Timestamp(sec=now // 10**9, nsec=now % 10**9),
                                frame_id="camera", width=64, height=48, encoding="uyvy",
                                step=128, data=data))
        sent += 1
        if args.stop_after and sent >= args.stop_after and args.exit_after:
            threading.Timer(args.exit_after, os._exit, args=(0,)).start()
    server.stop()


if __name__ == "__main__":
    main()
