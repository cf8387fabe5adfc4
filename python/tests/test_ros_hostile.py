"""The node under hostile parameters and Paths (issue: a failure never corrupts), as a process
over Fast DDS shared memory (ros_support.py): seconds that would overflow rclpy's timers refused
at start-up (exit 2) and while running (the change refused whole, the node up); a pose_max_gap
beyond ROS time's span taken as no limit; ~/reset replacing the latched /map at once by an empty
one; Paths beyond the tf tree's bound or with two poses at one stamp refused, naming the topic."""

from __future__ import annotations

import time

import numpy as np
import pytest

import ros_support  # noqa: F401  (the ROS environment, before rclpy starts)
from ros_support import NodeProcess

rclpy = ros_support.import_or_skip("rclpy")
ros_support.import_or_skip("tf2_msgs")

from std_srvs.srv import Trigger  # noqa: E402
from test_ros_node import set_parameter  # noqa: E402


@pytest.fixture(scope="module")
def node():
    # pose_max_gap far beyond ROS time's span: "no gap limit", which once crashed the first Path
    proc = NodeProcess({"backend": "cpu_double", "scan_qos": "reliable", "map_update_interval": 0.2,
                        "transform_timeout": 0.5, "pose_max_gap": 1e300})
    proc.wait_for("ready")
    yield proc
    proc.kill()


@pytest.mark.parametrize("name", ["map_update_interval", "scan_batch_interval", "transform_timeout"])
def test_seconds_that_overflow_a_timer_stop_the_start_naming_the_parameter(name):
    proc = NodeProcess({name: 1e12})
    rc = proc.proc.wait(30)
    proc._reader.join(2)
    assert rc == 2, proc.output[-2000:]
    assert f"{name}: 1000000000000.0 must be" in proc.output and "86400" in proc.output
    assert "Traceback" not in proc.output


def test_a_path_with_no_gap_limit_renders_and_the_node_stays_up(ros, node, intel):
    stamps = 10**12 + np.arange(60, dtype=np.int64) * 100_000_000
    before = ros.map_count()
    ros.replay(intel.scans.select(0, 60), stamps)
    assert ros.wait_map(before, timeout=30) is not None, node.output[-2000:]
    ros.wait_quiet(0.6)
    before = ros.map_count()
    ros.publish_path(stamps, intel.poses[:60] + [0.05, 0.0, 0.0])
    assert ros.wait_map(before, timeout=30) is not None, node.output[-2000:]
    assert node.proc.poll() is None


@pytest.mark.parametrize("name", ["map_update_interval", "scan_batch_interval"])
def test_seconds_that_overflow_a_timer_are_refused_while_running(ros, node, name):
    got = set_parameter(ros, name, 1e12)
    assert not got.successful and name in got.reason and "86400" in got.reason
    assert node.proc.poll() is None
    assert set_parameter(ros, name, 0.2).successful  # and the node still takes good values


def test_paths_beyond_the_bound_or_with_a_repeated_stamp_are_refused(ros, node, intel):
    stamps = 10**12 + np.arange(60, dtype=np.int64) * 100_000_000
    far = intel.poses[:60].copy()
    far[7, 0] = 1e300
    ros.publish_path(stamps, far)
    assert "pose 7 (stamp 1000.700000000) has position (1e+300" in node.wait_for("beyond 1e+12 m")
    twice = stamps.copy()
    twice[20] = twice[19]
    ros.publish_path(twice, intel.poses[:60])
    line = node.wait_for("have one stamp")
    assert "/trajectory: poses 19 and 20 of the Path have one stamp, 1001.900000000" in line, line
    assert node.proc.poll() is None


def test_a_self_link_and_a_reversed_link_are_left_out_and_mapping_goes_on(ros, node, intel):
    from tf2_msgs.msg import TFMessage

    later = 10**12 + 10**10 + np.arange(60, 120, dtype=np.int64) * 100_000_000  # no jump back
    ros.tf.publish(TFMessage(transforms=[ros.transform("map", "map", int(later[0]), (0, 0, 0))]))
    assert "self link" in node.wait_for("/tf: ") or "self link" in node.output
    ros.tf.publish(TFMessage(transforms=[ros.transform("map", "base_link", int(later[0]), (0, 0, 0)),
                                         ros.transform("base_link", "map", int(later[0]), (0, 0, 0))]))
    node.wait_for("cycle")
    ros.wait_quiet(0.6)
    before = ros.map_count()
    ros.replay(intel.scans.select(60, 60), later)
    assert ros.wait_map(before, timeout=30) is not None, node.output[-2000:]
    assert "tf has a cycle" not in node.output, node.output[-2000:]


def test_reset_replaces_the_latched_map_by_an_empty_one_at_once(ros, node, intel):
    ros.wait_quiet(0.6)
    last = ros.latest()
    assert last is not None and (np.frombuffer(bytes(last.data), np.int8) != -1).any()
    before = ros.map_count()
    assert ros.call(Trigger, "/vasco_mapper/reset", Trigger.Request()).success
    got = ros.wait_map(before, timeout=10)
    assert got is not None, node.output[-2000:]
    assert (got.info.width, got.info.height) == (last.info.width, last.info.height)  # no resize for nav2
    assert (np.frombuffer(bytes(got.data), np.int8) == -1).all()
    from nav_msgs.srv import GetMap
    served = ros.call(GetMap, "/vasco_mapper/dynamic_map", GetMap.Request()).map  # once crashed after a reset
    assert served.info == got.info and bytes(served.data) == bytes(got.data)
    # a subscriber that joins now gets the empty map, not the dropped scans' map
    from nav_msgs.msg import OccupancyGrid
    from ros_player import LATCHED

    late: list = []
    sub = ros.node.create_subscription(OccupancyGrid, "map", late.append, LATCHED)
    end = time.monotonic() + 10
    while not late and time.monotonic() < end:
        time.sleep(0.05)
    ros.node.destroy_subscription(sub)
    assert late and (np.frombuffer(bytes(late[-1].data), np.int8) == -1).all()
