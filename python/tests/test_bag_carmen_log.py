"""write_carmen_log: a bag's scans as a CARMEN log of ROBOTLASER1 lines (bag2carmen), field by
field; the maximum range a log line gets."""

from __future__ import annotations

import gzip
import io
import math

import numpy as np
import pytest

pytest.importorskip("rosbags")

from bag_reader_support import (vb, writer, bm, FORMATS, RMAX, ANGLE_MIN, ANGLE_STEP, stamps_of, plain_ranges,
                                base_poses, make, bits, quat_yaw, parse_robotlaser,
                                rep117_case)  # noqa: E402


# ----------------------------------------------------------------------------------------------
# write_carmen_log


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
# Maximum ranges


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
