"""An independent SSL-Vision reader and log writer for tests/it/ssl_vision.rs (standard library
only): a protobuf wire-format decoder written from the messages' public field numbers, no .proto
file and no protobuf package, and the league's log format (SSL_LOG_FILE, version 1, big-endian).

    python3 ssl_vision.py receive OUT.json OUT.log FRAMES TIMEOUT_S

binds 127.0.0.1 on a free port, prints the port on stdout, receives packets until FRAMES
detection frames came (or TIMEOUT_S passed), writes what it decoded as JSON and the raw packets
as a league log (vision messages, with a referee and a blank message among them, as real logs
have, for eotn to skip).
"""

import json
import socket
import struct
import sys
import time

# Field number -> (name, type, repeated). Types: scalar names, or a message's schema name.
SCHEMAS = {
    "wrapper": {1: ("detection", "frame", False), 2: ("geometry", "geometry", False)},
    "frame": {
        1: ("frame_number", "uint32", False),
        2: ("t_capture", "double", False),
        3: ("t_sent", "double", False),
        4: ("camera_id", "uint32", False),
        5: ("balls", "ball", True),
        6: ("robots_yellow", "robot", True),
        7: ("robots_blue", "robot", True),
        8: ("t_capture_camera", "double", False),
    },
    "ball": {
        1: ("confidence", "float", False),
        2: ("area", "uint32", False),
        3: ("x", "float", False),
        4: ("y", "float", False),
        5: ("z", "float", False),
        6: ("pixel_x", "float", False),
        7: ("pixel_y", "float", False),
    },
    "robot": {
        1: ("confidence", "float", False),
        2: ("robot_id", "uint32", False),
        3: ("x", "float", False),
        4: ("y", "float", False),
        5: ("orientation", "float", False),
        6: ("pixel_x", "float", False),
        7: ("pixel_y", "float", False),
        8: ("height", "float", False),
    },
    "geometry": {1: ("field", "field_size", False), 2: ("calib", "calibration", True)},
    "field_size": {
        1: ("field_length", "int32", False),
        2: ("field_width", "int32", False),
        3: ("goal_width", "int32", False),
        4: ("goal_depth", "int32", False),
        5: ("boundary_width", "int32", False),
        6: ("field_lines", "line", True),
        7: ("field_arcs", "arc", True),
        11: ("line_thickness", "int32", False),
    },
    "line": {
        1: ("name", "string", False),
        2: ("p1", "vector", False),
        3: ("p2", "vector", False),
        4: ("thickness", "float", False),
    },
    "arc": {
        1: ("name", "string", False),
        2: ("center", "vector", False),
        3: ("radius", "float", False),
        4: ("a1", "float", False),
        5: ("a2", "float", False),
        6: ("thickness", "float", False),
    },
    "vector": {1: ("x", "float", False), 2: ("y", "float", False)},
    "calibration": {
        1: ("camera_id", "uint32", False),
        2: ("focal_length", "float", False),
        3: ("principal_point_x", "float", False),
        4: ("principal_point_y", "float", False),
        5: ("distortion", "float", False),
        6: ("q0", "float", False),
        7: ("q1", "float", False),
        8: ("q2", "float", False),
        9: ("q3", "float", False),
        10: ("tx", "float", False),
        11: ("ty", "float", False),
        12: ("tz", "float", False),
        16: ("pixel_image_width", "uint32", False),
        17: ("pixel_image_height", "uint32", False),
    },
}


def varint(buf, pos):
    value, shift = 0, 0
    while True:
        b = buf[pos]
        pos += 1
        value |= (b & 0x7F) << shift
        if b < 0x80:
            return value, pos
        shift += 7


def decode(buf, schema):
    """Decodes one message of `schema` (a SCHEMAS key); unknown fields are skipped."""
    fields = SCHEMAS[schema]
    out = {}
    pos = 0
    while pos < len(buf):
        key, pos = varint(buf, pos)
        number, wire = key >> 3, key & 7
        if wire == 0:
            raw, pos = varint(buf, pos)
        elif wire == 1:
            raw, pos = buf[pos : pos + 8], pos + 8
        elif wire == 2:
            n, pos = varint(buf, pos)
            raw, pos = buf[pos : pos + n], pos + n
        elif wire == 5:
            raw, pos = buf[pos : pos + 4], pos + 4
        else:
            raise ValueError(f"wire type {wire} at byte {pos}")
        if number not in fields:
            continue
        name, kind, repeated = fields[number]
        if kind == "double":
            value = struct.unpack("<d", raw)[0]
        elif kind == "float":
            value = struct.unpack("<f", raw)[0]
        elif kind == "uint32":
            value = raw
        elif kind == "int32":
            value = raw - (1 << 64) if raw >= 1 << 63 else raw
        elif kind == "string":
            value = raw.decode("utf-8")
        else:
            value = decode(raw, kind)
        if repeated:
            out.setdefault(name, []).append(value)
        else:
            out[name] = value
    return out


def log_message(out, receiver_ns, kind, payload):
    out.write(struct.pack(">qii", receiver_ns, kind, len(payload)))
    out.write(payload)


def receive(out_json, out_log, frames, timeout_s):
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4 << 20)
    sock.bind(("127.0.0.1", 0))
    print(sock.getsockname()[1], flush=True)
    sock.settimeout(0.2)
    deadline = time.monotonic() + timeout_s
    packets, detections, geometry = [], [], []
    while len(detections) < frames and time.monotonic() < deadline:
        try:
            data = sock.recv(65536)
        except socket.timeout:
            continue
        packets.append((time.time_ns(), data))
        wrapper = decode(data, "wrapper")
        if "detection" in wrapper:
            detections.append(wrapper["detection"])
        if "geometry" in wrapper:
            geometry.append(wrapper["geometry"])
    with open(out_json, "w") as f:
        json.dump({"detections": detections, "geometry": geometry}, f)
    with open(out_log, "wb") as f:
        f.write(b"SSL_LOG_FILE")
        f.write(struct.pack(">i", 1))
        for k, (t, data) in enumerate(packets):
            log_message(f, t, 4, data)  # MESSAGE_SSL_VISION_2014
            if k == 0:
                log_message(f, t, 3, b"\x08\x01")  # a referee message: skipped
                log_message(f, t, 0, b"")  # a blank message: skipped


if __name__ == "__main__":
    if len(sys.argv) != 6 or sys.argv[1] != "receive":
        sys.exit(__doc__)
    receive(sys.argv[2], sys.argv[3], int(sys.argv[4]), float(sys.argv[5]))
