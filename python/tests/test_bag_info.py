"""vasco_gpu.bag_info and bag2map --info on bags the tests write: the topics with counts and
rates, the tf tree (parents, static or moving, roots), the scan topics and pose sources, and the
command that maps the bag, which bag2map then runs; or why bag2map refuses the bag, which
bag2map then does. A file that is not a bag is an error naming it."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosbags")

import vasco_gpu as vg  # noqa: E402
from vasco_gpu.bags import BagError  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bag_maker  # noqa: E402
from test_bags import run_script  # noqa: E402

N_SCANS = 20
DT = 0.1
STAMPS = [100.0 + DT * k for k in range(N_SCANS)]
RANGES = [np.linspace(1.0, 3.0, 37) for _ in STAMPS]  # a wall in front of a laser
ANGLE_MIN, ANGLE_STEP = -0.9, 0.05
ROS1_FMT = "rosbag1"


def laser_bag(tmp_path, fmt, name="test", **kw):
    """A bag of N_SCANS LaserScans on /scan at 10 Hz, with what kw adds (bag_maker.write_bag)."""
    path = bag_maker.bag_path(tmp_path, fmt, name)
    poses = np.column_stack([np.linspace(0, 1, N_SCANS), np.zeros(N_SCANS), np.zeros(N_SCANS)])
    for key in ("tf_poses", "odom_poses"):
        if kw.get(key) is True:
            kw[key] = poses
    return bag_maker.write_bag(path, fmt, STAMPS, RANGES, ANGLE_MIN, ANGLE_STEP, 0.0, 20.0, **kw)


def odom_tree_bag(tmp_path, fmt=ROS1_FMT):
    """A robot recorded with odometry only: tf odom -> base_link moving, base_link -> laser static."""
    rec = bag_maker.Recording(fmt)
    rec.tf(STAMPS[0], "base_link", "laser", 0.2, 0.0, 0.0, static=True)
    for k, t in enumerate(STAMPS):
        rec.scan("/scan", t, "laser", RANGES[k], ANGLE_MIN, ANGLE_STEP, 0.0, 20.0)
        rec.tf(t, "odom", "base_link", 0.05 * k, 0.0, 0.0)
    return rec.write(bag_maker.bag_path(tmp_path, fmt, "odom_only"))


def run_command(info, tmp_path, replace=()):
    """info.command run as bag2map, the map written in tmp_path; the placeholders replaced."""
    assert info.command[0] == "bag2map" and info.command[-1].endswith(".map")
    args = [dict(replace).get(a, a) for a in info.command[1:-1]]
    out = tmp_path / info.command[-1]
    r = run_script("bag2map", "--backend", "cpu_double", "-q", *args, out)
    return r, out


def link(info, child):
    tf = info.tf.links[child]
    return tf.parent, tf.static


@pytest.mark.parametrize("fmt", ["mcap", ROS1_FMT])
def test_a_bag_with_tf_and_odometry(tmp_path, fmt):
    path = laser_bag(tmp_path, fmt, tf_poses=True, static_mount=(0.2, 0.0, 0.0), odom_poses=True)
    info = vg.bag_info(path)
    topics = {t.name: t for t in info.topics}
    assert set(topics) == {"/scan", "/tf", "/tf_static", "/odom"}
    assert topics["/scan"].type == "sensor_msgs/LaserScan" and topics["/scan"].count == N_SCANS
    assert (topics["/tf"].count, topics["/odom"].count, topics["/tf_static"].count) == (N_SCANS, N_SCANS, 1)
    assert topics["/scan"].rate_hz == pytest.approx(1 / DT, rel=1e-6)  # 19 intervals in 1.9 s
    assert topics["/tf_static"].rate_hz is None
    assert info.duration == pytest.approx(STAMPS[-1] - STAMPS[0], abs=1e-6)
    assert info.message_count == 3 * N_SCANS + 1
    assert link(info, "base_link") == ("map", False) and link(info, "laser") == ("base_link", True)
    assert info.tf.links["base_link"].count == N_SCANS
    assert info.tf.roots() == ["map"] and info.tf.complete
    assert [(s.topic, s.frame) for s in info.scans] == [("/scan", "laser")]
    assert [(p.topic, p.frame, p.child) for p in info.poses] == [("/odom", "map", "base_link")]
    assert info.refusal is None and info.command == ["bag2map", str(path), "test.map"]
    text = info.text()
    for words in ("/odom", "nav_msgs/Odometry", "10.00 Hz", "laser  (parent base_link, static)",
                  "base_link  (parent map, moving", "roots (frames with no parent): map",
                  "tf: map -> base_link -> laser, moving", "bag2map maps it with:", f"bag2map {path} test.map"):
        assert words in text, words
    r, out = run_command(info, tmp_path)
    assert r.returncode == 0, r.stderr
    assert out.exists()


def test_an_odometry_only_tree_names_its_root(tmp_path):
    path = odom_tree_bag(tmp_path)
    info = vg.bag_info(path)
    assert info.storage == "ROS 1 bag"
    assert info.tf.roots() == ["odom"] and link(info, "base_link") == ("odom", False)
    assert info.command == ["bag2map", "--fixed-frame", "odom", str(path), "odom_only.map"]
    assert any("no 'map' frame" in n for n in info.notes)
    assert any("odometry drifts" in n and "--poses" in n for n in info.notes)
    r, out = run_command(info, tmp_path)
    assert r.returncode == 0, r.stderr


def test_the_console_script_prints_the_report(tmp_path):
    path = odom_tree_bag(tmp_path)
    r = run_script("bag2map", "--info", path)
    assert r.returncode == 0, r.stderr
    assert r.stdout == vg.bag_info(path).text()
    assert f"bag2map --fixed-frame odom {path} odom_only.map" in r.stdout
    r = run_script("bag2map", path, "--info")  # the flag anywhere
    assert r.returncode == 0 and "roots (frames with no parent): odom" in r.stdout


def test_a_bag_without_scans(tmp_path):
    path = laser_bag(tmp_path, "sqlite3", scan_topic=None, tf_poses=True)
    info = vg.bag_info(path)
    assert [t.name for t in info.topics] == ["/tf"] and info.scans == []
    assert info.command is None and "no sensor_msgs/LaserScan" in info.refusal
    r = run_script("bag2map", "--info", path)
    assert r.returncode == 0 and "bag2map with no options refuses it: no sensor_msgs/LaserScan" in r.stdout
    assert run_script("bag2map", path, tmp_path / "x.map").returncode == 1  # and bag2map does refuse it


def test_a_moving_sensor_without_poses_is_refused_with_the_ways_to_get_them(tmp_path):
    path = laser_bag(tmp_path, "mcap")
    info = vg.bag_info(path)
    assert info.command is None and info.poses == [] and not info.tf.links
    for words in ("SLAM or odometry", "--poses FILE", "--static-pose X,Y,THETA"):
        assert words in info.refusal
    for keyword in ("pose_topic", "static_pose", "fixed_frame"):  # the command line's option names only
        assert keyword not in info.refusal
    assert run_script("bag2map", path, tmp_path / "x.map").returncode == 1


def test_odometry_without_tf_suggests_the_pose_topic(tmp_path):
    path = laser_bag(tmp_path, "mcap", odom_poses=True)
    info = vg.bag_info(path)
    assert "no /tf" in info.refusal
    assert info.command[:5] == ["bag2map", "--pose-topic", "/odom", "--laser-mount", "X,Y,THETA"]
    assert run_script("bag2map", path, tmp_path / "x.map").returncode == 1  # refused, as said
    r, out = run_command(info, tmp_path, replace={"X,Y,THETA": "0,0,0"})
    assert r.returncode == 0, r.stderr


def test_several_scan_topics_are_named(tmp_path):
    path = laser_bag(tmp_path, "mcap", extra_scan_topics=("/rear",), tf_poses=True, static_mount=(0, 0, 0))
    info = vg.bag_info(path)
    assert "several scan topics" in info.refusal
    assert info.command[1:5] == ["--scan-topic", "/rear", "--scan-topic", "/scan"]
    assert run_script("bag2map", path, tmp_path / "x.map").returncode == 1
    r, out = run_command(info, tmp_path)
    assert r.returncode == 0, r.stderr


def test_a_map_frame_not_above_the_scans(tmp_path):
    # map -> odom is recorded, but for another robot: the laser's tree has the root 'odom'
    rec = bag_maker.Recording("mcap")
    rec.tf(STAMPS[0], "base_link", "laser", 0.0, 0.0, 0.0, static=True)
    for k, t in enumerate(STAMPS):
        rec.scan("/scan", t, "laser", RANGES[k], ANGLE_MIN, ANGLE_STEP, 0.0, 20.0)
        rec.tf(t, "odom", "base_link", 0.05 * k, 0.0, 0.0)
        rec.tf(t, "map", "other_odom", 0.0, 0.0, 0.0)
    path = rec.write(tmp_path / "two.mcap")
    info = vg.bag_info(path)
    assert info.tf.roots() == ["map", "odom"]
    assert "'map' has no connection to the scans' frame 'laser'" in info.refusal
    assert info.command[1:3] == ["--fixed-frame", "odom"]


def test_the_tf_tree_of_a_long_bag_is_read_from_its_ends(tmp_path):
    # 3000 /tf messages: the first TF_HEAD and the last TF_TAIL are read; map -> odom, which a
    # localiser starts late, is seen; a link only in the middle is not, and the report says so.
    from vasco_gpu.bags import info as bag_info_module

    rec = bag_maker.Recording("mcap")
    rec.tf(0.0, "base_link", "laser", 0.0, 0.0, 0.0, static=True)
    n = 3000
    for k in range(n):
        t = 0.01 * k
        rec.tf(t, "odom", "base_link", 0.0, 0.0, 0.0)
        if k % 100 == 0:
            rec.scan("/scan", t, "laser", RANGES[0], ANGLE_MIN, ANGLE_STEP, 0.0, 20.0)
        if 1400 <= k < 1410:
            rec.tf(t, "base_link", "arm", 0.0, 0.0, 0.0)
        if k >= n - 50:
            rec.tf(t, "map", "odom", 0.0, 0.0, 0.0)
    info = vg.bag_info(rec.write(tmp_path / "long.mcap"))
    total = n + 10 + 50
    assert info.tf.tf_total == total and not info.tf.complete
    assert bag_info_module.TF_HEAD <= info.tf.tf_read <= bag_info_module.TF_HEAD + bag_info_module.TF_TAIL < total
    assert link(info, "odom") == ("map", False) and "arm" not in info.tf.links
    assert info.tf.roots() == ["map"] and info.refusal is None
    assert any(f"of the {total} /tf messages" in n for n in info.notes)
    assert f"(the first and last) /tf" in info.text()


def _cloud(rec, t, frame):
    """A PointCloud2 of four points at 1.0 m height, 2 m around the sensor."""
    T = rec.messages.T
    pts = np.array([[2, 0, 1], [0, 2, 1], [-2, 0, 1], [0, -2, 1]], dtype="<f4")
    fields = [T["sensor_msgs/msg/PointField"](name=c, offset=4 * k, datatype=7, count=1) for k, c in enumerate("xyz")]
    msg = T["sensor_msgs/msg/PointCloud2"](header=rec.messages.header(t, frame), height=1, width=len(pts),
                                           fields=fields, is_bigendian=False, point_step=12, row_step=12 * len(pts),
                                           data=np.frombuffer(pts.tobytes(), dtype=np.uint8), is_dense=True)
    rec.add(t, "/points", "sensor_msgs/msg/PointCloud2", msg)


@pytest.mark.parametrize("mounted", [True, False])
def test_a_point_cloud_needs_a_static_chain_from_the_base(tmp_path, mounted):
    rec = bag_maker.Recording("mcap")
    rec.tf(STAMPS[0], "base_link" if mounted else "odom", "lidar", 0.0, 0.0, 0.0, static=True)
    for k, t in enumerate(STAMPS):
        rec.tf(t, "map", "odom", 0.0, 0.0, 0.0)
        rec.tf(t, "odom", "base_link", 0.0, 0.0, 0.0)
        _cloud(rec, t, "lidar")
    info = vg.bag_info(rec.write(tmp_path / "cloud.mcap"))
    assert [(s.topic, s.type, s.frame) for s in info.scans] == [("/points", "sensor_msgs/PointCloud2", "lidar")]
    if mounted:
        assert info.refusal is None and "--base-frame" not in info.command
    else:
        assert "height band" in info.refusal and info.command[1:3] == ["--base-frame", "lidar"]
    r, out = run_command(info, tmp_path)
    assert r.returncode == 0, r.stderr


def test_a_file_that_is_not_a_bag(tmp_path):
    notes = tmp_path / "notes.bag"
    notes.write_text("not a bag\n")
    with pytest.raises(BagError) as e:
        vg.bag_info(notes)
    assert "notes.bag" in str(e.value) and "not a ROS bag" in str(e.value)
    r = run_script("bag2map", "--info", notes)
    assert r.returncode == 1 and r.stdout == ""
    assert r.stderr.startswith(f"bag2map: {notes}: ") and "not a ROS bag" in r.stderr
    r = run_script("bag2map", "--info", tmp_path / "missing.mcap")
    assert r.returncode == 1 and "missing.mcap" in r.stderr and "no such file" in r.stderr
    good = odom_tree_bag(tmp_path)
    r = run_script("bag2map", "--info", notes, good)  # each bag reported; the bad one named, exit 1
    assert r.returncode == 1 and r.stdout == vg.bag_info(good).text() and str(notes) in r.stderr


def test_info_takes_bags_only(tmp_path):
    path = odom_tree_bag(tmp_path)
    for args in (["--info"], ["--info", "--backend", "cpu_double", path]):
        r = run_script("bag2map", *args)
        assert r.returncode == 2 and "--info takes bags only" in r.stderr
    assert "bag2map --info BAG" in run_script("bag2map", "--help").stdout


def test_bag2map_given_a_carmen_log_names_log2map(tmp_path):
    """A CARMEN log where a bag is asked for: exit 2 and the log2map command, not a reader's error."""
    log = Path(__file__).resolve().parents[2] / "logs" / "intel.gfs.log.gz"
    r = run_script("bag2map", str(log), str(tmp_path / "out.map"))
    assert r.returncode == 2, r.stderr
    assert "is a CARMEN log" in r.stderr and f"log2map {log} OUTPUT" in r.stderr
    assert not (tmp_path / "out.map").exists()
