#!/usr/bin/env python3
"""The floor under the node's Path -> /map: a process that maps nothing and answers each Path
with a /map made beforehand, of the size the node's last /map had. It takes the Path as the node
does (its topic, QoS, as bytes) and publishes as the node does (the map-sized shared-memory
profile, the kept message buffers, /map's QoS), so what ros_node_bench measures through it is
what ROS 2 itself costs a Path and a map of that size: DDS both ways, the wake-ups, rclpy's
publish and the subscriber's conversion. The node cannot go below it plus its own render.

  bench/ros_floor_relay.py WIDTH HEIGHT   (ROS environment as the bench's: SHM, its domain)
Prints "ready" once subscribed; SIGINT ends it with status 0."""

from __future__ import annotations

import sys
from array import array

from vasco_gpu.ros.message_buffers import keep_message_buffers
from vasco_gpu.ros.transport import use_map_sized_shm

keep_message_buffers()  # as the node: before the large allocations
use_map_sized_shm()  # as the node: before rclpy loads Fast DDS

import rclpy  # noqa: E402
from nav_msgs.msg import OccupancyGrid, Path  # noqa: E402
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor  # noqa: E402

from vasco_gpu.ros.node import PATH  # noqa: E402  (the node's QoS for the Path)
from vasco_gpu.ros.publication import LATCHED  # noqa: E402  (and for /map)
from vasco_gpu.ros.settings import NODE_PARAMETERS  # noqa: E402

PATH_TOPIC = next(p.default for p in NODE_PARAMETERS if p.name == "path_topic")


def main(argv) -> int:
    width, height = int(argv[1]), int(argv[2])
    rclpy.init()
    node = rclpy.create_node("vasco_floor_relay")
    grid = OccupancyGrid()
    grid.header.frame_id = "map"
    grid.info.width, grid.info.height, grid.info.resolution = width, height, 0.05
    grid.data = array("b", bytes(width * height))
    pub = node.create_publisher(OccupancyGrid, "map", LATCHED)

    def on_path(_raw: bytes) -> None:
        grid.header.stamp = node.get_clock().now().to_msg()
        pub.publish(grid)

    node.create_subscription(Path, PATH_TOPIC, on_path, PATH, raw=True)
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    print("ready", flush=True)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
