"""Sessions that survive a restart, over Fast DDS shared memory (ros_support.py): a node maps the
intel log and a Path moves it, ~/save_session writes session_path; a new node with load_session
and no scan publishes, as its first /map, the last /map of the first node (cells, resolution
and place); log2map's route to the same file is session_file's test. Also the refusals: no
session_path, and a load_session that is not a session file stops the start (exit 2, naming
the file and line)."""

from __future__ import annotations

import types

import numpy as np
import pytest

import ros_support  # noqa: F401  (the ROS environment, before rclpy starts)
from ros_support import NodeProcess

rclpy = ros_support.import_or_skip("rclpy")
ros_support.import_or_skip("tf2_msgs")

from std_srvs.srv import Trigger  # noqa: E402
from test_ros_node import window  # noqa: E402

PARAMS = {"backend": "cpu_double", "map_mode": "scale", "scan_qos": "reliable", "map_update_interval": 0.2}


def as_map(msg):
    """A /map message as window()'s `want`: its size, place and cell."""
    info = msg.info
    return types.SimpleNamespace(shape=(info.width, info.height), resolution=float(info.resolution),
                                 origin=(info.origin.position.x, info.origin.position.y, 0.0))


def test_a_saved_session_is_the_first_map_after_a_restart(ros, intel, tmp_path):
    path = tmp_path / "site.session.log.gz"
    first = NodeProcess({**PARAMS, "session_path": str(tmp_path / "none" / "x.log")})
    try:
        first.wait_for("ready")
        refused = ros.call(Trigger, "/vasco_mapper/save_session", Trigger.Request())
        assert not refused.success and "session not saved" in refused.message, refused.message
        stamps = 10**12 + np.arange(len(intel), dtype=np.int64) * 100_000_000
        ros.replay(intel.scans, stamps)
        ros.wait_quiet(1.0)
        rng = np.random.default_rng(5)
        ros.publish_path(stamps, intel.poses + rng.normal(0, [0.02, 0.02, 0.003], intel.poses.shape))
        ros.wait_quiet(1.0)
    except BaseException:
        first.kill()
        raise
    # session_path is read when used: set it now, as a params file would have from the start
    from test_ros_node import set_parameter
    assert set_parameter(ros, "session_path", str(path)).successful
    saved = ros.call(Trigger, "/vasco_mapper/save_session", Trigger.Request())
    assert saved.success and f"wrote {len(intel)} scans" in saved.message, saved.message
    ros.wait_quiet(1.0)
    last = ros.latest()
    code, _ = first.interrupt()
    assert code == 0, first.output[-2000:]

    before = ros.map_count()
    second = NodeProcess({**PARAMS, "load_session": str(path)})
    try:
        second.wait_for("ready")
        assert f"{len(intel)} scans of {path} restored" in second.output
        got = ros.wait_map(before, timeout=30)
        assert got is not None, second.output[-2000:]
        inner = window(last, as_map(got))
        assert inner is not None, "the restored map does not lie on the last map's cells"
        assert np.array_equal(inner, np.frombuffer(bytes(got.data), dtype=np.int8)), \
            "the first /map after the restart differs from the last one before it"
        assert "0 scans mapped" not in second.output
    finally:
        second.kill()


@pytest.mark.parametrize("content", [b"", b"ROBOTLASER1 1 2 3\n", b"VASCO_SESSION 2 scans 0\n"])
def test_a_bad_session_file_stops_the_start_naming_it(tmp_path, content):
    bad = tmp_path / "bad.session.log"
    bad.write_bytes(content)
    proc = NodeProcess({**PARAMS, "load_session": str(bad)})
    try:
        code = proc.proc.wait(timeout=30)
    finally:
        proc.kill()
    assert code == 2, proc.output[-2000:]
    assert str(bad) in proc.output, proc.output[-2000:]
