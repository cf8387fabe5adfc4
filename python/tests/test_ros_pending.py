"""Scans that tf gives no pose within transform_timeout, without a running node (posing.py):
with a path_topic they wait (Unposed), bounded by the bytes the session may still use, the
oldest dropped first, until a later /tf or a Path covers their stamps; without one they are
refused as before."""

from __future__ import annotations

import math
import time
from types import SimpleNamespace as NS

import numpy as np
import pytest

from vasco_gpu.msgs.table import MESSAGE_TYPES
from vasco_gpu.ros.posing import Pending, Posing, Unposed, laser_poses_on_path
from vasco_gpu.ros.settings import Settings

LASER_SCAN = next(t for t in MESSAGE_TYPES if t.class_name == "LaserScan")
S = 10**9


def _stamp(ns):
    return NS(sec=ns // S, nanosec=ns % S)


def _tf(parent, child, ns, x=0.0, theta=0.0):
    return NS(header=NS(frame_id=parent, stamp=_stamp(ns)), child_frame_id=child,
              transform=NS(translation=NS(x=float(x), y=0.0, z=0.0),
                           rotation=NS(x=0.0, y=0.0, z=math.sin(theta / 2), w=math.cos(theta / 2))))


def _scan(ns, beams=10):
    return NS(header=NS(frame_id="laser", stamp=_stamp(ns)), angle_min=-0.5, angle_increment=0.1,
              angle_max=float(np.float32(-0.5) + np.float32(0.1) * np.float32(beams - 1)),
              range_min=0.0, range_max=30.0, ranges=[2.0] * beams, intensities=[])


class Log:
    def __init__(self):
        self.refused: list[tuple[str, str]] = []
        self.kept: list[str] = []

    def __call__(self, topic, cause, text):
        self.refused.append((topic, cause))


def _posing(path_topic="trajectory", room=lambda: None, dropped=lambda p: None):
    settings = Settings.from_values({"transform_timeout": 1e-6, "path_topic": path_topic}, {})
    log = Log()
    posing = Posing(lambda: settings, str, log, unposed=Unposed(room, dropped),
                    kept=lambda topic, text: log.kept.append(text))
    posing.add_tf(NS(transforms=[_tf("base_link", "laser", 0, x=0.5)]), True)  # the mount only
    return posing, log


def test_scans_without_tf_wait_for_a_path_that_poses_them():
    posing, log = _posing()
    for k in range(3):
        posing.add_scan(_scan((10 + k) * S), "scan", LASER_SCAN, None)
    time.sleep(0.001)
    assert posing.take_posed() == [] and not log.refused  # given up as to tf, not refused
    assert len(log.kept) == 3 and log.kept[0].startswith("scan: scan at stamp 10.000000000: no transform within")
    assert log.kept[0].endswith("it waits for a pose from a later /tf or a Path on trajectory")
    assert len(posing.unposed) == 3 and not posing.pending
    # a Path over the first two stamps: those posed at its poses composed with the mount
    path_ns = np.array([10 * S, 11 * S], dtype=np.int64)
    path = np.array([[1.0, 2.0, 0.0], [2.0, 2.0, math.pi / 2]])
    posed = posing.take_on_path(path_ns, path, S)
    assert [p.ns for p, _ in posed] == [10 * S, 11 * S]
    assert posed[0][1] == pytest.approx([1.5, 2.0, 0.0])
    assert posed[1][1] == pytest.approx([2.0, 2.5, math.pi / 2])
    assert [p.ns for p in posing.unposed.scans] == [12 * S]
    # a /tf that comes later poses the one left
    posing.add_tf(NS(transforms=[_tf("map", "base_link", 11 * S, x=3.0), _tf("map", "base_link", 13 * S, x=3.0)]),
                  False)
    posed = posing.take_posed()
    assert [p.ns for p, _ in posed] == [12 * S] and posed[0][1] == pytest.approx([3.5, 0.0, 0.0])
    assert len(posing.unposed) == 0 and posing.unposed.bytes == 0


def test_without_a_path_topic_they_are_refused_as_before():
    posing, log = _posing(path_topic="")
    posing.add_scan(_scan(10 * S), "scan", LASER_SCAN, None)
    time.sleep(0.001)
    assert posing.take_posed() == [] and len(posing.unposed) == 0
    assert log.refused == [("scan", "scans without a transform")] and not log.kept


def test_the_waiting_scans_keep_within_their_room_the_oldest_dropped_first():
    dropped = []
    room = [3 * (10 * 4 + 72)]  # three scans of 10 float32 ranges
    posing, log = _posing(room=lambda: room[0], dropped=dropped.append)
    for k in range(5):
        posing.add_scan(_scan((10 + k) * S), "scan", LASER_SCAN, None)
    time.sleep(0.001)
    posing.take_posed()
    assert [p.ns for p in dropped] == [10 * S, 11 * S]
    assert [p.ns for p in posing.unposed.scans] == [12 * S, 13 * S, 14 * S]
    room[0] = 10 * 4 + 72  # the map took memory since
    posing.unposed.fit()
    assert [p.ns for p in dropped] == [10 * S, 11 * S, 12 * S, 13 * S] and len(posing.unposed) == 1
    room[0] = 0
    posing.unposed.fit()
    assert len(posing.unposed) == 0 and posing.unposed.bytes == 0 and not log.refused


def test_a_path_poses_only_scans_in_its_span_off_its_gaps_with_a_mount():
    reading = NS(frame="laser")
    scans = [Pending("scan", ns, reading, 0.0, 0.0, LASER_SCAN) for ns in (5 * S, 10 * S, 15 * S, 25 * S)]
    path_ns = np.array([10 * S, 20 * S, 30 * S], dtype=np.int64)
    path = np.array([[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [20.0, 0.0, 0.0]])
    got = laser_poses_on_path(scans, path_ns, path, 10 * S, lambda frame: np.zeros(3))
    assert got[0] is None and got[1] == pytest.approx([0, 0, 0]) and got[2] == pytest.approx([5, 0, 0])
    assert got[3] == pytest.approx([15, 0, 0])
    assert laser_poses_on_path(scans, path_ns, path, 5 * S, lambda frame: np.zeros(3))[2] is None  # a gap
    assert laser_poses_on_path(scans, path_ns, path, 10 * S, lambda frame: None) == [None] * 4  # no mount
    assert laser_poses_on_path(scans, path_ns[:0], path[:0], S, lambda frame: None) == [None] * 4
