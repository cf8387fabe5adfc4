"""Tests of vasco_gpu.bags' reader (ROS bags -> scans and laser poses -> CARMEN logs) on its own.

The subpackage is loaded by file path as a package of its own: vasco_gpu's __init__ imports the
compiled extension, which these tests neither need nor build. The bags are small synthetic
ones written by bag_maker in the three formats rosbags writes (ROS 1 .bag, ROS 2 sqlite3 and
MCAP directories).
"""

from __future__ import annotations

import ast
import gzip
import importlib
import importlib.util
import io
import math
import pickle
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosbags")

HERE = Path(__file__).resolve().parent
BAGS = HERE.parent / "src" / "vasco_gpu" / "bags"
# The modules that import the compiled extension (through the parent package): not loaded here.
ENGINE_MODULES = ("load.py", "cli.py", "carmen2bag.py")


def _load(name: str, path: Path, package: bool = False):
    """A module (or, with package, the package of path's directory) loaded from a file and
    registered under name (dataclasses and pickle need that)."""
    where = [str(path.parent)] if package else None
    spec = importlib.util.spec_from_file_location(name, path, submodule_search_locations=where)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


vb = _load("vasco_gpu_bags_under_test", BAGS / "__init__.py", package=True)
writer = importlib.import_module("vasco_gpu_bags_under_test.carmen_writer")
bm = _load("vasco_gpu_bag_maker", HERE / "bag_maker.py")

FORMATS = bm.FORMATS
T0 = 1_700_000_000.05  # a realistic epoch, with a fraction nanoseconds do not hold exactly
RMIN, RMAX = 0.1, 30.0
ANGLE_MIN, ANGLE_STEP = -1.5707963, 0.0174533


def stamps_of(n: int, dt: float = 0.1) -> list[float]:
    return [T0 + k * dt for k in range(n)]


def plain_ranges(n_scans: int, n_beams: int = 37, seed: int = 1) -> list[np.ndarray]:
    """Valid float32 ranges (within [RMIN, RMAX]), random bits in the mantissa."""
    rng = np.random.default_rng(seed)
    return [rng.uniform(RMIN, RMAX, n_beams).astype(np.float32) for _ in range(n_scans)]


def base_poses(n: int) -> np.ndarray:
    k = np.arange(n, dtype=np.float64)
    return np.column_stack([1.0 + 0.3 * k, -2.0 + 0.1 * k * k, 0.4 * k - 1.0])


def make(tmp_path, fmt, name="bag", n=5, ranges=None, **kw) -> Path:
    """A bag of n scans in tmp_path; keywords go to bag_maker.write_bag."""
    stamps = kw.pop("stamps", stamps_of(n))
    if ranges is None:
        ranges = plain_ranges(len(stamps))
    return bm.write_bag(bm.bag_path(tmp_path, fmt, name), fmt, stamps, ranges, ANGLE_MIN, ANGLE_STEP,
                        RMIN, RMAX, **kw)


def bits(a) -> np.ndarray:
    a = np.ascontiguousarray(a)
    return a.view(np.uint32 if a.dtype == np.float32 else np.uint64)


def quat_yaw(yaw: float) -> float:
    """The yaw the reader gets back from bag_maker's quaternion of yaw."""
    x, y, z, w = bm.yaw_quaternion(yaw)
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


def expected_stamps(stamps) -> np.ndarray:
    return np.array([s + ns * 1e-9 for s, ns in map(bm.split_stamp, stamps)])


# ----------------------------------------------------------------------------------------------
# Scans


@pytest.mark.parametrize("fmt", FORMATS)
def test_scans_read_back_bit_for_bit(tmp_path, fmt):
    ranges = plain_ranges(6, n_beams=41)
    stamps = stamps_of(6)
    p = make(tmp_path, fmt, ranges=ranges, stamps=stamps, tf_poses=base_poses(6), static_mount=(0, 0, 0))
    b = vb.read_bag(p)
    assert b.path == str(p) and b.topic == "/scan" and b.frame_id == "laser"
    assert b.pose_source == "tf"
    np.testing.assert_array_equal(b.stamps, expected_stamps(stamps))
    assert b.stamps.dtype == np.float64 and b.stamps.shape == (6,)
    assert b.ranges.dtype == np.float32
    assert np.array_equal(bits(b.ranges), bits(np.concatenate(ranges)))
    assert b.beam_counts.dtype == np.int64 and b.beam_counts.tolist() == [41] * 6
    assert b.first_angle.tolist() == [float(np.float32(ANGLE_MIN))] * 6
    assert b.angle_step.tolist() == [float(np.float32(ANGLE_STEP))] * 6
    assert b.counts == {"messages": 6, "nan": 0, "pos_inf": 0, "neg_inf": 0, "below_min": 0, "above_max": 0}
    assert b.poses.shape == (6, 3) and b.poses.dtype == np.float64
    assert b.range_max.tolist() == [float(np.float32(RMAX))] * 6


def test_reader_does_not_import_the_extension():
    """The reader's modules import nothing of vasco_gpu outside bags/ (vasco_gpu's __init__
    loads the compiled extension); only load.py and cli.py, which hand the scans to it, do."""
    modules = sorted(p for p in BAGS.glob("*.py") if p.name not in ENGINE_MODULES)
    assert {p.name for p in modules} >= {"__init__.py", "reader.py", "tf.py", "carmen_writer.py"}
    for path in modules:
        imported = []
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                imported += [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                imported.append("." * node.level + (node.module or ""))
        outside = [m for m in imported if m.startswith("..") or m.startswith("vasco_gpu")]
        assert not outside, (path.name, outside)


@pytest.mark.parametrize("fmt", ["sqlite3", "mcap"])
def test_bare_storage_file_and_directory_without_metadata(tmp_path, fmt):
    p = make(tmp_path, fmt, tf_poses=base_poses(5), static_mount=(0.1, 0.0, 0.0))
    whole = vb.read_bag(p)
    storage = next(x for x in p.iterdir() if x.suffix in (".db3", ".mcap"))
    bare = vb.read_bag(storage)
    assert bare.path == str(storage)
    assert np.array_equal(bits(bare.ranges), bits(whole.ranges))
    assert np.array_equal(bits(bare.poses), bits(whole.poses))
    (p / "metadata.yaml").unlink()
    lone = vb.read_bag(p)
    assert np.array_equal(bits(lone.poses), bits(whole.poses))


@pytest.mark.parametrize("dropped", ["all", "tf2_msgs/msg/TFMessage"])
def test_ros2_bag_without_type_definitions(tmp_path, dropped):
    """Older rosbag2 recordings store no definitions: the ROS 2 Humble ones are used, also for
    the types a bag leaves undefined while defining others."""
    import sqlite3

    p = make(tmp_path, "sqlite3", tf_poses=base_poses(5), static_mount=(0.1, 0.0, 0.0))
    want = vb.read_bag(p)
    db = sqlite3.connect(p / f"{p.name}.db3")
    if dropped == "all":
        db.execute("DELETE FROM message_definitions")
    else:
        db.execute("DELETE FROM message_definitions WHERE topic_type = ?", (dropped,))
    db.commit()
    db.close()
    got = vb.read_bag(p)
    assert np.array_equal(bits(got.poses), bits(want.poses))
    assert np.array_equal(bits(got.ranges), bits(want.ranges))


def test_leading_slash_frames_are_stripped(tmp_path):
    p = make(tmp_path, "rosbag1", laser_frame="/laser", tf_poses=base_poses(5), static_mount=(0.1, 0.0, 0.0))
    b = vb.read_bag(p)
    assert b.frame_id == "laser"
    assert b.mounts is not None and b.mounts[0].tolist() == [0.1, 0.0, 0.0]


def test_scans_in_different_frames(tmp_path):
    frames = ["laser", "laser", "laser_rear", "laser"]
    p = make(tmp_path, "mcap", n=4, laser_frame=frames, tf_poses=base_poses(4), static_mount=(0, 0, 0))
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p)
    sec, ns = bm.split_stamp(stamps_of(4)[2])
    text = str(e.value)
    assert f"{sec}.{ns:09d}" in text and "'laser_rear'" in text and "'/scan'" in text and p.name in text
    assert e.value.topic == "/scan" and e.value.stamp == pytest.approx(stamps_of(4)[2], abs=1e-6)


# ----------------------------------------------------------------------------------------------
# REP 117


def rep117_case():
    """(input ranges, expected 'skip' output, expected 'free' output, expected counts)."""
    f32 = np.float32
    v = np.array([RMIN, RMAX, 5.25, np.nan, np.inf, -np.inf, 0.05, 0.0, -1.0, 30.5, 60.0, 12.0], dtype=f32)
    nan = f32(np.nan)
    skip = np.array([RMIN, RMAX, 5.25, nan, np.inf, nan, nan, nan, nan, nan, nan, 12.0], dtype=f32)
    free = skip.copy()
    free[4] = np.nextafter(f32(50), f32(0))
    counts = {"nan": 1, "pos_inf": 1, "neg_inf": 1, "below_min": 3, "above_max": 2}
    return v, skip, free, counts


@pytest.mark.parametrize("fmt", FORMATS)
@pytest.mark.parametrize("mode", ["skip", "free"])
def test_rep117_table(tmp_path, fmt, mode):
    v, skip, free, counts = rep117_case()
    p = make(tmp_path, fmt, ranges=[v, v[::-1].copy()], stamps=stamps_of(2), tf_poses=base_poses(2),
             static_mount=(0, 0, 0))
    b = vb.read_bag(p, no_return=mode)
    want = skip if mode == "skip" else free
    got = b.ranges[:len(v)]
    assert np.array_equal(np.isnan(got), np.isnan(want))
    ok = ~np.isnan(want)
    assert np.array_equal(bits(got[ok]), bits(want[ok]))
    assert np.array_equal(bits(b.ranges[len(v):][::-1][ok]), bits(want[ok]))
    assert b.counts == {"messages": 2, **{k: 2 * c for k, c in counts.items()}}
    if mode == "free":
        assert got[4] == np.nextafter(np.float32(50), np.float32(0)) and got[4] < np.float32(50)
        assert vb.NO_RETURN_FREE == got[4] and vb.NO_RETURN_FREE.dtype == np.float32


def test_bad_arguments_are_value_errors(tmp_path):
    p = make(tmp_path, "rosbag1", tf_poses=base_poses(5))
    with pytest.raises(ValueError, match="no_return"):
        vb.read_bag(p, no_return="clear")
    with pytest.raises(ValueError, match="pose_source"):
        vb.read_bag(p, pose_source="odom")
    with pytest.raises(ValueError, match="pose_topic"):
        vb.read_bag(p, pose_source="topic")
    with pytest.raises(ValueError, match="laser_mount"):
        vb.read_bag(p, laser_mount=(0.1, 0.0))


# ----------------------------------------------------------------------------------------------
# Poses from tf


@pytest.mark.parametrize("fmt", FORMATS)
def test_identity_mount_leaves_poses_bit_for_bit(tmp_path, fmt):
    poses = base_poses(7)
    mounted = vb.read_bag(make(tmp_path, fmt, "a", n=7, tf_poses=poses, static_mount=(0.0, 0.0, 0.0)))
    direct = vb.read_bag(make(tmp_path, fmt, "b", n=7, tf_poses=poses, laser_frame="base_link"))
    assert np.array_equal(bits(mounted.poses), bits(direct.poses))
    assert np.array_equal(bits(mounted.poses[:, :2]), bits(poses[:, :2]))  # exact hits, no arithmetic
    # yaw: atan2 of the quaternion (numpy's atan2 may differ from math's in the last bit)
    np.testing.assert_allclose(mounted.poses[:, 2], [quat_yaw(y) for y in poses[:, 2]], rtol=0, atol=1e-15)
    np.testing.assert_allclose(mounted.poses[:, 2], poses[:, 2], rtol=0, atol=1e-15)
    assert mounted.mounts.tolist() == [[0.0, 0.0, 0.0]] * 7
    assert direct.mounts.tolist() == [[0.0, 0.0, 0.0]] * 7  # base_link is the scan frame


@pytest.mark.parametrize("fmt", FORMATS)
def test_mount_offset_gives_hand_computed_laser_poses(tmp_path, fmt):
    poses = base_poses(6)
    b = vb.read_bag(make(tmp_path, fmt, n=6, tf_poses=poses, static_mount=(0.1, 0.0, 0.0)))
    for (x, y, yaw), got in zip(poses, b.poses):
        want = (x + math.cos(yaw) * 0.1, y + math.sin(yaw) * 0.1, yaw)
        assert got.tolist() == pytest.approx(want, abs=1e-12)
    assert b.mounts.shape == (6, 3) and b.mounts.tolist() == [[0.1, 0.0, 0.0]] * 6


def test_mount_with_rotation(tmp_path):
    poses = base_poses(4)
    mount = (0.25, -0.05, 0.5)
    b = vb.read_bag(make(tmp_path, "mcap", n=4, tf_poses=poses, static_mount=mount))
    mx, my, mt = mount
    for (x, y, t), got in zip(poses, b.poses):
        want = (x + math.cos(t) * mx - math.sin(t) * my, y + math.sin(t) * mx + math.cos(t) * my, t + mt)
        assert got.tolist() == pytest.approx(want, abs=1e-12)
    assert b.mounts[0].tolist() == pytest.approx(list(mount), abs=1e-15)


@pytest.mark.parametrize("fmt", FORMATS)
def test_tf_interpolation_between_samples(tmp_path, fmt):
    tf_stamps = [T0, T0 + 1.0, T0 + 2.0]
    tf_poses = np.array([[0.0, 0.0, 0.2], [1.0, 2.0, 0.6], [3.0, 2.0, 3.0]])
    scan_stamps = [T0, T0 + 0.25, T0 + 1.0, T0 + 1.5, T0 + 2.0]
    p = make(tmp_path, fmt, stamps=scan_stamps, tf_poses=tf_poses, tf_stamps=tf_stamps,
             static_mount=(0, 0, 0))
    b = vb.read_bag(p)
    ns = [bm.stamp_ns(t) for t in scan_stamps]
    tf_ns = [bm.stamp_ns(t) for t in tf_stamps]
    for k, got in enumerate(b.poses):
        j = min(max(np.searchsorted(tf_ns, ns[k], side="right") - 1, 0), 1)
        f = (ns[k] - tf_ns[j]) / (tf_ns[j + 1] - tf_ns[j])
        a, c = tf_poses[j], tf_poses[j + 1]
        want = (a[0] + (c[0] - a[0]) * f, a[1] + (c[1] - a[1]) * f, a[2] + (c[2] - a[2]) * f)
        assert got.tolist() == pytest.approx(want, abs=1e-12), k
    assert b.poses[0, :2].tolist() == [0.0, 0.0] and b.poses[2, :2].tolist() == [1.0, 2.0]


def test_tf_interpolation_takes_the_short_arc(tmp_path):
    tf_poses = np.array([[0.0, 0.0, 3.0], [0.0, 0.0, -3.0]])
    p = make(tmp_path, "rosbag1", stamps=[T0 + 0.5], tf_poses=tf_poses, tf_stamps=[T0, T0 + 1.0],
             laser_frame="base_link")
    yaw = vb.read_bag(p).poses[0, 2]
    assert abs(abs(yaw) - math.pi) < 1e-9  # halfway through pi, not through 0


@pytest.mark.parametrize("fmt", FORMATS)
def test_stamp_outside_tf_span(tmp_path, fmt):
    p = make(tmp_path, fmt, stamps=[T0 + 0.5, T0 + 1.5], tf_poses=base_poses(2),
             tf_stamps=[T0 + 1.0, T0 + 2.0], static_mount=(0, 0, 0))
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p)
    text = str(e.value)
    sec, ns = bm.split_stamp(T0 + 0.5)
    assert p.name in text and f"{sec}.{ns:09d}" in text
    assert "map -> base_link" in text and "outside" in text
    s1, n1 = bm.split_stamp(T0 + 1.0)
    assert f"{s1}.{n1:09d}" in text  # the span
    assert e.value.file == str(p) and e.value.stamp == pytest.approx(T0 + 0.5, abs=1e-6)


def test_broken_chain_names_the_missing_link(tmp_path):
    p = make(tmp_path, "sqlite3", tf_poses=base_poses(5))  # no base_link -> laser
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p)
    text = str(e.value)
    assert p.name in text and "no transform chain from 'map' to 'laser'" in text
    assert "'laser' is not in tf" in text and "frames in /tf: base_link, map" in text

    q = make(tmp_path, "sqlite3", "odom", tf_poses=base_poses(5), static_mount=(0.1, 0, 0))
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(q, fixed_frame="odom")
    text = str(e.value)
    assert "'laser' reaches 'map' via base_link" in text and "'odom' has no connection to it" in text


def test_fixed_frame_none_is_the_root(tmp_path):
    p = make(tmp_path, "mcap", tf_poses=base_poses(5), static_mount=(0, 0, 0))
    a = vb.read_bag(p, fixed_frame=None)
    b = vb.read_bag(p)
    assert np.array_equal(bits(a.poses), bits(b.poses))


def test_fixed_frame_off_the_laser_branch_uses_the_inverse(tmp_path):
    # map -> base_link (dynamic), base_link -> laser and base_link -> imu (static): the laser in
    # 'imu' is inv(T_base_imu) * T_base_laser, constant over time.
    laser, imu = (0.3, 0.1, 0.5), (-0.2, 0.4, -0.7)
    p = make(tmp_path, "rosbag1", tf_poses=base_poses(5), static_mount=laser,
             static_transforms=[("base_link", "imu", *imu)])
    b = vb.read_bag(p, fixed_frame="imu")
    ix, iy, it = imu
    dx, dy = laser[0] - ix, laser[1] - iy
    want = (math.cos(it) * dx + math.sin(it) * dy, -math.sin(it) * dx + math.cos(it) * dy, laser[2] - it)
    for got in b.poses:
        assert got.tolist() == pytest.approx(want, abs=1e-12)
    np.testing.assert_allclose(vb.read_bag(p, fixed_frame="laser").poses, 0.0, atol=1e-15)
    np.testing.assert_allclose(vb.read_bag(p, fixed_frame="base_link").poses, [laser] * 5, atol=1e-15)


def test_frame_with_two_parents(tmp_path):
    p = make(tmp_path, "mcap", tf_poses=base_poses(5), static_mount=(0, 0, 0),
             static_transforms=[("map", "laser", 0, 0, 0)])
    with pytest.raises(vb.BagError, match="frame 'laser' has two parents"):
        vb.read_bag(p)


def test_no_tf_and_no_pose_topic(tmp_path):
    p = make(tmp_path, "rosbag1")
    with pytest.raises(vb.BagError, match="--pose-topic") as e:
        vb.read_bag(p)
    assert p.name in str(e.value) and "--poses FILE" in str(e.value)


# ----------------------------------------------------------------------------------------------
# Poses from a pose topic


@pytest.mark.parametrize("fmt", FORMATS)
def test_odometry_topic_with_static_mount(tmp_path, fmt):
    poses = base_poses(6)
    p = make(tmp_path, fmt, n=6, odom_poses=poses, static_mount=(0.1, 0.0, 0.0))
    b = vb.read_bag(p, pose_topic="/odom")
    assert b.pose_source == "topic:/odom"
    for (x, y, yaw), got in zip(poses, b.poses):
        want = (x + math.cos(yaw) * 0.1, y + math.sin(yaw) * 0.1, yaw)
        assert got.tolist() == pytest.approx(want, abs=1e-12)
    assert b.mounts.tolist() == [[0.1, 0.0, 0.0]] * 6


@pytest.mark.parametrize("fmt", FORMATS)
def test_odometry_interpolated_and_laser_mount_argument(tmp_path, fmt):
    odom_stamps = [T0 - 1.0, T0 + 1.0, T0 + 3.0]
    odom = np.array([[0.0, 0.0, 0.0], [2.0, 1.0, 1.0], [2.0, 3.0, 1.5]])
    scan_stamps = [T0, T0 + 1.0, T0 + 2.5]
    p = make(tmp_path, fmt, stamps=scan_stamps, odom_poses=odom, odom_stamps=odom_stamps)
    mount = (0.2, 0.1, 0.3)
    b = vb.read_bag(p, pose_topic="odom", laser_mount=mount)  # name without the slash
    ns, o_ns = [bm.stamp_ns(t) for t in scan_stamps], [bm.stamp_ns(t) for t in odom_stamps]
    for k, got in enumerate(b.poses):
        j = 0 if ns[k] < o_ns[1] else 1
        f = (ns[k] - o_ns[j]) / (o_ns[j + 1] - o_ns[j])
        a, c = odom[j], odom[j + 1]
        bx, by = a[0] + (c[0] - a[0]) * f, a[1] + (c[1] - a[1]) * f
        bt = quat_yaw(a[2]) + (quat_yaw(c[2]) - quat_yaw(a[2])) * f
        want = (bx + math.cos(bt) * mount[0] - math.sin(bt) * mount[1],
                by + math.sin(bt) * mount[0] + math.cos(bt) * mount[1], bt + mount[2])
        assert got.tolist() == pytest.approx(want, abs=1e-12), k
    assert b.mounts.tolist() == [list(mount)] * 3


def test_pose_stamped_topic_identity_mount_unchanged(tmp_path):
    poses = base_poses(5)
    p = make(tmp_path, "mcap", pose_stamped=poses, laser_frame="base_link")
    b = vb.read_bag(p, pose_topic="/pose")
    assert b.pose_source == "topic:/pose"
    assert np.array_equal(bits(b.poses[:, :2]), bits(poses[:, :2]))
    np.testing.assert_allclose(b.poses[:, 2], [quat_yaw(y) for y in poses[:, 2]], rtol=0, atol=1e-15)


def test_pose_topic_errors(tmp_path):
    poses = base_poses(5)
    p = make(tmp_path, "rosbag1", odom_poses=poses, static_mount=(0.1, 0, 0))
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p, pose_topic="/odom", fixed_frame="odom")
    assert "'map'" in str(e.value) and "'odom'" in str(e.value) and p.name in str(e.value)
    assert e.value.topic == "/odom"
    assert vb.read_bag(p, pose_topic="/odom", fixed_frame=None).poses.shape == (5, 3)
    with pytest.raises(vb.BagError, match="no pose topic '/gps'"):
        vb.read_bag(p, pose_topic="/gps")
    with pytest.raises(vb.BagError, match="pose topic '/scan' is sensor_msgs/LaserScan"):
        vb.read_bag(p, pose_topic="/scan")
    with pytest.raises(vb.BagError, match="child_frame_id 'base_link', not the base frame 'base'"):
        vb.read_bag(p, pose_topic="/odom", base_frame="base")


def test_pose_topic_without_mount_chain(tmp_path):
    p = make(tmp_path, "sqlite3", odom_poses=base_poses(5))
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p, pose_topic="/odom")
    assert "--laser-mount" in str(e.value) and "'base_link'" in str(e.value) and "'laser'" in str(e.value)


def test_scan_outside_pose_topic_span(tmp_path):
    p = make(tmp_path, "mcap", stamps=[T0, T0 + 5.0], odom_poses=base_poses(2), odom_stamps=[T0, T0 + 1.0],
             laser_frame="base_link")
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p, pose_topic="/odom")
    sec, ns = bm.split_stamp(T0 + 5.0)
    assert f"{sec}.{ns:09d}" in str(e.value) and "'/odom'" in str(e.value) and p.name in str(e.value)
    assert e.value.topic == "/odom"


def test_pose_source_none(tmp_path):
    p = make(tmp_path, "rosbag1", tf_poses=base_poses(5), static_mount=(0.1, 0, 0))
    b = vb.read_bag(p, pose_source="none")
    assert b.pose_source == "none" and np.isnan(b.poses).all() and b.poses.shape == (5, 3)
    assert b.mounts.tolist() == [[0.1, 0.0, 0.0]] * 5
    q = make(tmp_path, "rosbag1", "bare")
    assert vb.read_bag(q, pose_source="none").mounts is None
    assert vb.read_bag(q, pose_source="none", laser_mount=(1, 2, 3)).mounts.tolist() == [[1.0, 2.0, 3.0]] * 5


# ----------------------------------------------------------------------------------------------
# Topic choice and errors


@pytest.mark.parametrize("fmt", FORMATS)
def test_several_scan_topics(tmp_path, fmt):
    p = make(tmp_path, fmt, tf_poses=base_poses(5), static_mount=(0, 0, 0), extra_scan_topics=("/scan_rear",))
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p)
    text = str(e.value)
    assert p.name in text and "'/scan'" in text and "'/scan_rear'" in text and "--scan-topic" in text
    assert vb.read_bag(p, scan_topic="/scan_rear").topic == "/scan_rear"
    assert vb.read_bag(p, scan_topic="scan_rear").topic == "/scan_rear"


def test_named_topic_missing_or_not_a_scan(tmp_path):
    p = make(tmp_path, "rosbag1", tf_poses=base_poses(5), static_mount=(0, 0, 0))
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p, scan_topic="/front_scan")
    assert "'/front_scan'" in str(e.value) and "scan topics: '/scan'" in str(e.value)
    assert e.value.topic == "/front_scan"
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p, scan_topic="/tf")
    assert "'/tf' is tf2_msgs/TFMessage, not sensor_msgs/LaserScan" in str(e.value)


@pytest.mark.parametrize("fmt", FORMATS)
def test_scan_topic_without_messages(tmp_path, fmt):
    p = make(tmp_path, fmt, stamps=[], ranges=[], tf_poses=base_poses(2), tf_stamps=[T0, T0 + 1])
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p)
    assert "'/scan' has no messages" in str(e.value) and p.name in str(e.value)


@pytest.mark.parametrize("fmt", FORMATS)
def test_no_scan_topic_and_empty_bag(tmp_path, fmt):
    p = make(tmp_path, fmt, "tfonly", scan_topic=None, tf_poses=base_poses(5))
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p)
    assert "no sensor_msgs/LaserScan, MultiEchoLaserScan or PointCloud2 topic (topics: '/tf' (tf2_msgs/TFMessage))" in str(e.value)
    q = make(tmp_path, fmt, "empty", stamps=[], ranges=[], scan_topic=None)
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(q)
    assert q.name in str(e.value) and "no sensor_msgs/LaserScan, MultiEchoLaserScan or PointCloud2 topic" in str(e.value)


def test_not_a_bag(tmp_path):
    missing = tmp_path / "nothere.bag"
    with pytest.raises(vb.BagError, match="nothere.bag: no such file"):
        vb.read_bag(missing)
    empty = tmp_path / "empty.bag"
    empty.write_bytes(b"")
    with pytest.raises(vb.BagError, match="empty.bag: is empty"):
        vb.read_bag(empty)
    text = tmp_path / "notes.bag"
    text.write_text("this is not a bag\n")
    with pytest.raises(vb.BagError, match="notes.bag: is not a ROS bag"):
        vb.read_bag(text)
    folder = tmp_path / "folder"
    folder.mkdir()
    with pytest.raises(vb.BagError, match="folder: is a directory without metadata.yaml"):
        vb.read_bag(folder)
    fake = tmp_path / "fake.mcap"
    fake.write_bytes(b"\x89MCAP0\r\n" + b"\0" * 40)
    with pytest.raises(vb.BagError, match="fake.mcap: cannot be read as a ROS bag") as e:
        vb.read_bag(fake)
    assert e.value.__cause__ is not None


@pytest.mark.parametrize("fmt", FORMATS)
def test_truncated_bag(tmp_path, fmt):
    p = make(tmp_path, fmt, n=20, tf_poses=base_poses(20), static_mount=(0, 0, 0))
    f = p if fmt == "rosbag1" else next(x for x in p.iterdir() if x.suffix in (".db3", ".mcap"))
    data = f.read_bytes()
    f.write_bytes(data[: len(data) // 2])
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p)
    assert p.name in str(e.value)
    assert "Traceback" not in str(e.value)


def test_ros1_bag_with_another_suffix(tmp_path):
    p = make(tmp_path, "rosbag1", tf_poses=base_poses(5), static_mount=(0, 0, 0))
    other = tmp_path / "recording.dat"
    shutil.copy(p, other)
    with pytest.raises(vb.BagError, match=r"recording.dat: is a ROS 1 bag but its name does not end in "):
        vb.read_bag(other)


def test_bag_error_attributes_and_pickle():
    e = vb.BagError("x.bag", "something", topic="/scan", stamp=1.5)
    assert str(e) == "x.bag: something" and (e.file, e.topic, e.stamp) == ("x.bag", "/scan", 1.5)
    f = pickle.loads(pickle.dumps(e))
    assert str(f) == str(e) and (f.file, f.topic, f.stamp) == ("x.bag", "/scan", 1.5)


def test_progress(tmp_path):
    p = make(tmp_path, "mcap", n=30, tf_poses=base_poses(30), static_mount=(0, 0, 0))
    calls = []
    vb.read_bag(p, progress=lambda done, total: calls.append((done, total)))
    assert calls and calls[-1] == (61, 61)  # 30 scans + 30 tf + 1 tf_static
    assert [d for d, _ in calls] == sorted(d for d, _ in calls)


# ----------------------------------------------------------------------------------------------
# write_carmen_log


def parse_robotlaser(line: str) -> dict:
    tok = line.split()
    assert tok[0] == "ROBOTLASER1"
    n = int(tok[8])
    rest = tok[9 + n:]
    assert int(rest[0]) == 0  # no remissions
    nums = [float(x) for x in rest[1:12]]
    return {
        "laser_type": int(tok[1]), "start": float(tok[2]), "fov": float(tok[3]), "res": float(tok[4]),
        "max_range": float(tok[5]), "accuracy": float(tok[6]), "remission_mode": int(tok[7]),
        "ranges": np.array([float(x) for x in tok[9:9 + n]], dtype=np.float64).astype(np.float32),
        "laser": nums[0:3], "robot": nums[3:6], "tv_rv": nums[6:8], "safety": nums[8:10],
        "turn_axis": nums[10],
        "ipc": float(rest[12]), "host": rest[13], "logger": float(rest[14]), "fields": len(rest),
    }


def check_log(text: str, b, robots) -> None:
    lines = text.splitlines()
    assert lines[0] == f"# written by vasco_gpu bag2carmen from {b.path} topic {b.topic}"
    assert len(lines) == 1 + len(b.stamps)
    offsets = np.concatenate([[0], np.cumsum(b.beam_counts)])
    for s, line in enumerate(lines[1:]):
        m = parse_robotlaser(line)
        assert m["fields"] == 15
        assert (m["laser_type"], m["accuracy"], m["remission_mode"]) == (99, 0.01, 0)
        assert m["start"] == b.first_angle[s] and m["res"] == b.angle_step[s]
        assert m["fov"] == b.angle_step[s] * (b.beam_counts[s] - 1)
        assert m["max_range"] == float(np.float32(RMAX))
        want = b.ranges[offsets[s]:offsets[s + 1]]
        assert np.array_equal(np.isnan(m["ranges"]), np.isnan(want))
        assert np.array_equal(bits(m["ranges"][~np.isnan(want)]), bits(want[~np.isnan(want)]))
        assert m["laser"] == b.poses[s].tolist()
        assert m["robot"] == pytest.approx(list(robots[s]), abs=1e-12)
        assert m["tv_rv"] == [0.0, 0.0] and m["safety"] == [0.0, 0.0] and m["turn_axis"] == 1e6
        assert m["ipc"] == b.stamps[s] and m["logger"] == b.stamps[s] and m["host"] == "bag"


@pytest.mark.parametrize("fmt", FORMATS)
def test_write_carmen_log_round_trip(tmp_path, fmt):
    v, _, _, _ = rep117_case()
    ranges = plain_ranges(4) + [v]
    poses = base_poses(5)
    p = make(tmp_path, fmt, ranges=ranges, tf_poses=poses, static_mount=(0.1, 0.0, 0.0))
    b = vb.read_bag(p)
    out = tmp_path / "out.log"
    vb.write_carmen_log(b, out)
    robots = [(x, y, quat_yaw(t)) for x, y, t in poses]  # the mount undone
    check_log(out.read_text(encoding="ascii"), b, robots)
    buf = io.StringIO()
    vb.write_carmen_log(b, buf)
    assert buf.getvalue() == out.read_text(encoding="ascii")


def test_write_carmen_log_gzip_and_robot_poses(tmp_path):
    poses = base_poses(5)
    b = vb.read_bag(make(tmp_path, "mcap", tf_poses=poses, laser_frame="base_link"))
    out = tmp_path / "out.log.gz"
    vb.write_carmen_log(b, out)
    with gzip.open(out, "rt", encoding="ascii") as f:
        text = f.read()
    check_log(text, b, b.poses)  # no mount: the robot pose is the laser pose
    given = poses + 1.0
    vb.write_carmen_log(b, tmp_path / "given.log", robot_poses=given)
    check_log((tmp_path / "given.log").read_text(), b, given)
    with pytest.raises(ValueError, match="robot_poses"):
        vb.write_carmen_log(b, tmp_path / "bad.log", robot_poses=given[:2])


def test_write_carmen_log_header_is_ascii(tmp_path):
    p = make(tmp_path, "rosbag1", "café", tf_poses=base_poses(5), laser_frame="base_link")
    b = vb.read_bag(p)
    out = tmp_path / "x.log"
    with open(out, "w", encoding="ascii", newline="\n") as f:  # as bag2carmen opens it
        vb.write_carmen_log(b, f)
    header = out.read_text(encoding="ascii").splitlines()[0]
    assert header.startswith("# written by vasco_gpu bag2carmen from ") and "caf\\xe9.bag topic /scan" in header


def test_write_carmen_log_refuses_scans_without_poses(tmp_path):
    p = make(tmp_path, "rosbag1", laser_frame="base_link")
    b = vb.read_bag(p, pose_source="none")
    with pytest.raises(ValueError, match="scan 0"):
        vb.write_carmen_log(b, tmp_path / "x.log")
    b.poses[:] = base_poses(5)
    b.poses[3] = np.nan
    with pytest.raises(ValueError, match="scan 3"):
        vb.write_carmen_log(b, tmp_path / "x.log")


def test_range_texts_round_trip_through_double():
    rng = np.random.default_rng(7)
    r = rng.integers(0, 2**32, 200_000, dtype=np.uint64).astype(np.uint32).view(np.float32)
    r = np.concatenate([r, np.array([0.0, -0.0, np.inf, -np.inf, np.nan, 1e-45, 3.4028235e38, 49.999996],
                                    dtype=np.float32)])
    texts = writer.range_texts(r)
    back = np.array([float(t) for t in texts], dtype=np.float64).astype(np.float32)
    same = (bits(back) == bits(r)) | (np.isnan(back) & np.isnan(r))
    assert same.all()
    assert "nan" in texts and "inf" in texts and "-inf" in texts
    assert writer.range_texts(np.array([2.35, 0.1], dtype=np.float32)) == ["2.35", "0.1"]


# ----------------------------------------------------------------------------------------------
# Bags as recorded: edges of the poses' span, gaps, receive stamps; several lasers; multi-echo


def chain_recording(fmt, scan_stamps, odom_stamps, map_stamps, frame="laser", mount=(0.0, 0.0, 0.0)):
    """A localisation stack's tf: map -> odom (identity, at map_stamps), odom -> base_link (the
    base poses, at odom_stamps), base_link -> frame on /tf_static; one LaserScan a scan stamp."""
    rec = bm.Recording(fmt)
    rec.tf(scan_stamps[0], "base_link", frame, *mount, static=True)
    for t in map_stamps:
        rec.tf(t, "map", "odom", 0.0, 0.0, 0.0)
    for t, p in zip(odom_stamps, base_poses(len(odom_stamps))):
        rec.tf(t, "odom", "base_link", *p)
    for t, r in zip(scan_stamps, plain_ranges(len(scan_stamps))):
        rec.scan("/scan", t, frame, r, ANGLE_MIN, ANGLE_STEP, RMIN, RMAX)
    return rec


def stamp_of(t: float) -> str:
    sec, ns = bm.split_stamp(t)
    return f"{sec}.{ns:09d}"


@pytest.mark.parametrize("fmt", FORMATS)
def test_scans_beyond_the_chain_are_edges(tmp_path, fmt):
    # map -> odom post-dated (from the 3rd scan + 0.05 s on), odometry ending at the 8th of 10.
    scans = stamps_of(10)
    rec = chain_recording(fmt, scans, scans[:8], [t + 0.05 for t in scans[2:]])
    p = rec.write(bm.bag_path(tmp_path, fmt))
    b = vb.read_bag(p, outside_span="edges")
    posed = np.isfinite(b.poses).all(axis=1)
    assert posed.tolist() == [False] * 3 + [True] * 5 + [False] * 2
    assert b.edges["before"] == 3 and b.edges["after"] == 2
    assert b.edges["first"] == pytest.approx(scans[2] + 0.05) and b.edges["last"] == pytest.approx(scans[7])
    with pytest.raises(vb.BagError, match="map -> odom"):
        vb.read_bag(p)  # outside_span="error": read_bag's default


@pytest.mark.parametrize("fmt", ["rosbag1", "mcap"])
def test_a_gap_inside_the_span_names_the_stamp(tmp_path, fmt):
    # odometry silent for 20 s, longer than tf2 keeps history: the scans in the gap have no pose.
    scans = stamps_of(4) + [T0 + 12.0] + [T0 + 25.0 + 0.1 * k for k in range(4)]
    odom = stamps_of(4) + [T0 + 25.0 + 0.1 * k for k in range(4)]
    p = chain_recording(fmt, scans, odom, scans).write(bm.bag_path(tmp_path, fmt))
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p, outside_span="edges")
    text = str(e.value)
    assert p.name in text and stamp_of(T0 + 12.0) in text and "gap" in text and "odom -> base_link" in text
    assert e.value.stamp == pytest.approx(T0 + 12.0, abs=1e-6)
    b = vb.read_bag(p, outside_span="skip")
    assert np.isnan(b.poses[4]).all() and np.isfinite(np.delete(b.poses, 4, axis=0)).all()


def test_receive_stamps_for_a_driver_with_a_bad_clock(tmp_path):
    # The laser's clock is off by 1000 s; the bag received each scan at the true time.
    scans = stamps_of(5)
    rec = bm.Recording("mcap")
    rec.tf(scans[0], "base_link", "laser", 0.0, 0.0, 0.0, static=True)
    for t, p in zip(scans, base_poses(5)):
        rec.tf(t, "map", "base_link", *p)
    for t, r in zip(scans, plain_ranges(5)):
        rec.scan("/scan", t - 1000.0, "laser", r, ANGLE_MIN, ANGLE_STEP, RMIN, RMAX, receive=t)
    p = rec.write(bm.bag_path(tmp_path, "mcap"))
    b = vb.read_bag(p, outside_span="edges")
    assert np.isnan(b.poses).all() and b.edges["before"] == 5
    r = vb.read_bag(p, stamp="receive")
    np.testing.assert_array_equal(r.stamps, expected_stamps(scans))
    good = vb.read_bag(make(tmp_path, "mcap", "good", tf_poses=base_poses(5), static_mount=(0, 0, 0)))
    assert np.array_equal(bits(r.poses), bits(good.poses))
    with pytest.raises(ValueError, match="stamp"):
        vb.read_bag(p, stamp="bag")


def two_lasers(fmt, n=9):
    """/front every scan stamp at (0.2, 0, 0), /rear every third at (-0.3, 0.1, pi); the rear's
    messages received 0.15 s late (after the next front scan)."""
    scans = stamps_of(n)
    rec = bm.Recording(fmt)
    rec.tf(scans[0], "base_link", "front", 0.2, 0.0, 0.0, static=True)
    rec.tf(scans[0], "base_link", "rear", -0.3, 0.1, math.pi, static=True)
    for t, p in zip(scans, base_poses(n)):
        rec.tf(t, "map", "base_link", *p)
    ranges = plain_ranges(n)
    for k, t in enumerate(scans):
        rec.scan("/front", t, "front", ranges[k], ANGLE_MIN, ANGLE_STEP, RMIN, RMAX)
        if k % 3 == 1:
            rec.scan("/rear", t + 0.01, "rear", ranges[k][:20], ANGLE_MIN, ANGLE_STEP, RMIN, RMAX, receive=t + 0.15)
    return rec


@pytest.mark.parametrize("fmt", FORMATS)
def test_two_lasers_each_at_its_mount_in_stamp_order(tmp_path, fmt):
    p = two_lasers(fmt).write(bm.bag_path(tmp_path, fmt))
    with pytest.raises(vb.BagError, match="several laser scan topics"):
        vb.read_bag(p)
    b = vb.read_bag(p, scan_topic=["/front", "rear"])
    assert b.topics == ("/front", "/rear") and b.frame_ids == ("front", "rear")
    assert len(b.stamps) == 12 and (np.diff(b.stamps) > 0).all()
    assert b.topic_index.tolist() == [0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0]
    assert b.beam_counts.tolist() == [20 if k == 1 else 37 for k in b.topic_index]
    assert b.mounts[b.topic_index == 0].tolist() == [[0.2, 0.0, 0.0]] * 9
    assert b.mounts[b.topic_index == 1][:, :2].tolist() == [[-0.3, 0.1]] * 3
    front = vb.read_bag(p, scan_topic="/front")
    assert np.array_equal(bits(b.poses[b.topic_index == 0]), bits(front.poses))
    rear = vb.read_bag(p, scan_topic="/rear")
    assert np.array_equal(bits(b.poses[b.topic_index == 1]), bits(rear.poses))
    assert np.array_equal(bits(b.ranges[:37]), bits(front.ranges[:37]))
    assert vb.read_bag(p, scan_topic="/front,/rear").topic_index.tolist() == b.topic_index.tolist()
    with pytest.raises(ValueError, match="several scan topics"):
        vb.read_bag(p, scan_topic=["/front", "/rear"], laser_mount=(0, 0, 0))


ECHOES = [[1.0, 2.0, 3.0], [], [4.5], [2.5, 7.25, 9.0]]
POWER = [[10.0, 90.0, 50.0], [], [3.0], [70.0, 70.0, 20.0]]


def echo_bag(tmp_path, fmt, power=POWER, name="echo"):
    rec = bm.Recording(fmt)
    rec.tf(T0, "map", "laser", 0.0, 0.0, 0.0, static=True)
    rec.multi_echo("/echoes", T0, "laser", ECHOES, power, ANGLE_MIN, ANGLE_STEP, RMIN, RMAX)
    return rec.write(bm.bag_path(tmp_path, fmt, name))


@pytest.mark.parametrize("fmt", FORMATS)
def test_multi_echo_scans(tmp_path, fmt):
    p = echo_bag(tmp_path, fmt)
    last = vb.read_bag(p)
    assert last.topic == "/echoes" and last.beam_counts.tolist() == [4]
    assert last.ranges.tolist() == [3.0, np.inf, 4.5, 9.0] and last.counts["pos_inf"] == 1
    assert vb.read_bag(p, echo="first").ranges.tolist() == [1.0, np.inf, 4.5, 2.5]
    assert vb.read_bag(p, echo="strongest").ranges.tolist() == [2.0, np.inf, 4.5, 2.5]  # a tie: the first
    assert vb.read_bag(p, no_return="free").ranges[1] == vb.NO_RETURN_FREE  # no echo: no return
    bare = echo_bag(tmp_path, fmt, power=[], name="bare")
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(bare, echo="strongest")
    text = str(e.value)
    assert bare.name in text and "'/echoes'" in text and stamp_of(T0) in text and "no intensities" in text
    assert vb.read_bag(bare).ranges.tolist() == [3.0, np.inf, 4.5, 9.0]
    with pytest.raises(ValueError, match="echo"):
        vb.read_bag(p, echo="second")


def test_a_bag_whose_only_sensor_is_not_a_laser(tmp_path):
    rec = bm.Recording("mcap")
    T = rec.messages.T
    image = T["sensor_msgs/msg/Image"](
        header=rec.messages.header(T0, "camera"), height=0, width=0, encoding="16UC1", is_bigendian=0, step=0,
        data=np.zeros(0, dtype=np.uint8))
    rec.add(T0, "/depth", "sensor_msgs/msg/Image", image)
    rec.tf(T0, "map", "camera", 0.0, 0.0, 0.0, static=True)
    p = rec.write(bm.bag_path(tmp_path, "mcap"))
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p)
    text = str(e.value)
    assert p.name in text and "'/depth' (sensor_msgs/Image)" in text and "depthimage_to_laserscan" in text
    with pytest.raises(vb.BagError, match="depthimage_to_laserscan"):
        vb.read_bag(p, scan_topic="/depth")


def path_bag(tmp_path, fmt="mcap", name="pathbag", mount=(0.2, 0.0, 0.0)):
    """Five scans in 'laser'; base_link -> laser on /tf_static; two nav_msgs/Path messages on
    /path: a first guess, then the final trajectory at every other scan stamp and beyond."""
    rec = bm.Recording(fmt)
    T = rec.messages.T
    t = stamps_of(5)
    rec.tf(t[0], "base_link", "laser", *mount, static=True)
    for k, s in enumerate(t):
        rec.scan("/scan", s, "laser", plain_ranges(1, seed=k)[0], ANGLE_MIN, ANGLE_STEP, RMIN, RMAX)

    def path(stamp, samples):
        return T["nav_msgs/msg/Path"](header=rec.messages.header(stamp, "map"), poses=[
            rec.messages.pose_stamped(ts, "map", *p) for ts, p in samples])

    rec.add(t[2], "/path", "nav_msgs/msg/Path", path(t[2], [(t[0], (9.0, 9.0, 0.0)), (t[2], (9.0, 9.0, 0.0))]))
    final = [(t[0], (0.0, 0.0, 0.0)), (t[2], (2.0, 1.0, 0.5)), (t[4], (4.0, 1.0, 1.0))]
    rec.add(t[4] + 0.01, "/path", "nav_msgs/msg/Path", path(t[4] + 0.01, final))
    return rec.write(bm.bag_path(tmp_path, fmt, name)), final


def test_a_path_topic_gives_the_poses_of_its_last_message(tmp_path):
    p, final = path_bag(tmp_path)
    b = vb.read_bag(p, pose_topic="/path")
    assert b.pose_source == "topic:/path"
    ns = [bm.stamp_ns(t) for t in stamps_of(5)]  # the stamps as the bag holds them (ns)
    f1, f3 = (ns[1] - ns[0]) / (ns[2] - ns[0]), (ns[3] - ns[2]) / (ns[4] - ns[2])  # ~0.5
    base = [(0.0, 0.0, 0.0), (2.0 * f1, 1.0 * f1, 0.5 * f1), (2.0, 1.0, 0.5),
            (2.0 + 2.0 * f3, 1.0, 0.5 + 0.5 * f3), (4.0, 1.0, 1.0)]
    want = [(x + 0.2 * math.cos(th), y + 0.2 * math.sin(th), th) for x, y, th in base]  # the mount, by hand
    np.testing.assert_allclose(b.poses, want, rtol=0, atol=1e-12)


def test_a_robot_that_does_not_move(tmp_path):
    p = make(tmp_path, "mcap", name="still")  # scans only: no tf, no pose topic
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p)
    assert "--static-pose X,Y,THETA" in str(e.value) and "--pose-topic" in str(e.value)
    b = vb.read_bag(p, static_pose=(1.0, 2.0, 0.5))
    assert b.pose_source == "static" and np.array_equal(b.poses, np.tile([1.0, 2.0, 0.5], (5, 1)))
    b = vb.read_bag(p, static_pose="1,2,0", laser_mount=(0.5, 0.0, 0.25))  # text, and a mount
    assert np.allclose(b.poses, np.tile([1.5, 2.0, 0.25], (5, 1)), rtol=0, atol=1e-15)
    with pytest.raises(ValueError, match="static_pose"):
        vb.read_bag(p, static_pose=(1.0, math.nan, 0.0))
    with pytest.raises(ValueError, match="static_pose"):
        vb.read_bag(p, static_pose=(1.0, 2.0, 0.0), pose_topic="/odom")


def test_a_pose_that_is_not_a_number_is_an_error_not_a_dropped_scan(tmp_path):
    t = stamps_of(3)
    rec = bm.Recording("mcap")
    for k, s in enumerate(t):
        rec.scan("/scan", s, "base_link", plain_ranges(1, seed=k)[0], ANGLE_MIN, ANGLE_STEP, RMIN, RMAX)
        rec.tf(s, "map", "base_link", math.nan if k == 1 else float(k), 0.0, 0.0)
    p = rec.write(bm.bag_path(tmp_path, "mcap", "nan_tf"))
    with pytest.raises(vb.TfError) as e:
        vb.read_bag(p)
    assert "tf map -> base_link at stamp" in str(e.value) and "has translation (nan" in str(e.value)
    assert p.name in str(e.value) and e.value.stamp == pytest.approx(t[1])
    rec = bm.Recording("mcap")
    for k, s in enumerate(t):
        rec.scan("/scan", s, "base_link", plain_ranges(1, seed=k)[0], ANGLE_MIN, ANGLE_STEP, RMIN, RMAX)
        rec.add(s, "/pose", "geometry_msgs/msg/PoseStamped",
                rec.messages.pose_stamped(s, "map", math.inf if k == 2 else 0.0, 0.0, 0.0))
    p = rec.write(bm.bag_path(tmp_path, "mcap", "inf_pose"))
    with pytest.raises(vb.BagError, match=r"pose on '/pose' at stamp .* has position \(inf"):
        vb.read_bag(p, pose_topic="/pose")


# ----------------------------------------------------------------------------------------------
# Bags that bag2carmen and bag2map refused with a traceback, or whose log log2map refused


def max_range_fields(b, tmp_path) -> list[float]:
    out = tmp_path / "out.log"
    vb.write_carmen_log(b, out)
    return [parse_robotlaser(line)["max_range"] for line in out.read_text().splitlines()[1:]]


def test_an_infinite_range_max_becomes_a_finite_maximum_range(tmp_path):
    # REP 117's range_max = +inf: every finite reading is a measurement. CARMEN's field must be
    # finite and above every reading of the topic (a reading at maximum_range is a max-range
    # reading to CARMEN's programs): the whole metre above the largest, at least 80 m.
    far = np.array([3.0, 95.5, np.inf, np.nan, 12.25], dtype=np.float32)
    near = np.array([1.0, 2.0, np.inf], dtype=np.float32)
    rec = bm.Recording("mcap")
    for k, t in enumerate(stamps_of(3)):
        rec.scan("/far", t, "base_link", far if k == 1 else far[[0, 4]], ANGLE_MIN, ANGLE_STEP, 0.0, math.inf)
        rec.scan("/near", t + 0.01, "base_link", near, ANGLE_MIN, ANGLE_STEP, 0.0, math.inf)
        rec.scan("/bounded", t + 0.02, "base_link", near, ANGLE_MIN, ANGLE_STEP, 0.0, 30.0)
        rec.tf(t, "map", "base_link", float(k), 0.0, 0.0)
    rec.tf(stamps_of(3)[-1] + 1, "map", "base_link", 3.0, 0.0, 0.0)
    p = rec.write(bm.bag_path(tmp_path, "mcap", "inf_range_max"))
    b = vb.read_bag(p, scan_topic=["/far", "/near", "/bounded"])
    fields = max_range_fields(b, tmp_path)
    by_topic = {b.topics[k]: {f for f, i in zip(fields, b.topic_index) if i == k} for k in range(3)}
    assert by_topic == {"/far": {96.0}, "/near": {80.0}, "/bounded": {30.0}}
    b.ranges[:] = np.inf  # no reading at all: CARMEN's 80 m
    assert set(max_range_fields(b, tmp_path)) == {80.0, 30.0}


def test_a_scan_of_more_beams_than_a_carmen_line_takes_names_the_bag_topic_and_stamp(tmp_path):
    # carmen::kMaxCount (100000) bounds a log line's count and the mapper's Scans: one beam more
    # was refused later, by the mapper, with an error naming neither the bag nor the scan.
    t = stamps_of(2)
    ranges = [np.full(100_000, 5.0, np.float32), np.full(100_001, 5.0, np.float32)]
    step = 2 * math.pi / 100_001
    p = bm.write_bag(bm.bag_path(tmp_path, "mcap", "wide"), "mcap", t, ranges, -math.pi, step, 0.0, 30.0,
                     tf_poses=base_poses(2), static_mount=(0.0, 0.0, 0.0))
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p)
    assert str(e.value).startswith(f"{p}: scan at stamp ") and "on '/scan' has 100001 beams" in str(e.value)
    assert e.value.topic == "/scan" and e.value.stamp == pytest.approx(t[1])
    one = bm.write_bag(bm.bag_path(tmp_path, "mcap", "widest"), "mcap", t[:1], ranges[:1], -math.pi, step, 0.0,
                       30.0, tf_poses=base_poses(1), static_mount=(0.0, 0.0, 0.0))
    assert vb.read_bag(one).beam_counts.tolist() == [100_000]


SCAN_FIELDS = ("float32 angle_min\nfloat32 angle_max\nfloat32 angle_increment\nfloat32 range_min\n"
               "float32 range_max\nfloat32[] ranges\n")


@pytest.mark.parametrize("fmt", FORMATS)
def test_a_scan_type_without_a_header_names_the_bag_topic_and_type(tmp_path, fmt):
    # A custom message recorded under LaserScan's name: read_bag ended in an AttributeError.
    fields = {"angle_min": -1.0, "angle_max": 1.0, "angle_increment": 1.0, "range_min": 0.0, "range_max": 10.0,
              "ranges": np.array([1.0, 2.0, 3.0], np.float32)}
    p = bm.write_foreign_type(bm.bag_path(tmp_path, fmt, "custom"), fmt, "/scan", bm.LASER_SCAN, SCAN_FIELDS,
                              [fields, fields], stamps_of(2))
    with pytest.raises(vb.BagError) as e:
        vb.read_bag(p, static_pose=(0.0, 0.0, 0.0))
    assert str(e.value) == (f"{p}: topic '/scan' (sensor_msgs/LaserScan): the message received at "
                            f"{bm.stamp_ns(T0) / 1e9:.9f} has no field 'header': the bag defines "
                            "sensor_msgs/LaserScan otherwise than ROS does (a custom message under a standard "
                            "name?), so it cannot be read as one")
    assert e.value.topic == "/scan"


def test_a_header_type_without_a_stamp_names_the_inner_type(tmp_path):
    # LaserScan's header of a custom std_msgs/Header without a stamp: the error names that type.
    definition = "std_msgs/Header header\n" + SCAN_FIELDS + "=" * 80 + "\nMSG: std_msgs/Header\nstring frame_id\n"
    p = bm.bag_path(tmp_path, "sqlite3", "custom_header")
    bm.write_foreign_type(p, "sqlite3", "/scan", bm.LASER_SCAN, definition, [{
        "header": {"frame_id": "laser"}, "angle_min": -1.0, "angle_max": 1.0, "angle_increment": 1.0, "range_min": 0.0,
        "range_max": 10.0, "ranges": np.array([1.0], np.float32)}], stamps_of(1))
    with pytest.raises(vb.BagError, match="has no field 'stamp' in its std_msgs/Header: the bag defines "
                                          "sensor_msgs/LaserScan otherwise"):
        vb.read_bag(p, static_pose=(0.0, 0.0, 0.0))


def test_rep117_table_by_hand_also_with_infinite_limits():
    # The module docstring's table, one beam a row; an infinite range_min / range_max (a driver
    # that leaves them open) takes no infinity in: -inf is still "too close", +inf "no return".
    from vasco_gpu.bags.scans import COUNT_KEYS, NO_RETURN_FREE, apply_rep117

    v = np.array([1.0, np.nan, np.inf, -np.inf, 0.01, 50.0], dtype=np.float32)
    nan = float("nan")
    for (rmin, rmax), kept, outside in (((0.1, 30.0), [nan, nan], (1, 1)),
                                        ((-math.inf, math.inf), [0.01, 50.0], (0, 0))):
        for no_return, inf_becomes in (("skip", math.inf), ("free", float(NO_RETURN_FREE))):
            counts = dict.fromkeys(COUNT_KEYS, 0)
            out = apply_rep117(v, rmin, rmax, no_return, counts)
            want = np.array([1.0, nan, inf_becomes, nan, *kept], dtype=np.float32)
            np.testing.assert_array_equal(out, want)
            assert (counts["nan"], counts["pos_inf"], counts["neg_inf"]) == (1, 1, 1)
            assert (counts["below_min"], counts["above_max"]) == outside
