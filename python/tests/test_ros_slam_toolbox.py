"""The node started from a slam_toolbox-style params file, over a real DDS (Fast DDS, shared
memory only: ros_support.py): slam_toolbox's keys with their meanings (scan_topic,
max_laser_range lowering vasco_range_sure, throttle_scans), an unknown key warned about once
(refused with strict_parameters), save_map_path as map_saver's base name; and the node's log
lines: a Path before any scan, scans without a mount counted as mapped, the resolved topic names
and the node's namespaced name in the exit summary."""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time

import numpy as np

import ros_support  # noqa: F401  (the ROS environment, before rclpy starts)
from ros_support import ROS_ENV, NodeProcess

rclpy = ros_support.import_or_skip("rclpy")
ros_support.import_or_skip("tf2_msgs")

import vasco_gpu as vg  # noqa: E402
from ros_player import RELIABLE  # noqa: E402
from sensor_msgs.msg import LaserScan  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402
from test_ros_node import grid_equals  # noqa: E402
from tf2_msgs.msg import TFMessage  # noqa: E402
from vasco_gpu.ros.settings import Settings  # noqa: E402

SCANS = 120  # of the intel log: enough for a map, quick to replay


class ParamsFileNode(NodeProcess):
    """``python -m vasco_gpu.ros --ros-args --params-file FILE`` with more ROS arguments."""

    def __init__(self, params_file, *ros_args):
        args = [sys.executable, "-m", "vasco_gpu.ros", "--ros-args", "--params-file", str(params_file), *ros_args]
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                     env={**os.environ, **ROS_ENV})
        self.lines: list[str] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()


def slam_toolbox_params(path, out):
    """A params file as slam_toolbox's, its section for every node (/**), with one key the node
    does not know (a typo of map_update_interval)."""
    keys = {"scan_topic": "/front_scan", "max_laser_range": 4.0, "throttle_scans": 2, "map_update_interval": 0.2,
            "map_update_intervall": 1.0, "odom_frame": "odom", "transform_timeout": 1.0, "tf_buffer_duration": 30.0,
            "minimum_time_interval": 0.0, "resolution": 0.05, "backend": "cpu_double", "map_mode": "scale",
            "scan_qos": "reliable", "save_map_path": str(out / "site")}
    text = "".join(f"    {k}: {v!r}\n" if isinstance(v, str) else f"    {k}: {v}\n" for k, v in keys.items())
    path.write_text("/**:\n  ros__parameters:\n" + text)
    return path


def test_a_slam_toolbox_params_file(ros, intel, tmp_path):
    node = ParamsFileNode(slam_toolbox_params(tmp_path / "slam.yaml", tmp_path))
    try:
        ready = node.wait_for("ready")
        assert "scans on /front_scan," in ready
        warned = [ln for ln in node.lines if "unknown parameters" in ln]
        assert len(warned) == 1 and "map_update_intervall: did you mean 'map_update_interval'?" in warned[0], warned
        assert sum("vasco_range_sure lowered from 5 to 4 m: max_laser_range 4" in ln for ln in node.lines) == 1
        ros.scan = ros.node.create_publisher(LaserScan, "/front_scan", RELIABLE)  # slam_toolbox's topic
        ros.wait_matched()
        ros.publish_path([10**12 - 2 * 10**9, 10**12 - 10**9], [(0.0, 0.0, 0.0)] * 2)  # before any scan: one log line
        node.wait_for("a Path before any scan was mapped")

        scans = intel.scans.select(0, SCANS)
        stamps = 10**12 + np.arange(SCANS, dtype=np.int64) * 100_000_000
        before = ros.map_count()
        ros.replay(scans, stamps)
        params = Settings.from_values({"max_laser_range": 4.0}, {}).params  # the node's rule, without ROS
        assert (params.range_max, params.range_sure) == (4.0, 4.0)
        kept = scans.select(0, 1)
        for i in range(2, SCANS, 2):  # throttle_scans 2: the first of every two
            kept.extend(scans.select(i, 1))
        want = vg.Mapper(params, backend="cpu_double")
        want.insert(kept)
        got = ros.wait_map(before, grid_equals(want.finish()), timeout=60)
        assert got is not None, node.output[-2000:]

        reply = ros.call(Trigger, "/vasco_mapper/save_map", Trigger.Request())
        assert reply.success, reply.message
        assert (tmp_path / "site.pgm").is_file() and (tmp_path / "site.yaml").is_file()  # map_saver's pair
        rc, _ = node.interrupt()
        assert rc == 0, node.output[-2000:]
        assert sum("a Path before any scan" in ln for ln in node.lines) == 1
        assert f"/vasco_mapper: {SCANS // 2} scans mapped; not mapped: {SCANS // 2} scans skipped by throttle_scans " \
               "on /front_scan" in node.output, node.output[-2000:]
    finally:
        node.kill()


def test_strict_parameters_refuse_an_unknown_key(tmp_path):
    node = ParamsFileNode(slam_toolbox_params(tmp_path / "slam.yaml", tmp_path), "-p", "strict_parameters:=true")
    assert node.proc.wait(30) == 2
    node._reader.join(2)
    assert "unknown parameters (not used): map_update_intervall: did you mean 'map_update_interval'? " \
           "(strict_parameters: true)" in node.output, node.output


def test_scans_without_a_mount_are_mapped_and_the_names_are_resolved(ros, tmp_path):
    """Scans in a frame with no /tf_static chain from base_link are mapped at their tf pose: the
    summary counts them as mapped, not as refused; the node put into a namespace names its
    topics and itself resolved."""
    params = tmp_path / "params.yaml"
    params.write_text("/**:\n  ros__parameters:\n    backend: cpu_double\n    scan_qos: reliable\n"
                      "    scan_topics: [scan, /scan]\n")
    node = ParamsFileNode(params, "-r", "__ns:=/robot1")
    try:
        ready = node.wait_for("ready")
        assert "scans on /robot1/scan, /scan," in ready, ready
        ros.scan = ros.node.create_publisher(LaserScan, "/scan", RELIABLE)
        end = time.monotonic() + 20  # the node's Path topic is /robot1/trajectory: not the player's
        while not (ros.scan.get_subscription_count() and ros.tf.get_subscription_count()) and time.monotonic() < end:
            time.sleep(0.02)
        for k in range(3):
            ns = 2 * 10**12 + k * 100_000_000
            ros.tf.publish(TFMessage(transforms=[ros.transform("map", "lidar_alone", ns, (0.1 * k, 0.0, 0.0))]))
            ros.scan.publish(ros.laser_scan(ns, np.full(181, 3.0), -np.pi / 2, np.pi / 180, frame="lidar_alone"))
        node.wait_for("no /tf_static chain base_link -> lidar_alone")
        time.sleep(1.0)  # the other two mapped (/map is the namespace's: not the player's to watch)
        rc, _ = node.interrupt()
        assert rc == 0, node.output[-2000:]
        summary = next((ln for ln in node.lines if ln.startswith("/robot1/vasco_mapper: ")), node.output[-2000:])
        assert summary.startswith("/robot1/vasco_mapper: 3 scans mapped (3 without a mount on /scan: a Path cannot "
                                  "move them)"), summary
        assert "not mapped" not in summary, summary
    finally:
        node.kill()
