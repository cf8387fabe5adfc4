"""The node's ~/dynamic_map (nav_msgs/GetMap) and its scans waiting for a pose, as a process over
Fast DDS shared memory (ros_support.py): before any map an empty grid; scans that never had a
transform (only their mount on /tf_static) wait, and a later Path poses them: /map is a Mapper's
map of those scans at the Path's poses (test_ros_node.py's bound on float32 angles); after that
Path, and after scans posed by tf, dynamic_map is the latest /map, header, info and data."""

from __future__ import annotations

import time

import numpy as np
import pytest

import ros_support  # noqa: F401  (the ROS environment, before rclpy starts)
from ros_support import NodeProcess

rclpy = ros_support.import_or_skip("rclpy")
ros_support.import_or_skip("tf2_msgs")

import vasco_gpu as vg  # noqa: E402
from nav_msgs.srv import GetMap  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402
from test_ros_node import assert_grid_matches, grid_equals  # noqa: E402
from tf2_msgs.msg import TFMessage  # noqa: E402


@pytest.fixture(scope="module")
def node():
    proc = NodeProcess({"backend": "cpu_double", "map_mode": "scale", "scan_qos": "reliable",
                        "map_update_interval": 0.2, "transform_timeout": 0.2})
    proc.wait_for("ready")
    yield proc
    proc.kill()


def dynamic_map(ros):
    return ros.call(GetMap, "/vasco_mapper/dynamic_map", GetMap.Request()).map


def assert_same_map(a, b):
    assert (a.header.frame_id, a.header.stamp.sec, a.header.stamp.nanosec) == \
        (b.header.frame_id, b.header.stamp.sec, b.header.stamp.nanosec)
    assert a.info == b.info and bytes(a.data) == bytes(b.data)


def scans_without_tf(ros, intel, stamps, rate_hz=500.0):
    """Every scan in 'laser' with only its mount on /tf_static: no /tf at all."""
    ros.wait_matched()
    ros.tf_static.publish(TFMessage(transforms=[ros.transform("base_link", "laser", 0, (0, 0, 0))]))
    for s in range(len(intel)):
        sc = intel.scans
        ros.scan.publish(ros.laser_scan(int(stamps[s]), sc.ranges_of(s), float(sc.first_angle[s]),
                                        float(sc.angle_step[s])))
        time.sleep(1.0 / rate_hz)


def test_dynamic_map_is_empty_then_a_path_poses_scans_that_had_no_tf_and_it_is_the_latest_map(ros, node, intel):
    empty = dynamic_map(ros)
    assert empty.info.width == 0 and empty.info.height == 0 and len(empty.data) == 0
    assert "no map yet" in node.wait_for("dynamic_map")

    stamps = 10**12 + np.arange(len(intel), dtype=np.int64) * 100_000_000
    scans_without_tf(ros, intel, stamps)
    ros.wait_quiet(1.0)
    assert ros.map_count() == 0, "a scan without a transform was mapped"
    before = ros.map_count()
    ros.publish_path(stamps, intel.poses)
    want = vg.Mapper(intel.params, backend="cpu_double")
    want.insert(intel.scans)
    want_map = want.finish()
    got = ros.wait_map(before, grid_equals(want_map), timeout=60)
    assert got is not None, f"no /map equal to the Mapper's; last:\n{node.output[-2000:]}"
    assert_grid_matches(got, want_map)
    ros.wait_quiet(1.0)
    assert_same_map(dynamic_map(ros), ros.latest())

    # scans posed by tf from the start: dynamic_map is again the latest /map
    r = ros.call(Trigger, "/vasco_mapper/reset", Trigger.Request())
    assert r.success, r.message
    ros.replay(intel.scans, stamps + 10**11)
    ros.wait_quiet(1.0)
    assert_same_map(dynamic_map(ros), ros.latest())


def test_the_exit_summary_counts_the_scans_still_waiting(ros, node, intel):
    stamps = 3 * 10**12 + np.arange(5, dtype=np.int64) * 100_000_000
    ros.wait_matched()
    for s, ns in enumerate(stamps):
        sc = intel.scans
        ros.scan.publish(ros.laser_scan(int(ns), sc.ranges_of(s), float(sc.first_angle[s]), float(sc.angle_step[s])))
    ros.wait_quiet(1.0)
    rc, _ = node.interrupt()
    assert rc == 0
    assert "5 scans waiting for a pose" in node.output, node.output[-2000:]
