"""vasco_gpu.ros: the ROS 2 mapping node ``vasco_mapper`` (console script ``vasco_map_node``,
or ``python -m vasco_gpu.ros``). Scans (LaserScan, MultiEchoLaserScan) posed by tf, the
optimizer's nav_msgs/Path moving every stored scan, the whole map republished on ``map``.
Needs rclpy (a system ROS 2, or ``pip install ".[ros]"``); ``import vasco_gpu`` does not
import this package. Guide: docs/ros.md."""

from __future__ import annotations

__all__ = ["main"]


def main(argv=None) -> int:
    """Runs the node until SIGINT or SIGTERM; 0 on a clean exit, 2 for a bad parameter."""
    from .run import main as run

    return run(argv)
