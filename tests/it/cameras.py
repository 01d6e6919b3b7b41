"""Two-camera recordings written by tools that are not eotn's, for tests/it/cameras.rs.

Usage: cameras.py SOURCE.mcap COUNT OUT_DIR. Takes COUNT frames of an eotn stream: the top
camera is every frame at full size, the bottom camera every second frame at half size (rows and
pixel pairs dropped), a different rate and size. Writes, and prints as JSON:
- `bag_two`: a rosbag2 (MCAP storage, by rosbags) with `/camera/top/image_raw` `yuv422_yuy2`
  and `/camera/bottom/image_raw` `rgb8`, each with its own `camera_info`;
- `bag_top`, `bag_bottom`: each camera alone, the same messages;
- `fox_two`: a Foxglove SDK MCAP with `/camera/top` (uyvy) and `/camera/bottom` (rgb8);
- `fox_top`, `fox_bottom`: each alone.
"""
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import numpy as np  # noqa: E402

from recordings import encodings, read_uyvy, ros_types, write_bag  # noqa: E402


def bottom_of(uyvy):
    """Half size: every second row, every second pixel pair (UYVY stays UYVY)."""
    h, w2 = uyvy.shape
    pairs = uyvy.reshape(h, w2 // 4, 4)[::2, ::2, :]
    return pairs.reshape(h // 2, -1).copy()


def image_messages(ts, frames, topic, encoding):
    T = ts.types
    Header, Time = T["std_msgs/msg/Header"], T["builtin_interfaces/msg/Time"]
    roi = T["sensor_msgs/msg/RegionOfInterest"](
        x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
    ns = topic.rsplit("/", 1)[0]
    out = []
    for t, uyvy in frames:
        stamp = Time(sec=int(t // 1_000_000_000), nanosec=int(t % 1_000_000_000))
        header = Header(stamp=stamp, frame_id=ns.strip("/").replace("/", "_"))
        h, w = uyvy.shape[0], uyvy.shape[1] // 2
        data = np.ascontiguousarray(encodings(uyvy)[encoding]).tobytes()
        ros_name = {"uyvy": "yuv422", "yuyv": "yuv422_yuy2"}.get(encoding, encoding)
        step = len(data) // h
        out.append((topic, "sensor_msgs/msg/Image", t, T["sensor_msgs/msg/Image"](
            header=header, height=h, width=w, encoding=ros_name, is_bigendian=0,
            step=step, data=np.frombuffer(data, np.uint8))))
        ci = T["sensor_msgs/msg/CameraInfo"](
            header=header, height=h, width=w, distortion_model="plumb_bob",
            d=np.zeros(5), k=np.array([200.0, 0, w / 2, 0, 200.0, h / 2, 0, 0, 1]),
            r=np.eye(3).flatten(), p=np.zeros(12), binning_x=0, binning_y=0, roi=roi)
        out.append((ns + "/camera_info", "sensor_msgs/msg/CameraInfo", t, ci))
    return out


def main(source, count, out):
    out.mkdir(parents=True, exist_ok=True)
    frames = read_uyvy(source, count)
    top = frames
    # The bottom camera: every second frame, 5 ms later, half size.
    bottom = [(t + 5_000_000, bottom_of(f)) for t, f in frames[::2]]
    ts = ros_types()
    top_msgs = image_messages(ts, top, "/camera/top/image_raw", "yuyv")
    bottom_msgs = image_messages(ts, bottom, "/camera/bottom/image_raw", "rgb8")
    both = sorted(top_msgs + bottom_msgs, key=lambda m: m[2])
    made = {}
    for name, msgs in [("bag_two", both), ("bag_top", top_msgs), ("bag_bottom", bottom_msgs)]:
        write_bag(out / name, msgs, ts, "mcap")
        made[name] = str(out / name)
    # The Foxglove SDK logs every camera at each time given; the bottom camera gets its own
    # frames by writing the two cameras as two files' worth of logs into one context.
    import foxglove
    from foxglove.channels import RawImageChannel
    from foxglove.messages import RawImage

    from recordings import foxglove_stamp

    def log(ch, t, uyvy, enc):
        data = bytes(np.ascontiguousarray(encodings(uyvy)[enc]).tobytes())
        h, w = uyvy.shape[0], uyvy.shape[1] // 2
        ch.log(RawImage(timestamp=foxglove_stamp(t), frame_id="camera", width=w, height=h,
                        encoding=enc, step=len(data) // h, data=data), log_time=t)

    for name, cams in [("fox_two", ["top", "bottom"]), ("fox_top", ["top"]),
                       ("fox_bottom", ["bottom"])]:
        ctx = foxglove.Context()
        chans = {c: RawImageChannel(f"/camera/{c}", context=ctx) for c in cams}
        events = []
        if "top" in chans:
            events += [(t, "top", f, "uyvy") for t, f in top]
        if "bottom" in chans:
            events += [(t, "bottom", f, "rgb8") for t, f in bottom]
        events.sort(key=lambda e: e[0])
        with foxglove.open_mcap(out / f"{name}.mcap", allow_overwrite=True, context=ctx):
            for t, c, f, enc in events:
                log(chans[c], t, f, enc)
        made[name] = str(out / f"{name}.mcap")
    print(json.dumps(made))


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), Path(sys.argv[3]))
