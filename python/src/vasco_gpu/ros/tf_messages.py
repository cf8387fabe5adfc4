"""tf2_msgs/TFMessage, the type of /tf and /tf_static. A system ROS 2 has it; the PyPI wheels of
ROS 2 do not, and the repository's ros/tf2_msgs package generates it (docs/ros.md)."""

from __future__ import annotations

from .._errors import Error

__all__ = ["MissingMessages", "tf_message_type"]

HOW = ("install it with `pip install ./ros/tf2_msgs` from the vasco_gpu repository (ROS 2 from "
       "PyPI), or source a ROS 2 installation that has tf2_msgs (apt: ros-$ROS_DISTRO-tf2-msgs)")


class MissingMessages(Error, ImportError):
    """A message package the node needs is not installed; the text says how to install it."""


def tf_message_type():
    """The TFMessage class; MissingMessages naming the fix when tf2_msgs is not installed."""
    try:
        from tf2_msgs.msg import TFMessage
    except ImportError as e:
        raise MissingMessages(f"the Python package tf2_msgs is missing ({e}): {HOW}") from None
    return TFMessage
