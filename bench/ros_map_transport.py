#!/usr/bin/env python3
"""A map from one process to another over Fast DDS's shared memory, as the node publishes it:
publish() -> the subscriber's callback, per map size, with Fast DDS's defaults (a message cut
into fragments of 65,500 bytes), with the node's own profile (vasco_gpu/ros/
fastdds_shm_maps.xml: whole messages up to 4 MiB), and with the profile and glibc's
thresholds raised in both processes as the node raises them in its own (vasco_gpu/ros/
message_buffers.py: the node takes Paths as large as maps; a subscriber of /map can do the
same), ratios in the same run. The publisher is a child process (the profile is read when
its participant starts); the subscriber is this one, which keeps Fast DDS's defaults and,
until the last column, glibc's.

  map        cells (an OccupancyGrid of one byte a cell: fr079, fr101 at 0.05 m, 2000 x 2000)
  default    median ms over --maps maps, Fast DDS's defaults on the publisher
  profile    the same with the node's profile
  +buffers   the profile, and glibc's thresholds raised in both processes (measured last)
  ratio      default / +buffers
  bench/ros_map_transport.py [--maps 20]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from array import array
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "python" / "tests"))
if "--publish" not in sys.argv:  # the child takes its parent's environment, domain included
    import ros_support  # noqa: E402,F401  (shared memory alone, a domain of its own)

import numpy as np  # noqa: E402

SIZES = [(941, 375), (1302, 1267), (2000, 2000)]
TOPIC = "map_transport_bench"


def qos():
    """/map's QoS, the node's own (reliable, transient local, depth 1)."""
    from vasco_gpu.ros.node import LATCHED

    return LATCHED


def publish(width: int, height: int, count: int, buffers: int) -> int:
    """The child: count maps, 0.2 s apart, each stamped with CLOCK_MONOTONIC when published."""
    if buffers:
        from vasco_gpu.ros.message_buffers import keep_message_buffers

        if not keep_message_buffers():
            raise RuntimeError("glibc's thresholds could not be raised here")
    import rclpy
    from nav_msgs.msg import OccupancyGrid

    rclpy.init()
    node = rclpy.create_node("map_transport_publisher")
    pub = node.create_publisher(OccupancyGrid, TOPIC, qos())
    end = time.monotonic() + 20
    while pub.get_subscription_count() == 0 and time.monotonic() < end:
        time.sleep(0.01)
    time.sleep(0.5)
    msg = OccupancyGrid()
    msg.info.width, msg.info.height = width, height
    msg.data = array("b", bytes(width * height))
    for _ in range(count):
        ns = time.monotonic_ns()
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(ns, 10**9)
        pub.publish(msg)
        time.sleep(0.2)
    time.sleep(0.5)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


def latencies(node, executor, width: int, height: int, count: int, profile: bool, buffers: bool = False) -> list[float]:
    from nav_msgs.msg import OccupancyGrid

    from vasco_gpu.ros.transport import MAP_SIZED_SHM_PROFILE

    got = []
    sub = node.create_subscription(OccupancyGrid, TOPIC, lambda m: got.append(
        (time.monotonic_ns() - (m.header.stamp.sec * 10**9 + m.header.stamp.nanosec)) * 1e-6), qos())
    env = {k: v for k, v in os.environ.items() if not k.endswith("_DEFAULT_PROFILES_FILE")}
    if profile:
        env["FASTDDS_DEFAULT_PROFILES_FILE"] = str(MAP_SIZED_SHM_PROFILE)
    child = subprocess.Popen([sys.executable, __file__, "--publish", str(width), str(height), str(count),
                              str(int(buffers))], env=env)
    try:
        end = time.monotonic() + 60
        while child.poll() is None and time.monotonic() < end:
            executor.spin_once(timeout_sec=0.05)
        if child.wait(10) != 0 or len(got) < count // 2:
            raise RuntimeError(f"{width} x {height}: {len(got)} of {count} maps came")
    finally:
        if child.poll() is None:
            child.kill()
        node.destroy_subscription(sub)
    return got[1:]  # the first may be the transient-local sample, sent on matching


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--maps", type=int, default=20)
    ap.add_argument("--publish", nargs=4, type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.publish:
        return publish(*args.publish)
    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    from vasco_gpu.ros.message_buffers import keep_message_buffers

    rclpy.init()
    node = rclpy.create_node("map_transport_bench")
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    print(f"# publish() -> subscriber over Fast DDS shared memory, median of {args.maps} maps")
    rows = {}
    try:
        for w, h in SIZES:
            rows[w, h] = [float(np.median(latencies(node, executor, w, h, args.maps, False))),
                          float(np.median(latencies(node, executor, w, h, args.maps, True)))]
        # then both processes with glibc's thresholds raised: from here on in this one too
        if not keep_message_buffers():
            raise RuntimeError("glibc's thresholds could not be raised here")
        for w, h in SIZES:
            rows[w, h].append(float(np.median(latencies(node, executor, w, h, args.maps, True, buffers=True))))
        print(f"{'map':>11} {'MB':>6} {'default ms':>10} {'profile ms':>10} {'+buffers ms':>11} {'ratio':>6}")
        for (w, h), (default, profile, kept) in rows.items():
            print(f"{f'{w}x{h}':>11} {w * h / 1e6:>6.2f} {default:>10.2f} {profile:>10.2f} {kept:>11.2f} "
                  f"{default / kept:>5.1f}x", flush=True)
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
