"""A robot-side sender written with the official Foxglove SDK (not eotn): `--frames` UYVY frames
of 64x48 on /camera/image (foxglove.RawImage) and their readings on /sensors (JSON) at 30 fps,
after the first viewer subscribes. Byte k of frame i is (k + 3 i) mod 256. With `--bottom`, a second
camera too (32x24 on /camera/bottom, byte k of frame i (k + 5 i) mod 256, readings on
/camera/bottom/sensors)."""

import argparse
import json
import threading
import time

import foxglove
from foxglove.channels import RawImageChannel
from foxglove.messages import RawImage, Timestamp


class Viewer(foxglove.ServerListener):
    """Sets `subscribed` once a viewer has subscribed to the image and its readings (waiting for
    the image alone lost the readings of the first frames on a loaded machine)."""

    WANTED = {"/camera/image", "/sensors"}

    def __init__(self):
        self.subscribed = threading.Event()
        self.topics = set()

    def on_subscribe(self, client, channel):
        self.topics.add(channel.topic)
        if self.WANTED <= self.topics:
            self.subscribed.set()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--port", type=int, required=True)
    ap.add_argument("--frames", type=int, default=20)
    ap.add_argument("--bottom", action="store_true",
                    help="also a second camera: 32x24 frames on /camera/bottom, its readings on "
                         "/camera/bottom/sensors")
    args = ap.parse_args()
    viewer = Viewer()
    server = foxglove.start_server(name="python-robot", host="127.0.0.1", port=args.port,
                                   server_listener=viewer)
    images = RawImageChannel(topic="/camera/image")
    sensors = foxglove.Channel("/sensors", message_encoding="json")
    if args.bottom:
        bottom = RawImageChannel(topic="/camera/bottom")
        bottom_sensors = foxglove.Channel("/camera/bottom/sensors", message_encoding="json")
    viewer.subscribed.wait(30)
    time.sleep(0.2)  # the sensors subscription follows the image's in the same request
    w, h = 64, 48
    for i in range(args.frames):
        now = time.time_ns()
        data = bytes((k + 3 * i) % 256 for k in range(w * h * 2))
        stamp = Timestamp(sec=now // 1_000_000_000, nsec=now % 1_000_000_000)
        images.log(RawImage(timestamp=stamp, frame_id="camera", width=w, height=h,
                            encoding="uyvy", step=2 * w, data=data), log_time=now)
        sensors.log(json.dumps({"head_pan_rad": 0.01 * i}).encode(), log_time=now)
        if args.bottom:
            small = bytes((k + 5 * i) % 256 for k in range(32 * 24 * 2))
            bottom.log(RawImage(timestamp=stamp, frame_id="bottom", width=32, height=24,
                                encoding="uyvy", step=64, data=small), log_time=now)
            bottom_sensors.log(json.dumps({"head_pan_rad": -0.01 * i}).encode(), log_time=now)
        time.sleep(1 / 30)
    time.sleep(1.0)
    server.stop()


if __name__ == "__main__":
    main()
