"""path_cdr.read_path against rclpy's own deserialisation of the same bytes: every layout the
fast reader takes, and the ones it hands over (frame ids of other lengths, truncated bytes)."""

from __future__ import annotations

import numpy as np
import pytest

import ros_support  # noqa: F401  (the ROS environment)

ros_support.import_or_skip("rclpy")

from geometry_msgs.msg import PoseStamped  # noqa: E402
from nav_msgs.msg import Path  # noqa: E402
from rclpy.serialization import serialize_message  # noqa: E402

from vasco_gpu.ros import path_cdr  # noqa: E402


def make_path(frames, frame="map", seed=0):
    rng = np.random.default_rng(seed)
    msg = Path()
    msg.header.frame_id, msg.header.stamp.sec, msg.header.stamp.nanosec = frame, 12, 345
    for k, f in enumerate(frames):
        ps = PoseStamped()
        ps.header.frame_id = f
        ps.header.stamp.sec, ps.header.stamp.nanosec = int(rng.integers(0, 2**31)), int(rng.integers(0, 10**9))
        p, o = ps.pose.position, ps.pose.orientation
        p.x, p.y, p.z = (float(v) for v in rng.normal(0, 100, 3))
        o.x, o.y, o.z, o.w = (float(v) for v in rng.normal(0, 1, 4))
        msg.poses.append(ps)
    return msg


def expected(msg):
    return (msg.header.frame_id, msg.header.stamp.sec * 10**9 + msg.header.stamp.nanosec,
            [p.header.stamp.sec * 10**9 + p.header.stamp.nanosec for p in msg.poses],
            [p.header.frame_id for p in msg.poses],
            [(p.pose.position.x, p.pose.position.y, p.pose.position.z) for p in msg.poses],
            [(p.pose.orientation.x, p.pose.orientation.y, p.pose.orientation.z, p.pose.orientation.w)
             for p in msg.poses])


@pytest.mark.parametrize("frames,frame", [([], "map"), (["map"], "map"), (["map"] * 1000, "map"),
                                          ([""] * 7, "m"), (["odom_long_name"] * 5, "world"),
                                          (["abc"] * 9, "abcd"), (["map", "odom", "map"], "map"),
                                          (["a", "bb", "ccc", "dddd"], "x")])
def test_read_path_equals_rclpys_deserialisation(frames, frame):
    msg = make_path(frames, frame, seed=len(frames))
    raw = serialize_message(msg)
    got = path_cdr.read_path(raw, Path)
    f, ns, stamps, ids, pos, quat = expected(msg)
    assert (got.frame_id, got.stamp_ns, got.frame_ids) == (f, ns, ids)
    assert got.distinct_frames == set(ids)
    assert got.stamps.tolist() == stamps
    assert got.positions.reshape(-1, 3).tolist() == [list(p) for p in pos]  # bit for bit
    assert got.orientations.reshape(-1, 4).tolist() == [list(q) for q in quat]


def test_the_fast_route_takes_one_frame_id_length():
    raw = serialize_message(make_path(["map"] * 50))
    assert raw[:2] == path_cdr.CDR_LE
    assert path_cdr._fast(raw).stamps.shape == (50,)
    with pytest.raises(ValueError):
        path_cdr._fast(serialize_message(make_path(["map", "odom"])))


def test_bytes_that_are_not_a_path_are_a_value_error():
    raw = serialize_message(make_path(["map"] * 20))
    # a pose count of 2^31 - 1 (after the encapsulation 4, stamp 8, "map" 4 + 4): refused before
    # anything is allocated for it
    huge = raw[:20] + (2**31 - 1).to_bytes(4, "little") + raw[24:]
    for bad in (raw[:40], raw[:-8], b"\x00\x01\x00\x00" + b"\xff" * 12, huge):
        with pytest.raises(ValueError):
            path_cdr.read_path(bad, Path)
