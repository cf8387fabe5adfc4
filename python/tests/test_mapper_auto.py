"""Mapper.insert(scans, transform=...): a session recorded in another frame joins a Mapper's
session, its transform given or found by aligning its scans to the grid the Mapper holds.
intel is split into two sessions sharing part of the route (test_align_sessions' split), the
second recorded in a frame moved by a transform chosen here: "auto" must give it back within a
map cell (0.1 m) and 0.5 degrees, and the map must be the bytes of inserting the scans moved
by Scans.transform (a route that does not pass through insert's transform)."""

from __future__ import annotations

import pytest

import vasco_gpu as vg
from conftest import FR079
from test_align_sessions import INTEL, assert_near, recorded_in, split

TRUTH = (-5.5, 8.0, 1.2)


@pytest.fixture(scope="module")
def halves():
    first, second, params = split(INTEL)
    params.resolution = 0.1  # the alignment's cell: a quick map, the same method
    return first, recorded_in(second, TRUTH), params


def moved_by(scans, t):
    out = scans.select(0)
    out.transform(*t)
    return out


def session(params, *batches):
    m = vg.Mapper(params, backend="cpu_double", threads=2)
    for b in batches:
        m.insert(b)
    return m


def test_auto_finds_the_transform_and_maps_the_scans_there(halves):
    first, second, params = halves
    before = second.poses
    m = session(params, first)
    r = m.insert(second, transform="auto")
    assert r["verdict"] == "aligned" and r["aligned"] == "auto", r
    assert_near(r["transform"], TRUTH)
    assert r["score"] > 0.15 and 0 < r["overlap"] <= 1
    assert len(m) == len(first) + len(second)
    assert (second.poses == before).all()  # the caller's scans are not moved
    # Exact: the bytes of the same scans moved by Scans.transform and inserted as they are.
    assert m.finish().sha256() == session(params, first, moved_by(second, r["transform"])).finish().sha256()


def test_a_given_transform_is_the_scans_moved_first(halves):
    first, second, params = halves
    m = session(params, first)
    assert m.insert(second, transform=TRUTH) is None
    assert m.finish().sha256() == session(params, first, moved_by(second, TRUTH)).finish().sha256()


def test_a_hint_near_the_truth_finds_it(halves):
    first, second, params = halves
    m = session(params, first)
    guess = (TRUTH[0] + 0.4, TRUTH[1] - 0.3, TRUTH[2] + 0.05, 1.0, 0.1)
    r = m.insert(second, transform=("auto", guess))
    assert_near(r["transform"], TRUTH)


def test_another_building_is_refused_and_the_session_is_as_it_was(halves):
    first, _, params = halves
    _, fr079_half, _ = split(FR079)
    m = session(params, first)
    digest = m.finish().sha256()
    with pytest.raises(vg.BadInputError) as e:
        m.insert(fr079_half, transform="auto")
    assert "not aligned" in str(e.value) and "best" in str(e.value) and "Mapper.insert" in str(e.value)
    assert len(m) == len(first) and m.finish().sha256() == digest


def test_auto_needs_scans_to_align_to(halves):
    first, _, params = halves
    m = vg.Mapper(params, backend="cpu_double")
    with pytest.raises(vg.StateError, match="no scans to align to"):
        m.insert(first, transform="auto")
    assert len(m) == 0


@pytest.mark.parametrize("bad", ["left", (1.0, 2.0), ("auto", (1.0, 2.0)), ("auto", (0.0, 0.0, 0.0, -1.0, 0.1)),
                                 (float("nan"), 0.0, 0.0)])
def test_bad_transforms_are_usage_errors_naming_insert(halves, bad):
    first, _, params = halves
    m = session(params, first)
    with pytest.raises(vg.UsageError, match="Mapper.insert"):
        m.insert(first, transform=bad)
    assert len(m) == len(first)
