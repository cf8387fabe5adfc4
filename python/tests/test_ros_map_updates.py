"""map_updates over Fast DDS shared memory (ros_support.py), as nav2's static layer takes them:
the tests' subscriber (ros_player.py) applies each update to the map before it. The intel log's
scans in a random order (poses shuffled, stamps rising: the grid grows in jumps), a Path in
between, more scans after it: at every pause the composed map is the node's own (~/dynamic_map,
header aside) and holds a Mapper's map of the scans sent (test_ros_node.py's float32-angle
bound), updates came between the full maps, and an update never leaves the map it applies to."""

from __future__ import annotations

import numpy as np
import pytest

import ros_support  # noqa: F401  (the ROS environment, before rclpy starts)
from ros_support import NodeProcess

rclpy = ros_support.import_or_skip("rclpy")
ros_support.import_or_skip("tf2_msgs")

import vasco_gpu as vg  # noqa: E402
from nav_msgs.srv import GetMap  # noqa: E402
from test_ros_node import assert_grid_matches  # noqa: E402


@pytest.fixture(scope="module")
def node():
    proc = NodeProcess({"backend": "cpu_double", "map_mode": "scale", "scan_qos": "reliable",
                        "map_update_interval": 0.1})
    proc.wait_for("ready")
    yield proc
    proc.kill()


def shuffled(intel, order):
    """The log's scans in `order` (a permutation): poses, ranges and angles moved together."""
    s = intel.scans
    counts = [len(s.ranges_of(i)) for i in order]
    return vg.Scans(s.poses[order], np.concatenate([s.ranges_of(i) for i in order]), counts,
                    np.asarray(s.first_angle)[order], np.asarray(s.angle_step)[order])


def assert_composed_is_the_nodes(ros):
    ros.wait_quiet(1.0)
    served = ros.call(GetMap, "/vasco_mapper/dynamic_map", GetMap.Request()).map
    ros.wait_quiet(0.5)  # an update the call published
    latest = ros.latest()
    assert served.info == latest.info
    assert bytes(served.data) == bytes(latest.data), "the map composed from /map and map_updates is not the node's"


def test_updates_compose_the_nodes_map(ros, node, intel):
    rng = np.random.default_rng(11)
    order = rng.permutation(len(intel))
    scans = shuffled(intel, order)
    stamps = 10**12 + np.arange(len(intel), dtype=np.int64) * 100_000_000
    half = len(intel) // 2
    full, updates = ros.full_maps, ros.updates
    ros.replay(scans.select(0, half), stamps[:half], rate_hz=200.0)
    assert_composed_is_the_nodes(ros)
    want = vg.Mapper(intel.params, backend="cpu_double")
    want.insert(scans.select(0, half))
    assert_grid_matches(ros.latest(), want.finish())
    assert ros.updates > updates, "no map_updates while scans were mapped"

    # a Path over the first half: a whole /map, then updates again for the second half
    moved = scans.poses[:half] + rng.normal(0, [0.02, 0.02, 0.003], (half, 3))
    maps = ros.full_maps
    ros.publish_path(stamps[:half], moved)
    ros.wait_quiet(1.0)
    assert ros.full_maps > maps, "a Path gave no whole /map"
    updates = ros.updates
    ros.replay(scans.select(half, len(intel) - half), stamps[half:], rate_hz=200.0)
    assert_composed_is_the_nodes(ros)
    assert ros.updates > updates
    assert ros.full_maps - full < ros.updates, "updates did not carry most changes"
