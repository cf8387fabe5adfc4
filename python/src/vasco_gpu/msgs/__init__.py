"""vasco_gpu.msgs: the ROS message adapters, below both the bag reader (:mod:`vasco_gpu.bags`)
and the ROS 2 node (:mod:`vasco_gpu.ros`). A message in (a rosbags object or an rclpy one: the
same fields), the mapper's arrays out. No rosbags, no rclpy and no compiled code here.

The parts, one job each: :mod:`.table` (each message type's role, reader and options),
:mod:`.scan_options` (the scan adapters' options: defaults, choices, checks), :mod:`.laser`
(LaserScan and MultiEchoLaserScan by REP 117), :mod:`.cloud` (PointCloud2 as a planar scan),
:mod:`.tf` (TfBuffer: TFMessages and lookups), :mod:`.path` (a nav_msgs/Path's poses checked),
:mod:`.header` (stamps, frame names), :mod:`.geometry` (quaternions, slerp, planar poses),
:mod:`.series` (samples over time), :mod:`.errors` (BagError, TfError).
"""

from __future__ import annotations

from .scan_options import SCAN_DEFAULTS, SCAN_OPTIONS, ScanSettings
from .table import MESSAGE_TYPES, MessageType, message_type

__all__ = ["MESSAGE_TYPES", "MessageType", "SCAN_DEFAULTS", "SCAN_OPTIONS", "ScanSettings", "message_type"]
