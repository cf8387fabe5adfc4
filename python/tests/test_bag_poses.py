"""read_bag's laser poses: from tf (mounts, interpolation, chains, fixed frames), from a pose
topic (Odometry, PoseStamped, Path), a robot that does not move, none."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("rosbags")

from bag_reader_support import (vb, bm, FORMATS, T0, RMIN, RMAX, ANGLE_MIN, ANGLE_STEP, stamps_of,
                                plain_ranges, base_poses, make, bits, quat_yaw)  # noqa: E402


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
    # read_bag speaks the Python API's words, bag2map's reader (wording "cli") the options'
    p = make(tmp_path, "rosbag1")
    with pytest.raises(vb.BagError, match="pose_topic=TOPIC") as e:
        vb.read_bag(p)
    assert p.name in str(e.value) and "poses=FILE" in e.value.message and "--" not in e.value.message
    with pytest.raises(vb.BagError, match="--pose-topic TOPIC") as e:
        vb.read_bag(p, wording="cli")
    assert "--poses FILE" in e.value.message and "_topic" not in e.value.message


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
    assert "static_pose=(X, Y, THETA)" in str(e.value) and "pose_topic=TOPIC" in str(e.value)
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
