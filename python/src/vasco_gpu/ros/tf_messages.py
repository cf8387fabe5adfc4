"""The message types the node needs beyond rclpy's own wheels: tf2_msgs/TFMessage (/tf and
/tf_static) and map_msgs/OccupancyGridUpdate (map_updates). A system ROS 2 has both; the PyPI
wheels of ROS 2 do not, and the repository's ros/ package generates them (docs/ros.md)."""

from __future__ import annotations

from .._errors import Error

__all__ = ["MissingMessages", "tf_message_type", "map_update_type"]

HOW = ("install them with `pip install ./ros` from the vasco_gpu repository (ROS 2 from PyPI; "
       "ROS_DISTRO=jazzy for Jazzy's wheels), or source a ROS 2 installation that has {apt} "
       "(apt: ros-$ROS_DISTRO-{deb})")


class MissingMessages(Error, ImportError):
    """A message package the node needs is not installed; the text says how to install it."""


def _missing(package: str, e: ImportError) -> MissingMessages:
    how = HOW.format(apt=package, deb=package.replace("_", "-"))
    return MissingMessages(f"the Python package {package} is missing ({e}): {how}")


def tf_message_type():
    """The TFMessage class; MissingMessages naming the fix when tf2_msgs is not installed."""
    try:
        from tf2_msgs.msg import TFMessage
    except ImportError as e:
        raise _missing("tf2_msgs", e) from None
    return TFMessage


def map_update_type():
    """The OccupancyGridUpdate class; MissingMessages naming the fix when map_msgs is not
    installed."""
    try:
        from map_msgs.msg import OccupancyGridUpdate
    except ImportError as e:
        raise _missing("map_msgs", e) from None
    return OccupancyGridUpdate
