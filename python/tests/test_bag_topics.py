"""read_bag on bags as recorded: which topics it reads (several lasers, missing or foreign
topics), bags that are not bags, the edges and gaps of the poses' span, receive stamps, errors
and progress."""

from __future__ import annotations

import math
import pickle
import shutil

import numpy as np
import pytest

pytest.importorskip("rosbags")

from bag_reader_support import (vb, bm, FORMATS, T0, RMIN, RMAX, ANGLE_MIN, ANGLE_STEP, stamps_of,
                                plain_ranges, base_poses, make, bits, expected_stamps, stamp_of)  # noqa: E402


# ----------------------------------------------------------------------------------------------
# Topics


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


# ----------------------------------------------------------------------------------------------
# Files that are not bags


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
# Bags as recorded: edges of the poses' span, gaps, receive stamps; several lasers


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
