"""The message table: each ROS message type the mapper reads, what it is for (scans, poses, tf),
its reader and the scan options it takes. The bag reader picks a topic's reader here by the
topic's type, and the node subscribes each scan type's topics from here; a new scan type is a
reader and a row (docs/contributing.md).

Types are spelled as ROS 2 names them (``sensor_msgs/msg/LaserScan``); :func:`norm_type` turns a
ROS 1 name (``sensor_msgs/LaserScan``) into it, so both find the same row.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from .cloud import read_point_cloud
from .laser import read_laser_scan, read_multi_echo

__all__ = ["MESSAGE_TYPES", "MessageType", "POSE_TYPES", "SCAN_TYPES", "TF_TYPES", "UNSUPPORTED_SENSORS",
           "message_type", "norm_type", "short_type"]


@dataclass(frozen=True)
class MessageType:
    """A row of the table.

    role: "scan" (read as a scan by ``read``), "pose" (the robot's poses: read_bag's pose topic,
    the node's Path) or "tf". read: (msg, ScanSettings, counts, fail, mount) -> LaserReading.
    options: the scan options (scan_options.SCAN_OPTIONS) it takes. topics: the node parameter
    listing its topics. mount: its reading needs the sensor's mount in the base frame (a cloud's
    height band), known before it is read. batched: the node takes it in its scan batches (a
    cloud, megabytes, is a callback of its own). noun: what the node's refusals call one."""

    name: str
    role: str
    read: Callable | None = None
    options: tuple = ()
    topics: str = ""
    mount: bool = False
    batched: bool = True
    noun: str = "scan"

    @property
    def package(self) -> str:
        return self.name.split("/")[0]

    @property
    def class_name(self) -> str:
        return self.name.split("/")[-1]


MESSAGE_TYPES = (
    MessageType("sensor_msgs/msg/LaserScan", "scan", read_laser_scan, ("no_return",), "scan_topics"),
    MessageType("sensor_msgs/msg/MultiEchoLaserScan", "scan", read_multi_echo, ("no_return", "echo"),
                "multi_echo_topics"),
    MessageType("sensor_msgs/msg/PointCloud2", "scan", read_point_cloud,
                ("no_return", "z_band", "cloud_angle_step", "cloud_range_max"), "cloud_topics", mount=True,
                batched=False, noun="cloud"),
    MessageType("nav_msgs/msg/Odometry", "pose"),
    MessageType("nav_msgs/msg/Path", "pose", topics="path_topic"),
    MessageType("geometry_msgs/msg/PoseStamped", "pose"),
    MessageType("geometry_msgs/msg/PoseWithCovarianceStamped", "pose"),
    MessageType("tf2_msgs/msg/TFMessage", "tf"),
    MessageType("tf/msg/tfMessage", "tf"),  # old ROS 1 tf
)

_BY_NAME = {t.name: t for t in MESSAGE_TYPES}
SCAN_TYPES = tuple(t.name for t in MESSAGE_TYPES if t.role == "scan")
POSE_TYPES = tuple(t.name for t in MESSAGE_TYPES if t.role == "pose")
TF_TYPES = tuple(t.name for t in MESSAGE_TYPES if t.role == "tf")

# Sensors a bag may hold that are not read: why each is not mapped, and what turns it into a
# type that is.
_DEPTH = "an image; depthimage_to_laserscan turns a depth image into a LaserScan"
UNSUPPORTED_SENSORS = {
    "sensor_msgs/msg/PointCloud": "a point cloud of the old type (sensor_msgs/PointCloud): "
                                  "point_cloud_converter turns it into a PointCloud2",
    "sensor_msgs/msg/Image": _DEPTH,
    "sensor_msgs/msg/CompressedImage": _DEPTH,
    "sensor_msgs/msg/Range": "one range a message (a sonar or infrared ranger), not a scan",
    "sensor_msgs/msg/Imu": "an inertial unit: no ranges",
}


def norm_type(msgtype: str | None) -> str | None:
    """ROS 2 spelling of a message type: sensor_msgs/LaserScan -> sensor_msgs/msg/LaserScan."""
    if msgtype and msgtype.count("/") == 1:
        pkg, name = msgtype.split("/")
        return f"{pkg}/msg/{name}"
    return msgtype


def short_type(msgtype: str | None) -> str:
    """ROS 1 spelling for messages: sensor_msgs/msg/LaserScan -> sensor_msgs/LaserScan."""
    return (msgtype or "mixed types").replace("/msg/", "/")


def message_type(msgtype: str | None) -> MessageType | None:
    """The row of a message type in either spelling; None for a type the mapper does not read."""
    return _BY_NAME.get(norm_type(msgtype) or "")
