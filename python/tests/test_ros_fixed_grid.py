"""A fixed grid (map_size, map_origin), over Fast DDS shared memory (ros_support.py): every /map
has the geometry asked for, 40 m x 40 m from (-15, -26) at 0.05 m, before and after a Path; the
scans' changes come as map_updates; the map is a fixed-frame Mapper's (frame and centre worked
out here from the parameters: 801 blocks of 2 fine cells a side, centred 801 fine cells from the
corner), to the float32-angle bound of test_ros_node.py."""

from __future__ import annotations

import numpy as np
import pytest

import ros_support  # noqa: F401  (the ROS environment, before rclpy starts)
from ros_support import NodeProcess

rclpy = ros_support.import_or_skip("rclpy")
ros_support.import_or_skip("tf2_msgs")

import vasco_gpu as vg  # noqa: E402
from test_ros_node import assert_grid_matches, grid_equals  # noqa: E402

SIZE, ORIGIN = [40.0, 40.0], [-15.0, -26.0]


@pytest.fixture(scope="module")
def node():
    proc = NodeProcess({"backend": "cpu_double", "map_mode": "scale", "scan_qos": "reliable",
                        "map_update_interval": 0.2, "map_size": SIZE, "map_origin": ORIGIN})
    proc.wait_for("ready")
    yield proc
    proc.kill()


def fixed_map(log, scans):
    """The map of a fixed frame: 0.05 m cells of 2 x 0.025 m, 800 of them a side within a frame
    of 801 blocks (CARMEN's finish leaves a frame's last block out), so 1602 fine cells, its
    centre 801 fine cells from the corner."""
    fine = 0.025
    frame = vg.Frame(1602, 1602, fine, 0.0)
    m = vg.Mapper(log.params, backend="cpu_double", frame=frame,
                  frame_centre=(ORIGIN[0] + 801 * fine, ORIGIN[1] + 801 * fine))
    m.insert(scans)
    return m.finish()


def test_the_grid_keeps_its_geometry_and_changes_come_as_updates(ros, node, intel):
    maps, updates = ros.full_maps, ros.updates
    stamps = 10**12 + np.arange(len(intel), dtype=np.int64) * 100_000_000
    ros.replay(intel.scans, stamps)
    want = fixed_map(intel, intel.scans)
    got = ros.wait_map(0, grid_equals(want), timeout=60)
    assert got is not None, node.output[-2000:]
    assert_grid_matches(got, want)
    ros.wait_quiet(1.0)
    assert ros.updates > updates, "no map_updates for the scans"
    geometry = {(m.info.width, m.info.height, round(m.info.origin.position.x, 9), round(m.info.origin.position.y, 9),
                 round(m.info.resolution, 6)) for _, m in ros.maps}
    assert geometry == {(800, 800, ORIGIN[0], ORIGIN[1], 0.05)}, geometry
    assert ros.full_maps - maps <= 2, "a fixed grid sent full maps for scans (the first, and a settle, at most)"

    rng = np.random.default_rng(7)
    moved = intel.poses + rng.normal(0, [0.02, 0.02, 0.003], intel.poses.shape)
    before = ros.map_count()
    ros.publish_path(stamps, moved)
    got = ros.wait_map(before, timeout=30)
    assert got is not None, node.output[-2000:]
    assert (got.info.width, got.info.height) == (800, 800)
    assert (got.info.origin.position.x, got.info.origin.position.y) == pytest.approx(ORIGIN, abs=1e-9)
