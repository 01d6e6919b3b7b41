#!/usr/bin/env python3
"""Writes the recordings robot-soccer teams make today, from the same frames, with writers that
are not eotn's: `rosbags` (rosbag2 folders, MCAP and SQLite storage), `mcap-ros2-support` (one
MCAP with ros2msg schemas) and the Foxglove SDK (foxglove.RawImage / CompressedImage).

    recordings.py SOURCE.mcap FRAMES OUT_DIR     writes every recording, prints a JSON manifest
    recordings.py --serve SOURCE.mcap FRAMES PORT   serves the frames live as ROS 2 `cdr`
                                                    channels (foxglove_bridge's way)

The frames are the first FRAMES images of an eotn stream (foxglove.RawImage, yuyv or uyvy),
turned into every encoding with the formulas of ../shared/FORMATS.md (YUV → RGB, exact integer
BT.601) and OpenCV (JPEG, PNG). The manifest names each recording and what its frames should
match: "exact" (lossless RGB/BGR and the 4:2:2 orders), "jpeg", "nv12", "bayer", "grey".
"""
import json
import re
import shutil
import sys
import time
from pathlib import Path

import cv2
import numpy as np
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory


def read_uyvy(source, count):
    """The first `count` frames of an eotn stream as UYVY arrays (h, 2w) and their times."""
    frames = []
    with open(source, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, channel, message, img in reader.iter_decoded_messages(topics=["/camera/image"]):
            data = np.frombuffer(img.data, dtype=np.uint8).reshape(img.height, img.step)
            data = data[:, : img.width * 2].copy()
            if img.encoding in ("yuyv", "yuv422_yuy2"):
                data = data.reshape(img.height, img.width // 2, 4)[:, :, [1, 0, 3, 2]]
                data = data.reshape(img.height, img.width * 2)
            frames.append((message.log_time, data))
            if len(frames) == count:
                break
    return frames


def planes(uyvy):
    """Y, U, V full-size planes of a UYVY frame (chroma repeated over each pixel pair)."""
    h, w2 = uyvy.shape
    q = uyvy.reshape(h, w2 // 4, 4).astype(np.int32)
    y = np.stack([q[:, :, 1], q[:, :, 3]], axis=2).reshape(h, w2 // 2)
    u = np.repeat(q[:, :, 0], 2, axis=1)
    v = np.repeat(q[:, :, 2], 2, axis=1)
    return y, u, v


def rgb_of(uyvy):
    """FORMATS.md's exact integer YUV → RGB."""
    y, u, v = planes(uyvy)
    c, d, e = 298 * (y - 16), u - 128, v - 128
    r = np.clip((c + 409 * e + 128) >> 8, 0, 255)
    g = np.clip((c - 100 * d - 208 * e + 128) >> 8, 0, 255)
    b = np.clip((c + 516 * d + 128) >> 8, 0, 255)
    return np.stack([r, g, b], axis=2).astype(np.uint8)


def nv12_of(uyvy):
    """NV12: the Y plane, then U V interleaved at half size (vertical pairs averaged)."""
    y, u, v = planes(uyvy)
    h, w = y.shape
    u2 = ((u[0::2, 0::2] + u[1::2, 0::2] + 1) // 2).astype(np.uint8)
    v2 = ((v[0::2, 0::2] + v[1::2, 0::2] + 1) // 2).astype(np.uint8)
    uv = np.stack([u2, v2], axis=2).reshape(h // 2, w)
    return np.concatenate([y.astype(np.uint8), uv], axis=0)


BAYER = {"rggb": [[0, 1], [1, 2]], "bggr": [[2, 1], [1, 0]], "gbrg": [[1, 2], [0, 1]],
         "grbg": [[1, 0], [2, 1]]}


def bayer_of(rgb, order):
    h, w, _ = rgb.shape
    out = np.zeros((h, w), np.uint8)
    for dy in range(2):
        for dx in range(2):
            out[dy::2, dx::2] = rgb[dy::2, dx::2, BAYER[order][dy][dx]]
    return out


def encodings(uyvy):
    """Every raw encoding of one frame: name → (bytes per row without padding, rows)."""
    rgb = rgb_of(uyvy)
    h, w, _ = rgb.shape
    alpha = np.full((h, w, 1), 255, np.uint8)
    yuyv = uyvy.reshape(h, w // 2, 4)[:, :, [1, 0, 3, 2]].reshape(h, w * 2)
    out = {
        "uyvy": uyvy, "yuyv": yuyv, "rgb8": rgb.reshape(h, w * 3),
        "bgr8": rgb[:, :, ::-1].reshape(h, w * 3),
        "rgba8": np.concatenate([rgb, alpha], axis=2).reshape(h, w * 4),
        "bgra8": np.concatenate([rgb[:, :, ::-1], alpha], axis=2).reshape(h, w * 4),
        "mono8": planes(uyvy)[0].astype(np.uint8), "nv12": nv12_of(uyvy),
    }
    for order in BAYER:
        out[f"bayer_{order}8"] = bayer_of(rgb, order)
    return out


def padded(rows, pad):
    """Rows with `pad` bytes of padding each (the `step` a driver may use)."""
    if pad == 0:
        return np.ascontiguousarray(rows).tobytes(), rows.shape[1]
    fill = np.full((rows.shape[0], pad), 0xEE, np.uint8)
    return np.concatenate([rows, fill], axis=1).tobytes(), rows.shape[1] + pad


def jpeg_of(uyvy):
    ok, buf = cv2.imencode(".jpg", rgb_of(uyvy)[:, :, ::-1], [cv2.IMWRITE_JPEG_QUALITY, 95])
    assert ok
    return buf.tobytes()


def png_of(uyvy):
    ok, buf = cv2.imencode(".png", rgb_of(uyvy)[:, :, ::-1])
    assert ok
    return buf.tobytes()


# --- ROS 2 messages through rosbags ---------------------------------------------------------

def ros_types():
    from rosbags.typesys import Stores, get_typestore
    return get_typestore(Stores.ROS2_HUMBLE)


def ros_messages(ts, frames, encoding=None, compressed=None, pad=0, with_tf=False):
    """(topic, msgtype, t, msg) for every frame and its side messages: the image, joint states,
    camera info; with `with_tf`, `/tf_static` first (the camera 25 cm up, level)."""
    T = ts.types
    Header, Time = T["std_msgs/msg/Header"], T["builtin_interfaces/msg/Time"]
    out = []
    tf = T["geometry_msgs/msg/TransformStamped"]
    tr = T["geometry_msgs/msg/Transform"]
    v3, q = T["geometry_msgs/msg/Vector3"], T["geometry_msgs/msg/Quaternion"]
    static = T["tf2_msgs/msg/TFMessage"](transforms=[
        tf(header=Header(stamp=Time(sec=0, nanosec=0), frame_id="base_footprint"),
           child_frame_id="camera_optical_frame",
           transform=tr(translation=v3(x=0.0, y=0.0, z=0.25),
                        rotation=q(x=-0.5, y=0.5, z=-0.5, w=0.5)))])
    t0 = frames[0][0]
    if with_tf:
        out.append(("/tf_static", "tf2_msgs/msg/TFMessage", t0, static))
    for t, uyvy in frames:
        stamp = Time(sec=int(t // 1_000_000_000), nanosec=int(t % 1_000_000_000))
        header = Header(stamp=stamp, frame_id="camera_optical_frame")
        h, w = uyvy.shape[0], uyvy.shape[1] // 2
        if compressed:
            data = jpeg_of(uyvy) if compressed == "jpeg" else png_of(uyvy)
            msg = T["sensor_msgs/msg/CompressedImage"](
                header=header, format=compressed, data=np.frombuffer(data, np.uint8))
            out.append(("/camera/image_raw/compressed", "sensor_msgs/msg/CompressedImage", t, msg))
        else:
            data, step = padded(encodings(uyvy)[encoding], pad)
            ros_name = {"uyvy": "yuv422", "yuyv": "yuv422_yuy2"}.get(encoding, encoding)
            msg = T["sensor_msgs/msg/Image"](
                header=header, height=h, width=w, encoding=ros_name, is_bigendian=0,
                step=step, data=np.frombuffer(data, np.uint8))
            out.append(("/camera/image_raw", "sensor_msgs/msg/Image", t, msg))
        js = T["sensor_msgs/msg/JointState"](
            header=header, name=["HeadYaw", "HeadPitch"],
            position=np.array([0.1, 0.2]), velocity=np.array([], dtype=np.float64),
            effort=np.array([], dtype=np.float64))
        out.append(("/joint_states", "sensor_msgs/msg/JointState", t, js))
        roi = T["sensor_msgs/msg/RegionOfInterest"](
            x_offset=0, y_offset=0, height=0, width=0, do_rectify=False)
        ci = T["sensor_msgs/msg/CameraInfo"](
            header=header, height=h, width=w, distortion_model="plumb_bob",
            d=np.zeros(5), k=np.array([200.0, 0, w / 2, 0, 200.0, h / 2, 0, 0, 1]),
            r=np.eye(3).flatten(), p=np.zeros(12), binning_x=0, binning_y=0, roi=roi)
        out.append(("/camera/camera_info", "sensor_msgs/msg/CameraInfo", t, ci))
    return out


def write_bag(path, messages, ts, storage, compression=None):
    from rosbags.rosbag2 import CompressionFormat, CompressionMode, StoragePlugin, Writer
    plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
    shutil.rmtree(path, ignore_errors=True)
    writer = Writer(path, version=8, storage_plugin=plugin)
    if compression:
        mode = CompressionMode.MESSAGE if compression == "message" else CompressionMode.FILE
        writer.set_compression(mode, CompressionFormat.ZSTD)
    with writer:
        conns = {}
        for topic, msgtype, t, msg in messages:
            if topic not in conns:
                conns[topic] = writer.add_connection(topic, msgtype, typestore=ts)
            writer.write(conns[topic], t, ts.serialize_cdr(msg, msgtype))


def as_version_7(metadata):
    """Rewrites a version-8 `metadata.yaml` as version 7 (drops `ros_distro`)."""
    text = metadata.read_text()
    v7, n = re.subn(r"(?m)^(\s+version:) 8$", r"\1 7", text)
    assert n == 1, text
    v7, n = re.subn(r"(?m)^\s+ros_distro:.*\n?", "", v7)
    assert n == 1, text
    assert "type_description_hash" in v7, text
    metadata.write_text(v7)


def split_bag(path, messages, ts, storage):
    """A split bag: two bags written by rosbags, their files in one folder, metadata listing
    both (as `ros2 bag record --max-bag-size` leaves it)."""
    half = len(messages) // 2
    first = [m for m in messages[:half]]
    second = [m for m in messages if m[0] == "/tf_static"] + messages[half:]
    write_bag(Path(str(path) + "_a"), first, ts, storage)
    write_bag(Path(str(path) + "_b"), second, ts, storage)
    shutil.rmtree(path, ignore_errors=True)
    path.mkdir()
    ext = "mcap" if storage == "mcap" else "db3"
    names = []
    for i, part in enumerate(["_a", "_b"]):
        src = Path(str(path) + part)
        f = next(src.glob(f"*.{ext}"))
        name = f"{path.name}_{i}.{ext}"
        shutil.move(str(f), path / name)
        names.append(name)
        if i == 0:
            meta = (src / "metadata.yaml").read_text()
        shutil.rmtree(src)
    first_name = f"{path.name}_a.{ext}"
    meta = meta.replace(f"  - {first_name}\n", "".join(f"  - {n}\n" for n in names))
    meta = meta.replace(f"path: {first_name}", f"path: {names[0]}")
    (path / "metadata.yaml").write_text(meta)


# --- MCAP through mcap-ros2-support and the Foxglove SDK --------------------------------------

IMAGE_MSGDEF = """std_msgs/Header header
uint32 height
uint32 width
string encoding
uint8 is_bigendian
uint32 step
uint8[] data
================================================================================
MSG: std_msgs/Header
builtin_interfaces/Time stamp
string frame_id
================================================================================
MSG: builtin_interfaces/Time
int32 sec
uint32 nanosec
"""


def write_mcap_ros2(path, frames, encoding):
    from mcap_ros2.writer import Writer
    with open(path, "wb") as f:
        w = Writer(f)
        schema = w.register_msgdef("sensor_msgs/msg/Image", IMAGE_MSGDEF)
        for t, uyvy in frames:
            h, w2 = uyvy.shape
            data = encodings(uyvy)[encoding]
            w.write_message("/camera/image_raw", schema, {
                "header": {"stamp": {"sec": t // 1_000_000_000, "nanosec": t % 1_000_000_000},
                           "frame_id": "camera"},
                "height": h, "width": w2 // 2,
                "encoding": {"uyvy": "yuv422", "yuyv": "yuv422_yuy2"}.get(encoding, encoding),
                "is_bigendian": 0, "step": data.shape[1], "data": data.tobytes()},
                log_time=t, publish_time=t)
        w.finish()


def foxglove_stamp(t):
    from foxglove.messages import Timestamp
    return Timestamp(sec=int(t // 1_000_000_000), nsec=int(t % 1_000_000_000))


def write_foxglove(path, frames, cameras):
    """An MCAP by the Foxglove SDK; `cameras` is [(topic, "jpeg"|"png"|raw encoding, pad)]."""
    import foxglove
    from foxglove.channels import CompressedImageChannel, RawImageChannel
    from foxglove.messages import CompressedImage, RawImage
    ctx = foxglove.Context()
    channels = []
    for topic, enc, _ in cameras:
        cls = CompressedImageChannel if enc in ("jpeg", "png") else RawImageChannel
        channels.append(cls(topic, context=ctx))
    with foxglove.open_mcap(path, allow_overwrite=True, context=ctx):
        for t, uyvy in frames:
            for (topic, enc, pad), ch in zip(cameras, channels):
                if enc in ("jpeg", "png"):
                    data = jpeg_of(uyvy) if enc == "jpeg" else png_of(uyvy)
                    ch.log(CompressedImage(timestamp=foxglove_stamp(t), frame_id="camera",
                                           data=data, format=enc), log_time=t)
                else:
                    data, step = padded(encodings(uyvy)[enc], pad)
                    h, w = uyvy.shape[0], uyvy.shape[1] // 2
                    ch.log(RawImage(timestamp=foxglove_stamp(t), frame_id="camera", width=w,
                                    height=h, encoding=enc, step=step, data=data), log_time=t)


def write_all(source, count, out):
    out.mkdir(parents=True, exist_ok=True)
    frames = read_uyvy(source, count)
    ts = ros_types()
    manifest = []

    def add(name, path, match):
        manifest.append({"name": name, "path": str(path), "match": match})

    write_foxglove(out / "reference.mcap", frames, [("/camera/image", "uyvy", 0)])
    add("reference uyvy (Foxglove SDK)", out / "reference.mcap", "exact")
    for enc, match, storage, pad in [
        ("yuyv", "exact", "mcap", 0), ("rgb8", "exact", "mcap", 0),
        ("bgr8", "exact", "sqlite", 8), ("uyvy", "exact", "sqlite", 0),
        ("rgba8", "exact", "mcap", 0), ("bgra8", "exact", "sqlite", 4),
        ("nv12", "nv12", "mcap", 0), ("mono8", "grey", "sqlite", 0),
        ("bayer_rggb8", "bayer", "mcap", 0), ("bayer_bggr8", "bayer", "sqlite", 0),
        ("bayer_gbrg8", "bayer", "mcap", 0), ("bayer_grbg8", "bayer", "sqlite", 0),
    ]:
        path = out / f"bag_{storage}_{enc}"
        write_bag(path, ros_messages(ts, frames, encoding=enc, pad=pad), ts, storage)
        add(f"rosbag2 {storage} sensor_msgs/Image {enc} step+{pad}", path, match)
    for storage in ["mcap", "sqlite"]:
        path = out / f"bag_{storage}_jpeg"
        write_bag(path, ros_messages(ts, frames, compressed="jpeg"), ts, storage)
        add(f"rosbag2 {storage} CompressedImage jpeg", path, "jpeg")
    path = out / "bag_mcap_png"
    write_bag(path, ros_messages(ts, frames, compressed="png"), ts, "mcap")
    add("rosbag2 mcap CompressedImage png", path, "exact")
    # A .db3 as Humble leaves it on a robot, without its metadata.yaml.
    lone = out / "lone"
    lone.mkdir(exist_ok=True)
    db3 = next((out / "bag_sqlite_bgr8").glob("*.db3"))
    shutil.copy(db3, lone / "robot_0.db3")
    add(".db3 without metadata.yaml", lone / "robot_0.db3", "exact")
    add("rosbag2 storage file (.mcap) alone", next((out / "bag_mcap_rgb8").glob("*.mcap")), "exact")
    add("rosbag2 metadata.yaml", out / "bag_sqlite_uyvy" / "metadata.yaml", "exact")
    for storage in ["mcap", "sqlite"]:
        path = out / f"tf_{storage}"
        write_bag(path, ros_messages(ts, frames, encoding="rgb8", with_tf=True), ts, storage)
        add(f"rosbag2 {storage} with /tf_static", path, "pose")
    for storage in ["mcap", "sqlite"]:
        path = out / f"split_{storage}"
        split_bag(path, ros_messages(ts, frames, encoding="rgb8"), ts, storage)
        add(f"split rosbag2 {storage}", path, "exact")
        for mode in ["message", "file"]:
            path = out / f"zstd_{mode}_{storage}"
            write_bag(path, ros_messages(ts, frames, encoding="yuyv"), ts, storage, mode)
            add(f"rosbag2 {storage} zstd {mode}", path, "exact")
    # Metadata version 7, as Iron's rosbag2 writes it: rosbags writes versions 8 and 9 only,
    # and version 7 is version 8 without `ros_distro` (rosbag2's yaml.hpp reads `ros_distro`
    # from version 8 on, `type_description_hash` from 7 on), so a version-8 bag is rewritten so.
    path = out / "bag_mcap_v7"
    write_bag(path, ros_messages(ts, frames, encoding="rgb8"), ts, "mcap")
    as_version_7(path / "metadata.yaml")
    add("rosbag2 mcap metadata v7", path, "exact")
    write_mcap_ros2(out / "mcap_ros2_yuv422.mcap", frames, "uyvy")
    add("mcap-ros2-support sensor_msgs/Image yuv422", out / "mcap_ros2_yuv422.mcap", "exact")
    for name, cams, match in [
        ("fox_jpeg", [("/camera/image", "jpeg", 0)], "jpeg"),
        ("fox_png", [("/camera/image", "png", 0)], "exact"),
        ("fox_rgb8", [("/cam", "rgb8", 0)], "exact"),
        ("fox_bgr8_padded", [("/cam", "bgr8", 16)], "exact"),
        ("fox_nv12", [("/cam", "nv12", 0)], "nv12"),
        ("fox_bayer_grbg8", [("/cam", "bayer_grbg8", 0)], "bayer"),
        ("fox_mono8", [("/cam", "mono8", 0)], "grey"),
        ("fox_two_cameras", [("/cam/front", "jpeg", 0), ("/cam/back", "rgb8", 0)], "jpeg"),
    ]:
        write_foxglove(out / f"{name}.mcap", frames, cams)
        add(f"Foxglove SDK {name}", out / f"{name}.mcap", match)
    print(json.dumps(manifest))


def serve(source, count, port):
    """Serves the frames live as foxglove_bridge does: ROS 2 topics as `cdr` channels with
    `ros2msg` schemas, the bytes serialised by rosbags; loops until killed."""
    import foxglove
    frames = read_uyvy(source, count)
    ts = ros_types()
    messages = ros_messages(ts, frames, encoding="rgb8")
    server = foxglove.start_server(name="ros2-bridge-like", host="127.0.0.1", port=port)
    channels = {}
    for topic, msgtype, _, _ in messages:
        if topic not in channels:
            schema = foxglove.Schema(name=msgtype, encoding="ros2msg",
                                     data=(IMAGE_MSGDEF if msgtype.endswith("/Image") else "").encode())
            channels[topic] = foxglove.Channel(topic, schema=schema, message_encoding="cdr")
    print(f"serving on {server.port}", flush=True)
    rounds = 0
    while rounds < 2000:
        rounds += 1
        for topic, msgtype, t, msg in messages:
            channels[topic].log(bytes(ts.serialize_cdr(msg, msgtype)), log_time=time.time_ns())
            if topic.startswith("/camera/image"):
                time.sleep(0.03)


if __name__ == "__main__":
    if sys.argv[1] == "--serve":
        serve(sys.argv[2], int(sys.argv[3]), int(sys.argv[4]))
    else:
        write_all(sys.argv[1], int(sys.argv[2]), Path(sys.argv[3]))
