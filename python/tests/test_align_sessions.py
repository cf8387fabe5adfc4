"""vasco_gpu.align_sessions and load_bag's ``(bag, 'auto')``: a real log split into two sessions
that share part of the route, the second recorded in a frame moved by a rigid transform the
test draws; the transform found must be that one within a map cell (0.1 m) and 0.5 degrees.
Two different buildings must be refused, naming the session."""

from __future__ import annotations

import math

import numpy as np
import pytest

import vasco_gpu as vg
from conftest import FR079, ROOT

INTEL = ROOT / "logs" / "intel.gfs.log.gz"
CELL = 0.1


def split(path):
    """Scans [0, 0.65 n) and [0.35 n, n) of the log (30 % of the route in both), and its params."""
    log = vg.load_log(path)
    n = len(log)
    return log.scans.select(0, n * 65 // 100), log.scans.select(n * 35 // 100), log.params


def inverse(t):
    """T^-1 of a rigid transform (x, y, theta), by 3x3 homogeneous matrices."""
    x, y, a = t
    m = np.array([[math.cos(a), -math.sin(a), x], [math.sin(a), math.cos(a), y], [0, 0, 1]])
    inv = np.linalg.inv(m)
    return inv[0, 2], inv[1, 2], math.atan2(inv[1, 0], inv[0, 0])


def recorded_in(scans, truth):
    """The scans as recorded in a frame F that `truth` takes into the shared frame: what
    align_sessions must find."""
    moved = scans.select(0)
    moved.transform(*inverse(truth))
    return moved


def assert_near(found, truth):
    assert abs(found[0] - truth[0]) <= CELL and abs(found[1] - truth[1]) <= CELL, (found, truth)
    assert abs(math.remainder(found[2] - truth[2], 2 * math.pi)) <= math.radians(0.5), (found, truth)


@pytest.fixture(scope="module")
def intel_halves():
    return split(INTEL)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_finds_the_transform_of_a_second_session(intel_halves, seed):
    first, second, params = intel_halves
    rng = np.random.default_rng(seed)
    truth = (rng.uniform(-20, 20), rng.uniform(-20, 20), rng.uniform(-math.pi, math.pi))
    before = second.poses
    moved = recorded_in(second, truth)
    [r] = vg.align_sessions([first, moved], params=params, threads=2)
    assert r["verdict"] == "aligned" and r["aligned"] == "auto" and r["input"] == "sessions[1]", r
    assert_near(r["transform"], truth)
    assert r["score"] > 0.15 and 0 < r["overlap"] <= 1 and r["matched"] > 0
    assert np.array_equal(second.poses, before)  # the sessions given are not moved


def test_the_reference_given_by_path(intel_halves):
    """A path is read with load_log: the whole intel log as the reference."""
    _, second, params = intel_halves
    truth = (4.0, -3.0, 0.7)
    [r] = vg.align_sessions([INTEL, recorded_in(second, truth)], params=params, threads=2, backend="cpu_threads")
    assert r["input"] == "sessions[1]"
    assert_near(r["transform"], truth)


def test_two_buildings_are_refused_naming_the_session(intel_halves):
    first, _, params = intel_halves
    _, fr079_half, _ = split(FR079)
    with pytest.raises(vg.BadInputError) as e:
        vg.align_sessions([first, fr079_half], params=params, threads=2)
    assert "sessions[1]" in str(e.value) and "best candidate" in str(e.value)
    assert e.value.results[-1]["verdict"] != "aligned"
    [r] = vg.align_sessions([first, fr079_half], params=params, threads=2, refuse=False)
    assert r["verdict"] in ("no_overlap", "ambiguous") and r["input"] == "sessions[1]"


def test_a_refused_session_is_left_out_and_the_next_still_aligned(intel_halves):
    first, second, params = intel_halves
    _, fr079_half, _ = split(FR079)
    truth = (-6.0, 2.5, -2.0)
    fr, intel = vg.align_sessions([first, fr079_half, recorded_in(second, truth)], params=params, threads=2,
                                  refuse=False)
    assert fr["verdict"] != "aligned" and intel["verdict"] == "aligned"
    assert_near(intel["transform"], truth)


def test_a_hint_searches_near_its_guess(intel_halves):
    first, second, params = intel_halves
    truth = (7.0, 1.0, 2.5)
    moved = recorded_in(second, truth)
    near = (truth[0] + 0.3, truth[1] - 0.2, truth[2] + 0.05, 1.0, 0.1)
    [r] = vg.align_sessions([first, moved], params=params, threads=2, hints=[near])
    assert_near(r["transform"], truth)
    # A guess 8 m and a radian off, searched within 1 m and 0.1 rad, cannot reach the truth.
    far = (truth[0] + 8.0, truth[1], truth[2] + 1.0, 1.0, 0.1)
    [r] = vg.align_sessions([first, moved], params=params, threads=2, hints=[far], refuse=False)
    assert r["verdict"] != "aligned"
    with pytest.raises(vg.UsageError):
        vg.align_sessions([first, moved], params=params, hints=[near, near])


def test_given_transforms_place_sessions_before_auto_ones(intel_halves):
    """(session, (x, y, theta)) is placed as given, and the next 'auto' one aligned to both."""
    first, second, params = intel_halves
    given, truth = (1.0, 2.0, 0.3), (-3.0, 5.0, 1.2)
    given_r, auto_r = vg.align_sessions([first, (recorded_in(second, given), given), recorded_in(second, truth)],
                                        params=params, threads=2)
    assert given_r["aligned"] == "given" and given_r["transform"] == given
    assert auto_r["aligned"] == "auto"
    assert_near(auto_r["transform"], truth)
    with pytest.raises(vg.UsageError):
        vg.align_sessions([(first, "auto"), second], params=params)
    with pytest.raises(vg.UsageError):
        vg.align_sessions([first, (second, "near")], params=params)


class _Recording:
    """What write_bag takes of a Log: its scans and their number."""

    def __init__(self, scans):
        self.scans = scans

    def __len__(self):
        return len(self.scans)


def test_load_bag_aligns_an_auto_bag(tmp_path, intel_halves):
    pytest.importorskip("rosbags")
    from vasco_gpu.bags.bag_writer import write_bag

    first, second, _ = intel_halves
    truth = (2.0, -4.0, -1.0)
    a, b = tmp_path / "a.bag", tmp_path / "b.bag"
    write_bag(_Recording(first), a, period=0.1)
    write_bag(_Recording(recorded_in(second, truth)), b, period=0.1)
    both = vg.load_bag(a, add=[(b, "auto")], align={"threads": 2})
    assert len(both) == len(first) + len(second)
    # The second session's poses in the shared frame: the original ones, within the accuracy.
    placed = both.poses[len(first):]
    assert np.abs(placed[:, :2] - second.poses[:, :2]).max() <= 2 * CELL
    far = (tmp_path / "far.bag")
    _, fr079_half, _ = split(FR079)
    write_bag(_Recording(fr079_half), far, period=0.1)
    with pytest.raises(vg.BadInputError, match="far.bag"):
        vg.load_bag(a, add=[(far, "auto")], align={"threads": 2})


def test_the_search_backend_is_chosen_and_checked(intel_halves):
    """cpu_* backends search on the CPU; a search that is not auto, cpu or gpu is a UsageError."""
    first, second, params = intel_halves
    [r] = vg.align_sessions([first, second], params=params, threads=2, backend="cpu_threads")
    assert r["gpu"] is False and r["verdict"] == "aligned"
    assert_near(r["transform"], (0.0, 0.0, 0.0))
    m = vg.Mapper(params, backend="cpu_threads", threads=2)
    m.insert(first.select(0, 50))
    part = m.finish()
    with pytest.raises(vg.UsageError, match="search"):
        vg._core._align_maps(part, part, search="tpu")
