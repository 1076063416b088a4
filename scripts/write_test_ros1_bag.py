#!/usr/bin/env python3
"""Write a ROS 1 bag (format 2.0) from the files `schuler simulate` writes, with the
`rosbags` package (a ROS 1 bag writer and serializer that schuler does not share),
for schuler's ROS 1 bag tests.

The messages are those of scripts/write_test_bag.py (same topics, stamps, values
and log times; ROS 1 headers carry a per-topic seq), serialized by rosbags for ROS 1
(noetic's definitions and md5sums), plus a latched /tf_static
(tf2_msgs/TFMessage) holding base_link -> imu_link. With --imu-rpy R,P,Y [deg] the
IMU frame is turned from base_link by tf2's RPY (fixed axes: R = Rz(Y) Ry(P) Rx(R)),
its quaternion in /tf_static, and every IMU vector is written in imu_link's axes:
v_imu = R^T v_base (base_link FLU, REP 103), as scripts/write_test_bag.py does.
"""

import argparse
import dataclasses
import math
import os
import sys

import numpy as np
from rosbags.rosbag1 import Writer
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import write_test_bag as ros2  # noqa: E402  (the same messages as the MCAP bags)

TYPES = {
    "/imu/data": "sensor_msgs/msg/Imu",
    "/gnss/fix": "sensor_msgs/msg/NavSatFix",
    "/gnss/vel": "geometry_msgs/msg/TwistWithCovarianceStamped",
    "/baro": "sensor_msgs/msg/FluidPressure",
    "/odom": "nav_msgs/msg/Odometry",
    "/tf_static": "tf2_msgs/msg/TFMessage",
}


def typestore():
    ts = get_typestore(Stores.ROS1_NOETIC)
    if "tf2_msgs/msg/TFMessage" not in ts.types:
        ts.register(get_types_from_msg(
            "geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage"))
    return ts


def build(ts, typename, value, seq):
    """The rosbags message of `typename` from a dict (ROS 2 field names; a header's
    missing seq is `seq`)."""
    cls = ts.types[typename]
    kwargs = {}
    for f in dataclasses.fields(cls):
        if f.name.startswith("__") or f.name.isupper():
            continue  # the type's name and its constants
        t = f.type if isinstance(f.type, str) else f.type.__name__
        if f.name == "seq" and "seq" not in value:
            kwargs["seq"] = seq
        elif t.startswith("np.ndarray"):
            kwargs[f.name] = np.array(value[f.name], dtype=np.float64)
        elif t.startswith("list["):
            sub = t[5:-1].replace("__msg__", "/msg/")
            kwargs[f.name] = [build(ts, sub, x, seq) for x in value[f.name]]
        elif "__msg__" in t:
            kwargs[f.name] = build(ts, t.replace("__msg__", "/msg/"), value[f.name], seq)
        else:
            kwargs[f.name] = value[f.name]
    return cls(**kwargs)


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("sim", help="a `schuler simulate --out` directory")
    p.add_argument("out", help="the .bag file to write (must not exist)")
    p.add_argument("--odometer-rate", type=float)
    p.add_argument("--latency", type=float, default=0.05)
    p.add_argument("--compression", choices=["none", "bz2", "lz4"], default="none")
    p.add_argument("--imu-rpy", default="0,0,0",
                   help="imu_link's roll, pitch, yaw from base_link [deg]")
    p.add_argument("--no-tf", action="store_true", help="no /tf_static")
    a = p.parse_args()
    latency_ns = round(a.latency * 1e9)
    rpy = [math.radians(float(x)) for x in a.imu_rpy.split(",")]
    q = ros2.rpy_quaternion(*rpy)
    rt = ros2.transposed_matrix(q)
    streams = [ros2.imu_messages(f"{a.sim}/imu.txt", None, None),
               ros2.gnss_messages(f"{a.sim}/gnss.csv", latency_ns),
               ros2.baro_messages(f"{a.sim}/baro.csv", latency_ns)]
    if a.odometer_rate:
        streams.append(ros2.odometry_messages(f"{a.sim}/truth.nav", a.odometer_rate,
                                              latency_ns))
    messages = [m for s in streams for m in s]
    messages.sort(key=lambda m: m[0])
    if not a.no_tf:
        first = messages[0][0]
        messages.insert(0, ros2.tf_static(first, q))
    ts = typestore()
    w = Writer(a.out)
    if a.compression != "none":
        w.set_compression(getattr(Writer.CompressionFormat, a.compression.upper()))
    counts = {}
    with w:
        conns = {}
        for topic, typename in TYPES.items():
            latching = 1 if topic == "/tf_static" else None
            conns[topic] = w.add_connection(topic, typename, typestore=ts,
                                            latching=latching)
        for log_ns, topic, msg in messages:
            if topic == "/imu/data":
                msg = ros2.turned(msg, rt)
                msg["header"]["frame_id"] = "imu_link"
            seq = counts.get(topic, 0)
            counts[topic] = seq + 1
            data = ts.serialize_ros1(build(ts, TYPES[topic], msg, seq), TYPES[topic])
            w.write(conns[topic], log_ns, data)
    print(f"{a.out}: " + ", ".join(f"{t} {n}" for t, n in sorted(counts.items())),
          file=sys.stderr)


if __name__ == "__main__":
    main()
