#!/usr/bin/env python3
"""Print every message of a ROS 1 bag that schuler reads (sensor_msgs/Imu,
NavSatFix, FluidPressure, geometry_msgs/TwistWithCovarianceStamped, nav_msgs/Odometry,
tf2_msgs/TFMessage), decoded by the `rosbags` package (not by schuler), one JSON
object per line: topic, type, 1-based index within the topic, log time [ns], the
header's stamp and frame, and the values as the 64-bit patterns of their float64s
(`bits`, in the order of the message definition), so that a comparison is exact.
For schuler's ROS 1 bag tests (crates/schuler-cli/tests/bag_python.rs).
"""

import json
import struct
import sys

from rosbags.rosbag1 import Reader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore


def bits(*xs):
    return [struct.unpack("<Q", struct.pack("<d", float(x)))[0] for x in xs]


def vec(v):
    return [v.x, v.y, v.z]


def quat(q):
    return [q.x, q.y, q.z, q.w]


def values(typename, m):
    if typename == "sensor_msgs/msg/Imu":
        return (quat(m.orientation) + list(m.orientation_covariance)
                + vec(m.angular_velocity) + list(m.angular_velocity_covariance)
                + vec(m.linear_acceleration) + list(m.linear_acceleration_covariance))
    if typename == "sensor_msgs/msg/NavSatFix":
        return ([m.status.status, m.status.service, m.latitude, m.longitude, m.altitude]
                + list(m.position_covariance) + [m.position_covariance_type])
    if typename == "geometry_msgs/msg/TwistWithCovarianceStamped":
        t = m.twist
        return vec(t.twist.linear) + vec(t.twist.angular) + list(t.covariance)
    if typename == "sensor_msgs/msg/FluidPressure":
        return [m.fluid_pressure, m.variance]
    if typename == "nav_msgs/msg/Odometry":
        p, t = m.pose, m.twist
        return (vec(p.pose.position) + quat(p.pose.orientation) + list(p.covariance)
                + vec(t.twist.linear) + vec(t.twist.angular) + list(t.covariance))
    if typename == "tf2_msgs/msg/TFMessage":
        out = []
        for t in m.transforms:
            out += vec(t.transform.translation) + quat(t.transform.rotation)
        return out
    return None


def main():
    ts = get_typestore(Stores.ROS1_NOETIC)
    if "tf2_msgs/msg/TFMessage" not in ts.types:
        ts.register(get_types_from_msg(
            "geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage"))
    counts = {}
    with Reader(sys.argv[1]) as r:
        for conn, log_ns, raw in r.messages():
            m = ts.deserialize_ros1(raw, conn.msgtype)
            v = values(conn.msgtype, m)
            if v is None:
                continue
            counts[conn.topic] = counts.get(conn.topic, 0) + 1
            out = {"topic": conn.topic, "type": conn.msgtype, "md5sum": conn.digest,
                   "index": counts[conn.topic], "log_time": log_ns, "bits": bits(*v)}
            h = getattr(m, "header", None)
            if h is None and conn.msgtype == "tf2_msgs/msg/TFMessage" and m.transforms:
                h = m.transforms[0].header
                out["child_frame_id"] = m.transforms[0].child_frame_id
            if h is not None:
                out.update(sec=h.stamp.sec, nanosec=h.stamp.nanosec, frame_id=h.frame_id)
            if conn.msgtype == "nav_msgs/msg/Odometry":
                out["child_frame_id"] = m.child_frame_id
            print(json.dumps(out))


if __name__ == "__main__":
    main()
