"""Starting and stopping the node: rclpy's context, the executor, a clean exit on SIGINT or
SIGTERM (the DDS participant destroyed, so no shared-memory segment is left behind), and a bad
parameter refused before anything starts."""

from __future__ import annotations

import sys

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor

from . import _interrupted
from .settings import SettingsError
from .tf_messages import MissingMessages


def main(argv=None) -> int:
    """0 after SIGINT or SIGTERM at any point (also while starting), 1 when ROS 2 does not start,
    2 for a bad parameter or a missing message package."""
    args = sys.argv if argv is None else argv
    try:
        rclpy.init(args=args)
    except KeyboardInterrupt:
        return 0
    except Exception as e:  # rclpy's RCLError and friends: no DDS participant, bad --ros-args
        print(f"vasco_mapper: ROS 2 did not start: {e}", file=sys.stderr)
        return 1
    node = None
    try:
        try:
            from .node import MappingNode  # nav_msgs, sensor_msgs, std_srvs

            node = MappingNode()
        except (SettingsError, MissingMessages, ImportError) as e:
            if _interrupted(e) or not rclpy.ok():  # a signal while the message packages loaded
                return 0
            print(f"vasco_mapper: {e}", file=sys.stderr)
            return 2
        except Exception:  # rclpy's RCLError: a signal shut ROS 2 down while the node was made
            if rclpy.ok():
                raise
            return 0
        executor = SingleThreadedExecutor()
        executor.add_node(node)
        # only now: a signal from here on ends the spin cleanly; activate logs the ready line
        if not node.settings.autostart:
            node.get_logger().info("unconfigured (autostart: false): waiting for a lifecycle manager to configure "
                                   "and activate the node")
        elif not node.start():
            if not rclpy.ok():  # a signal shut ROS 2 down while the node configured
                return 0
            print(f"vasco_mapper: {node.configure_error or 'activation failed'}", file=sys.stderr)
            return 2
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        _close(node)
    return 0


def _close(node) -> None:
    """The exit summary, the node destroyed, ROS 2 shut down: each step runs even when a SIGINT
    lands inside an earlier one. rclpy's signal handler passes the signal on to Python's own, so
    a KeyboardInterrupt can arise at any line, also here (on Jazzy, where rclpy shuts the context
    down at once, the node may be closing already when it comes)."""
    steps = [rclpy.try_shutdown]
    if node is not None:
        # the node's own name: renamed (__node) or in a namespace, it is not vasco_mapper
        steps[:0] = [lambda: print(f"{node.get_fully_qualified_name()}: {node.summary()}", file=sys.stderr),
                     node.destroy_node]
    for step in steps:
        try:
            step()
        except KeyboardInterrupt:
            pass
