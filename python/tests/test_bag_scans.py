"""read_bag's scans (vasco_gpu.bags on its own, without the extension): ranges read back bit for
bit in every bag format, REP 117, frames, multi-echo, what a scan message may not be."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("rosbags")

from bag_reader_support import (vb, laser, bm, FORMATS, T0, RMIN, RMAX, ANGLE_MIN, ANGLE_STEP, stamps_of,
                                plain_ranges, base_poses, make, bits, expected_stamps, stamp_of,
                                rep117_case)  # noqa: E402


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
# REP 117


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


def test_rep117_table_by_hand_also_with_infinite_limits():
    # The module docstring's table, one beam a row; an infinite range_min / range_max (a driver
    # that leaves them open) takes no infinity in: -inf is still "too close", +inf "no return".
    COUNT_KEYS, NO_RETURN_FREE, apply_rep117 = laser.COUNT_KEYS, laser.NO_RETURN_FREE, laser.apply_rep117
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


# ----------------------------------------------------------------------------------------------
# MultiEchoLaserScan


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


# ----------------------------------------------------------------------------------------------
# Scan messages refused with the bag, topic and stamp named


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
