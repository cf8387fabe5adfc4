"""The node as a managed node (lifecycle_msgs' services, as nav2's lifecycle manager drives it),
a process over Fast DDS shared memory (ros_support.py): with autostart false nothing is
subscribed, mapped or published until configure + activate; deactivate stops mapping (scans
sent meanwhile are never mapped, also after the next activate); cleanup releases the mapper;
shutdown finalizes. The maps are compared with a Mapper's map of the scans that should count."""

from __future__ import annotations

import time

import numpy as np
import pytest

import ros_support  # noqa: F401  (the ROS environment, before rclpy starts)
from ros_support import NodeProcess

rclpy = ros_support.import_or_skip("rclpy")
ros_support.import_or_skip("tf2_msgs")

import vasco_gpu as vg  # noqa: E402
from lifecycle_msgs.msg import State, Transition  # noqa: E402
from lifecycle_msgs.srv import ChangeState, GetState  # noqa: E402
from nav_msgs.srv import GetMap  # noqa: E402
from test_ros_node import assert_grid_matches, grid_equals  # noqa: E402
from tf2_msgs.msg import TFMessage  # noqa: E402

NAME = "/vasco_mapper"


@pytest.fixture(scope="module")
def node():
    proc = NodeProcess({"backend": "cpu_double", "map_mode": "scale", "scan_qos": "reliable", "autostart": False,
                        "map_update_interval": 0.2})
    proc.wait_for("waiting for a lifecycle manager")
    yield proc
    proc.kill()


def state(ros) -> int:
    return ros.call(GetState, f"{NAME}/get_state", GetState.Request()).current_state.id


def transition(ros, tid: int) -> bool:
    req = ChangeState.Request()
    req.transition.id = tid
    return ros.call(ChangeState, f"{NAME}/change_state", req).success


def service_there(ros, srv_type, name, timeout=1.0) -> bool:
    client = ros.node.create_client(srv_type, name)
    try:
        return client.wait_for_service(timeout_sec=timeout)
    finally:
        ros.node.destroy_client(client)


def scan_subscribers(ros, want: int, timeout=10.0) -> bool:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if ros.scan.get_subscription_count() == want:
            return True
        time.sleep(0.02)
    return False


def mapper_map(intel, count: int):
    """A Mapper's map of the log's first count scans."""
    m = vg.Mapper(intel.params, backend="cpu_double")
    m.insert(intel.scans.select(0, count))
    return m.finish()


def send_unmatched(ros, intel, stamps, picked):
    """Scans and their /tf sent whether or not anyone listens (the node inactive)."""
    ros.tf_static.publish(TFMessage(transforms=[ros.transform("base_link", "laser", 0, (0, 0, 0))]))
    sc = intel.scans
    for s in picked:
        ros.tf.publish(TFMessage(transforms=[ros.transform("map", "base_link", int(stamps[s]), sc.poses[s])]))
        ros.scan.publish(ros.laser_scan(int(stamps[s]), sc.ranges_of(s), float(sc.first_angle[s]),
                                        float(sc.angle_step[s])))
        time.sleep(0.002)


def test_lifecycle_transitions_gate_mapping(ros, node, intel):
    assert state(ros) == State.PRIMARY_STATE_UNCONFIGURED
    assert not service_there(ros, GetMap, f"{NAME}/dynamic_map"), "unconfigured, yet a map service"
    assert scan_subscribers(ros, 0, timeout=0.5)

    assert transition(ros, Transition.TRANSITION_CONFIGURE)
    assert state(ros) == State.PRIMARY_STATE_INACTIVE
    empty = ros.call(GetMap, f"{NAME}/dynamic_map", GetMap.Request()).map
    assert empty.info.width == 0, "configured: the mapper is new, no map yet"
    assert scan_subscribers(ros, 0, timeout=0.5), "inactive, yet subscribed to scans"

    n = len(intel)
    stamps = 10**12 + np.arange(n, dtype=np.int64) * 100_000_000
    h = n // 2  # the first half, then the second
    assert transition(ros, Transition.TRANSITION_ACTIVATE)
    assert state(ros) == State.PRIMARY_STATE_ACTIVE
    assert "ready" in node.wait_for("ready")
    before = ros.map_count()
    ros.replay(intel.scans.select(0, h), stamps[:h])
    want_first = mapper_map(intel, h)
    got = ros.wait_map(before, grid_equals(want_first), timeout=60)
    assert got is not None, f"no /map of the first half; last:\n{node.output[-2000:]}"
    assert_grid_matches(got, want_first)

    # inactive: the second half is sent and never mapped, also once active again
    assert transition(ros, Transition.TRANSITION_DEACTIVATE)
    assert state(ros) == State.PRIMARY_STATE_INACTIVE
    assert scan_subscribers(ros, 0), "deactivated, yet subscribed to scans"
    send_unmatched(ros, intel, stamps, range(h, n))
    assert transition(ros, Transition.TRANSITION_ACTIVATE)
    ros.wait_quiet(1.0)
    latest = ros.call(GetMap, f"{NAME}/dynamic_map", GetMap.Request()).map
    assert_grid_matches(latest, want_first)
    # ... then sent again while active: the whole log's map, each scan once
    before = ros.map_count()
    ros.replay(intel.scans.select(h, n - h), stamps[h:])
    want_all = mapper_map(intel, n)
    got = ros.wait_map(before, grid_equals(want_all), timeout=60)
    assert got is not None, f"no /map of the whole log; last:\n{node.output[-2000:]}"

    # cleanup releases the mapper: configured again, it starts from no map
    assert transition(ros, Transition.TRANSITION_DEACTIVATE)
    assert transition(ros, Transition.TRANSITION_CLEANUP)
    assert state(ros) == State.PRIMARY_STATE_UNCONFIGURED
    assert not service_there(ros, GetMap, f"{NAME}/dynamic_map")
    assert transition(ros, Transition.TRANSITION_CONFIGURE)
    assert ros.call(GetMap, f"{NAME}/dynamic_map", GetMap.Request()).map.info.width == 0
    assert transition(ros, Transition.TRANSITION_INACTIVE_SHUTDOWN)
    assert state(ros) == State.PRIMARY_STATE_FINALIZED
    code, _ = node.interrupt()
    assert code == 0, node.output[-2000:]
    assert "0 scans mapped" in node.output, node.output[-1000:]


def test_the_nav2_example_params_file_starts_for_a_lifecycle_manager(ros, tmp_path):
    """examples/ros/vasco_mapper_nav2.yaml, as docs/ros.md gives it: strict_parameters accepts
    every key, the node waits unconfigured, and configure + activate bring it up."""
    from pathlib import Path

    from test_ros_slam_toolbox import ParamsFileNode

    example = Path(__file__).resolve().parents[2] / "examples" / "ros" / "vasco_mapper_nav2.yaml"
    proc = ParamsFileNode(example, "-p", "backend:=cpu_double", "-p", f"save_map_path:={tmp_path / 'site'}")
    try:
        proc.wait_for("waiting for a lifecycle manager")
        assert "unknown parameters" not in proc.output, proc.output[-2000:]
        assert transition(ros, Transition.TRANSITION_CONFIGURE)
        assert transition(ros, Transition.TRANSITION_ACTIVATE)
        assert state(ros) == State.PRIMARY_STATE_ACTIVE
        assert "ready" in proc.wait_for("ready")
    finally:
        proc.kill()
