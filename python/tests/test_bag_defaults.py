"""Bags as recorded map by default where the choice is clear, and say what to do where it is not:
a tf tree without 'map' (the one root the scans reach, with a warning), a LaserScan whose
angle_max disagrees with its ranges by rounding (velodyne_laserscan's), a height band that keeps
no point of the clouds, a moving sensor without poses, and a bag rosbags cannot open."""

from __future__ import annotations

import math
import shutil
import sys
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

pytest.importorskip("rosbags")

import vasco_gpu as vg  # noqa: E402
import vasco_gpu.bags as vb  # noqa: E402
from vasco_gpu.bags.load import read_for_engine  # noqa: E402
from vasco_gpu.msgs import laser  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bag_maker as bm  # noqa: E402

T0 = 1000.0
N = 6
RANGES = np.full(90, 3.0)
# velodyne_laserscan at its default resolution, as a Jackal bag records it
VELODYNE = dict(n=897, angle_min=-3.14159274, angle_max=3.14159274, angle_increment=0.00700000022)


def base_poses(n=N):
    return [(0.2 * k, 0.1 * k, 0.05 * k) for k in range(n)]


def odom_bag(tmp_path, fmt="mcap", root="odom", name="odom", scans=True, moving=True):
    """Scans in 'laser', base_link -> laser on /tf_static, root -> base_link on /tf (no 'map')."""
    rec = bm.Recording(fmt)
    rec.tf(T0, "base_link", "laser", 0.0, 0.0, 0.0, static=True)
    for k, p in enumerate(base_poses()):
        t = T0 + 0.1 * k
        if scans:
            rec.scan("/scan", t, "laser", RANGES, -1.5, 1.5 * 2 / 89, 0.1, 20.0)
        if moving:
            rec.tf(t, root, "base_link", *p)
    return rec.write(bm.bag_path(tmp_path, fmt, name))


def test_no_map_frame_maps_in_the_one_root_with_one_warning(tmp_path):
    p = odom_bag(tmp_path)
    d = read_for_engine(p)  # bag2map's reader: the command line's words
    assert len(d["warnings"]) == 1
    text = d["warnings"][0]
    for part in ("no 'map' frame", "'odom'", "--fixed-frame", "drifts", "--poses FILE", str(p)):
        assert part in text, part
    # the poses are those given on /tf (identity mount, scans at the tf stamps): odom's frame
    np.testing.assert_allclose(d["bag"].poses, base_poses(), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(d["bag"].poses, vb.read_bag(p, fixed_frame="odom").poses)
    # load_bag warns once, in the Python API's words
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        vg.load_bag(p)
    texts = [str(w.message) for w in caught if issubclass(w.category, vb.BagWarning)]
    assert len(texts) == 1 and "fixed_frame=FRAME" in texts[0] and "poses=FILE" in texts[0]
    assert "--" not in texts[0]


def test_a_fixed_frame_given_or_read_bag_keeps_map(tmp_path):
    p = odom_bag(tmp_path, name="keep")
    assert read_for_engine(p, fixed_frame="odom")["warnings"] == []
    with pytest.raises(vb.BagError, match="no transform chain from 'map' to 'laser'"):
        vb.read_bag(p)  # read_bag's own default stays 'map'


def test_scans_reaching_two_roots_are_refused_naming_the_roots(tmp_path):
    rec = bm.Recording("sqlite3")
    rec.tf(T0, "base_link", "laser", 0.0, 0.0, 0.0, static=True)
    rec.tf(T0, "rig", "laser2", 0.0, 0.0, 0.0, static=True)
    for k, p in enumerate(base_poses()):
        t = T0 + 0.1 * k
        rec.scan("/scan", t, "laser", RANGES, -1.5, 1.5 * 2 / 89, 0.1, 20.0)
        rec.scan("/scan2", t, "laser2", RANGES, -1.5, 1.5 * 2 / 89, 0.1, 20.0)
        rec.tf(t, "odom", "base_link", *p)
        rec.tf(t, "world", "rig", *p)
    path = rec.write(tmp_path / "two")
    with pytest.raises(vb.BagError) as e:
        read_for_engine(path, scan_topic="/scan,/scan2")
    text = e.value.message
    assert "--fixed-frame FRAME" in text and "the roots in tf: odom, world" in text
    assert "'laser' reaches 'odom'" in text and "'laser2' reaches 'world'" in text


def test_a_static_tree_alone_gives_no_poses(tmp_path):
    p = odom_bag(tmp_path, moving=False, name="static")
    with pytest.raises(vb.BagError) as e:
        read_for_engine(p)
    text = e.value.message
    assert "on /tf_static only" in text and "SLAM or odometry" in text and "--poses FILE" in text


def test_a_moving_sensor_without_poses_says_where_poses_come_from(tmp_path):
    p = bm.write_bag(bm.bag_path(tmp_path, "mcap", "bare"), "mcap", [T0 + 0.1 * k for k in range(N)],
                     [RANGES] * N, -1.5, 1.5 * 2 / 89, 0.1, 20.0)
    with pytest.raises(vb.BagError) as e:
        read_for_engine(p)
    cli = e.value.message
    for part in ("SLAM or odometry", "slam_toolbox", "Cartographer", "--poses FILE", "--pose-topic TOPIC",
                 "--static-pose X,Y,THETA"):
        assert part in cli, part
    assert "_" not in cli.replace("slam_toolbox", "")  # no Python keyword names
    with pytest.raises(vg.Error) as e:
        vg.load_bag(p)
    assert "poses=FILE" in str(e.value) and "static_pose=(X, Y, THETA)" in str(e.value)
    assert "--poses" not in str(e.value)


# ----------------------------------------------------------------------------------------------
# LaserScan angles


def velodyne_bag(tmp_path, n=VELODYNE["n"], angle_max=VELODYNE["angle_max"], name="velodyne"):
    rec = bm.Recording("mcap")
    ranges = np.full(n, 4.0)
    for k in range(3):
        bm.scan_with_angle_max(rec, "/scan", T0 + 0.1 * k, "velodyne", ranges, VELODYNE["angle_min"], angle_max,
                               VELODYNE["angle_increment"])
    return rec.write(tmp_path / f"{name}.mcap")


def test_a_velodyne_laserscan_is_taken_beam_by_beam_with_one_warning(tmp_path):
    p = velodyne_bag(tmp_path)
    d = read_for_engine(p, static_pose=(0.0, 0.0, 0.0))
    b = d["bag"]
    assert list(b.beam_counts) == [897] * 3
    # beam i at angle_min + i * angle_increment: the message's float32 values unchanged
    assert np.all(b.first_angle == float(np.float32(VELODYNE["angle_min"])))
    assert np.all(b.angle_step == float(np.float32(VELODYNE["angle_increment"])))
    assert len(d["warnings"]) == 1
    text = d["warnings"][0]
    assert "3 of the 3 scans on '/scan'" in text and "has 897 ranges" in text and "898.6 beams" in text


@pytest.mark.parametrize("n, angle_max, words", [
    (180, 1.0, "makes 201.0 beams (11.7 % off"),  # the node's bad message: 201 beams by the angles
    (1000, 3.14159274, "more than a turn"),  # 1000 beams of 0.007 rad: 7 rad, over 2 pi and a step
])
def test_what_cannot_be_a_scan_is_refused_naming_the_numbers(tmp_path, n, angle_max, words):
    a0 = -1.0 if n == 180 else VELODYNE["angle_min"]
    inc = 0.01 if n == 180 else VELODYNE["angle_increment"]
    rec = bm.Recording("sqlite3")
    bm.scan_with_angle_max(rec, "/scan", T0, "laser", np.full(n, 2.0), a0, angle_max, inc)
    p = rec.write(tmp_path / "bad")
    with pytest.raises(vb.BagError) as e:
        read_for_engine(p, static_pose=(0.0, 0.0, 0.0))
    assert f"has {n} ranges, but angle_min" in e.value.message and words in e.value.message


def scan_msg(n, a0, a1, da):
    return SimpleNamespace(range_min=0.1, range_max=30.0, angle_min=a0, angle_max=a1, angle_increment=da,
                           ranges=np.full(n, 2.0, dtype=np.float32), header=SimpleNamespace(frame_id="laser"))


def test_the_bound_on_the_count():
    counts = dict.fromkeys(laser.COUNT_KEYS, 0)
    fail = lambda what: ValueError(what)
    exact = float(np.float32(-1.0) + np.float32(0.01) * np.float32(199))
    laser.read_laser(scan_msg(200, -1.0, exact, 0.01), no_return="skip", counts=counts, fail=fail)
    assert counts.get(laser.ANGLES_OFF, 0) == 0  # float32 rounding only: no warning
    # 2 % of 1000 beams: 19.5 off is taken, 20.5 is not
    laser.read_laser(scan_msg(1000, 0.0, 0.001 * 1018.5, 0.001), no_return="skip", counts=counts, fail=fail)
    assert counts[laser.ANGLES_OFF] == 1
    with pytest.raises(ValueError, match="makes 1020.5 beams"):
        laser.read_laser(scan_msg(1000, 0.0, 0.001 * 1019.5, 0.001), no_return="skip", counts=counts, fail=fail)
    # a small scan keeps the 1.5 beams of slack: 10 ranges for 11.4 beams
    laser.read_laser(scan_msg(10, 0.0, 0.1 * 10.4, 0.1), no_return="skip", counts=counts, fail=fail)
    assert counts[laser.ANGLES_OFF] == 2


# ----------------------------------------------------------------------------------------------
# Point clouds and the height band


def flat_cloud_bag(tmp_path, z=0.089):
    """A 2-D lidar's cloud in the base frame, every point at one height (a Neato's)."""
    rec = bm.Recording("mcap")
    angles = np.linspace(-math.pi, math.pi, 360, endpoint=False)
    pts = np.column_stack([2 * np.cos(angles), 2 * np.sin(angles), np.full(360, z)])
    for k in range(3):
        bm.point_cloud(rec, "/cloud", T0 + 0.1 * k, "base_link", pts)
    return rec.write(tmp_path / "flat.mcap")


def test_a_band_that_drops_every_point_names_the_band_and_the_heights(tmp_path):
    p = flat_cloud_bag(tmp_path)
    with pytest.raises(vb.BagError) as e:
        read_for_engine(p, static_pose=(0.0, 0.0, 0.0))
    text = e.value.message
    for part in ("--z-band 0.2,1.8", "from 0.089 to 0.089 m", "1080 points of the 3 clouds", "'base_link'",
                 "--z-band 0.03,0.14"):
        assert part in text, part
    with pytest.raises(vb.BagError, match=r"z_band=\(0.2, 1.8\)"):
        vb.read_bag(p, static_pose=(0.0, 0.0, 0.0))
    b = read_for_engine(p, static_pose=(0.0, 0.0, 0.0), z_band="0.03,0.14")["bag"]  # the band it suggests
    assert b.counts["points"] == 1080


# ----------------------------------------------------------------------------------------------
# Bags rosbags cannot open


def test_a_ros1_bag_rosbags_rejects_names_the_check_and_the_repair(tmp_path):
    p = odom_bag(tmp_path, "rosbag1", root="map", name="good")
    data = bytearray(p.read_bytes())
    # an index data record's header is 47 bytes (ver, conn, count, op=4): a length that is not
    # fails rosbags' assert, which said only "AssertionError"
    at = next(k for k in range(len(data) - 51)
              if data[k:k + 4] == (47).to_bytes(4, "little") and b"op=\x04" in data[k + 4:k + 51])
    data[at] = 48
    bad = tmp_path / "bad.bag"
    bad.write_bytes(bytes(data))
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(bad)
    text = e.value.message
    assert "AssertionError" not in text and "a check of rosbags' reader failed" in text
    assert "rosbag reindex" in text


@pytest.mark.parametrize("fmt, repair", [("mcap", "mcap recover"), ("sqlite3", ".recover")])
def test_a_ros2_bag_cut_short_names_the_repair(tmp_path, fmt, repair):
    p = odom_bag(tmp_path, fmt, root="map", name="whole")
    cut = tmp_path / "cut"
    shutil.copytree(p, cut)
    store = next(x for x in cut.iterdir() if x.suffix in (".mcap", ".db3"))
    store.write_bytes(store.read_bytes()[: store.stat().st_size // 2])
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(cut)
    assert "cannot be read as a ROS bag" in e.value.message and repair in e.value.message
