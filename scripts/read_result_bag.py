#!/usr/bin/env python3
"""Print every message of a ROS 2 bag (MCAP) as one JSON object per line, decoded by
the `mcap` and `mcap-ros2-support` packages (not by schuler): topic, schema name,
message encoding, log time [ns], the header's stamp and frame, and the fields
schuler's result bag carries (Odometry: child frame, position, orientation x y z w,
pose covariance, linear velocity; NavSatFix: status, latitude, longitude, altitude,
covariance and its type; Vector3Stamped: the vector). For schuler's bag tests.
"""

import json
import sys

from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory


def fields(schema_name, m):
    if schema_name == "nav_msgs/msg/Odometry":
        p, q = m.pose.pose.position, m.pose.pose.orientation
        v = m.twist.twist.linear
        return {
            "child_frame_id": m.child_frame_id,
            "position": [p.x, p.y, p.z],
            "orientation": [q.x, q.y, q.z, q.w],
            "pose_covariance": list(m.pose.covariance),
            "linear": [v.x, v.y, v.z],
        }
    if schema_name == "sensor_msgs/msg/NavSatFix":
        return {
            "status": m.status.status,
            "latitude": m.latitude,
            "longitude": m.longitude,
            "altitude": m.altitude,
            "position_covariance": list(m.position_covariance),
            "position_covariance_type": m.position_covariance_type,
        }
    if schema_name == "geometry_msgs/msg/Vector3Stamped":
        return {"vector": [m.vector.x, m.vector.y, m.vector.z]}
    return {}


def main():
    with open(sys.argv[1], "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        out = sys.stdout
        for schema, channel, message, decoded in reader.iter_decoded_messages(
                log_time_order=False):
            row = {
                "topic": channel.topic,
                "type": schema.name,
                "encoding": channel.message_encoding,
                "log_time": message.log_time,
                "sec": decoded.header.stamp.sec,
                "nanosec": decoded.header.stamp.nanosec,
                "frame_id": decoded.header.frame_id,
            }
            row.update(fields(schema.name, decoded))
            out.write(json.dumps(row) + "\n")


if __name__ == "__main__":
    main()
