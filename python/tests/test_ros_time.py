"""The node's time, over a real DDS (Fast DDS, shared memory only: ros_support.py), with
use_sim_time:=true: /map published with no /clock at all, stamped by the latest scan; a log
played twice in a row (its stamps going back) mapped as one pass, or with on_time_jump:=keep as
both; /map stamped by /clock while it runs, and /clock going back starting a new map too."""

from __future__ import annotations

import time

import numpy as np
import pytest

import ros_support  # noqa: F401  (the ROS environment, before rclpy starts)
from ros_support import NodeProcess

rclpy = ros_support.import_or_skip("rclpy")
ros_support.import_or_skip("tf2_msgs")

import vasco_gpu as vg  # noqa: E402
from ros_player import stamp_of  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402
from test_ros_node import INTEL, grid_equals, set_parameter, window  # noqa: E402

SCANS = 120  # of the intel log: enough for a map, quick to replay
T0 = 10**12  # the pass's first stamp; its scans 0.1 s apart


@pytest.fixture(scope="module")
def intel():
    log = vg.load_log(INTEL, map_resolution=0.05)
    return log, log.scans.select(0, SCANS)


@pytest.fixture(scope="module")
def node():
    proc = NodeProcess({"backend": "cpu_double", "map_mode": "scale", "scan_qos": "reliable", "use_sim_time": True,
                        "map_update_interval": 0.2, "transform_timeout": 1.0})
    proc.wait_for("ready")
    yield proc
    proc.kill()


def one_pass(log, scans, times: int = 1):
    """The map of the scans inserted times over (the same evidence again: times 2)."""
    m = vg.Mapper(log.params, backend="cpu_double")
    for _ in range(times):
        m.insert(scans)
    return m.finish()


def play(ros, node, scans, t0: int = T0):
    """One pass of the scans, then until the node has published what it mapped; its last /map."""
    ros.replay(scans, t0 + np.arange(len(scans), dtype=np.int64) * 10**8)
    ros.wait_quiet(1.5)
    got = ros.latest()
    assert got is not None, node.output[-2000:]
    return got


def jump_lines(node) -> list[str]:
    return [ln for ln in node.lines if "time went back" in ln]


def test_map_without_clock_stamped_by_the_latest_scan(ros, node, intel):
    # use_sim_time and no /clock: the node's clock reads 0, its timers run on the steady clock
    log, scans = intel
    got = play(ros, node, scans)
    assert grid_equals(one_pass(log, scans))(got), node.output[-2000:]
    last = T0 + (SCANS - 1) * 10**8
    assert (got.header.stamp.sec, got.header.stamp.nanosec) == (last // 10**9, last % 10**9)
    node.first_pass = window(got, one_pass(log, scans)).tobytes()


def test_a_log_played_twice_maps_one_pass(ros, node, intel):
    log, scans = intel
    n = ros.map_count()
    got = play(ros, node, scans)  # the same stamps again: back 11.9 s
    assert ros.map_count() > n
    lines = jump_lines(node)
    assert len(lines) == 1 and "a new map (120 scans dropped; on_time_jump: reset)" in lines[0], node.output[-2000:]
    # the first pass's map, byte for byte (/map's canvas may differ: its growth follows the batches)
    assert window(got, one_pass(log, scans)).tobytes() == node.first_pass
    twice = one_pass(log, scans, 2)
    assert not grid_equals(twice)(got)  # which doubled evidence is not


def test_on_time_jump_keep_maps_both_passes(ros, node, intel):
    log, scans = intel
    assert set_parameter(ros, "on_time_jump", "keep").successful
    try:
        got = play(ros, node, scans)
        lines = jump_lines(node)
        assert len(lines) == 2 and "the map keeps its 120 scans (on_time_jump: keep)" in lines[1], lines
        assert grid_equals(one_pass(log, scans, 2))(got), node.output[-2000:]
        assert window(got, one_pass(log, scans)).tobytes() != node.first_pass
    finally:
        assert set_parameter(ros, "on_time_jump", "reset").successful


def test_clock_stamps_the_map_and_going_back_starts_a_new_map(ros, node, intel):
    log, scans = intel
    clock = ros.node.create_publisher(Clock, "/clock", 10)
    try:
        assert ros.call(Trigger, "/vasco_mapper/reset", Trigger.Request()).success
        now = T0 + 100 * 10**9  # /clock ahead of every stamp here
        end = time.monotonic() + 10
        while clock.get_subscription_count() == 0 and time.monotonic() < end:
            time.sleep(0.02)
        clock.publish(Clock(clock=stamp_of(now)))
        time.sleep(0.5)
        got = play(ros, node, scans.select(0, 30), T0 + 20 * 10**9)
        assert (got.header.stamp.sec, got.header.stamp.nanosec) == (now // 10**9, 0)  # the node's clock
        assert grid_equals(one_pass(log, scans.select(0, 30)))(got)
        before = len(jump_lines(node))
        clock.publish(Clock(clock=stamp_of(T0)))  # back 100 s: behind the stamps mapped
        line = node.wait_for("on /clock", timeout=10)
        assert "a new map (30 scans dropped; on_time_jump: reset)" in line and len(jump_lines(node)) == before + 1
        # the scans of the new time map as a pass of their own, and tell of no jump again
        got = play(ros, node, scans.select(30, 30), T0 + 10**9)
        assert grid_equals(one_pass(log, scans.select(30, 30)))(got), node.output[-2000:]
        assert len(jump_lines(node)) == before + 1
    finally:
        ros.node.destroy_publisher(clock)
