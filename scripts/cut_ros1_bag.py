#!/usr/bin/env python3
"""Copy the first seconds of a ROS 1 bag into a new bag with the `rosbags` package
(a ROS 1 bag reader and writer that schuler does not share), for schuler's ROS 1 bag
tests (tests/data/ros1_bag/README.md).

The messages whose log time is at most --seconds after the bag's first are copied
unchanged (the serialized bytes as they are, in the order the reader gives them),
on connections with the original's topics, types, definitions, md5sums, caller ids
and latching, into chunks of at most --chunk-kib KiB (rosbags closes a chunk when it
passes that size) in the chosen compression.
"""

import argparse
import sys

from rosbags.rosbag1 import Reader, Writer


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("bag", help="the ROS 1 bag to copy from")
    p.add_argument("out", help="the .bag file to write (must not exist)")
    p.add_argument("--seconds", type=float, default=5.0)
    p.add_argument("--chunk-kib", type=int, default=16)
    p.add_argument("--compression", choices=["none", "bz2", "lz4"], default="none")
    a = p.parse_args()
    w = Writer(a.out)
    if a.compression != "none":
        w.set_compression(getattr(Writer.CompressionFormat, a.compression.upper()))
    w.chunk_threshold = a.chunk_kib * 1024
    count = 0
    with Reader(a.bag) as r, w:
        conns = {}
        for c in r.connections:
            conns[c.id] = w.add_connection(
                c.topic, c.msgtype, msgdef=c.msgdef.data, md5sum=c.digest,
                callerid=c.ext.callerid, latching=c.ext.latching)
        end = r.start_time + round(a.seconds * 1e9)
        for c, log_ns, raw in r.messages():
            if log_ns > end:
                break
            w.write(conns[c.id], log_ns, raw)
            count += 1
    print(f"{a.out}: {count} messages", file=sys.stderr)


if __name__ == "__main__":
    main()
