"""Bag options whose value no bag could make valid are usage errors: bag2map and bag2carmen exit 2
before reading the bag, with one line naming the option and its value and not the bag (as
log2map's own bad options are). A pose a user gives (--static-pose, static_pose=, --laser-mount,
a pose topic's positions) is refused beyond tf's bound on a translation, 1e12 m: at 1e300 the
map's origin is inf, which no map file can hold."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("rosbags")

import vasco_gpu as vg  # noqa: E402
import vasco_gpu.bags as vb  # noqa: E402
from vasco_gpu.msgs.tf import MAX_TRANSLATION  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bag_maker as bm  # noqa: E402

T0 = 1000.0
RANGES = np.linspace(2.0, 6.0, 90)


def still_bag(tmp_path, fmt="mcap"):
    """Scans in 'laser', base_link -> laser on /tf_static, no poses: a sensor that does not move."""
    rec = bm.Recording(fmt)
    rec.tf(T0, "base_link", "laser", 0.1, 0.0, 0.0, static=True)
    for k in range(5):
        rec.scan("/scan", T0 + 0.1 * k, "laser", RANGES, -1.5, 3.0 / 89, 0.1, 20.0)
    return rec.write(bm.bag_path(tmp_path, fmt, "still"))


def script(name, *args):
    exe = Path(sys.executable).parent / name
    entry = {"bag2map": "bag2map_main", "bag2carmen": "bag2carmen_main"}[name]
    cmd = [str(exe)] if exe.exists() else [
        sys.executable, "-c", f"import sys; from vasco_gpu.bags.cli import {entry}; sys.exit({entry}())"]
    return subprocess.run(cmd + [str(a) for a in args], capture_output=True, text=True, timeout=300)


BAD_VALUES = [
    ("--static-pose", "nan", "three finite numbers"),
    ("--static-pose", "inf,0,0", "three finite numbers"),
    ("--static-pose", "1,2", "three finite numbers"),
    ("--static-pose", "x,0,0", "is not a number"),
    ("--static-pose", "1e300,0,0", "within 1e+12 m"),
    ("--static-pose", "0,-1e15,0", "within 1e+12 m"),
    ("--laser-mount", "1e13,0,0", "within 1e+12 m"),
    ("--z-band", "2,1", "MIN < MAX"),
    ("--z-band", "x", "is not a number"),
    ("--z-band", "nan,1", "two finite heights"),
    ("--cloud-angle-step", "0", "between 0.01 and 10 degrees"),
    ("--cloud-angle-step", "nan", "between 0.01 and 10 degrees"),
    ("--cloud-range-max", "-1", "above 0 and at most 1000 m"),
    ("--cloud-range-max", "many", "is not a number"),
    ("--no-return", "bogus", "one of ('skip', 'free')"),
    ("--echo", "loudest", "one of ('first', 'last', 'strongest')"),
    ("--stamp", "bogus", "one of ('header', 'receive')"),
]


@pytest.mark.parametrize("flag, value, why", BAD_VALUES)
def test_bag2map_refuses_a_bad_value_as_a_usage_error(tmp_path, flag, value, why):
    bag = still_bag(tmp_path)
    pose = [] if flag == "--static-pose" else ["--static-pose", "0,0,0"]
    for args in ([flag, value], [f"{flag}={value}"]):
        r = script("bag2map", *pose, *args, bag, tmp_path / "x.map")
        assert r.returncode == 2, r.stderr
        lines = r.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("bag2map: "), r.stderr
        assert flag in lines[0] and repr(value) in lines[0] and why in lines[0], r.stderr
        assert str(bag) not in r.stderr
        assert not (tmp_path / "x.map").exists()


@pytest.mark.parametrize("flag, value, why", [v for v in BAD_VALUES if v[0] != "--laser-mount"][::3])
def test_bag2carmen_refuses_a_bad_value_as_a_usage_error(tmp_path, flag, value, why):
    bag = still_bag(tmp_path)
    pose = [] if flag == "--static-pose" else ["--static-pose", "0,0,0"]
    r = script("bag2carmen", *pose, flag, value, bag, tmp_path / "x.log")
    assert r.returncode == 2, r.stderr
    assert flag in r.stderr and repr(value) in r.stderr and why in r.stderr and str(bag) not in r.stderr
    assert not (tmp_path / "x.log").exists()


def test_a_static_pose_within_the_bound_maps(tmp_path):
    bag = still_bag(tmp_path)
    r = script("bag2map", "--static-pose", "2.5,-1,0.3", bag, tmp_path / "x.map")
    assert r.returncode == 0, r.stderr
    assert np.isfinite(np.asarray(vg.read_map(tmp_path / "x.map").origin, dtype=float)).all()


@pytest.mark.parametrize("pose", [(1e300, 0.0, 0.0), (0.0, -2e12, 0.0), (math.nan, 0.0, 0.0), (0.0, math.inf, 0.0),
                                  "1e300,0,0"])
def test_load_bag_and_read_bag_refuse_a_static_pose_beyond_the_bound(tmp_path, pose):
    bag = still_bag(tmp_path)
    with pytest.raises(ValueError, match=r"static_pose") as e:
        vg.load_bag(bag, static_pose=pose)
    assert "static_pose" in str(e.value)
    with pytest.raises(ValueError, match=r"static_pose"):
        vb.read_bag(bag, static_pose=pose)
    with pytest.raises(ValueError, match=r"laser_mount"):
        vb.read_bag(bag, static_pose=(0, 0, 0), laser_mount=pose)


def test_the_bound_is_the_tf_trees():
    # the same constant, inclusive at its edge as tf's
    bag_bound = 1e12
    assert MAX_TRANSLATION == bag_bound
    from vasco_gpu.bags.options import checked_pose

    assert checked_pose((MAX_TRANSLATION, -MAX_TRANSLATION, 0.0), "p").tolist() == [1e12, -1e12, 0.0]
    with pytest.raises(ValueError):
        checked_pose((np.nextafter(MAX_TRANSLATION, np.inf), 0.0, 0.0), "p")


def test_a_pose_topic_beyond_the_bound_is_refused_naming_topic_and_stamp(tmp_path):
    rec = bm.Recording("mcap")
    rec.tf(T0, "base_link", "laser", 0.0, 0.0, 0.0, static=True)
    for k in range(4):
        t = T0 + 0.1 * k
        rec.scan("/scan", t, "laser", RANGES, -1.5, 3.0 / 89, 0.1, 20.0)
        rec.add(t, "/pose", "geometry_msgs/msg/PoseStamped",
                rec.messages.pose_stamped(t, "map", 1e300 if k == 2 else 0.0, 0.0, 0.0))
    bag = rec.write(bm.bag_path(tmp_path, "mcap", "far"))
    with pytest.raises(vb.BagError, match=r"pose on '/pose' at stamp 1000.2\d* has position \(1e\+300") as e:
        vb.read_bag(bag, pose_topic="/pose")
    assert "up to 1e+12" in str(e.value) and e.value.topic == "/pose"
